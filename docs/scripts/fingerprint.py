"""Bit-exact behaviour fingerprint of the core and the FMU, compared with an earlier commit.

    python docs/scripts/fingerprint.py --base <commit>        # ~40 s on 2 cores (below)
    python docs/scripts/fingerprint.py --base <commit> --allow-rounding --amplification
    python docs/scripts/fingerprint.py                          # this tree only: the hashes

Proof for issue 16 ("behaviour stays exactly as it is"). Every job, a scene run at one
communication step, is recorded to the last bit:

- per step: the core's time, position, velocity and spin angle after the step and the step
  report (F_contact, F_n, F_n_peak, P_n, T_f, E_diss, mode (the core's where the report has
  none), status, message, work, work_cap,
  number of impacts and transitions) and the cumulative counters (n_impacts, E_diss,
  t_last_impact, v_last_impact, mode); every impact (t, z, v-, v+, rdot, P_n, P_t, stick,
  E_diss) and transition (t, name) in an event list; all as IEEE doubles, hashed (sha256)
  per job;
- at the end: ``core.get_state()`` and the counters in full, floats as ``float.hex``.

The FMU (built from each tree with its own build.py) runs a few scenes through FMPy's
``FMU2Slave``; per step every output is read, at the end the serialised FMU state.

Scenes: (a) every ``models/scenes/*_par.json`` (inputs from ``<Scene>_in.csv``), (b) the five
benchmark scenes of docs/scripts/benchmarks.py (1 s each; their start values frozen below,
``--check-scenes`` compares them with ``benchmarks.make_scenes()``), (c) a bearing-failure
drop: chapter rotor, g = 9.81, levitated steady whirl at 184.2 rad/s, amb_on 1 -> 0 at
10 ms, 0.3 s. Steps: ``seg`` (one call per held-input segment: the whole run, or two calls
around the AMB failure), 0.1 s, 1e-3 s, 1e-4 s and, for (a) and (c), 1e-5 s; a step whose
schedule equals an earlier one's (0.1 s on a 0.1 s scene) is left out. The scene
definitions are read once, here, from the current tree, and handed to both recordings.

``--base C`` checks out C in a temporary ``git worktree add --detach`` (removed at the end),
and records it and the current tree (with its uncommitted changes) in two subprocesses run in
parallel, each with ``PYTHONPATH=<tree>/fmu_src`` (its own code, not the installed editable
package; each recording checks where ``rotortd`` came from) and ``PYTHONHASHSEED=0``. The
recording code is this file's, in both trees; it needs only ``TouchdownCore(params, z0, v0,
psi0, t0)``, ``.step(h, Omega, F_ext=, amb_on=)``, ``.get_state()``, ``RotorParams(**fields)``
and the StepReport fields, and reads every other attribute (report fields, counters, impact
fields) with ``getattr`` and a default, so a renamed field shows up as a difference, not a
crash.

The table: per job whether it is identical; else the first differing quantity (in time
order: step row, impact or transition, then the final counters and state), the largest
difference in scaled units, and whether impact counts and modes are equal at every step.
Scaled units: positions in c_r, velocities in c_r |Omega|, times in 1/|Omega|, angles in
rad; forces (m c_r Omega^2), impulses (m c_r |Omega|), torques (R m c_r Omega^2) and
energies (m (c_r Omega)^2) against the larger of that unit and their own size, since a
step-averaged P/h at 1e-5 s or the cumulative E_diss is many units large and rounds
relative to it; other final-state values relative; ``inf`` where a value is missing,
non-finite or not a number on one side (e.g. the sliding step memo ``H``). Exit 0 iff all
jobs are identical; with ``--allow-rounding`` iff every difference is <= 1e-13 scaled with
equal counts, modes and statuses (work counters may differ). An FMU output the head adds
(T_imb) is reported as "adds ..." and the job compared on the base's columns, the head's
saved state without it; a removed output is a difference. The saved state's schema
bookkeeping (versions; J and the adapter's spin when null) is not compared.

``--amplification`` measures, per scene on the current tree at 1e-3 s, how much a 1e-12
scaled perturbation of the initial state (+-x, +-y in c_r, +-vx, +-vy in c_r |Omega|) grows:
the largest scaled state difference over the run divided by 1e-12. Only on scenes with an
amplification <= 10 can a rounding-only change be judged by its size.

Run time (2 cores, base and head in parallel): 35-45 s for the default set, measured while
other sessions kept the load average near 14; per tree ~28 s CPU for the core recordings,
~4 s for the FMU runs and ~1.5 s for its build; ``--amplification`` adds ~5-10 s, ``--no-fmu``
saves the FMU part. The temporary files (~55 MB per tree) are removed unless ``--keep``.
"""

from __future__ import annotations

import argparse
import array
import csv
import hashlib
import itertools
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import zlib
from collections.abc import Callable, Iterable
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
OMEGA = 184.2
ROUNDING = 1e-13
"""--allow-rounding: largest accepted scaled difference."""
AMP_DELTA = 1e-12
AMP_STEP = "1e-3"
STEP_VALUES: dict[str, float | None] = {"seg": None, "0.1": 0.1, "1e-3": 1e-3, "1e-4": 1e-4,
                                        "1e-5": 1e-5}
STEPS_FINE = ("seg", "0.1", "1e-3", "1e-4", "1e-5")
STEPS_BENCH = ("seg", "0.1", "1e-3", "1e-4")
FMU_JOBS: tuple[tuple[str, str], ...] = (
    ("AMB_drop", "1e-3"), ("AMB_drop", "1e-4"), ("Chatter_to_rub", "seg"),
    ("Chatter_to_rub", "1e-4"), ("limit_cycle", "seg"), ("limit_cycle", "1e-3"),
    ("bearing_drop", "1e-3"), ("bearing_drop", "1e-4"))
"""(scene, step) run through the FMU as well."""
PARAM_NAMES = ("m", "c", "k", "e_c", "phi", "c_r", "R", "mu", "d", "g")

Spec = dict[str, Any]
"""A scene as JSON data: floats as float.hex strings (see scene_spec)."""

# ------------------------------------------------------------------------------ scenes

_CHAPTER = {"m": "0x1.9000000000000p+5", "k": "0x1.de84000000000p+19",
            "e_c": "0x1.3a92a30553261p-12", "phi": "0x1.ae147ae147ae1p-3",
            "c_r": "0x1.6f0068db8bac7p-11", "R": "0x1.47ae147ae147bp-5",
            "mu": "0x1.3333333333333p-3", "d": "0x1.e666666666666p-1", "g": "0x0.0p+0"}
_G981 = "0x1.39eb851eb851fp+3"
_DROP_START = ("-0x1.29ba4e80fd520p-11", "-0x1.7196ec9baf749p-12", "0x1.09ee650c053eep-4",
               "-0x1.ac72e82c0624cp-4", "0x0.0p+0")
BENCH: dict[str, tuple[dict[str, str], tuple[str, ...], float, bool]] = {
    # name: (c and g over the chapter set, start x y vx vy psi0, t_off, steady start),
    # from benchmarks.make_scenes() (checked by --check-scenes)
    "free_whirl": ({"c": "0x1.5960000000000p+11"},
                   ("-0x1.9ade88d6663fbp-12", "-0x1.bf204fe6fc7fdp-12",
                    "0x1.41b8a64acd47fp-4", "-0x1.27a21edbddf8ap-4", "0x0.0p+0"),
                   math.inf, True),
    "limit_cycle": ({"c": "0x1.cc80000000000p+9"},
                    ("-0x1.5621b7b1943f8p-16", "-0x1.1a780b1d9b88fp-12",
                     "-0x1.6729d9a37b1edp-4", "0x1.9a16476e2a5fdp-6",
                     "0x1.6e8797226e98ap+0"), math.inf, False),
    "chattering": ({"c": "0x1.5960000000000p+11"}, ("0x0.0p+0",) * 5, math.inf, False),
    "dry_whip": ({"c": "0x1.2b53333333333p+9"}, ("0x0.0p+0",) * 5, math.inf, False),
    "drop": ({"c": "0x1.5e00000000000p+10", "g": _G981}, _DROP_START, 0.1, True),
}
BENCH_T_END = 1.0


def scene_spec(name: str, group: str, params: dict[str, str], start: Iterable[str],
               segments: list[list[float]], steady: bool, steps: tuple[str, ...]) -> Spec:
    """One scene: params and start as hex, held-input segments [t_end, Omega, F_x, F_y,
    amb_on] (t from 0), whether it starts on the steady whirl, its steps."""
    x, y, vx, vy, psi0 = start
    return {"name": name, "group": group, "params": params, "x0": x, "y0": y, "vx0": vx,
            "vy0": vy, "psi0": psi0, "segments": [[float(v).hex() for v in s] for s in segments],
            "steady": steady, "steps": list(steps)}


def bench_specs() -> list[Spec]:
    """The five benchmark scenes (b), 1 s each, amb_on -> 0 at t_off."""
    out = []
    for name, (over, start, t_off, steady) in BENCH.items():
        segs = [[BENCH_T_END, OMEGA, 0.0, 0.0, 1.0]]
        if t_off < BENCH_T_END:
            segs = [[t_off, OMEGA, 0.0, 0.0, 1.0], [BENCH_T_END, OMEGA, 0.0, 0.0, 0.0]]
        out.append(scene_spec(name, "bench", {**_CHAPTER, **over}, start, segs, steady,
                              STEPS_BENCH))
    return out


def drop_spec() -> Spec:
    """(c) the bearing-failure drop: benchmark drop's rotor and start, amb_on -> 0 at 10 ms,
    0.3 s."""
    params = {**_CHAPTER, "c": "0x1.5e00000000000p+10", "g": _G981}
    segs = [[0.01, OMEGA, 0.0, 0.0, 1.0], [0.3, OMEGA, 0.0, 0.0, 0.0]]
    return scene_spec("bearing_drop", "drop", params, _DROP_START, segs, True, STEPS_FINE)


def validation_specs(root: Path) -> list[Spec]:
    """(a) every models/scenes/<Scene>_par.json of ``root`` with its <Scene>_in.csv."""
    out = []
    for par in sorted((root / "models" / "scenes").glob("*_par.json")):
        meta = json.loads(par.read_text())
        name = par.name[: -len("_par.json")]
        sv = meta["start_values"]
        held = {"Omega": float(meta["Omega"]), "F_x": 0.0, "F_y": 0.0, "amb_on": 1.0}
        segs = input_segments(par.parent / f"{name}_in.csv", held, float(meta["stop_time"]))
        params = {n: float(sv[n]).hex() for n in PARAM_NAMES}
        start = (float(sv.get(n, 0.0)).hex() for n in ("x0", "y0", "vx0", "vy0", "psi0"))
        out.append(scene_spec(name, "validation", params, start, segs, False, STEPS_FINE))
    return out


def input_segments(path: Path, held: dict[str, float], stop: float) -> list[list[float]]:
    """Held-input segments of a piecewise-constant input CSV (a step change is a repeated
    time); without the file, one segment to ``stop``."""
    order = ("Omega", "F_x", "F_y", "amb_on")
    if not path.exists():
        return [[stop, *(held[k] for k in order)]]
    with path.open() as fh:
        rows = list(csv.reader(fh))
    head = [h.strip('"') for h in rows[0]]
    pts = [(float(r[0]), {**held, **{h: float(v) for h, v in zip(head[1:], r[1:])}})
           for r in rows[1:]]
    segs: list[list[float]] = []
    for (t_a, va), (t_b, vb) in itertools.pairwise(pts):
        if t_b == t_a:
            continue
        if va != vb:
            raise ValueError(f"{path.name}: input ramps between {t_a} and {t_b}; only "
                             "held (piecewise-constant) inputs are supported")
        if segs and segs[-1][1:] == [va[k] for k in order]:
            segs[-1][0] = min(t_b, stop)
        else:
            segs.append([min(t_b, stop), *(va[k] for k in order)])
    return [s for s in segs if s[0] <= stop]


def all_specs(root: Path, only: str | None) -> list[Spec]:
    """Every scene of the default set (or those whose name matches ``only``)."""
    specs = validation_specs(root) + bench_specs() + [drop_spec()]
    return [s for s in specs if only is None or re.search(only, s["name"])]


# ------------------------------------------------------------------------------ schedules


def _fx(text: str) -> float:
    return float.fromhex(text)


def segments_of(spec: Spec) -> list[tuple[float, float, complex, float]]:
    """(t_end, Omega, F_ext, amb_on) of each held-input segment."""
    return [(_fx(t), _fx(w), complex(_fx(fx), _fx(fy)), _fx(a))
            for t, w, fx, fy, a in spec["segments"]]


def schedule(spec: Spec, h: float | None) -> list[tuple[float, float, float, complex, float]]:
    """The communication steps (t_start, h_j, Omega, F_ext, amb_on): h in each segment, the
    last step of a segment cut to its end (h when the segment is a multiple of h)."""
    out, t_a = [], 0.0
    for t_b, omega, force, amb in segments_of(spec):
        span = t_b - t_a
        step = span if h is None else h
        n = max(1, math.ceil(span / step - 1e-9))
        last = span - (n - 1) * step
        if abs(last - step) <= 1e-9 * step:
            last = step
        out += [(t_a + j * step, step if j < n - 1 else last, omega, force, amb)
                for j in range(n)]
        t_a = t_b
    return out


def jobs_of(specs: list[Spec], fmu: bool) -> list[tuple[str, str, str]]:
    """(kind, scene, step) of every job; a step with the schedule of an earlier one is
    left out."""
    jobs = []
    for spec in specs:
        seen: list[list[float]] = []
        for label in spec["steps"]:
            hs = [s[1] for s in schedule(spec, STEP_VALUES[label])]
            if hs in seen:
                continue
            seen.append(hs)
            jobs.append(("core", spec["name"], label))
    if fmu:
        names = {s["name"] for s in specs}
        jobs += [("fmu", n, lab) for n, lab in FMU_JOBS if n in names]
    return jobs


# ------------------------------------------------------------------------------ recording
# Runs in a subprocess with PYTHONPATH=<tree>/fmu_src: only the standard library, rotortd
# and (for the FMU) fmpy. Every optional attribute is read with getattr and a default.

ROW_COLS = ("t", "x", "y", "vx", "vy", "psi", "h", "F_cx", "F_cy", "F_n", "F_n_peak", "P_n",
            "T_f", "E_diss_step", "mode_step", "status", "message", "work", "work_cap",
            "n_impacts_step", "n_transitions", "n_impacts", "E_diss", "t_last_impact",
            "v_last_impact", "mode")
IMPACT_COLS = ("step", "t", "x", "y", "vx_minus", "vy_minus", "vx_plus", "vy_plus", "rdot",
               "P_n", "P_t", "stick", "E_diss")
TRANSITION_COLS = ("step", "t", "name")
NAN = math.nan


def _num(value: Any) -> float:
    """A report value as a double (bools and ints exactly; anything else NaN)."""
    try:
        return float(value)
    except (TypeError, ValueError):
        return NAN


def _cplx(value: Any) -> tuple[float, float]:
    try:
        c = complex(value)
    except (TypeError, ValueError):
        return NAN, NAN
    return c.real, c.imag


def _crc(text: Any) -> float:
    """A string (message, transition name) as a number: its crc32."""
    return float(zlib.crc32(str(text).encode()))


def hexify(value: Any) -> Any:
    """JSON-able copy with every float as float.hex (complex as [re, im])."""
    if isinstance(value, bool) or value is None or isinstance(value, (int, str)):
        return value
    if isinstance(value, float):
        return value.hex()
    if isinstance(value, complex):
        return [value.real.hex(), value.imag.hex()]
    if isinstance(value, dict):
        return {str(k): hexify(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [hexify(v) for v in value]
    return repr(value)


def core_row(core: Any, rep: Any, h: float) -> list[float]:
    """One step's row (ROW_COLS) from the core and its report."""
    g = getattr
    fx, fy = _cplx(g(rep, "F_contact", NAN))
    x, y = _cplx(g(core, "z", NAN))
    vx, vy = _cplx(g(core, "v", NAN))
    return [_num(g(core, "t", NAN)), x, y, vx, vy, _num(g(core, "psi", NAN)), h, fx, fy,
            _num(g(rep, "F_n", NAN)), _num(g(rep, "F_n_peak", NAN)), _num(g(rep, "P_n", NAN)),
            _num(g(rep, "T_f", NAN)), _num(g(rep, "E_diss", NAN)),
            _num(g(rep, "mode", g(core, "mode", NAN))),  # (the report's mode: core.mode)
            _num(g(rep, "status", NAN)), _crc(g(rep, "message", "")), _num(g(rep, "work", NAN)),
            _num(g(rep, "work_cap", NAN)), float(len(g(rep, "impacts", ()) or ())),
            float(len(g(rep, "transitions", ()) or ())), _num(g(core, "n_impacts", NAN)),
            _num(g(core, "E_diss", NAN)), _num(g(core, "t_last_impact", NAN)),
            _num(g(core, "v_last_impact", NAN)), _num(g(core, "mode", NAN))]


def impact_row(k: int, imp: Any) -> list[float]:
    """One impact (IMPACT_COLS) of step k."""
    g = getattr
    return [float(k), _num(g(imp, "t", NAN)), *_cplx(g(imp, "z", NAN)),
            *_cplx(g(imp, "v_minus", NAN)), *_cplx(g(imp, "v_plus", NAN)),
            _num(g(imp, "rdot", NAN)), _num(g(imp, "P_n", NAN)), _num(g(imp, "P_t", NAN)),
            _num(g(imp, "stick", NAN)), _num(g(imp, "E_diss", NAN))]


def transition_row(k: int, tr: Any) -> list[float]:
    """One transition (t, name) of step k."""
    try:
        t, name = tr
    except (TypeError, ValueError):
        t, name = NAN, repr(tr)
    return [float(k), _num(t), _crc(name)]


def make_params(rotortd: Any, spec: Spec) -> Any:
    """RotorParams of a scene (levitate left at its default, True, as in the FMU)."""
    return rotortd.RotorParams(**{k: _fx(v) for k, v in spec["params"].items()})


def start_of(spec: Spec, scale: float = 0.0, direction: int = -1) -> tuple[complex, complex]:
    """(z0, v0), optionally perturbed by ``scale`` (scaled units) along x, y, vx or vy
    (direction 0..3)."""
    x, y, vx, vy = (_fx(spec[k]) for k in ("x0", "y0", "vx0", "vy0"))
    c_r = _fx(spec["params"]["c_r"])
    vs = c_r * abs(segments_of(spec)[0][1])
    if direction >= 0:
        d = [0.0] * 4
        d[direction] = scale * (c_r if direction < 2 else vs)
        x, y, vx, vy = x + d[0], y + d[1], vx + d[2], vy + d[3]
    return complex(x, y), complex(vx, vy)


def run_core(rotortd: Any, spec: Spec, label: str, z0: complex, v0: complex,
             on_step: Callable[[int, Any, Any, float], None]) -> Any:
    """Run a scene on TouchdownCore, calling ``on_step(k, core, report, h)`` per step."""
    core = rotortd.TouchdownCore(make_params(rotortd, spec), z0, v0, _fx(spec["psi0"]), 0.0)
    for k, (_t, h, omega, force, amb) in enumerate(schedule(spec, STEP_VALUES[label])):
        rep = core.step(h, omega, F_ext=force, amb_on=amb)
        on_step(k, core, rep, h)
    return core


def core_counters(rotortd: Any, core: Any, spec: Spec) -> dict[str, Any]:
    """Final counters and kinematics (getattr defaults), and the steady-whirl start that
    ``on_steady_whirl`` gives today (if the scene starts there and the method exists)."""
    names = ("t", "z", "v", "psi", "mode", "n_impacts", "t_last_impact", "v_last_impact",
             "E_diss", "t_contact_entry")
    out = {n: getattr(core, n, None) for n in names}
    _t, _h, omega, _force, amb = schedule(spec, None)[-1]
    kin = getattr(core, "kinematics", None)
    out["kinematics"] = _try(lambda: list(kin(omega, amb))) if kin else None
    if spec["steady"]:
        out["steady_start"] = _try(lambda: _steady_start(rotortd, spec))
    return out


def _steady_start(rotortd: Any, spec: Spec) -> list[complex]:
    _t, omega, force, amb = segments_of(spec)[0]
    c = rotortd.TouchdownCore.on_steady_whirl(make_params(rotortd, spec), omega, F_ext=force,
                                              amb_on=amb, psi0=_fx(spec["psi0"]))
    return [c.z, c.v]


def _try(fn: Callable[[], Any]) -> Any:
    try:
        return fn()
    except Exception as exc:
        return f"error: {type(exc).__name__}: {exc}"


class Recorder:
    """Rows, events and hash of one job, written as <out>/<job>.{rows,imp,tr}."""

    def __init__(self) -> None:
        self.rows = array.array("d")
        self.imps = array.array("d")
        self.trs = array.array("d")

    def core_step(self, k: int, core: Any, rep: Any, h: float) -> None:
        self.rows.extend(core_row(core, rep, h))
        for imp in getattr(rep, "impacts", ()) or ():
            self.imps.extend(impact_row(k, imp))
        for tr in getattr(rep, "transitions", ()) or ():
            self.trs.extend(transition_row(k, tr))

    def save(self, out: Path, job: str) -> str:
        """Write the arrays; return the sha256 of rows, impacts and transitions."""
        digest = hashlib.sha256()
        for ext, arr in (("rows", self.rows), ("imp", self.imps), ("tr", self.trs)):
            data = arr.tobytes()
            digest.update(len(data).to_bytes(8, "little"))
            digest.update(data)
            (out / f"{job}.{ext}").write_bytes(data)
        return digest.hexdigest()


def job_name(kind: str, scene: str, label: str) -> str:
    return f"{kind}__{scene}__{label}"


def record_core_job(rotortd: Any, spec: Spec, label: str, out: Path) -> dict[str, Any]:
    """Record one core job; return its summary (hash, final state, counters)."""
    rec = Recorder()
    t0 = time.perf_counter()
    z0, v0 = start_of(spec)
    core = run_core(rotortd, spec, label, z0, v0, rec.core_step)
    return {"hash": rec.save(out, job_name("core", spec["name"], label)),
            "columns": [ROW_COLS, IMPACT_COLS, TRANSITION_COLS],
            "state": hexify(core.get_state()),
            "counters": hexify(core_counters(rotortd, core, spec)),
            "seconds": time.perf_counter() - t0}


def record_core(specs: dict[str, Spec], jobs: list[list[str]], out: Path) -> dict[str, Any]:
    """Record every core job; exceptions are recorded as the job's error."""
    import rotortd

    res: dict[str, Any] = {"_rotortd": str(Path(rotortd.__file__).resolve())}
    for _kind, scene, label in jobs:
        res[job_name("core", scene, label)] = _guarded(
            lambda s=scene, lab=label: record_core_job(rotortd, specs[s], lab, out))
    return res


def _guarded(fn: Callable[[], dict[str, Any]]) -> dict[str, Any]:
    try:
        return fn()
    except Exception as exc:
        return {"error": f"{type(exc).__name__}: {exc}"}


# ------------------------------------------------------------------------------ FMU


def fmu_start_values(spec: Spec) -> dict[str, Any]:
    """Start values of the FMU: parameters, the start (or start_steady), first inputs."""
    sv: dict[str, Any] = {k: _fx(v) for k, v in spec["params"].items()}
    if spec["steady"]:
        sv["start_steady"] = True
    else:
        sv.update({k: _fx(spec[k]) for k in ("x0", "y0", "vx0", "vy0")})
    sv["psi0"] = _fx(spec["psi0"])
    _t, omega, force, amb = segments_of(spec)[0]
    sv.update(Omega=omega, F_x=force.real, F_y=force.imag, amb_on=amb)
    return sv


class FmuRunner:
    """RotorTouchdown through FMPy's FMU2Slave: doStep per scheduled step, all outputs read."""

    def __init__(self, fmu_path: Path, unzip: Path) -> None:
        from fmpy import extract, read_model_description

        self.md = read_model_description(str(fmu_path))
        self.unzip = extract(str(fmu_path), str(unzip))
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        outs = sorted((v for v in self.md.modelVariables if v.causality == "output"),
                      key=lambda v: v.name)
        self.groups = {t: [v for v in outs if v.type == t] for t in ("Real", "Integer",
                                                                     "Boolean")}
        self.columns = ["t", *(v.name for t in ("Real", "Integer", "Boolean")
                               for v in self.groups[t])]

    def run(self, spec: Spec, label: str) -> tuple[array.array, dict[str, Any]]:
        from fmpy.fmi2 import FMU2Slave

        fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=self.unzip, instanceName="fp",
                        modelIdentifier=self.md.coSimulation.modelIdentifier)
        fmu.instantiate()
        try:
            self._set(fmu, fmu_start_values(spec))
            fmu.setupExperiment(startTime=0.0)
            fmu.enterInitializationMode()
            fmu.exitInitializationMode()
            rows = self._loop(fmu, spec, label)
            final = self._final_state(fmu)
            fmu.terminate()
        finally:
            fmu.freeInstance()
        return rows, final

    def _set(self, fmu: Any, values: dict[str, Any]) -> None:
        for name, val in values.items():
            if isinstance(val, bool):
                fmu.setBoolean([self.vr[name]], [val])
            else:
                fmu.setReal([self.vr[name]], [float(val)])

    def _loop(self, fmu: Any, spec: Spec, label: str) -> array.array:
        rows = array.array("d")
        vrs = {t: [v.valueReference for v in g] for t, g in self.groups.items()}
        held: tuple[float, complex, float] | None = None
        for t, h, omega, force, amb in schedule(spec, STEP_VALUES[label]):
            if held is not None and held != (omega, force, amb):
                self._set(fmu, {"Omega": omega, "F_x": force.real, "F_y": force.imag,
                                "amb_on": amb})
            held = (omega, force, amb)
            status = fmu.doStep(t, h)
            rows.append(t + h if status == 0 else NAN)
            rows.extend(float(x) for x in fmu.getReal(vrs["Real"]))
            rows.extend(float(x) for x in fmu.getInteger(vrs["Integer"]))
            rows.extend(float(bool(x)) for x in fmu.getBoolean(vrs["Boolean"]))
        return rows

    @staticmethod
    def _final_state(fmu: Any) -> dict[str, Any]:
        """The serialised FMU state (JSON in RotorTouchdown), parsed."""
        state = fmu.getFMUstate()
        data = bytes(fmu.serializeFMUstate(state))
        fmu.freeFMUstate(state)
        try:
            return json.loads(data.decode())
        except ValueError:
            return {"bytes_sha256": hashlib.sha256(data).hexdigest()}


def record_fmu_job(runner: FmuRunner, spec: Spec, label: str, out: Path) -> dict[str, Any]:
    t0 = time.perf_counter()
    rows, final = runner.run(spec, label)
    rec = Recorder()
    rec.rows = rows
    return {"hash": rec.save(out, job_name("fmu", spec["name"], label)),
            "columns": [runner.columns, IMPACT_COLS, TRANSITION_COLS],
            "state": hexify(final), "counters": {}, "seconds": time.perf_counter() - t0}


def record_fmu(specs: dict[str, Spec], jobs: list[list[str]], out: Path,
               fmu_path: Path) -> dict[str, Any]:
    """Record every FMU job with the FMU built from this tree."""
    try:
        runner = FmuRunner(fmu_path, out / "fmu_unzip")
    except Exception as exc:
        return {job_name("fmu", s, lab): {"error": f"FMU load: {exc}"} for _k, s, lab in jobs}
    return {job_name("fmu", s, lab): _guarded(
        lambda s=s, lab=lab: record_fmu_job(runner, specs[s], lab, out)) for _k, s, lab in jobs}


# ------------------------------------------------------------------------------ amplification


def amplification_job(rotortd: Any, spec: Spec) -> dict[str, Any]:
    """Largest scaled state difference over the run, per 1e-12 start perturbation (8
    directions), at AMP_STEP; and whether the impact count changed."""
    c_r = _fx(spec["params"]["c_r"])
    vs = c_r * abs(segments_of(spec)[0][1])

    def trace(z0: complex, v0: complex) -> tuple[list[tuple[complex, complex]], int]:
        pts: list[tuple[complex, complex]] = []
        core = run_core(rotortd, spec, AMP_STEP, z0, v0,
                        lambda _k, c, _r, _h: pts.append((c.z, c.v)))
        return pts, core.n_impacts

    ref, n_ref = trace(*start_of(spec))
    amp, counts = 0.0, set()
    for direction in range(4):
        for sign in (1.0, -1.0):
            pts, n = trace(*start_of(spec, sign * AMP_DELTA, direction))
            counts.add(n)
            dev = max(max(abs(z - zr) / c_r, abs(v - vr) / vs)
                      for (z, v), (zr, vr) in zip(pts, ref))
            amp = max(amp, dev / AMP_DELTA)
    return {"amplification": amp, "count_changes": counts != {n_ref}}


def record_amplification(specs: dict[str, Spec]) -> dict[str, Any]:
    import rotortd

    return {name: _guarded(lambda s=spec: amplification_job(rotortd, s))
            for name, spec in specs.items()}


# ------------------------------------------------------------------------------ child entry


def child_main(task_path: Path) -> int:
    """Entry of a recording subprocess: a JSON task (mode, specs, jobs, out[, fmu])."""
    task = json.loads(task_path.read_text())
    specs = {s["name"]: s for s in task["specs"]}
    out = Path(task["out"])
    if task["mode"] == "core":
        res = record_core(specs, task["jobs"], out)
    elif task["mode"] == "fmu":
        res = record_fmu(specs, task["jobs"], out, Path(task["fmu"]))
    else:
        res = record_amplification(specs)
    (out / f"{task['mode']}.json").write_text(json.dumps(res))
    sys.stdout.flush()
    os._exit(0)  # no interpreter teardown: PythonFMU may corrupt the heap at exit


# ------------------------------------------------------------------------------ trees


def tree_env(tree: Path) -> dict[str, str]:
    """Environment of a recording: its tree's fmu_src first, fixed hash seed."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update(PYTHONPATH=str(tree / "fmu_src"), PYTHONHASHSEED="0")
    return env


def add_worktree(commit: str, path: Path) -> None:
    """A detached worktree of ``commit`` at ``path``; exits with git's message if refused."""
    proc = subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", "--quiet",
                           str(path), commit], capture_output=True, text=True)
    if proc.returncode:
        raise SystemExit(f"git worktree add {commit} failed: {proc.stderr.strip()}")


def remove_worktree(path: Path) -> None:
    subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(path)],
                   capture_output=True)
    subprocess.run(["git", "-C", str(ROOT), "worktree", "prune"], capture_output=True)


def build_fmu(tree: Path, dest: Path) -> Path:
    """RotorTouchdown.fmu built by the tree's own build.py (not validated)."""
    proc = subprocess.run([sys.executable, "build.py", "--dest", str(dest), "--only",
                           "RotorTouchdown", "--no-check"], cwd=tree, env=tree_env(tree),
                          capture_output=True, text=True)
    fmu = dest / "RotorTouchdown.fmu"
    if proc.returncode or not fmu.exists():
        raise RuntimeError(f"FMU build in {tree} failed: {proc.stderr[-1000:]}")
    return fmu


def run_child(tree: Path, task: dict[str, Any], work: Path) -> dict[str, Any]:
    """Run one recording task in a subprocess in ``tree``'s environment."""
    path = work / f"{task['mode']}_task.json"
    path.write_text(json.dumps(task))
    proc = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--record",
                           str(path)], cwd=tree, env=tree_env(tree), capture_output=True,
                          text=True)
    res_path = Path(task["out"]) / f"{task['mode']}.json"
    if not res_path.exists():
        raise RuntimeError(f"recording ({task['mode']}) in {tree} failed, rc "
                           f"{proc.returncode}: {proc.stderr[-2000:]}")
    return json.loads(res_path.read_text())


def record_tree(tree: Path, specs: list[Spec], jobs: list[tuple[str, str, str]],
                work: Path) -> dict[str, Any]:
    """Record every job in ``tree`` (core, then FMU); return {job: summary}."""
    work.mkdir(parents=True)
    base = {"specs": specs, "out": str(work)}
    core = run_child(tree, {**base, "mode": "core", "jobs": [j for j in jobs if j[0] == "core"]},
                     work)
    origin = core.pop("_rotortd")
    if not origin.startswith(str(tree.resolve() / "fmu_src")):
        raise RuntimeError(f"the recording of {tree} imported rotortd from {origin}")
    fmu_jobs = [j for j in jobs if j[0] == "fmu"]
    if not fmu_jobs:
        return core
    try:
        fmu = build_fmu(tree, work / "fmu")
    except RuntimeError as exc:
        return {**core, **{job_name(*j): {"error": str(exc)} for j in fmu_jobs}}
    return {**core, **run_child(tree, {**base, "mode": "fmu", "jobs": fmu_jobs,
                                       "fmu": str(fmu)}, work)}


# ------------------------------------------------------------------------------ comparison

TIME_KEYS = {"t", "t_lo", "t_last", "t_contact", "t_last_impact", "t_contact_entry", "H",
             "h", "time"}
POS_KEYS = {"z", "x", "y", "x0", "y0"}
VEL_KEYS = {"v", "vx", "vy", "v_last", "v_last_impact", "rdot", "vx_minus",
            "vy_minus", "vx_plus", "vy_plus", "v_rel", "vx0", "vy0"}
RATE_KEYS = {"dtheta", "whirl_rate", "Omega", "Omega_out"}
ANGLE_KEYS = {"psi", "theta", "psi0", "r_rel", "u_re", "u_im", "du_re", "du_im"}
FORCE_KEYS = {"F_cx", "F_cy", "F_n", "F_n_peak", "F_bx", "F_by", "F_amb_x", "F_amb_y"}
IMPULSE_KEYS = {"P_n", "P_t"}
TORQUE_KEYS = {"T_f"}
ENERGY_KEYS = {"E_diss", "E_diss_step"}
COUNT_KEYS = {"n_impacts", "n_impacts_step", "n_transitions"}
MODE_KEYS = {"mode", "mode_step", "in_contact", "slip", "locked", "on_wall"}
"""Discrete state: a difference clears "modes equal" (slip is the sliding direction)."""
SIZED_KEYS = FORCE_KEYS | IMPULSE_KEYS | TORQUE_KEYS | ENERGY_KEYS
"""Measured against max(unit, |value|): a step-averaged force P/h at a small step, or the
cumulative E_diss, is many units large, and its rounding is relative to its size."""


def scales(spec: Spec) -> dict[str, float]:
    """Unit of each kind of quantity (SI): c_r, c_r |Omega|, 1/|Omega|, ..."""
    p = {k: _fx(v) for k, v in spec["params"].items()}
    w = abs(segments_of(spec)[0][1])
    c_r, m = p["c_r"], p["m"]
    force = m * c_r * w * w
    out = {}
    for keys, unit in ((TIME_KEYS, 1.0 / w), (POS_KEYS, c_r), (VEL_KEYS, c_r * w),
                       (RATE_KEYS, w), (ANGLE_KEYS, 1.0), (FORCE_KEYS, force),
                       (IMPULSE_KEYS, force / w), (TORQUE_KEYS, p["R"] * force),
                       (ENERGY_KEYS, m * (c_r * w) ** 2)):
        out.update(dict.fromkeys(keys, unit))
    return out


def scaled_diff(a: float, b: float, unit: float | None, sized: bool = False) -> float:
    """|a - b| in units of ``unit``, or of max(unit, |a|, |b|) if ``sized``, or relative if
    ``unit`` is None; 0 for equal values, inf for NaN or inf against a number."""
    if a == b or (math.isnan(a) and math.isnan(b)):
        return 0.0
    if not (math.isfinite(a) and math.isfinite(b)):
        return math.inf
    if unit is None:
        return abs(a - b) / max(abs(a), abs(b))
    return abs(a - b) / (max(unit, abs(a), abs(b)) if sized else unit)


class Verdict:
    """The comparison of one job between base and head."""

    def __init__(self, job: tuple[str, str, str]) -> None:
        self.job = job
        self.identical = False
        self.first = ""
        self.first_at = math.inf  # step index of the first difference
        self.max_scaled = 0.0
        self.counts_equal = True
        self.modes_equal = True
        self.status_equal = True
        self.error = ""
        self.added: list[str] = []  # outputs the head records beyond the base's

    def note(self, at: float, what: str) -> None:
        """Keep the earliest difference (ties: the first noted)."""
        if not self.first or at < self.first_at:
            self.first_at, self.first = at, what

    def rounding_only(self) -> bool:
        return (not self.error and self.max_scaled <= ROUNDING and self.counts_equal
                and self.modes_equal and self.status_equal)


def load_table(work: Path, job: str, ext: str, ncols: int) -> Any:
    import numpy as np

    data = np.frombuffer((work / f"{job}.{ext}").read_bytes(), dtype="<f8")
    return data.reshape(-1, ncols)


def compare_tables(v: Verdict, a: Any, b: Any, cols: list[str], units: dict[str, float],
                   label: str) -> None:
    """Bitwise comparison of two tables: step rows by index, impacts and transitions by
    order. An event of step k comes before the state at the end of step k."""
    import numpy as np

    def when(table: Any, i: int) -> float:
        return float(i) if label == "step" else float(table[i, 0]) - 0.5

    n = min(len(a), len(b))
    if len(a) != len(b):
        v.note(when(a if n < len(a) else b, n), f"{label} count {len(a)} -> {len(b)}")
        if label == "impact":
            v.counts_equal = False
    diff = a[:n].view("<u8") != b[:n].view("<u8")
    if not diff.any():
        return
    i, j = map(int, np.argwhere(diff)[0])
    where = f"step {i}" if label == "step" else f"{label} #{i} (step {int(a[i, 0])})"
    v.note(when(a, i), f"{cols[j]} at {where}")
    for j in np.nonzero(diff.any(axis=0))[0]:
        name = cols[int(j)]
        flag_difference(v, name)
        if name in units:
            for x, y in zip(a[:n, j][diff[:, j]], b[:n, j][diff[:, j]]):
                v.max_scaled = max(v.max_scaled, scaled_diff(float(x), float(y), units[name],
                                                             name in SIZED_KEYS))


def flag_difference(v: Verdict, name: str) -> None:
    """A difference in a count, mode or status column clears that flag."""
    if name in COUNT_KEYS or name == "stick":
        v.counts_equal = False
    elif name in MODE_KEYS:
        v.modes_equal = False
    elif name in ("status", "message"):
        v.status_equal = False


def flatten(value: Any, prefix: str = "") -> dict[str, Any]:
    """{"key.sub.0": leaf} of a nested JSON value."""
    if isinstance(value, dict):
        out: dict[str, Any] = {}
        for k, x in value.items():
            out.update(flatten(x, f"{prefix}{k}."))
        return out
    if isinstance(value, list):
        out = {}
        for i, x in enumerate(value):
            out.update(flatten(x, f"{prefix}{i}."))
        return out
    return {prefix.rstrip("."): value}


def _as_float(x: Any) -> float | None:
    if isinstance(x, str):
        try:
            return float.fromhex(x)
        except ValueError:
            return None
    return None


def _unit_of(path: str, units: dict[str, float]) -> float | None:
    """Scale of a final-state leaf by the last non-index part of its key path."""
    parts = [p for p in path.split(".") if not p.isdigit()]
    if "params" in parts:
        return None
    for part in reversed(parts):
        if part in units:
            return units[part]
    return None


SCHEMA_LEAVES = ("version",)
"""Leaves of a saved state that are bookkeeping of its schema, not physics: left out."""
NULL_WHEN_HELD = ("J", "spin")
"""Leaves that a held-speed state holds as null or lacks, by schema version (the core's
J since rotortd-state 2, the adapter's spin until rotortd-fmu-state 1): left out when null."""


CACHE_KEYS = ("imb_h",)
"""State entries that record a cache's choice between two roundings (the imbalance torque's
proved-free closed form), new in rotortd-state 2: not compared."""


def physics_leaves(value: Any) -> dict[str, Any]:
    """``flatten(value)`` without the schema's bookkeeping (SCHEMA_LEAVES, the
    NULL_WHEN_HELD leaves when null, CACHE_KEYS), so that a schema version bump compares
    equal."""
    out = {}
    for key, x in flatten(value).items():
        parts = key.split(".")
        last = parts[-1]
        if (last in SCHEMA_LEAVES or (last in NULL_WHEN_HELD and x is None)
                or any(c in parts for c in CACHE_KEYS)):
            continue
        out[key] = x
    return out


def compare_final(v: Verdict, a: dict[str, Any], b: dict[str, Any], units: dict[str, float],
                  what: str) -> None:
    """Final state or counters: every leaf, floats bit-exact (as float.hex). A differing
    leaf that is not a float (a flag, an integer, a missing key) counts as infinitely
    different unless it is a count or a mode."""
    fa, fb = physics_leaves(a), physics_leaves(b)
    for key in sorted(set(fa) | set(fb), key=lambda k: (k not in fa, k)):
        x, y = fa.get(key, "<absent>"), fb.get(key, "<absent>")
        if x == y:
            continue
        v.note(math.inf, f"{what} {key}")
        name = [p for p in key.split(".") if not p.isdigit()][-1]
        flag_difference(v, name)
        fx, fy = _as_float(x), _as_float(y)
        if fx is not None and fy is not None:
            sized = bool(SIZED_KEYS & set(key.split(".")))
            v.max_scaled = max(v.max_scaled, scaled_diff(fx, fy, _unit_of(key, units), sized))
        elif name not in COUNT_KEYS | MODE_KEYS:
            v.max_scaled = math.inf


def compare_job(job: tuple[str, str, str], ra: dict[str, Any], rb: dict[str, Any],
                wa: Path, wb: Path, spec: Spec) -> Verdict:
    """Compare the recordings of one job in base (a) and head (b)."""
    v = Verdict(job)
    if "error" in ra or "error" in rb:
        v.error = f"base: {ra.get('error', 'ok')}; head: {rb.get('error', 'ok')}"
        v.first = "error"
        v.max_scaled = math.inf
        return v
    if ((ra["hash"], physics_leaves(ra["state"]), ra["counters"])
            == (rb["hash"], physics_leaves(rb["state"]), rb["counters"])):
        v.identical = True
        return v
    units = scales(spec)
    name = job_name(*job)
    added: set[str] = set()
    for ext, ca, cb, label in zip(("rows", "imp", "tr"), ra["columns"], rb["columns"],
                                  ("step", "impact", "transition")):
        if not set(ca) <= set(cb):
            v.note(-1.0, f"recorded {label} columns removed: {sorted(set(ca) - set(cb))}")
            v.max_scaled = math.inf
            continue
        added |= set(cb) - set(ca)  # a new output: compared on the base's columns
        tb = load_table(wb, name, ext, len(cb))[:, [list(cb).index(c) for c in ca]]
        compare_tables(v, load_table(wa, name, ext, len(ca)), tb, list(ca), units, label)
    v.added = sorted(added)
    compare_final(v, ra["counters"], rb["counters"], units, "counter")
    compare_final(v, ra["state"], _without_keys(rb["state"], added), units, "state")
    if added and not v.first:  # identical on everything the base recorded
        v.identical = True
        v.first = f"adds {', '.join(v.added)}"
    return v


def _without_keys(value: Any, names: set[str]) -> Any:
    """value with every dict key in names removed, recursively (an added output's value
    in the head's saved FMU state)."""
    if not names:
        return value
    if isinstance(value, dict):
        return {k: _without_keys(x, names) for k, x in value.items() if k not in names}
    if isinstance(value, list):
        return [_without_keys(x, names) for x in value]
    return value


# ------------------------------------------------------------------------------ report


def fmt_amp(amp: dict[str, Any] | None) -> str:
    if not amp:
        return ""
    if "error" in amp:
        return "error"
    mark = "*" if amp["count_changes"] else ""
    return f"{amp['amplification']:.3g}{mark}"


def print_table(verdicts: list[Verdict], amps: dict[str, Any]) -> None:
    print(f"{'kind':4s} {'scene':22s} {'step':>5s} {'ident':5s} {'counts=':7s} "
          f"{'modes=':6s} {'max scaled':>10s} {'amp':>8s}  first difference")
    for v in verdicts:
        kind, scene, label = v.job
        diff = "" if v.identical else f"{v.max_scaled:10.3g}"
        amp = fmt_amp(amps.get(scene)) if kind == "core" else ""
        first = v.error or v.first
        print(f"{kind:4s} {scene:22s} {label:>5s} {_yn(v.identical):5s} "
              f"{_yn(v.counts_equal):7s} {_yn(v.modes_equal):6s} {diff:>10s} {amp:>8s}  "
              f"{first}")


def _yn(flag: bool) -> str:
    return "yes" if flag else "NO"


def print_hashes(res: dict[str, Any], jobs: list[tuple[str, str, str]]) -> None:
    for job in jobs:
        r = res[job_name(*job)]
        print(f"{job[0]:4s} {job[1]:22s} {job[2]:>5s}  {r.get('hash', r.get('error'))}")


# ------------------------------------------------------------------------------ main


def check_scenes() -> int:
    """Compare the frozen benchmark starts with benchmarks.make_scenes() of this tree."""
    sys.path[:0] = [str(ROOT / "docs" / "scripts"), str(ROOT / "tests"), str(ROOT),
                    str(ROOT / "fmu_src")]
    import benchmarks as bm

    bad = 0
    for spec, sc in zip(bench_specs(), bm.make_scenes()):
        fixed = start_of(spec)
        p = {k: getattr(sc.params, k).hex() for k in PARAM_NAMES}
        same = (spec["name"] == sc.name and fixed == (sc.z0, sc.v0) and p == spec["params"]
                and _fx(spec["psi0"]) == sc.psi0 and segments_of(spec) == [
                    (a, b, c, d) for a, b, c, d in sc.segments()])
        print(f"{spec['name']:12s} {'frozen = benchmarks' if same else 'DIFFERS'}")
        bad += not same
    return 1 if bad else 0


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", help="commit to compare the current tree with")
    ap.add_argument("--allow-rounding", action="store_true",
                    help=f"exit 0 also for differences <= {ROUNDING:g} scaled with equal "
                         "counts, modes and statuses")
    ap.add_argument("--amplification", action="store_true",
                    help="measure each scene's amplification of a 1e-12 start perturbation")
    ap.add_argument("--only", help="regular expression: scenes whose name matches")
    ap.add_argument("--no-fmu", action="store_true", help="core only")
    ap.add_argument("--keep", action="store_true", help="keep the temporary directory")
    ap.add_argument("--check-scenes", action="store_true",
                    help="check the frozen benchmark scenes against benchmarks.py")
    ap.add_argument("--record", type=Path, help=argparse.SUPPRESS)
    return ap.parse_args(argv)


def run(args: argparse.Namespace, tmp: Path) -> int:
    specs = all_specs(ROOT, args.only)
    jobs = jobs_of(specs, not args.no_fmu)
    by_name = {s["name"]: s for s in specs}
    t0 = time.perf_counter()
    trees = {"head": ROOT}
    if args.base:
        trees["base"] = tmp / "base_tree"
        add_worktree(args.base, trees["base"])
    try:
        with ThreadPoolExecutor(max_workers=2) as pool:
            futs = {k: pool.submit(record_tree, tree, specs, jobs, tmp / k)
                    for k, tree in trees.items()}
            amp_fut = pool.submit(run_child, ROOT, {"mode": "amp", "specs": specs,
                                                    "out": str(tmp), "jobs": []}, tmp) \
                if args.amplification else None
            res = {k: f.result() for k, f in futs.items()}
            amps = amp_fut.result() if amp_fut else {}
    finally:
        if args.base:
            remove_worktree(trees["base"])
    secs = time.perf_counter() - t0
    if not args.base:
        print_hashes(res["head"], jobs)
        print(f"{len(jobs)} jobs recorded in {secs:.0f} s (no --base: nothing compared)")
        return 0
    verdicts = [compare_job(j, res["base"][job_name(*j)], res["head"][job_name(*j)],
                            tmp / "base", tmp / "head", by_name[j[1]]) for j in jobs]
    print(f"base {args.base} vs current tree {ROOT}")
    print_table(verdicts, amps)
    return summarise(verdicts, amps, args.allow_rounding, secs)


def summarise(verdicts: list[Verdict], amps: dict[str, Any], allow_rounding: bool,
              secs: float) -> int:
    same = sum(v.identical for v in verdicts)
    rounding = [v for v in verdicts if not v.identical and v.rounding_only()]
    print(f"{same}/{len(verdicts)} jobs identical, {len(rounding)} within rounding "
          f"(<= {ROUNDING:g} scaled, equal counts and modes); {secs:.0f} s")
    if amps:
        print_judgeable(verdicts, amps)
    if same == len(verdicts):
        return 0
    return 0 if allow_rounding and same + len(rounding) == len(verdicts) else 1


def print_judgeable(verdicts: list[Verdict], amps: dict[str, Any]) -> None:
    """The scenes whose amplification is <= 10, and how their core jobs fared."""
    low = sorted(n for n, a in amps.items() if a.get("amplification", math.inf) <= 10)
    print(f"amplification <= 10 (rounding judgeable; * in amp = a perturbed run changed the "
          f"impact count): {', '.join(low) or 'none'}")
    mine = [v for v in verdicts if v.job[0] == "core" and v.job[1] in low]
    print(f"  their {len(mine)} core jobs: {sum(v.identical for v in mine)} identical, "
          f"{sum(not v.identical and v.rounding_only() for v in mine)} within rounding, "
          f"{sum(not v.rounding_only() for v in mine)} beyond")


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    if args.record:
        return child_main(args.record)
    if args.check_scenes:
        return check_scenes()
    tmp = Path(tempfile.mkdtemp(prefix="fingerprint_"))
    try:
        return run(args, tmp)
    finally:
        if args.keep:
            print(f"kept {tmp}")
        else:
            shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    raise SystemExit(main())
