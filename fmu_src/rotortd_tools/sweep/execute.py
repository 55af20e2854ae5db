"""Running a planned sweep: serially, or on a Dask cluster (local processes or remote)."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from rotortd_tools.sweep.jobs import run_batch, run_job, run_segment
from rotortd_tools.sweep.plan import Plan, batches, make_plan
from rotortd_tools.sweep.spec import Settings, SweepSpec
from rotortd_tools.sweep.store import ParquetSink, prepare_output


def run_serial(plan: Plan, settings: Settings, sink: Callable[[list[dict]], Any]) -> None:
    """Run a plan in this process (reference for the Dask run; same rows, same numbers)."""
    for job in plan.independent:
        sink([run_job(job, settings)[0]])
    for chain, state in plan.chains:
        for job in chain:
            row, state = run_job(job, settings, state)
            sink([row])


def submit_plan(client: Any, plan: Plan, settings: Settings, batch: int, chunk: int) -> list:
    """Submit the plan to a Dask client: batches of independent jobs and chained segments."""
    futures = [
        client.submit(run_batch, b, settings, pure=False)
        for b in batches(plan.independent, batch)
    ]
    for chain, state in plan.chains:
        prev: Any = ([], state)
        for seg in batches(chain, chunk):
            prev = client.submit(run_segment, seg, settings, prev, pure=False)
            futures.append(prev)
    return futures


def run_dask(client: Any, plan: Plan, settings: Settings, sink: Callable[[list[dict]], Any],
             batch: int = 4, chunk: int = 8, progress: bool = True) -> None:
    """Run a plan on a Dask client; rows go to ``sink`` as tasks complete."""
    from dask.distributed import as_completed
    from tqdm import tqdm

    futures = submit_plan(client, plan, settings, batch, chunk)
    with tqdm(total=plan.n_todo, disable=not progress, unit="run", smoothing=0.05) as bar:
        for fut in as_completed(futures):
            res = fut.result()
            rows = res[0] if isinstance(res, tuple) else res
            sink(rows)
            bar.update(len(rows))


@contextlib.contextmanager
def dask_client(scheduler: str | None = None, workers: int | None = None) -> Iterator[Any]:
    """A client on ``scheduler`` (an existing cluster) or on a new LocalCluster of processes."""
    from dask.distributed import Client, LocalCluster

    if scheduler:
        with Client(scheduler) as client:
            yield client
        return
    n = workers or os.cpu_count() or 1
    with LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        yield client


def run_sweep(spec: SweepSpec, settings: Settings, out: Path | str, *,
              scheduler: str | None = None, workers: int | None = None,
              serial: bool = False, overwrite: bool = False, batch: int = 4,
              chunk: int = 8, progress: bool = True, flush_s: float = 2.0
              ) -> dict[str, int]:
    """Run (or resume) a sweep into the Parquet directory ``out``; return row counts."""
    settings.validate()
    out = Path(out)
    prepare_output(out, spec, settings, overwrite)
    sink = ParquetSink(out, flush_s=flush_s)
    ex = sink.existing or {}
    states = dict(zip(ex.get("key", []), ex.get("final_state", [])))
    plan = make_plan(spec, sink.done, states)
    try:
        if plan.n_todo == 0:
            pass
        elif serial:
            run_serial(plan, settings, sink.add)
        else:
            with dask_client(scheduler, workers) as client:
                run_dask(client, plan, settings, sink.add, batch, chunk, progress)
    finally:
        sink.flush()
    return {"total": plan.n_total, "resumed": plan.n_done, "computed": plan.n_todo}
