"""Probe the per-step work bound (docs/model.md 7) on random scenes in the FMU's ranges.

Draws parameters, initial states, inputs and step sizes over the ranges the FMU accepts
(log-uniform over positive ranges, with the ends and zero included), runs each scene on
the core directly, the way rotortd_fmi/touchdown.py calls it (``TouchdownCore.step``, or
``SpinCore.step`` with ``integrate_spin``: the spin a state, J drawn over its range, the
drive torque held), each scene in a subprocess with a time
limit, and records per step: wall time, work units, status. Prints the slowest steps, the
largest work of a completed step and the worst time per work unit.

    PYTHONPATH=fmu_src python docs/scripts/work_bound_probe.py --cases 3000 --seed 1
    PYTHONPATH=fmu_src python docs/scripts/work_bound_probe.py --one 1234  # one case, verbose
"""

from __future__ import annotations

import argparse
import json
import math
import os
import random
import subprocess
import sys
import time


def _logu(rng: random.Random, lo: float, hi: float) -> float:
    return 10.0 ** rng.uniform(math.log10(lo), math.log10(hi))


def _pick(rng: random.Random, ends: list[float], lo: float, hi: float, p_end: float = 0.2
          ) -> float:
    """One of ``ends`` with probability p_end, else log-uniform on [lo, hi]."""
    return rng.choice(ends) if rng.random() < p_end else _logu(rng, lo, hi)


def _signed(rng: random.Random, lo: float, hi: float, p_zero: float = 0.2) -> float:
    if rng.random() < p_zero:
        return 0.0
    return rng.choice((-1.0, 1.0)) * _pick(rng, [hi], lo, hi, 0.1)


def sample(case: int) -> dict:
    """The scene of case number ``case`` (deterministic)."""
    rng = random.Random(case)
    c_r = _pick(rng, [1e-6, 0.1], 1e-6, 0.1)
    r0 = rng.choice([0.0, 1.0, rng.random()])
    a0 = rng.uniform(-math.pi, math.pi)
    p = {
        "m": _pick(rng, [1e-3, 1e6], 1e-3, 1e6),
        "c": _pick(rng, [0.0, 1e9], 1e-3, 1e9, 0.3),
        "k": _pick(rng, [0.0, 1e12], 1e-3, 1e12, 0.3),
        "e_c": _pick(rng, [0.0, 0.1], 1e-9, 0.1, 0.3),
        "phi": rng.uniform(-1e4, 1e4) if rng.random() < 0.2 else rng.uniform(-math.pi, math.pi),
        "c_r": c_r,
        "R": _pick(rng, [1e-3, 10.0], 1e-3, 10.0),
        "mu": _pick(rng, [0.0, 10.0], 1e-3, 10.0, 0.3),
        "d": rng.choice([0.0, 1.0, 0.95, rng.random(), 1.0 - _logu(rng, 1e-9, 1e-1)]),
        "g": rng.choice([0.0, 9.81, 1e4, _logu(rng, 1e-3, 1e4)]),
        "levitate": rng.random() < 0.5,
    }
    scene = {
        "params": p,
        "z0": [r0 * c_r * math.cos(a0), r0 * c_r * math.sin(a0)],
        "v0": [_signed(rng, 1e-6, 1e4), _signed(rng, 1e-6, 1e4)],
        "psi0": rng.uniform(-1e4, 1e4) if rng.random() < 0.2 else 0.0,
        "spin": rng.random() < 0.3,
        "J": _pick(rng, [1e-9, 1e7], 1e-9, 1e7),
        "h_spin": _pick(rng, [1e-8, 1.0], 1e-8, 1.0),  # unused (deprecated); kept so that
        # the draws, hence the scenes of every case number, stay those of earlier runs
        "h": _pick(rng, [1e-12, 10.0, 1e-4, 1e-3], 1e-12, 10.0, 0.3),
        "n_steps": rng.choice([3, 10, 30]),
        "inputs": [],
    }
    for _ in range(rng.choice([1, 2])):
        scene["inputs"].append({
            "Omega": _signed(rng, 1e-3, 1e5),
            "F": [_signed(rng, 1e-3, 1e12, 0.5), _signed(rng, 1e-3, 1e12, 0.5)],
            "amb_on": rng.choice([0.0, 1.0, rng.random()]),
            "T_drive": _signed(rng, 1e-3, 1e9, 0.5),
        })
    return scene


def run_scene(scene: dict, t_limit: float, verbose: bool = False) -> dict:
    """Run one scene; per step (h, wall s, work, status, message)."""
    from rotortd import CrossParameterError, RotorParams, SpinCore, TouchdownCore

    p = RotorParams(**scene["params"])
    ins = scene["inputs"]
    z0, v0 = complex(*scene["z0"]), complex(*scene["v0"])
    spin = scene["spin"]
    if spin:
        try:
            core = SpinCore(p, scene["J"], z0=z0, v0=v0, psi0=scene["psi0"], Omega0=ins[0]["Omega"])
        except CrossParameterError as exc:  # J too small for well-posed contact: refused
            return {"steps": [], "refused": str(exc)[:300]}
    else:
        core = TouchdownCore(p, z0=z0, v0=v0, psi0=scene["psi0"])
    steps = []
    total = 0.0
    for i in range(scene["n_steps"]):
        inp = ins[min(i * len(ins) // scene["n_steps"], len(ins) - 1)]
        F = complex(*inp["F"])
        t = time.process_time()
        if spin:
            rep = core.step(scene["h"], F_ext=F, amb_on=inp["amb_on"], T_drive=inp["T_drive"])
        else:
            rep = core.step(scene["h"], inp["Omega"], F_ext=F, amb_on=inp["amb_on"])
        work = rep.work
        dt = time.process_time() - t
        total += dt
        steps.append([dt, work, rep.status, rep.message[:300]])
        if verbose:
            print(f"step {i}: {dt:.4f} s work {work} status {rep.status} mode {core.mode} "
                  f"{rep.message[:200]}", flush=True)
        if rep.status != 0 or total > t_limit:
            break
    return {"steps": steps}


def _worker(case: int, t_limit: float) -> None:
    out = run_scene(sample(case), t_limit)
    print(json.dumps(out))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", type=int, default=300)
    ap.add_argument("--seed", type=int, default=0, help="first case number")
    ap.add_argument("--timeout", type=float, default=60.0, help="per scene, s")
    ap.add_argument("--one", type=int, help="run one case in this process, verbose")
    ap.add_argument("--worker", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--out", default="", help="write all results as JSON here")
    args = ap.parse_args()
    if args.worker is not None:
        _worker(args.worker, args.timeout)
        return
    if args.one is not None:
        sc = sample(args.one)
        print(json.dumps(sc, indent=1))
        run_scene(sc, args.timeout, verbose=True)
        return
    results = {}
    slow, worst_unit, max_work_ok = [], 0.0, 0
    for case in range(args.seed, args.seed + args.cases):
        t = time.perf_counter()
        try:
            cp = subprocess.run(
                [sys.executable, __file__, "--worker", str(case), "--timeout", str(args.timeout)],
                capture_output=True, text=True, timeout=args.timeout + 10.0, env=os.environ,
            )
            res = json.loads(cp.stdout) if cp.returncode == 0 else {"error": cp.stderr[-500:]}
        except subprocess.TimeoutExpired:
            res = {"error": f"timeout after {args.timeout + 10.0} s"}
        wall = time.perf_counter() - t
        results[case] = res
        steps = res.get("steps", [])
        step_max = max((s[0] for s in steps), default=0.0)
        for dt, work, status, _msg in steps:
            if work > 0 and dt > 1e-3:
                worst_unit = max(worst_unit, dt / work)
            if status == 0:
                max_work_ok = max(max_work_ok, work)
        capped = [s for s in steps if s[2] != 0]
        if "error" in res or step_max > 1.0 or capped:
            slow.append(case)
            print(f"case {case}: wall {wall:.1f} s, slowest step {step_max:.2f} s, "
                  f"{'CAP ' + capped[0][3][:120] if capped else ''}{res.get('error', '')[-200:]}",
                  flush=True)
    print(f"{args.cases} cases: {len(slow)} slow/capped/failed; max work of an OK step "
          f"{max_work_ok}; worst time per unit (steps > 1 ms) {worst_unit * 1e6:.2f} us")
    if args.out:
        with open(args.out, "w") as f:
            json.dump(results, f)


if __name__ == "__main__":
    main()
