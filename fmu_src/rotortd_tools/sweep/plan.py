"""Planning: the jobs of a sweep, split into independent runs and continuation chains."""

from __future__ import annotations

import json
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

from rotortd_tools.sweep.jobs import Job
from rotortd_tools.sweep.spec import CONTINUATION, SweepSpec


@dataclass
class Plan:
    """What remains to run: independent jobs and continuation chains (ordered jobs)."""

    independent: list[Job]
    chains: list[tuple[list[Job], dict | None]]
    n_total: int
    n_done: int

    @property
    def n_todo(self) -> int:
        """Rows still to compute."""
        return len(self.independent) + sum(len(c) for c, _ in self.chains)


def all_jobs(spec: SweepSpec) -> dict[str, list[Job]]:
    """Jobs per start label, in sweep order (first axis fastest)."""
    points = spec.points()
    out: dict[str, list[Job]] = {}
    for start in spec.starts:
        out[start] = [
            Job(i, tuple(pt.items()), tuple(spec.values_of(pt).items()), start)
            for i, pt in enumerate(points)
        ]
    return out


def chains_of(jobs: list[Job], spec: SweepSpec) -> list[list[Job]]:
    """Split a continuation start's jobs into passes along the first axis (up or down)."""
    n1 = spec.axes[0].n if spec.axes else 1
    passes = [jobs[i:i + n1] for i in range(0, len(jobs), n1)]
    if jobs and jobs[0].start.partition(":")[0] == "down":
        passes = [list(reversed(p)) for p in passes]
    return passes


def make_plan(spec: SweepSpec, done: set[str], states: dict[str, str | None]) -> Plan:
    """Remaining work; a continuation pass resumes after its last finished point."""
    independent: list[Job] = []
    chains: list[tuple[list[Job], dict | None]] = []
    n_total = 0
    for start, jobs in all_jobs(spec).items():
        n_total += len(jobs)
        if start.partition(":")[0] not in CONTINUATION:
            independent += [j for j in jobs if j.key not in done]
            continue
        for chain in chains_of(jobs, spec):
            k = 0
            while k < len(chain) and chain[k].key in done:
                k += 1
            if k < len(chain):
                st = states.get(chain[k - 1].key) if k else None
                chains.append((chain[k:], json.loads(st) if st else None))
    n_todo = len(independent) + sum(len(c) for c, _ in chains)
    return Plan(independent, chains, n_total, n_total - n_todo)



def batches(jobs: Sequence[Job], size: int) -> Iterator[list[Job]]:
    """Consecutive batches of at most ``size`` jobs."""
    for i in range(0, len(jobs), size):
        yield list(jobs[i:i + size])


