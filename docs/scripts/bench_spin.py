"""Cost of the spin as a state: the drop into dry whirl through FMPy, and per contact mode.

    python docs/scripts/bench_spin.py               # ~3 min (timing + callgrind)
    python docs/scripts/bench_spin.py --no-valgrind # timing only

1. Timed, one process: ``fmpy.simulate_fmu`` runs the drop into dry whirl (the chapter's
   rotor with g = 9.81, J = m R^2/2 = 0.04 kg m^2, integrate_spin, from the levitated
   steady whirl at 184.2 rad/s with the bearing failed from t = 0) for 0.3 s at the
   communication step 1e-4 s, and the same on the floor FMU (benchmarks.py: the same
   variables, a do_step that does nothing). Median of --repeats runs each, alternating;
   prints the ratio FMU/floor (the issue's target: at most 10) and the CPU per simulated
   second.
2. Instructions (valgrind callgrind, deterministic) per 1e-4 s step of ``SpinCore.step``
   in each kind of segment: free flight in closed form (bearing off, the imbalance orbit
   inside the clearance), free flight integrated (bearing on, the levitated whirl), sliding
   (pressed to the wall by F_ext with a drive torque balancing the friction) and rolling
   (dry whirl, after the drop), each as the difference of two runs of different length
   after the same warm-up, so start-up and warm-up cancel. The child is
   bench_instructions.py's SPIN_CHILD, which ``bench_instructions.py --base`` also counts
   on both trees.
Writes docs/bench_spin.json; docs/benchmarks.md quotes it.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import bench_instructions as BI  # noqa: E402 (docs/scripts: callgrind, SPIN_CHILD)
import benchmarks as B  # noqa: E402 (docs/scripts: the FMU builds and the floor FMU)
from rotortd import RotorParams, TouchdownCore  # noqa: E402

OUT = B.ROOT / "docs" / "bench_spin.json"
H, T_END, OMEGA0 = 1e-4, 0.3, 184.2
P = RotorParams(g=9.81)
J_HALF = 0.5 * P.m * P.R ** 2


def drop_start_values() -> dict[str, Any]:
    """FMU start values of the drop: the levitated whirl's state, bearing failed."""
    held = TouchdownCore.on_steady_whirl(P, OMEGA0)
    return {"g": P.g, "integrate_spin": True, "J": J_HALF, "Omega": OMEGA0, "amb_on": 0.0,
            "x0": held.z.real, "y0": held.z.imag, "vx0": held.v.real, "vy0": held.v.imag}


def simulate(fmu: tuple[str, Any]) -> tuple[float, np.ndarray]:
    """CPU seconds of one simulate_fmu run of the drop, and its output rows."""
    from fmpy import simulate_fmu

    unzip, md = fmu
    t0 = time.process_time()
    res = simulate_fmu(unzip, validate=False, model_description=md, stop_time=T_END,
                       output_interval=H, start_values=drop_start_values(),
                       output=[*B.ALL_OUT, "Omega_out"])
    return time.process_time() - t0, res


def timed(repeats: int) -> dict[str, Any]:
    with tempfile.TemporaryDirectory() as tmp:
        fmus = B.build_fmus(Path(tmp))
        fmu, floor = fmus["RotorTouchdown"], fmus["RotorTouchdownFloor"]
        t_fmu, t_floor = [], []
        for _ in range(repeats):
            cpu, res = simulate(fmu)
            t_fmu.append(cpu)
            t_floor.append(simulate(floor)[0])
    modes = res["mode"]
    first_roll = float(res["time"][int(np.argmax(modes == 2))])
    out = {"fmu_cpu_s": t_fmu, "floor_cpu_s": t_floor,
           "ratio": statistics.median(t_fmu) / statistics.median(t_floor),
           "fmu_cpu_per_simulated_s": statistics.median(t_fmu) / T_END,
           "steps": round(T_END / H), "first_rolling_s": first_roll,
           "Omega_end": float(res["Omega_out"][-1]),
           "rolling_at_every_step_after": bool(np.all(modes[modes.argmax():] == 2))}
    print(f"drop into dry whirl, {out['steps']} steps of {H:g} s: FMU "
          f"{statistics.median(t_fmu):.3f} s CPU, floor {statistics.median(t_floor):.3f} s; "
          f"FMU/floor = {out['ratio']:.2f} "
          f"(target <= 10); {out['fmu_cpu_per_simulated_s']:.2f} s CPU per simulated second")
    return out


def instructions() -> dict[str, float]:
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        script = Path(tmp) / "child.py"
        script.write_text(BI.SPIN_CHILD)
        src = str(B.ROOT / "fmu_src")
        for kind in BI.SPIN_KINDS:
            out[kind] = BI.per_unit(script, [src, kind], *BI.SPIN_STEPS[kind])
            print(f"{kind:>18}: {out[kind] / 1e3:9.1f} k instructions per 1e-4 s step")
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--no-valgrind", action="store_true")
    args = ap.parse_args()
    result = {"timed": timed(args.repeats)}
    if not args.no_valgrind:
        result["instructions_per_step"] = instructions()
    OUT.write_text(json.dumps(result, indent=1) + "\n")
    print(f"wrote {OUT.relative_to(B.ROOT)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
