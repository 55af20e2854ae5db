"""Measurements on the drop of issue 24 with the independent reference (docs/model.md §10).

``PYTHONPATH=. python -m tests.reference.real_bearing_scenes [--t-end 0.3] [--jobs a,b]``
prints one JSON object per job: the drop with the turning race (the issue's scene), with a
fixed race, with a fixed race on a rigid support, the three with the softer Hertz contact
k_c = 3.16e6 N/m (which reproduces the issue's quoted numbers), and the peak normal force of
the first contacts against the integrator's tolerance. Each summary
gives the race catch-up time (first sticking), the spin and race speeds at the end, the whirl
rate of ``z - z_b`` averaged over the last 0.1 s (negative: backward whirl), the contact
count, the peak normal force, the balances' residuals and the wall time.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from typing import Any

import numpy as np

from tests.reference.real_bearing import (
    Result,
    drop_par,
    drop_scene,
    drop_start,
    energy_terms,
    kin,
    momentum_terms,
)


def summary(res: Result, t_end: float, **kw: Any) -> dict[str, Any]:
    """JSON-able figures of a drop run (SI units)."""
    par = drop_par(**kw)
    t = res.t
    ks = [kin(par, y) for y in res.y]
    om = np.array([k.Om for k in ks])
    wb = np.array([k.wb for k in ks])
    thd = np.array([k.thd for k in ks])
    last = t >= t_end - 0.1 - 1e-12
    mean = float(np.mean(thd[last]))
    e = energy_terms(par, drop_start(par), res.y_end)
    L = momentum_terms(par, drop_start(par), res.y_end)
    kend = kin(par, res.y_end)
    stick = res.first("stick")
    return {
        "t_first_contact": res.contacts[0]["t_close"] if res.contacts else None,
        "t_first_stick": stick,
        "Omega_end": kend.Om, "omega_b_end": kend.wb,
        "surface_speeds_end": [par.R * kend.Om, par.R_b * kend.wb],
        "Omega_min": float(om.min()), "omega_b_max": float(wb.max()),
        "whirl_rate_mean_last_0.1s": mean,
        "whirl_rate_min_last_0.1s": float(thd[last].min()),
        "whirl_rate_max_last_0.1s": float(thd[last].max()),
        "minus_R_Omega_over_cr_end": -par.R * kend.Om / par.c_r,
        "minus_R_Omega_over_cr_plus_delta_end": -par.R * kend.Om / (par.c_r + kend.delta),
        "delta_end": kend.delta,
        "mode_end": res.transitions[-1][1],
        "contacts": len(res.contacts),
        "N_peak": res.N_peak,
        "N_peak_time": max(res.peaks, key=lambda p: p[1])[0] if res.peaks else None,
        "E_fric": e["E_fric"], "E_drag": e["E_drag"], "E_sup": e["E_sup"],
        "E_cdamp": e["E_cdamp"],
        "energy_residual_rel": e["residual"] / e["scale"],
        "momentum_residual_rel": L["residual"] / L["scale"] if L["scale"] else 0.0,
        "nfev": res.nfev, "phases": res.phases,
    }


JOBS: dict[str, dict[str, Any]] = {
    "turning": {},
    "fixed": {"race_turns": False},
    "fixed_rigid_support": {"race_turns": False, "support_compliant": False},
    "turning_hertz_3.16e6": {"p_c": 1.5, "k_c": 3.16e6},
    "fixed_hertz_3.16e6": {"race_turns": False, "p_c": 1.5, "k_c": 3.16e6},
    "fixed_rigid_support_hertz_3.16e6": {"race_turns": False, "support_compliant": False,
                                         "p_c": 1.5, "k_c": 3.16e6},
}


def peak_convergence(t_end: float = 0.01) -> dict[str, Any]:
    """Peak normal force of each contact over the first ``t_end`` of the drop at rtol 1e-9 to
    1e-13: the largest relative change against rtol 1e-13 per contact."""
    runs = {rt: drop_scene(t_end=t_end, rtol=rt, n_grid=2) for rt in (1e-9, 1e-10, 1e-11,
                                                                      1e-12, 1e-13)}
    ref = runs[1e-13]
    out: dict[str, Any] = {"t_end": t_end, "contacts": len(ref.contacts),
                           "N_peaks_rtol_1e-13": [c["N_peak"] for c in ref.contacts]}
    for rt, r in runs.items():
        n = min(len(r.contacts), len(ref.contacts))
        dev = max(abs(a["N_peak"] / b["N_peak"] - 1.0)
                  for a, b in zip(r.contacts[:n], ref.contacts[:n], strict=True))
        out[f"rtol_{rt:g}"] = {"contacts": len(r.contacts), "max_rel_dev_peak": dev,
                               "t_first_stick": r.first("stick")}
    return out


def main(argv: list[str] | None = None) -> int:
    """CLI: run the jobs and print their JSON summaries."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--t-end", type=float, default=0.3)
    ap.add_argument("--jobs", default=",".join([*JOBS, "peaks"]))
    args = ap.parse_args(argv)
    for job in args.jobs.split(","):
        t0 = time.perf_counter()
        if job == "peaks":
            out = peak_convergence()
        else:
            kw = JOBS[job]
            res = drop_scene(t_end=args.t_end, n_grid=round(args.t_end * 1e4) + 1, **kw)
            out = summary(res, args.t_end, **kw)
            out["params"] = kw
        out["job"] = job
        out["wall_s"] = round(time.perf_counter() - t0, 1)
        json.dump(out, sys.stdout, default=lambda x: None if math.isnan(x) else x)
        sys.stdout.write("\n")
        sys.stdout.flush()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
