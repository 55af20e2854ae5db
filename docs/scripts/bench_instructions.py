"""Deterministic cost figures: instructions counted by valgrind's callgrind.

    apt-get install valgrind && python docs/scripts/bench_instructions.py   # ~5 min
    python docs/scripts/bench_instructions.py --base <commit>                # ~10 min

Timed ratios on a shared machine scatter (docs/benchmarks.md). Instruction counts do not,
so this script counts them for the ratios that sit near their goals:

- instructions per FMU step, RotorTouchdown against the floor FMU, in the lean FMPy loop of
  benchmarks.py (doStep at 1e-3 s, all outputs read every step), on the free whirl and
  the limit cycle, and on the free whirl in libcosim (LIBCOSIM_CHILD: the FMU alone, every
  variable read by libcosim's last-value observer after every step; issue 26 item 3 asks
  for at most 1.10 and 1.30 of the floor there);
- instructions of the core alone per simulated second of the limit-cycle and chattering
  scenes, in one call per held-input segment, in 0.1 s calls and in 1e-3 s steps, with the
  held-speed imbalance torque off (``TouchdownCore.imbalance_torque = False``: the
  motion's cost, as a core before T_imb had it; ``--imbalance-torque`` turns it on; the FMU
  figures always compute it, T_imb being an output);
- instructions of DOP853 at rtol 1e-12 (tests/reference/direct.py, as benchmarks.py runs
  it) on the limit cycle, for the core-vs-DOP853 target. DOP853 spends part of its time in
  numpy's C loops, where an instruction is cheaper than in the interpreter, so this ratio
  is a proxy for the timed one, not a replacement.

Each figure is the difference of two runs of different length in fresh processes with a
fixed hash seed, so the interpreter's start-up and the imports cancel (with random hash
seeds, dict layouts moved a 200-step run by 14M instructions; with a fixed one, by 0.1M).
The child processes import only FMPy or the core, never numpy or this script's module, to
keep that start-up small. Prints a table and writes docs/bench_instructions.json.

``--base C`` counts the same figures, DOP853's left out, and bench_spin.py's figures of the
spin as a state (instructions per 1e-4 s step of ``SpinCore.step`` in closed-form flight,
integrated flight, sliding and rolling: SPIN_CHILD, the difference of two runs of
SPIN_STEPS after the same warm-up) for commit C and for the current tree (with its
uncommitted changes), one after the other in the same run, and judges each count against
"no worse than before within 2 %" (head <= base * 1.02). C is checked out in a temporary
``git worktree add --detach`` (fingerprint.py's add_worktree, removed at the end). Per tree:
both FMUs are built into the temporary directory by that tree's own
``benchmarks.build_fmus`` (its build.py, its floor FMU, its variables) in a child process,
and every child runs with ``PYTHONPATH=<tree>/fmu_src`` (fingerprint.py's tree_env), the
core and spin children with ``<tree>/fmu_src`` first on sys.path, so the editable install
does not win; a sanity check prints where each tree's core and spin children and
RotorTouchdown FMU imported ``rotortd`` from, and stops unless it is that tree's fmu_src or
the FMU's resources copied from it. The scenes are made once, here, from the current tree
and handed to both. The children run with ``OPENBLAS_NUM_THREADS=1``: FMPy imports numpy,
whose OpenBLAS worker threads spin for a time-dependent number of instructions (a 0-step FMU run
scattered by 40M instructions, 10k per step in the 4000-step difference; single-threaded,
by 5k instructions). Prints the table (figure, base, head, head/base - 1, verdict) and writes
docs/bench_instructions_base.json with both commits' hashes; exit 1 if a figure is worse.
"""

from __future__ import annotations

import argparse
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
import fingerprint as FP  # noqa: E402 (docs/scripts/fingerprint.py: base worktree, env)

OUT = B.ROOT / "docs" / "bench_instructions.json"
OUT_BASE = B.ROOT / "docs" / "bench_instructions_base.json"
TOLERANCE = 0.02
"""--base: a figure passes if head <= base * (1 + TOLERANCE)."""
SINGLE_THREAD = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
LAYOUT_PADS = (0, 100, 700, 2000, 5000)
"""Lengths of a padding variable in a child's environment (``layout_env``): each gives
another memory layout of the interpreter, under which the same FMU counts up to about 1.5 %
apart (docs/benchmarks.md, "Quiet steps"); the quiet steps' goals are judged on the counts
under all of them."""
ORIGIN = "origin"
"""Extra last argument of the FMU and core children (spelt out in their text): print where
rotortd came from."""
MEASURED = ("fmu_src", "build.py", "docs/scripts/benchmarks.py")
"""--base: the head's sources whose uncommitted changes the result records."""
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
if sys.argv[-1] == "origin":
    print(sys.modules["rotortd"].__file__)
'''

LIBCOSIM_CHILD = '''
import pickle, sys
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
from libcosimpy.CosimObserver import CosimObserver
from libcosimpy.CosimSlave import CosimLocalSlave
log_output_level(CosimLogLevel.WARNING)
D = pickle.load(open(sys.argv[1], "rb"))
f, n = D[sys.argv[2]], int(sys.argv[4])
step_ns = 1_000_000
ex = CosimExecution.from_step_size(step_ns)
i = ex.add_local_slave(CosimLocalSlave(fmu_path=f["file"], instance_name="count"))
vr = f["vr"]
for name, val in D[sys.argv[3]].items():
    if isinstance(val, bool):
        ex.boolean_initial_value(i, vr[name], val)
    else:
        ex.real_initial_value(i, vr[name], float(val))
ex.add_observer(CosimObserver.create_last_value())
assert ex.simulate_until(n * step_ns)
ex.stop()
'''
"""The libcosim child: the FMU alone in a libcosim execution (libcosimpy), doStep at 1e-3 s
in integer ns, every variable read after every step by its last-value observer; the steps
run in libcosim's C++ loop (simulate_until)."""

CORE_CHILD = '''
import os, pickle, sys
D = pickle.load(open(sys.argv[1], "rb"))
sys.path.insert(0, D["src"])
from rotortd import RotorParams, TouchdownCore
sc, mode, n = D[sys.argv[2]], sys.argv[3], int(sys.argv[4])
p = RotorParams(**sc["params"])
imb = os.environ.get("BENCH_IMBALANCE_TORQUE") == "1"
for _ in range(n):
    core = TouchdownCore(p, z0=sc["z0"], v0=sc["v0"], psi0=sc["psi0"])
    if hasattr(core, "imbalance_torque"):  # (a core before it had no T_imb at all)
        core.imbalance_torque = imb
    t = 0.0
    for t_end, omega, force, amb in sc["segments"]:
        h = t_end - t if mode == "seg" else float(mode)
        for _ in range(round((t_end - t) / h)):
            core.step(h, omega, force, amb)
        t = t_end
if sys.argv[-1] == "origin":
    print(sys.modules["rotortd"].__file__)
'''

SPIN_CHILD = '''
import cmath, sys
sys.path.insert(0, sys.argv[1])
from rotortd import RotorParams, SpinCore
kind, n = sys.argv[2], int(sys.argv[3])
p = RotorParams(g=9.81)
J, h = 0.5 * p.m * p.R ** 2, 1e-4
if kind == "flight_closed":      # bearing off, no gravity, mass centre at rest at the
    q = RotorParams(g=0.0)       # origin: the geometric centre circles at radius e_c < c_r
    core = SpinCore(q, J=J, v0=-1j * 184.2 * q.e_c * cmath.exp(1j * q.phi), Omega0=184.2)
    warm, ins = 100, {"amb_on": 0.0}
elif kind == "flight_integrated":  # bearing on: the levitated whirl, Omega slowly braked
    core = SpinCore.on_steady_whirl(p, 184.2, J=J)
    warm, ins = 100, {"amb_on": 1.0}
elif kind == "sliding":          # pressed down, the drive torque balancing the friction
    core = SpinCore(p, J=J, Omega0=184.2)
    warm, ins = 1000, {"amb_on": 0.0, "F_ext": -5000j, "T_drive": 0.04 * 0.15 * 5490.5}
else:                            # rolling: dry whirl after the drop
    core = SpinCore.on_steady_whirl(p, 184.2, J=J)
    warm, ins = 1000, {"amb_on": 0.0}
for _ in range(warm + n):
    core.step(h, **ins)
assert core.mode == {"flight_closed": 0, "flight_integrated": 0, "sliding": 1,
                     "rolling": 2}[kind], (kind, core.mode)
if sys.argv[-1] == "origin":
    print(sys.modules["rotortd"].__file__)
'''
"""Instructions of ``SpinCore.step`` at 1e-4 s in one kind of segment (argv: fmu_src, kind,
steps[, "origin"]); the kinds are SPIN_KINDS. Public names and keyword arguments only (all
but ``params``), so the same text runs on e272741's flat core and on today's. Shared with
bench_spin.py."""
SPIN_KINDS = ("flight_closed", "flight_integrated", "sliding", "rolling")
SPIN_STEPS = {"flight_closed": (20, 2020), "flight_integrated": (20, 220), "sliding": (20, 220),
              "rolling": (20, 220)}
"""Steps after the warm-up of the short and the long spin run (their difference is counted).
Closed-form flight costs ~0.1M instructions a step, and a run of the child scatters by up to
3M (callgrind, fixed hash seed; both trees): over 200 steps that is 15 %, over 2000, 1.5 %."""

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


BUILD_CHILD = '''
import json, sys
from pathlib import Path
sys.path.insert(0, sys.argv[1])
import benchmarks
fmus = benchmarks.build_fmus(Path(sys.argv[2]))
Path(sys.argv[3]).write_text(json.dumps({k: str(u) for k, (u, _md) in fmus.items()}))
'''


Env = dict[str, str]


def layout_env(pad: int) -> Env:
    """This environment, single-threaded, with a padding variable of ``pad`` characters
    (``LAYOUT_PADS``)."""
    return {**os.environ, **SINGLE_THREAD, "BENCH_LAYOUT_PAD": "x" * pad}


def instructions(script: Path, *args: str, env: Env | None = None) -> int:
    """Instructions callgrind counts for one run of ``python script args``; ``env`` replaces
    the environment (default: this one's)."""
    cmd = ["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null",
           sys.executable, str(script), *args]
    env = {**(os.environ if env is None else env),
           "PYTHONHASHSEED": "0"}  # else dict layouts, and counts, vary
    err = subprocess.run(cmd, capture_output=True, text=True, check=True, env=env).stderr
    return int(re.search(r"Collected : (\d+)", err).group(1))


def per_unit(script: Path, args: list[str], n_short: int, n_long: int,
             env: Env | None = None) -> float:
    """Instructions per unit of the last argument: (I(n_long) - I(n_short)) / difference."""
    lo = instructions(script, *args, str(n_short), env=env)
    hi = instructions(script, *args, str(n_long), env=env)
    return (hi - lo) / (n_long - n_short)


def fmu_tables(tmp: Path, scenes: dict[str, B.Scene], fmus: dict[str, tuple[str, Any]]) -> Path:
    """Pickle what the FMU child needs of both FMUs (name -> (unzip dir, model description))
    and the scenes' start values."""
    data: dict[str, Any] = {"outputs": (B.REAL_OUT, B.INT_OUT, B.BOOL_OUT)}
    for key, (unzip, md) in (("fmu", fmus["RotorTouchdown"]),
                             ("floor", fmus["RotorTouchdownFloor"])):
        data[key] = {"unzip": unzip, "guid": md.guid,
                     "mid": md.coSimulation.modelIdentifier,
                     "vr": {v.name: v.valueReference for v in md.modelVariables},
                     "file": str(fmu_file(unzip, md))}
    for name, sc in scenes.items():
        data[name] = B.start_values(sc)
    path = tmp / "fmu.pkl"
    path.write_bytes(pickle.dumps(data))
    return path


def fmu_file(unzip: str, md: Any) -> Path:
    """The .fmu beside the FMU's unzip directory (benchmarks.build_fmus builds it into
    ``<tmp>/fmus`` and extracts it to ``<tmp>/<name>``)."""
    return Path(unzip).parent / "fmus" / f"{md.coSimulation.modelIdentifier}.fmu"


def core_tables(tmp: Path, scenes: dict[str, B.Scene], tree: Path = B.ROOT) -> Path:
    """Pickle the scenes' parameters, starts and held-input segments for the core child,
    which imports ``tree``'s core."""
    data: dict[str, Any] = {"src": str(tree / "fmu_src"), "root": str(tree)}
    for name, sc in scenes.items():
        p, c_r, rtol = sc.params, sc.params.c_r, 1e-12
        data[name] = {"params": {f: getattr(p, f) for f in p.__dataclass_fields__},
                      "z0": sc.z0, "v0": sc.v0, "psi0": sc.psi0,
                      "segments": sc.segments(),
                      "atol": [rtol * c_r] * 2 + [rtol * c_r * B.W] * 2}  # as run_direct
    path = tmp / "core.pkl"
    path.write_bytes(pickle.dumps(data))
    return path


def write_children(tmp: Path) -> dict[str, Path]:
    """The child scripts in tmp: fmu, core, spin, dop, build."""
    texts = {"fmu": FMU_CHILD, "core": CORE_CHILD, "spin": SPIN_CHILD, "dop": DOP_CHILD,
             "build": BUILD_CHILD, "libcosim": LIBCOSIM_CHILD}
    paths = {k: tmp / f"{k}_child.py" for k in texts}
    for k, path in paths.items():
        path.write_text(texts[k])
    return paths


def count_fmu_steps(child: Path, pkl: Path, env: Env | None = None) -> dict[str, Any]:
    """Instructions per FMU step, RotorTouchdown and floor, on the free whirl and the
    limit cycle (FMPy), and on the free whirl in libcosim."""
    out: dict[str, Any] = {}
    runs = [(child, scene, goal, 200, 4200) for scene, goal in (("free_whirl", 1.1),
                                                                ("limit_cycle", 1.5))]
    runs.append((child.parent / "libcosim_child.py", "free_whirl libcosim", 1.3, 200, 2200))
    for script, name, goal, short, long in runs:
        scene = name.split()[0]
        fmu, floor = (per_unit(script, [str(pkl), w, scene], short, long, env)
                      for w in ("fmu", "floor"))
        out[name] = {"fmu": fmu, "floor": floor, "ratio": fmu / floor, "goal": goal}
        print(f"{name:12s} per FMU step: RotorTouchdown {fmu / 1e3:7.1f}k, floor "
              f"{floor / 1e3:7.1f}k instructions, ratio {fmu / floor:.3f} (goal <= {goal})",
              flush=True)
    return out


def count_core(child: Path, pkl: Path, env: Env | None = None) -> dict[str, float]:
    """Instructions of the core per simulated second, per scene and call mode."""
    out: dict[str, float] = {}
    for scene in ("limit_cycle", "chattering"):
        for mode in ("seg", "0.1", "1e-3"):
            per_s = per_unit(child, [str(pkl), scene, mode], 1, 3, env)
            out[f"{scene} {mode}"] = per_s
            print(f"{scene:12s} core, {mode:>4s} calls: {per_s / 1e6:6.1f}M instructions "
                  "per simulated second", flush=True)
    return out


def count_spin(child: Path, src: Path, env: Env | None = None) -> dict[str, float]:
    """Instructions per 1e-4 s step of ``SpinCore.step`` of the core in ``src`` (a tree's
    fmu_src), per kind of segment (SPIN_CHILD)."""
    out: dict[str, float] = {}
    for kind in SPIN_KINDS:
        out[kind] = per_unit(child, [str(src), kind], *SPIN_STEPS[kind], env=env)
        print(f"{kind:>18s} spin state: {out[kind] / 1e3:9.1f}k instructions per 1e-4 s "
              "step", flush=True)
    return out


def count_tree(children: dict[str, Path], fmu_pkl: Path, core_pkl: Path,
               env: Env | None = None) -> dict[str, Any]:
    """Every figure but DOP853's for the FMUs and core the pickles point to."""
    out: dict[str, Any] = {"fmu_step": count_fmu_steps(children["fmu"], fmu_pkl, env),
                           "core_per_second": count_core(children["core"], core_pkl, env)}
    cps = out["core_per_second"]
    ratio = cps["chattering 1e-3"] / cps["limit_cycle 1e-3"]
    out["chattering_vs_limit_cycle_core_1e-3"] = ratio
    print(f"chattering / limit cycle, core at 1e-3 s steps: {ratio:.2f} (goal <= 3)")
    return out


def count_dop(child: Path, core_pkl: Path, cps: dict[str, float]) -> dict[str, Any]:
    """DOP853 on the limit cycle and its ratio to the core's figures ``cps``."""
    dop = per_unit(child, [str(core_pkl), "limit_cycle"], 1, 2)
    vs = {m: dop / cps[f"limit_cycle {m}"] for m in ("seg", "0.1", "1e-3")}
    print(f"DOP853 at rtol 1e-12, limit cycle: {dop / 1e6:.0f}M instructions; DOP853 / core: "
          + ", ".join(f"{v:.1f} ({m} calls)" for m, v in vs.items()) + " (goal >= 50)")
    return {"dop853_limit_cycle": dop, "dop853_vs_core": vs}


def run_head(tmp: Path, scenes: dict[str, B.Scene]) -> int:
    """No --base: this tree's figures with DOP853's, to docs/bench_instructions.json."""
    children = write_children(tmp)
    fmu_pkl = fmu_tables(tmp, scenes, B.build_fmus(tmp))
    core_pkl = core_tables(tmp, scenes)
    env = {**os.environ, **SINGLE_THREAD}
    out = {"machine": B.machine(), **count_tree(children, fmu_pkl, core_pkl, env)}
    out.update(count_dop(children["dop"], core_pkl, out["core_per_second"]))
    OUT.write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {OUT}")
    return 0


# ------------------------------------------------------------------------------ --base


def tree_fmus(tree: Path, work: Path, build_child: Path) -> dict[str, tuple[str, Any]]:
    """Both FMUs built into ``work`` by ``tree``'s own benchmarks.build_fmus, in a child
    with the tree's environment; name -> (unzip dir, model description)."""
    from fmpy import read_model_description

    res = work / "fmus.json"
    proc = subprocess.run([sys.executable, str(build_child), str(tree / "docs" / "scripts"),
                           str(work), str(res)], cwd=tree, env=FP.tree_env(tree),
                          capture_output=True, text=True)
    if proc.returncode or not res.exists():
        raise SystemExit(f"FMU build in {tree} failed: {proc.stderr[-2000:]}")
    unzips = json.loads(res.read_text())
    return {name: (unzip, read_model_description(unzip)) for name, unzip in unzips.items()}


def rotortd_origin(child: Path, args: list[str], env: Env) -> Path:
    """Where a 0-step run of ``child`` imported rotortd from (also warms any bytecode
    cache, so the counted runs start alike)."""
    proc = subprocess.run([sys.executable, str(child), *args, "0", ORIGIN], env=env,
                          capture_output=True, text=True)
    if proc.returncode:
        raise SystemExit(f"{child.name} {args}: {proc.stderr[-2000:]}")
    return Path(proc.stdout.strip().splitlines()[-1]).parent


def same_package(copy: Path, src: Path) -> bool:
    """Every .py of package ``src``, in its subfolders too, is in ``copy`` with the same
    bytes."""
    return all((copy / f.relative_to(src)).exists()
               and (copy / f.relative_to(src)).read_bytes() == f.read_bytes()
               for f in src.rglob("*.py") if "__pycache__" not in f.parts)


def check_origins(tree: Path, children: dict[str, Path], fmu_pkl: Path, core_pkl: Path,
                  env: Env) -> None:
    """Stop unless the core and spin children import ``tree``'s rotortd and the FMU a copy
    of it."""
    src = tree / "fmu_src" / "rotortd"
    core = rotortd_origin(children["core"], [str(core_pkl), "limit_cycle", "seg"], env)
    spin = rotortd_origin(children["spin"], [str(src.parent), "flight_closed"], env)
    fmu = rotortd_origin(children["fmu"], [str(fmu_pkl), "fmu", "free_whirl"], env)
    print(f"rotortd of {tree}: core child {core}, spin child {spin}, FMU {fmu}", flush=True)
    for name, origin in (("core", core), ("spin", spin)):
        if origin.resolve() != src.resolve():
            raise SystemExit(f"the {name} child imported rotortd from {origin}, not {src}")
    if not same_package(fmu, src):
        raise SystemExit(f"the FMU's rotortd ({fmu}) is not a copy of {src}")


def count_in_tree(tree: Path, work: Path, scenes: dict[str, B.Scene],
                  fmu_only: bool = False) -> dict[str, Any]:
    """Every figure but DOP853's for ``tree``, and its spin-state figures (only the FMU
    figures with ``fmu_only``), its FMUs built and its children run in ``work``."""
    work.mkdir(parents=True)
    children = write_children(work)
    env = {**FP.tree_env(tree), **SINGLE_THREAD}
    fmu_pkl = fmu_tables(work, scenes, tree_fmus(tree, work, children["build"]))
    core_pkl = core_tables(work, scenes, tree)
    check_origins(tree, children, fmu_pkl, core_pkl, env)
    if fmu_only:
        return {"fmu_step": count_fmu_steps(children["fmu"], fmu_pkl, env)}
    out = count_tree(children, fmu_pkl, core_pkl, env)
    out["spin_per_step"] = count_spin(children["spin"], tree / "fmu_src", env)
    return out


def git(*args: str) -> str:
    return subprocess.run(["git", "-C", str(B.ROOT), *args], capture_output=True, text=True,
                          check=True).stdout.strip()


def figures(res: dict[str, Any]) -> dict[str, float]:
    """The compared figures of one tree's counts, by name."""
    out = {}
    for scene, d in res["fmu_step"].items():
        out.update({f"FMU step {scene} {k}": d[k] for k in ("fmu", "floor", "ratio")})
    if "core_per_second" in res:  # (not with --fmu-only)
        out.update({f"core/s {k}": v for k, v in res["core_per_second"].items()})
        out["core chattering/limit_cycle 1e-3"] = res["chattering_vs_limit_cycle_core_1e-3"]
        out.update({f"spin step {k}": v for k, v in res["spin_per_step"].items()})
    return out


def compare(base: dict[str, Any], head: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """Per figure: base, head, head/base - 1, and whether head <= base * (1 + TOLERANCE)."""
    fb, fh = figures(base), figures(head)
    return {k: {"base": fb[k], "head": fh[k], "change": fh[k] / fb[k] - 1,
                "judged": is_count(k), "ok": fh[k] <= fb[k] * (1 + TOLERANCE) or not is_count(k)}
            for k in fb}


def is_count(name: str) -> bool:
    """A figure the criterion judges: an instruction count of the model per FMU step, per
    simulated second or per spin-state step. The ratios (to the floor, chattering to limit
    cycle) are shown, not judged: a ratio also moves when its denominator gets cheaper; so
    is the floor FMU's own count, the host's cost and not the model's (it rose by design
    when the floor began to publish its outputs as RotorTouchdown does, issue 26). So are
    the libcosim figures: its last-value observer reads every variable after every step, so
    they grow with the variable table (the real bearing's parameters and outputs, issue 24,
    came after e272741), which the floor's count shows; they were added in session 16,
    after the criterion's figures were set."""
    return ((name.endswith("fmu") and "libcosim" not in name)
            or name.startswith(("core/s", "spin step")))


def fmt(name: str, value: float) -> str:
    """A figure for the table: per-step counts in k, per-second counts in M."""
    if name.endswith(("fmu", "floor")) or name.startswith("spin step"):
        return f"{value / 1e3:.1f}k"
    if name.startswith("core/s"):
        return f"{value / 1e6:.2f}M"
    return f"{value:.4f}"


def print_comparison(rows: dict[str, dict[str, Any]], base: str, head: str) -> None:
    print(f"\ninstructions, base {base} vs head {head}; verdict: head <= base * "
          f"{1 + TOLERANCE:g}")
    print(f"{'figure':36s} {'base':>10s} {'head':>10s} {'head/base-1':>11s}  verdict")
    for k, r in rows.items():
        print(f"{k:36s} {fmt(k, r['base']):>10s} {fmt(k, r['head']):>10s} "
              f"{100 * r['change']:+10.2f}%  "
              f"{('ok' if r['ok'] else 'WORSE') if r['judged'] else 'shown'}")


def run_base(commit: str, tmp: Path, scenes: dict[str, B.Scene],
             fmu_only: bool = False) -> int:
    """--base: both trees' figures, compared, to docs/bench_instructions_base.json (with
    ``fmu_only``, the FMU figures only, printed and not written)."""
    base_hash = git("rev-parse", "--verify", f"{commit}^{{commit}}")
    head_hash = git("rev-parse", "HEAD")
    dirty = git("status", "--porcelain", "--", *MEASURED)
    base_tree = tmp / "base_tree"
    FP.add_worktree(base_hash, base_tree)
    try:
        res = {}
        for key, tree in (("base", base_tree), ("head", B.ROOT)):
            print(f"--- {key}: {tree}", flush=True)
            res[key] = count_in_tree(tree, tmp / key, scenes, fmu_only)
    finally:
        FP.remove_worktree(base_tree)
    rows = compare(res["base"], res["head"])
    if fmu_only:
        print_comparison(rows, base_hash[:7], head_hash[:7] + ("+" if dirty else ""))
        return 0 if all(r["ok"] for r in rows.values()) else 1
    out = {"machine": B.machine(), "criterion": f"head <= base * {1 + TOLERANCE:g}",
           "base": {"commit": base_hash, **res["base"]},
           "head": {"commit": head_hash, "uncommitted_sources": dirty.splitlines(),
                    **res["head"]},
           "env": SINGLE_THREAD, "figures": rows}
    OUT_BASE.write_text(json.dumps(out, indent=1) + "\n")
    print_comparison(rows, base_hash[:7], head_hash[:7] + ("+" if dirty else ""))
    print(f"wrote {OUT_BASE}")
    return 0 if all(r["ok"] for r in rows.values()) else 1


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", metavar="COMMIT",
                    help="count COMMIT and the current tree and judge each figure against "
                         f"head <= base * {1 + TOLERANCE:g}; the DOP853 figures are skipped; "
                         "writes docs/bench_instructions_base.json")
    ap.add_argument("--imbalance-torque", action="store_true",
                    help="the core-alone figures with the held-speed imbalance torque "
                         "computed (TouchdownCore.imbalance_torque; default off there: the "
                         "motion's cost, comparable with a core that had no T_imb). The FMU "
                         "figures always compute it (T_imb is an output)")
    ap.add_argument("--fmu-only", action="store_true",
                    help="with --base: only the FMU figures, printed (~8 min)")
    return ap.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    os.environ["BENCH_IMBALANCE_TORQUE"] = "1" if args.imbalance_torque else "0"
    if shutil.which("valgrind") is None:
        print("valgrind not found: apt-get install valgrind", file=sys.stderr)
        return 2
    scenes = {sc.name: sc for sc in B.make_scenes()}
    tmp = Path(tempfile.mkdtemp(prefix="bench_instr_"))
    try:
        if args.base:
            return run_base(args.base, tmp, scenes, args.fmu_only)
        return run_head(tmp, scenes)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    raise SystemExit(main())
