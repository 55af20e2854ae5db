"""Jobs: one run of a sweep (a point from a start) turned into a row, alone or chained."""

from __future__ import annotations

import json
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from rotortd_tools.bearing_args import BEARING_NAMES
from rotortd_tools.sweep.schema import empty_signature
from rotortd_tools.sweep.signature import simulate, simulate_drop
from rotortd_tools.sweep.spec import (
    SCALED_NAMES,
    Settings,
    bearing_params,
    point_params,
    spin_inputs,
)
from rotortd_tools.sweep.starts import NoStart, core_for


@dataclass(frozen=True)
class Job:
    """One run: point index, swept values, all given values, start label."""

    index: int
    point: tuple[tuple[str, float], ...]
    values: tuple[tuple[str, float], ...]
    start: str

    @property
    def key(self) -> str:
        """Identity in the output: swept values (exact repr) and start label."""
        return point_key(dict(self.point), self.start)


def point_key(point: dict[str, float], start: str) -> str:
    """``name=repr(value)`` of the swept values in order, then ``|start``."""
    return ",".join(f"{k}={float(v)!r}" for k, v in point.items()) + "|" + start


def base_row(job: Job, settings: Settings) -> dict[str, Any]:
    """Identity and parameter columns of a job (signature columns empty)."""
    _p, Omega, sp = point_params(dict(job.values))
    row: dict[str, Any] = {"key": job.key, "index": job.index, "start": job.start}
    row.update({k: float(getattr(sp, k)) for k in SCALED_NAMES})
    row["Omega"] = Omega
    J, T_drive = spin_inputs(dict(job.values))
    row["J"] = math.nan if J is None else J
    row["T_drive"] = math.nan if J is None else T_drive
    bp = bearing_params(dict(job.values))
    row.update({n: math.nan if bp is None else float(getattr(bp, n)) for n in BEARING_NAMES})
    row.update({"transient": settings.transient, "record": settings.record})
    return row


def run_job(job: Job, settings: Settings, state: dict | None = None
            ) -> tuple[dict[str, Any], dict | None]:
    """Run one job (from ``state`` if given, else its start); return (row, final state).
    With J the core is a SpinCore driven by T_drive, on the point's real bearing if it has
    one; the ``drop`` start runs the drop."""
    row = base_row(job, settings)
    t0 = time.process_time()
    p, Omega, sp = point_params(dict(job.values))
    J, T_drive = spin_inputs(dict(job.values))
    T = None if J is None else T_drive
    try:
        core = core_for(job.start, p, Omega, sp, state, J, bearing_params(dict(job.values)))
        run = simulate_drop if job.start == "drop" else simulate
        sig = run(core, Omega, settings, T)
        final = core.get_state() if sig["status"] == "ok" else None
    except NoStart as exc:
        sig, final = {"status": "no-start", "message": str(exc)}, None
    except (ValueError, RuntimeError, ArithmeticError) as exc:
        sig, final = {"status": "error", "message": f"{type(exc).__name__}: {exc}"}, None
    row.update(empty_signature())
    row.update(sig)
    if sig["status"] != "ok":
        row["regime"] = "no-start" if sig["status"] == "no-start" else "failed"
    row["final_state"] = json.dumps(final) if final is not None else None
    row["cpu_s"] = time.process_time() - t0
    return row, final



def run_batch(jobs: Sequence[Job], settings: Settings) -> list[dict[str, Any]]:
    """Run independent jobs (a Dask task); rows in job order."""
    return [run_job(job, settings)[0] for job in jobs]


def run_segment(jobs: Sequence[Job], settings: Settings, prev: tuple[list, dict | None]
                ) -> tuple[list[dict[str, Any]], dict | None]:
    """Run a continuation segment (a Dask task) from the previous segment's final state."""
    state = prev[1]
    rows = []
    for job in jobs:
        row, state = run_job(job, settings, state)
        rows.append(row)
    return rows, state


