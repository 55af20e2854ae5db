"""Deterministic cost figures: instructions counted by valgrind's callgrind.

    apt-get install valgrind && python docs/scripts/bench_instructions.py   # ~5 min

Timed ratios on a shared machine scatter (docs/benchmarks.md). Instruction counts do not,
so this script counts them for the ratios that sit near their goals:

- instructions per FMU step, RotorTouchdown against the floor FMU, in the lean FMPy loop of
  benchmarks.py (doStep at 1e-3 s, all outputs read every step), on the free whirl and
  the limit cycle;
- instructions of the core alone per simulated second of the limit-cycle and chattering
  scenes, in one call per held-input segment, in 0.1 s calls and in 1e-3 s steps;
- instructions of DOP853 at rtol 1e-12 (tests/reference/direct.py, as benchmarks.py runs
  it) on the limit cycle, for the core-vs-DOP853 target. DOP853 spends part of its time in
  numpy's C loops, where an instruction is cheaper than in the interpreter, so this ratio
  is a proxy for the timed one, not a replacement.

Each figure is the difference of two runs of different length in fresh processes with a
fixed hash seed, so the interpreter's start-up and the imports cancel (with random hash
seeds, dict layouts moved a 200-step run by 14M instructions; with a fixed one, by 0.1M).
The child processes import only FMPy or the core, never numpy or this script's module, to
keep that start-up small. Prints a table and writes docs/bench_instructions.json.
"""

from __future__ import annotations

import json
import os
import pickle
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import benchmarks as B  # noqa: E402 (docs/scripts/benchmarks.py: scenes, FMU builds)

OUT = B.ROOT / "docs" / "bench_instructions.json"

FMU_CHILD = '''
import pickle, sys
from fmpy.fmi2 import FMU2Slave
D = pickle.load(open(sys.argv[1], "rb"))
f, n = D[sys.argv[2]], int(sys.argv[4])
vr = f["vr"]
fmu = FMU2Slave(guid=f["guid"], unzipDirectory=f["unzip"], modelIdentifier=f["mid"],
                instanceName="count")
fmu.instantiate()
for name, val in D[sys.argv[3]].items():
    if isinstance(val, bool):
        fmu.setBoolean([vr[name]], [val])
    else:
        fmu.setReal([vr[name]], [float(val)])
fmu.setupExperiment(startTime=0.0)
fmu.enterInitializationMode()
fmu.exitInitializationMode()
rv, iv, bv = ([vr[x] for x in names] for names in D["outputs"])
for j in range(n):
    fmu.doStep(j * 1e-3, 1e-3)
    fmu.getReal(rv)
    fmu.getInteger(iv)
    fmu.getBoolean(bv)
fmu.terminate()
fmu.freeInstance()
'''

CORE_CHILD = '''
import pickle, sys
D = pickle.load(open(sys.argv[1], "rb"))
sys.path.insert(0, D["src"])
from rotortd import RotorParams, TouchdownCore
sc, mode, n = D[sys.argv[2]], sys.argv[3], int(sys.argv[4])
p = RotorParams(**sc["params"])
for _ in range(n):
    core = TouchdownCore(p, sc["z0"], sc["v0"], sc["psi0"])
    t = 0.0
    for t_end, omega, force, amb in sc["segments"]:
        h = t_end - t if mode == "seg" else float(mode)
        for _ in range(round((t_end - t) / h)):
            core.step(h, omega, force, amb)
        t = t_end
'''

DOP_CHILD = '''
import pickle, sys
D = pickle.load(open(sys.argv[1], "rb"))
sys.path[:0] = [D["root"], D["src"]]
from tests.reference.direct import direct_simulate
sc, n = D[sys.argv[2]], int(sys.argv[3])
for _ in range(n):
    r = direct_simulate(sc["params"], sc["z0"], sc["v0"], sc["psi0"], 0.0, sc["segments"],
                        method="DOP853", rtol=1e-12, atol=sc["atol"], max_impacts=3000)
    assert r.status == "ok", r.status
'''


def instructions(script: Path, *args: str) -> int:
    """Instructions callgrind counts for one run of ``python script args``."""
    cmd = ["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null",
           sys.executable, str(script), *args]
    env = {**os.environ, "PYTHONHASHSEED": "0"}  # else dict layouts, and counts, vary
    err = subprocess.run(cmd, capture_output=True, text=True, check=True, env=env).stderr
    return int(re.search(r"Collected : (\d+)", err).group(1))


def per_unit(script: Path, args: list[str], n_short: int, n_long: int) -> float:
    """Instructions per unit of the last argument: (I(n_long) - I(n_short)) / difference."""
    lo = instructions(script, *args, str(n_short))
    hi = instructions(script, *args, str(n_long))
    return (hi - lo) / (n_long - n_short)


def fmu_tables(tmp: Path, scenes: dict[str, B.Scene]) -> Path:
    """Build both FMUs into tmp and pickle what the FMU child needs."""
    fmus = B.build_fmus(tmp)
    data: dict[str, Any] = {"outputs": (B.REAL_OUT, B.INT_OUT, B.BOOL_OUT)}
    for key, (unzip, md) in (("fmu", fmus["RotorTouchdown"]),
                             ("floor", fmus["RotorTouchdownFloor"])):
        data[key] = {"unzip": unzip, "guid": md.guid,
                     "mid": md.coSimulation.modelIdentifier,
                     "vr": {v.name: v.valueReference for v in md.modelVariables}}
    for name, sc in scenes.items():
        data[name] = B.start_values(sc)
    path = tmp / "fmu.pkl"
    path.write_bytes(pickle.dumps(data))
    return path


def core_tables(tmp: Path, scenes: dict[str, B.Scene]) -> Path:
    """Pickle the scenes' parameters, starts and held-input segments for the core child."""
    data: dict[str, Any] = {"src": str(B.ROOT / "fmu_src"), "root": str(B.ROOT)}
    for name, sc in scenes.items():
        p, c_r, rtol = sc.params, sc.params.c_r, 1e-12
        data[name] = {"params": {f: getattr(p, f) for f in p.__dataclass_fields__},
                      "z0": sc.z0, "v0": sc.v0, "psi0": sc.psi0,
                      "segments": sc.segments(),
                      "atol": [rtol * c_r] * 2 + [rtol * c_r * B.W] * 2}  # as run_direct
    path = tmp / "core.pkl"
    path.write_bytes(pickle.dumps(data))
    return path


def main() -> int:
    if shutil.which("valgrind") is None:
        print("valgrind not found: apt-get install valgrind", file=sys.stderr)
        return 2
    scenes = {sc.name: sc for sc in B.make_scenes()}
    tmp = Path(tempfile.mkdtemp(prefix="bench_instr_"))
    fmu_child, core_child, dop_child = (tmp / f"{k}_child.py" for k in ("fmu", "core", "dop"))
    fmu_child.write_text(FMU_CHILD)
    core_child.write_text(CORE_CHILD)
    dop_child.write_text(DOP_CHILD)
    fmu_pkl, core_pkl = fmu_tables(tmp, scenes), core_tables(tmp, scenes)
    out: dict[str, Any] = {"machine": B.machine(), "fmu_step": {}, "core_per_second": {}}
    for scene, goal in (("free_whirl", 1.2), ("limit_cycle", 1.5)):
        fmu, floor = (per_unit(fmu_child, [str(fmu_pkl), w, scene], 200, 4200)
                      for w in ("fmu", "floor"))
        out["fmu_step"][scene] = {"fmu": fmu, "floor": floor, "ratio": fmu / floor,
                                  "goal": goal}
        print(f"{scene:12s} per FMU step: RotorTouchdown {fmu / 1e3:7.1f}k, floor "
              f"{floor / 1e3:7.1f}k instructions, ratio {fmu / floor:.3f} (goal <= {goal})",
              flush=True)
    for scene in ("limit_cycle", "chattering"):
        for mode in ("seg", "0.1", "1e-3"):
            per_s = per_unit(core_child, [str(core_pkl), scene, mode], 1, 3)
            out["core_per_second"][f"{scene} {mode}"] = per_s
            print(f"{scene:12s} core, {mode:>4s} calls: {per_s / 1e6:6.1f}M instructions "
                  "per simulated second", flush=True)
    cps = out["core_per_second"]
    ratio = cps["chattering 1e-3"] / cps["limit_cycle 1e-3"]
    out["chattering_vs_limit_cycle_core_1e-3"] = ratio
    print(f"chattering / limit cycle, core at 1e-3 s steps: {ratio:.2f} (goal <= 3)")
    dop = per_unit(dop_child, [str(core_pkl), "limit_cycle"], 1, 2)
    out["dop853_limit_cycle"] = dop
    out["dop853_vs_core"] = {m: dop / cps[f"limit_cycle {m}"] for m in ("seg", "0.1", "1e-3")}
    print(f"DOP853 at rtol 1e-12, limit cycle: {dop / 1e6:.0f}M instructions; DOP853 / core: "
          + ", ".join(f"{v:.1f} ({m} calls)" for m, v in out["dop853_vs_core"].items())
          + " (goal >= 50)")
    OUT.write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {OUT}")
    shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
