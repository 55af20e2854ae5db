"""The drop-outcome map over friction mu and spin inertia J (docs/sweeps.md, issue 17).

    PYTHONPATH=fmu_src python docs/scripts/drop_map.py [--n-mu 16] [--n-J 16]
        [--drop-time 0.4] [--drop-window 0.1] [--workers 2] [--out /tmp/drop_map.parquet]

Runs, through the sweep machinery on a Dask LocalCluster (``rotortd_tools.sweep.run_sweep``),
the equivalent of

    rotortd sweep mu=0.02:0.5:log16 J=3.2e-4:1.6:log16 --starts drop \\
        --drop-time 0.4 --drop-window 0.1 --drop-step 1e-4 --workers 2 --out OUT

The rotor (chapter set, Omega0 = 184.2 rad/s, SpinCore with inertia J in kg m^2, T_drive =
0) starts on the levitated steady whirl and drops when the bearing fails (amb_on = 0, g =
9.81 m/s^2); the last window is classified (``classify_drop``). J spans from just above the
well-posedness bound at mu = 0.5 (m mu e_c (R + e_c) = 3.02e-4 kg m^2) to 20 m R^2 = 1.6
kg m^2. Writes docs/img/drop_map.png (``rotortd sweep-plot``'s drop map) and
docs/drop_map.json (the grid, the run time, and per point mu, J, outcome, window means).
The output directory resumes like any sweep (rerun to finish an interrupted run).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import time
from pathlib import Path

from rotortd_tools import sweep as sw
from rotortd_tools.sweep_plot import plot_sweep

ROOT = Path(__file__).resolve().parents[2]
MU = (0.02, 0.5)
J = (3.2e-4, 1.6)
KEEP = ("mu", "J", "regime", "Omega_mean", "whirl_mean", "slip_ratio", "contact_frac",
        "roll_frac", "n_impacts", "Omega_end", "cpu_s")


def main() -> None:
    """Run the sweep, draw the map, write the JSON summary."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n-mu", type=int, default=16)
    ap.add_argument("--n-J", type=int, default=16)
    ap.add_argument("--drop-time", type=float, default=0.4, help="s")
    ap.add_argument("--drop-window", type=float, default=0.1, help="s")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", type=Path, default=Path("/tmp/drop_map.parquet"))
    ap.add_argument("--img", type=Path, default=ROOT / "docs/img/drop_map.png")
    ap.add_argument("--json", type=Path, default=ROOT / "docs/drop_map.json")
    args = ap.parse_args()
    tokens = [f"mu={MU[0]}:{MU[1]}:log{args.n_mu}", f"J={J[0]}:{J[1]}:log{args.n_J}"]
    spec = sw.parse_spec(tokens, "drop")
    settings = sw.Settings(drop_time=args.drop_time, drop_window=args.drop_window)
    t0 = time.perf_counter()
    counts = sw.run_sweep(spec, settings, args.out, workers=args.workers, batch=2)
    wall = time.perf_counter() - t0
    plot_sweep(args.out, args.img)
    data = sw.read_sweep(args.out)
    order = sorted(range(len(data["key"])), key=lambda i: (data["J"][i], data["mu"][i]))
    rows = [{k: _num(data[k][i]) for k in KEEP} for i in order]
    outcomes: dict[str, int] = {}
    for r in rows:
        outcomes[r["regime"]] = outcomes.get(r["regime"], 0) + 1
    doc = {
        "command": "rotortd sweep " + " ".join(tokens) + " --starts drop "
                   f"--drop-time {args.drop_time} --drop-window {args.drop_window} "
                   f"--drop-step {settings.drop_step} --workers {args.workers}",
        "grid": {"mu": list(spec.axes[0].values), "J": list(spec.axes[1].values)},
        "settings": {"drop_time_s": settings.drop_time, "drop_window_s": settings.drop_window,
                     "drop_step_s": settings.drop_step, "Omega0_rad_s": data["Omega"][0]},
        "counts": counts,
        "wall_s_this_run": round(wall, 1),
        "cpu_s_sum": round(sum(data["cpu_s"]), 1),
        "cpu_s_max": round(max(data["cpu_s"]), 2),
        "workers": args.workers,
        "machine": {"cpus": os.cpu_count(), "python": platform.python_version(),
                    "load_avg_at_end": [round(v, 2) for v in os.getloadavg()]},
        "outcomes": outcomes,
        "points": rows,
    }
    args.json.write_text(json.dumps(doc, indent=1) + "\n")
    print(f"{counts}; wall {wall:.1f} s, CPU {doc['cpu_s_sum']} s; outcomes {outcomes}")
    print(f"wrote {args.img} and {args.json}")


def _num(v: object) -> object:
    """JSON-safe value: floats rounded to 6 significant digits, NaN as None."""
    if isinstance(v, float):
        return None if math.isnan(v) else float(f"{v:.6g}")
    return v


if __name__ == "__main__":
    main()
