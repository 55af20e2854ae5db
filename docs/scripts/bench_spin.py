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
3. Instructions (callgrind) per 1e-4 s FMU step of the quiet step with the spin as a state
   (integrate_spin, the levitated whirl, bearing on), RotorTouchdown against the floor FMU
   in the same FMU2Slave loop (every output read every step), with the inputs held and
   with T_drive set before every step by a PI drive on Omega_out (QUIET_PI); the issue's
   goal is a ratio of at most 1.5 (``--quiet-only`` counts only these).
4. Timed (``--bearing``): the drop onto the real bearing of issue 24 (the options of
   docs/model.md §10 on: the race turns, the support gives, the contact is compliant with
   k_c = 1e9 N/m; mu = 0.15, d = 0.9), 3000 steps of 1e-4 s through simulate_fmu, against
   the floor FMU (issue 24's target: at most 10x), and the FMU's CPU per simulated second
   over the first 0.1 s at k_c = 1e8 ... 1e11 N/m (docs/img/bearing_cost_kc.png).
5. Timed (``--speeds``): the drop of 1. from the levitated whirl at Omega0 = 184.2, 1000
   and 3000 rad/s (issue 26 item 4: at most 5x the floor at every speed), FMU against the
   floor, the median of --repeats pair ratios (alternating), and CPU per simulated second
   against Omega0 (docs/img/dry_whirl_drop_speeds.png).
Writes docs/bench_spin.json; docs/benchmarks.md quotes it.
"""

from __future__ import annotations

import argparse
import json
import os
import pickle
import statistics
import subprocess
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

FMU_CHILD = '''
import pickle, sys
from fmpy.fmi2 import FMU2Slave
D = pickle.load(open(sys.argv[1], "rb"))
f, pi, n = D[sys.argv[2]], sys.argv[3] == "pi", int(sys.argv[4])
vr, h = f["vr"], D["h"]
fmu = FMU2Slave(guid=f["guid"], unzipDirectory=f["unzip"], modelIdentifier=f["mid"],
                instanceName="count")
fmu.instantiate()
for name, val in D["start"].items():
    if name not in vr:  # (the floor has no integrate_spin)
        continue
    if isinstance(val, bool):
        fmu.setBoolean([vr[name]], [val])
    else:
        fmu.setReal([vr[name]], [float(val)])
fmu.setupExperiment(startTime=0.0)
fmu.enterInitializationMode()
fmu.exitInitializationMode()
rv, iv, bv = ([vr[x] for x in names] for names in D["outputs"])
kT, iW = [vr["T_drive"]], len(rv) - 1  # Omega_out is read last
W_ref, kp, ki = D["pi"]
W, integral = D["start"]["Omega"], 0.0
for j in range(n):
    if pi:  # a PI drive: T_drive from the speed error, set before every step
        e = W_ref - W
        integral += e * h
        fmu.setReal(kT, [kp * e + ki * integral])
    fmu.doStep(j * h, h)
    W = fmu.getReal(rv)[iW]
    fmu.getInteger(iv)
    fmu.getBoolean(bv)
fmu.terminate()
fmu.freeInstance()
'''
QUIET_PI = (OMEGA0 + 1.0, 0.05, 2.0)
"""The PI drive of the quiet spin-state count: (W_ref rad/s, k_p N m s, k_i N m)."""


def quiet_start_values() -> dict[str, Any]:
    """FMU start values of the quiet spin-state step: the chapter's rotor with gravity,
    levitated (bearing on) on its steady whirl at OMEGA0, the spin a state (J = m R^2/2)."""
    return {"g": P.g, "integrate_spin": True, "J": J_HALF, "Omega": OMEGA0, "amb_on": 1.0,
            "start_steady": True}


def quiet_fmu_steps() -> dict[str, Any]:
    """Instructions per 1e-4 s FMU step (callgrind, FMPy's FMU2Slave loop, every output
    read every step) of the quiet spin-state step, RotorTouchdown against the floor FMU
    (benchmarks.py), with the inputs held and with T_drive set by a PI drive before every
    step; each the difference of a 1100- and a 100-step run, under each memory layout of
    ``bench_instructions.LAYOUT_PADS``: the medians, the ratio's range, every layout's."""
    out: dict[str, Any] = {}
    with tempfile.TemporaryDirectory() as tmp:
        count = _fmu_child(Path(tmp), quiet_start_values())
        for drive in ("held", "pi"):
            lays = []
            for pad in BI.LAYOUT_PADS:
                fmu, floor = (count(w, drive, pad) for w in ("fmu", "floor"))
                lays.append({"pad": pad, "fmu": fmu, "floor": floor, "ratio": fmu / floor})
                print(f"quiet spin-state step, T_drive {drive:>4s}, layout {pad:5d}: "
                      f"RotorTouchdown {fmu / 1e3:7.1f}k, floor {floor / 1e3:7.1f}k "
                      f"instructions per FMU step, ratio {fmu / floor:.3f}", flush=True)
            ratios = [lay["ratio"] for lay in lays]
            out[drive] = {"fmu": statistics.median(lay["fmu"] for lay in lays),
                          "floor": statistics.median(lay["floor"] for lay in lays),
                          "ratio": statistics.median(ratios), "ratio_min": min(ratios),
                          "ratio_max": max(ratios), "goal": 1.5, "layouts": lays}
            print(f"quiet spin-state step, T_drive {drive:>4s}: ratio {out[drive]['ratio']:.3f} "
                  f"(median of {len(lays)} layouts, {min(ratios):.3f} to {max(ratios):.3f}; "
                  f"goal <= 1.5)", flush=True)
    return out


def _fmu_child(tmp: Path, start: dict[str, Any], steps: tuple[int, int] = (100, 1100)
               ) -> Any:
    """Build both FMUs into tmp and set up FMU_CHILD from ``start``; return
    ``count(which, drive)``: instructions per FMU step of "fmu" or "floor" with T_drive
    "held" or set by the "pi" drive (the difference of two runs of ``steps`` steps)."""
    fmus = B.build_fmus(tmp)
    data: dict[str, Any] = {"h": H, "start": start, "pi": QUIET_PI,
                            "outputs": ([*B.REAL_OUT, "Omega_out"], B.INT_OUT, B.BOOL_OUT)}
    for key, name in (("fmu", "RotorTouchdown"), ("floor", "RotorTouchdownFloor")):
        unzip, md = fmus[name]
        data[key] = {"unzip": unzip, "guid": md.guid, "mid": md.coSimulation.modelIdentifier,
                     "vr": {v.name: v.valueReference for v in md.modelVariables}}
    pkl = tmp / "child.pkl"
    pkl.write_bytes(pickle.dumps(data))
    script = tmp / "fmu_child.py"
    script.write_text(FMU_CHILD)
    env = {**os.environ, **BI.SINGLE_THREAD}
    for w in ("fmu", "floor"):  # a 0-step run first: the bytecode caches written, so the
        subprocess.run([sys.executable, str(script), str(pkl), w, "held", "0"],  # counted
                       env=env, check=True, capture_output=True)  # runs start alike
    return lambda which, drive, pad=0: BI.per_unit(script, [str(pkl), which, drive], *steps,
                                                   BI.layout_env(pad))


def rolling_fmu_steps() -> tuple[float, float]:
    """Instructions per FMU step in FMU_CHILD's loop (every output read) of RotorTouchdown
    and of the floor FMU, in the drop from 1000 rad/s over its steps 1500 to 2000 (rolling
    at about 330 rad/s): the floor's step that issue 26 compares a rolling step with, and
    the FMU's (``bench_dry_whirl_speed.py``)."""
    with tempfile.TemporaryDirectory() as tmp:
        count = _fmu_child(Path(tmp), drop_start_values(1000.0), (1500, 2000))
        return count("fmu", "held"), count("floor", "held")


def drop_start_values(omega0: float = OMEGA0) -> dict[str, Any]:
    """FMU start values of the drop: the levitated whirl's state at omega0 (rad/s), bearing
    failed."""
    held = TouchdownCore.on_steady_whirl(P, omega0)
    return {"g": P.g, "integrate_spin": True, "J": J_HALF, "Omega": omega0, "amb_on": 0.0,
            "x0": held.z.real, "y0": held.z.imag, "vx0": held.v.real, "vy0": held.v.imag}


def simulate(fmu: tuple[str, Any], omega0: float = OMEGA0) -> tuple[float, np.ndarray]:
    """CPU seconds of one simulate_fmu run of the drop from omega0 (rad/s), and its rows."""
    from fmpy import simulate_fmu

    unzip, md = fmu
    t0 = time.process_time()
    res = simulate_fmu(unzip, validate=False, model_description=md, stop_time=T_END,
                       output_interval=H, start_values=drop_start_values(omega0),
                       output=[*B.ALL_OUT, "Omega_out"])
    return time.process_time() - t0, res


def alternate(run: Any, fmu: Any, floor: Any, repeats: int
              ) -> tuple[list[float], list[float], Any]:
    """``repeats`` pairs of ``run`` (-> (CPU s, rows)) on the FMU then the floor, alternating
    so that each pair shares the machine's phase: (FMU CPU s, floor CPU s, the last FMU
    rows)."""
    t_fmu, t_floor, res = [], [], None
    for _ in range(repeats):
        cpu, res = run(fmu)
        t_fmu.append(cpu)
        t_floor.append(run(floor)[0])
    return t_fmu, t_floor, res


SPEEDS = (184.2, 1000.0, 3000.0)
"""Issue 26's drop speeds Omega0 (rad/s)."""


def timed_speeds(repeats: int) -> dict[str, Any]:
    """Issue 26 item 4: the drop into dry whirl from the levitated whirl at each of SPEEDS,
    FMU against the floor (median of ``repeats`` pair ratios, alternating), with the
    fraction of steps in rolling."""
    out: dict[str, Any] = {}
    with tempfile.TemporaryDirectory() as tmp:
        fmus = B.build_fmus(Path(tmp))
        fmu, floor = fmus["RotorTouchdown"], fmus["RotorTouchdownFloor"]
        for w in SPEEDS:
            t_fmu, t_floor, res = alternate(lambda f, w=w: simulate(f, w), fmu, floor, repeats)
            ratio = statistics.median(a / b for a, b in zip(t_fmu, t_floor))
            rolling = float(np.mean(res["mode"] == 2))
            out[f"{w:g}"] = {"fmu_cpu_s": t_fmu, "floor_cpu_s": t_floor, "ratio": ratio,
                             "fmu_cpu_per_simulated_s": statistics.median(t_fmu) / T_END,
                             "floor_cpu_per_simulated_s": statistics.median(t_floor) / T_END,
                             "rolling_fraction": rolling,
                             "Omega_end": float(res["Omega_out"][-1])}
            print(f"drop into dry whirl from Omega0 = {w:g} rad/s: FMU "
                  f"{statistics.median(t_fmu):.3f} s CPU, floor "
                  f"{statistics.median(t_floor):.3f} s, FMU/floor {ratio:.2f} (issue 26's "
                  f"target <= 5); rolling in {rolling:.0%} of the steps, Omega at "
                  f"{T_END:g} s {out[f'{w:g}']['Omega_end']:.1f} rad/s", flush=True)
    return out


def plot_speeds(out: dict[str, Any]) -> Path:
    """docs/img/dry_whirl_drop_speeds.png: CPU per simulated second against Omega0."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ws = [float(w) for w in out]
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.loglog(ws, [r["fmu_cpu_per_simulated_s"] for r in out.values()], "o-",
              label="RotorTouchdown, the drop into dry whirl")
    floor = [r["floor_cpu_per_simulated_s"] for r in out.values()]
    ax.loglog(ws, floor, "s--", color="grey", label="floor FMU")
    ax.loglog(ws, [5 * f for f in floor], ":", color="grey", label="5 x floor (issue 26's target)")
    ax.set_xticks(ws, [f"{w:g}" for w in ws])  # (the speeds measured; no minor labels)
    ax.xaxis.set_minor_formatter(plt.NullFormatter())
    return _save_cost_plot(fig, ax, "rotor speed at the drop, Omega0 [rad/s]",
                           f"{T_END:g} s from the levitated whirl, step {H:g} s, FMPy",
                           "dry_whirl_drop_speeds.png")


def _save_cost_plot(fig: Any, ax: Any, xlabel: str, title: str, name: str) -> Path:
    """Label a CPU-per-simulated-second plot; write it as ``name`` in the docs image folder."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel("CPU seconds per simulated second")
    ax.set_title(title)
    ax.legend(fontsize=8)
    fig.tight_layout()
    path = B.ROOT / "docs" / "img" / name
    fig.savefig(path, dpi=110)
    return path


def timed(repeats: int) -> dict[str, Any]:
    with tempfile.TemporaryDirectory() as tmp:
        fmus = B.build_fmus(Path(tmp))
        fmu, floor = fmus["RotorTouchdown"], fmus["RotorTouchdownFloor"]
        t_fmu, t_floor, res = alternate(simulate, fmu, floor, repeats)
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


BEARING = {"mu": 0.15, "d": 0.9, "race_turns": True, "J_b": 2e-4, "T_b0": 0.02,
           "c_bw": 1e-5, "omega_b0": 0.0, "support_compliant": True, "m_b": 2.0, "k_b": 5e7,
           "c_b": 2e3, "contact_compliant": True, "k_c": 1e9, "p_c": 1.0}
"""The real bearing of issue 24's drop (docs/model.md §10)."""
K_C_SWEEP = (1e8, 1e9, 1e10, 1e11)
T_SWEEP = 0.1


def simulate_bearing(fmu: tuple[str, Any], t_end: float, k_c: float) -> tuple[float, Any]:
    """CPU seconds of one simulate_fmu run of the drop onto the real bearing, its rows."""
    from fmpy import simulate_fmu

    unzip, md = fmu
    t0 = time.process_time()
    res = simulate_fmu(unzip, validate=False, model_description=md, stop_time=t_end,
                       output_interval=H,
                       start_values={**drop_start_values(), **BEARING, "k_c": k_c},
                       output=[*B.ALL_OUT, "Omega_out", "omega_b"])
    return time.process_time() - t0, res


def timed_bearing(repeats: int) -> dict[str, Any]:
    """The drop onto the real bearing, 3000 steps, FMU against the floor (median of
    ``repeats``, alternating), and the FMU's cost against k_c over T_SWEEP s."""
    with tempfile.TemporaryDirectory() as tmp:
        fmus = B.build_fmus(Path(tmp))
        fmu, floor = fmus["RotorTouchdown"], fmus["RotorTouchdownFloor"]
        t_fmu, t_floor, res = alternate(
            lambda f: simulate_bearing(f, T_END, BEARING["k_c"]), fmu, floor, repeats)
        sweep = {}
        for k_c in K_C_SWEEP:
            sweep[f"{k_c:g}"] = simulate_bearing(fmu, T_SWEEP, k_c)[0] / T_SWEEP
            print(f"k_c = {k_c:g} N/m: {sweep[f'{k_c:g}']:.2f} s CPU per simulated second")
    out = {"fmu_cpu_s": t_fmu, "floor_cpu_s": t_floor,
           "ratio": statistics.median(t_fmu) / statistics.median(t_floor),
           "steps": round(T_END / H), "Omega_end": float(res["Omega_out"][-1]),
           "omega_b_end": float(res["omega_b"][-1]),
           "F_n_peak_max": float(res["F_n_peak"].max()),
           "cpu_per_simulated_s_vs_k_c": sweep, "sweep_span_s": T_SWEEP}
    print(f"drop onto the real bearing, {out['steps']} steps of {H:g} s: FMU "
          f"{statistics.median(t_fmu):.3f} s CPU, floor {statistics.median(t_floor):.3f} s; "
          f"FMU/floor = {out['ratio']:.1f} (issue 24's target <= 10)")
    return out


def plot_bearing_cost(out: dict[str, Any]) -> Path:
    """docs/img/bearing_cost_kc.png: CPU per simulated second against k_c."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ks = [float(k) for k in out["cpu_per_simulated_s_vs_k_c"]]
    cpu = list(out["cpu_per_simulated_s_vs_k_c"].values())
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.loglog(ks, cpu, "o-", label="RotorTouchdown, the drop onto the real bearing")
    floor = statistics.median(out["floor_cpu_s"]) / T_END
    ax.axhline(floor, color="grey", ls="--", label="floor FMU")
    ax.axhline(10 * floor, color="grey", ls=":", label="10 x floor (issue 24's target)")
    return _save_cost_plot(fig, ax, "contact stiffness k_c at 10 um [N/m]",
                           f"first {out['sweep_span_s']:g} s of the drop, step 1e-4 s, FMPy",
                           "bearing_cost_kc.png")


def instructions() -> dict[str, float]:
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        script = Path(tmp) / "child.py"
        script.write_text(BI.SPIN_CHILD)
        src = str(B.ROOT / "fmu_src")
        for kind in BI.SPIN_KINDS:
            subprocess.run([sys.executable, str(script), src, kind, "0"], check=True)  # (pyc)
            out[kind] = BI.per_unit(script, [src, kind], *BI.SPIN_STEPS[kind])
            print(f"{kind:>18}: {out[kind] / 1e3:9.1f} k instructions per 1e-4 s step")
    return out


def _into_existing(key: str, measure: Any, plot: Any) -> int:
    """Only one part of the run: its result into docs/bench_spin.json under ``key`` (the
    other parts kept), and its plot when it has one."""
    result = json.loads(OUT.read_text()) if OUT.exists() else {}
    result[key] = part = measure()
    OUT.write_text(json.dumps(result, indent=1) + "\n")
    plotted = f" and {plot(part).relative_to(B.ROOT)}" if plot else ""
    print(f"wrote {OUT.relative_to(B.ROOT)}{plotted}")
    return 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--no-valgrind", action="store_true")
    ap.add_argument("--quiet-only", action="store_true",
                    help="only count the quiet spin-state FMU step (3.) under five memory "
                         "layouts, ~20 min")
    ap.add_argument("--bearing", action="store_true",
                    help="only the drop onto the real bearing (4.): FMU against the floor "
                         "and the cost against k_c, into the existing file, ~5 min")
    ap.add_argument("--speeds", action="store_true",
                    help="only the drop into dry whirl at Omega0 = 184.2, 1000, 3000 rad/s "
                         "(issue 26 item 4), FMU against the floor, with its plot, ~5 min")
    args = ap.parse_args()
    if args.speeds:
        return _into_existing("drop_speeds", lambda: timed_speeds(args.repeats), plot_speeds)
    if args.bearing:
        return _into_existing("real_bearing", lambda: timed_bearing(args.repeats),
                              plot_bearing_cost)
    if args.quiet_only:
        return _into_existing("quiet_fmu_step", quiet_fmu_steps, None)
    result = json.loads(OUT.read_text()) if OUT.exists() else {}  # (the parts of the
    result["timed"] = timed(args.repeats)  # flagged runs kept: --speeds, --bearing)
    if not args.no_valgrind:
        result["instructions_per_step"] = instructions()
        result["quiet_fmu_step"] = quiet_fmu_steps()
    OUT.write_text(json.dumps(result, indent=1) + "\n")
    print(f"wrote {OUT.relative_to(B.ROOT)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
