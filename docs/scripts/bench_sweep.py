"""Benchmark of ``rotortd sweep``: a 1000-point gamma sweep on one Dask worker versus two.

    python docs/scripts/bench_sweep.py [--points 1000] [--sample 100] [--out docs/sweep_bench.json]

Measured in one process, so the ratios are comparable (absolute times depend on the
machine and on what else runs on it):

- ``direct``: a bare ``TouchdownCore`` run called directly (rest start, the same steps as a
  sweep point: transient 300 + record 100 scaled time, 32 steps per revolution, nothing
  recorded), on every (points/sample)-th point;
- ``run_job``: one sweep point in this process (core run + signature + row), same points;
- ``dask-1``, ``dask-2``: the whole sweep on a LocalCluster of 1 and 2 worker processes
  (``threads_per_worker=1``), results collected as they complete; cluster start-up is timed
  separately and not included.

Writes the figures and ratios to a JSON file and prints them.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import time
from pathlib import Path

from rotortd import TouchdownCore
from rotortd_tools import sweep as sw

SETTINGS = sw.Settings(transient=300.0, record=100.0)


def bare_run(gamma: float, settings: sw.Settings) -> None:
    """The core alone: same parameters, start and steps as a sweep point."""
    p, Omega, _ = sw.point_params({"gamma": gamma})
    core = TouchdownCore(p)
    h = 2.0 * math.pi / (Omega * settings.steps_per_rev)
    n = round((settings.transient + settings.record) * settings.steps_per_rev / (2 * math.pi))
    for _ in range(n):
        core.step(h, Omega)


def time_direct(jobs: list[sw.Job]) -> tuple[float, float]:
    """Mean seconds per point: bare core run, and run_job (core + signature)."""
    t0 = time.perf_counter()
    for job in jobs:
        bare_run(dict(job.point)["gamma"], SETTINGS)
    t1 = time.perf_counter()
    for job in jobs:
        sw.run_job(job, SETTINGS)
    t2 = time.perf_counter()
    return (t1 - t0) / len(jobs), (t2 - t1) / len(jobs)


def time_dask(plan: sw.Plan, workers: int, batch: int) -> tuple[float, float, int]:
    """(start-up s, sweep wall s, rows) on a LocalCluster of ``workers`` processes."""
    rows: list[dict] = []
    t0 = time.perf_counter()
    with sw.dask_client(None, workers) as client:
        client.wait_for_workers(workers)
        t1 = time.perf_counter()
        sw.run_dask(client, plan, SETTINGS, rows.extend, batch=batch, progress=False)
        t2 = time.perf_counter()
    return t1 - t0, t2 - t1, len(rows)


def main() -> None:
    """Run the benchmark and write the JSON report."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=1000)
    ap.add_argument("--sample", type=int, default=100, help="points timed directly")
    ap.add_argument("--batch", type=int, default=4)
    ap.add_argument("--out", type=Path, default=Path("docs/sweep_bench.json"))
    args = ap.parse_args()
    spec = sw.parse_spec([f"gamma=0.05:0.3:{args.points}"], "rest")
    plan = sw.make_plan(spec, set(), {})
    step = max(1, args.points // args.sample)
    direct, per_job = time_direct(plan.independent[::step])
    res: dict = {
        "command": f"rotortd sweep gamma=0.05:0.3:{args.points} --starts rest "
                   "(transient 300, record 100, 32 steps/rev)",
        "machine": {"cpus": os.cpu_count(), "python": platform.python_version()},
        "direct_core_s_per_point": direct,
        "run_job_s_per_point": per_job,
        "sample_points": len(plan.independent[::step]),
    }
    for w in (1, 2):
        start, wall, n = time_dask(plan, w, args.batch)
        res[f"dask_{w}"] = {"startup_s": start, "wall_s": wall, "rows": n,
                            "s_per_point": wall / n}
    res["speedup_2_vs_1"] = res["dask_1"]["wall_s"] / res["dask_2"]["wall_s"]
    res["dask_1_per_point_over_direct"] = res["dask_1"]["s_per_point"] / direct
    res["dask_2_per_point_over_direct"] = res["dask_2"]["s_per_point"] / direct
    res["run_job_over_direct"] = per_job / direct
    args.out.write_text(json.dumps(res, indent=1) + "\n")
    print(json.dumps(res, indent=1))
    print(f"speed-up 2 workers vs 1: {res['speedup_2_vs_1']:.2f}x; cost per point vs a "
          f"direct core run: 1 worker {res['dask_1_per_point_over_direct']:.2f}x, "
          f"2 workers {res['dask_2_per_point_over_direct']:.2f}x "
          f"(signature overhead in-process {res['run_job_over_direct']:.2f}x)")


if __name__ == "__main__":
    main()
