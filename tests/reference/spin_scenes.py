"""Drop scene of the spin reference: bearing failure from the levitated steady whirl.

The chapter rotor (m = 50 kg, c = 1400 N s/m, k = 9.8e5 N/m, e_c = 0.3 mm, phi = 0.21,
c_r = 0.7 mm, R = 40 mm, mu = 0.15, d = 0.95, g = 9.81 m/s^2, levitated) whirls steadily at
Omega0 = 184.2 rad/s with the bearing on; the bearing fails at t = 0 (a = 0 for the run,
F_ext = 0, T_drive = 0) and the rotor with the spin as a state (J = 0.5 m R^2 and 5 m R^2) drops
into the touchdown bearing.

CLI: ``PYTHONPATH=fmu_src python -m tests.reference.spin_scenes [--t-end 0.3]`` prints a JSON
summary per J: times [s] of the first impact, of entering sustained contact and rolling; Omega
[rad/s] at t = 0.1, 0.2, 0.3 s and its mean over the last 0.1 s; counts and run time.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from typing import Any

import numpy as np

from tests.reference.spin_reference import SpinResult, simulate, steady_whirl_start

OMEGA0 = 184.2
CHAPTER_G: dict[str, Any] = {
    "m": 50.0, "c": 1400.0, "k": 9.8e5, "e_c": 0.3e-3, "phi": 0.21, "c_r": 0.7e-3, "R": 0.04,
    "mu": 0.15, "d": 0.95, "g": 9.81, "levitate": True,
}


def drop_scene(J: float, t_end: float = 0.3, n_grid: int = 3001, rtol: float = 1e-12
               ) -> SpinResult:
    """Run the drop from the levitated steady whirl (psi0 = 0) with a = 0; grid step t_end/(n-1)."""
    z0, v0 = steady_whirl_start(CHAPTER_G, OMEGA0, a=1.0)
    grid = np.linspace(0.0, t_end, n_grid)
    return simulate(CHAPTER_G, J, OMEGA0, z0, v0, 0.0, t_end, grid, a=0.0, rtol=rtol)


def summary(res: SpinResult, t_end: float) -> dict[str, Any]:
    """JSON-able summary of a drop run (times in s, speeds in rad/s)."""
    s = res.samples
    t, om = s["t"], s["Omega"]

    def at(tq: float) -> float | None:
        if tq > t_end + 1e-12:
            return None
        return float(om[int(np.argmin(np.abs(t - tq)))])

    last = t >= t_end - 0.1 - 1e-12
    contact = next((tt for tt, nm in res.transitions if nm in ("sliding", "rolling")), None)
    return {
        "t_first_impact": res.impacts[0]["t"] if res.impacts else None,
        "t_sustained_contact": contact,
        "t_rolling": res.first_time("rolling"),
        "Omega_0.1": at(0.1), "Omega_0.2": at(0.2), "Omega_0.3": at(0.3),
        "Omega_mean_last_0.1s": float(np.trapezoid(om[last], t[last]) / (t[last][-1] - t[last][0])),
        "impacts": len(res.impacts),
        "plastic_impacts": sum(bool(i["plastic"]) for i in res.impacts),
        "capped_impacts": sum(bool(i["capped"]) for i in res.impacts),
        "transitions": [[tt, nm] for tt, nm in res.transitions],
        "final_mode": res.mode,
        "final_theta_dot_over_minus_R_Omega_per_c_r": (
            float(s["theta_dot"][-1] / (-CHAPTER_G["R"] * om[-1] / CHAPTER_G["c_r"]))
            if om[-1] != 0 else None),
        "E_impacts_J": res.E_impacts, "E_friction_J": res.E_friction,
        "status": res.status, "nfev": res.nfev,
    }


def main(argv: list[str] | None = None) -> int:
    """CLI entry point: print the JSON summary for J = 0.5 m R^2 and 5 m R^2."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--t-end", type=float, default=0.3, help="end time [s] (default 0.3)")
    args = ap.parse_args(argv)
    m, R = CHAPTER_G["m"], CHAPTER_G["R"]
    out: dict[str, Any] = {"Omega0": OMEGA0, "t_end": args.t_end, "runs": {}}
    for label, factor in (("J=0.5mR^2", 0.5), ("J=5mR^2", 5.0)):
        J = factor * m * R * R
        t0 = time.perf_counter()
        res = drop_scene(J, args.t_end)
        summ = summary(res, args.t_end)
        summ["J"] = J
        summ["wall_s"] = round(time.perf_counter() - t0, 2)
        out["runs"][label] = summ
    json.dump(out, sys.stdout, indent=1, default=lambda x: None if math.isnan(x) else x)
    sys.stdout.write("\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
