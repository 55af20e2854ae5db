"""Bit-exact behaviour fingerprint of the core and the FMU, compared with an earlier commit.

    python docs/scripts/fingerprint.py --base <commit>        # ~25 s on 2 cores (below)
    python docs/scripts/fingerprint.py --base <commit> --criteria
    python docs/scripts/fingerprint.py --base <commit> --amplification   # ~90 s
    python docs/scripts/fingerprint.py                          # this tree only: the hashes
    python docs/scripts/fingerprint.py --check-scenes           # frozen scenes vs this tree

Proof for issue 16 ("behaviour stays exactly as it is") and the proof tool of issue 23 (one
physics family: what may move, and by how much). Every job, a scene run at one
communication step, is recorded to the last bit:

- per step: the core's time, position, velocity, spin angle and spin speed after the step
  and the step report (F_contact, F_n, F_n_peak, P_n, T_f, T_imb, E_diss, mode (the
  core's where the report has none), status, message, work, work_cap, number of impacts
  and transitions) and the cumulative counters (n_impacts, E_diss, t_last_impact,
  v_last_impact, mode); every impact (t, z, v-, v+, rdot, P_n, P_t, stick, E_diss) and
  transition (t, name) in an event list; all as IEEE doubles, hashed (sha256) per job;
- at the end: the core's state JSON (``get_state()``), its reads and ``outputs()`` by
  name, floats as ``float.hex``;
- the job's tag: the segment kinds it passed through, with counts (TAGS: P proved-free
  flight, F searched flight, S sliding, R rolling, L/Q/K the linear, quadratic and locked
  rub; with the spin as a state C closed-form flight, I integrated flight, q the quiet
  step (integrated, proved clear at once), s sliding, r rolling), and a summary: impacts,
  contact time (from the transitions' times), the largest r/c_r at the steps' ends, the
  steps ending in each mode, nonzero statuses.

The FMU (built from each tree with its own build.py) runs a few scenes through FMPy's
``FMU2Slave`` (a spin_* scene with integrate_spin = true); per step every output is read, at
the end the serialised FMU state. An FMU job takes the tag of the core job of its scene and
step; its contact time counts the steps that end in contact.

Scenes: (a) every ``models/scenes/*_par.json`` (inputs from ``<Scene>_in.csv``), (b) the five
benchmark scenes of docs/scripts/benchmarks.py (1 s each; their start values frozen below,
``--check-scenes`` compares them with ``benchmarks.make_scenes()``), (c) a bearing-failure
drop: chapter rotor, g = 9.81, levitated steady whirl at 184.2 rad/s, amb_on 1 -> 0 at
10 ms, 0.3 s, (d) the spin as a state (SPIN; ``SpinCore``, the scenes of docs/spin.md and
docs/scripts/bench_spin.py): the drop into dry whirl (rolling backward whirl) from
the levitated whirl with the bearing failed, J = m R^2/2 and 5 m R^2, 0.3 s; pressed
sliding (F_ext = -5000j N, the drive torque R mu N balancing the friction), 0.2 s; the
levitated whirl with the bearing on (integrated flight), 0.1 s; closed-form flight (bearing
off, g = 0), 0.1 s; the run-down with a braking drive through impacts and a forward rub,
0.9 s at 1e-3 s (``--check-scenes`` checks their parameters and levitated starts against
RotorParams and TouchdownCore.on_steady_whirl). Steps: ``seg`` (one call per held-input
segment: the whole run, or two calls around the AMB failure), 0.1 s, 1e-3 s, 1e-4 s and,
for (a) and (c), 1e-5 s; (d) at 1e-3 and 1e-4 s; a step whose schedule equals an earlier
one's (0.1 s on a 0.1 s scene) is left out. The scene definitions are read once, here,
from the current tree, and handed to both recordings.

``--base C`` checks out C in a temporary ``git worktree add --detach`` (removed at the end),
and records it and the current tree (with its uncommitted changes) in two subprocesses run in
parallel, each with ``PYTHONPATH=<tree>/fmu_src`` (its own code, not the installed editable
package; each recording checks where ``rotortd`` came from) and ``PYTHONHASHSEED=0``. The
recording code is this file's, in both trees. It reaches the tree only through the section
"tree adapter": ``adapt`` builds a scene's core (classes found in ``rotortd`` or any of its
modules; keyword arguments, else positional), binds its step (``step(h, Omega=, F_ext=,
amb_on=)``, or ``step(h, F_ext=, amb_on=, T_drive=)`` with the spin as a state), reads the
state by public name (``core.t``, ``.z``, ... else the ``core.outputs()`` field of that
name) and the state JSON (``get_state()``, else ``state.to_json()``); report, impact and
transition fields are read with ``getattr`` and a default, so a renamed field shows up as a
difference, not a crash; what no fallback fits is the job's error, to be fixed in the
adapter. The tags come from a hook: ``install_segment_hook`` wraps ``run`` of the segment
classes (HOOKED, by class name: Flight, Sliding, Rolling, LinearRub, QuadraticRub,
LockedRub, SpinFlight, SpinContact) so that each logs its kind, read from public attributes
of the segment (``Flight.search``, ``SpinFlight.closed``, ``SpinContact.rolling``); a held
step that runs no segment from flight is TouchdownCore's proved-free whole step. No private
attribute of the core is read. Without any of those classes (a refactored tree) the tags
fall back to the modes the steps passed through (f, d, o). The tag that is judged is the
base's.

Final states are compared leaf by leaf through STATE_NAMES (the core's state; the FMU's
below its "core" key, FMU_STATE_NAMES): a map from the base's names to the head's, today
each name to itself. A new state layout (per-component records, a version bump) is declared
there, and only there (its docstring shows how); then it is not a difference. Leaves only
the head has are listed as added, not differences; schema bookkeeping and caches map to
None (not compared).

The table: per job whether it is identical; the largest difference in scaled units; the
base's impacts, modes at the steps' ends (free/sliding/rolling) and nonzero statuses
("base->head" where they differ); the amplification; the base's tag; the issue-23 criterion
that applies and whether it holds; for a differing job, on a second line, the first
differing quantity (in time order: step row, impact or transition, then the final counters
and state) and whether impact counts, modes and statuses are equal at every step. The
criteria (``Verdict.judge``): a job carried only by closed forms (CLOSED_FORM: proved-free
flight, closed-form rolling, the rubs) must be bit-identical; a job whose amplification is
<= AMP_LOW (10) must be within rounding (<= 1e-13 scaled, equal counts, modes and
statuses); any other job's impact rate, contact fraction and largest r within STATS_TOL
(1 %). Scaled units: positions in c_r, velocities in c_r |Omega|, times in 1/|Omega|,
rates in |Omega|, angles in rad; forces (m c_r Omega^2), impulses (m c_r |Omega|), torques
(R m c_r Omega^2) and energies (m (c_r Omega)^2) against the larger of that unit and their
own size, since a step-averaged P/h at 1e-5 s or the cumulative E_diss is many units large
and rounds relative to it; other final-state values relative; ``inf`` where a value is
missing, non-finite or not a number on one side. Omega is that of the first segment (the
initial spin with the spin as a state). Exit 0 iff all jobs are identical; with
``--allow-rounding`` iff every difference is <= 1e-13 scaled with equal counts, modes and
statuses (work counters may differ); with ``--criteria`` iff every job meets its criterion.
An FMU output the head adds (T_imb) is reported as "adds ..." and the job compared on the
base's columns.

Amplification (``amplification_job``): per core job, at its own steps, on the base tree,
the largest scaled state difference at the steps' ends (z in c_r, v in c_r |Omega|, the
spin in |Omega|) over the run, divided by 1e-12, for a 1e-12 scaled perturbation of the
start (+-x, +-y, +-vx, +-vy and, with the spin as a state, +-Omega0); "*" when a perturbed
run's impact count differs. It costs 8 to 10 runs of the job, so it is measured only for
the jobs that differ (and the core jobs of differing FMU jobs), in two children; all
identical: nothing to measure. ``--amplification`` measures every core job (~65 s more);
``--no-amplification`` none (the rounding and statistics criteria then print "?").

Run time (2 cores, base and head in parallel, load average below 1): ~25 s for the default
set (of which the spin scenes ~4-7 s CPU per tree for the core jobs and ~2 s for their FMU
jobs), ~85 s with ``--amplification``; per tree ~15 s CPU for the core recordings, ~3-6 s
for the FMU runs and ~1.5 s for its build; ``--no-fmu`` saves the FMU part. The temporary
files (~60 MB per tree) are removed unless ``--keep``.
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
from typing import Any, NamedTuple

ROOT = Path(__file__).resolve().parents[2]
OMEGA = 184.2
ROUNDING = 1e-13
"""--allow-rounding: largest accepted scaled difference."""
AMP_LOW = 10.0
"""Issue 23: a job whose amplification is at most this is judged by ROUNDING."""
STATS_TOL = 0.01
"""Issue 23: above AMP_LOW, impact rate, contact fraction and largest r within this."""
AMP_DELTA = 1e-12
STEP_VALUES: dict[str, float | None] = {"seg": None, "0.1": 0.1, "1e-3": 1e-3, "1e-4": 1e-4,
                                        "1e-5": 1e-5}
STEPS_FINE = ("seg", "0.1", "1e-3", "1e-4", "1e-5")
STEPS_BENCH = ("seg", "0.1", "1e-3", "1e-4")
FMU_JOBS: tuple[tuple[str, str], ...] = (
    ("AMB_drop", "1e-3"), ("AMB_drop", "1e-4"), ("Chatter_to_rub", "seg"),
    ("Chatter_to_rub", "1e-4"), ("limit_cycle", "seg"), ("limit_cycle", "1e-3"),
    ("bearing_drop", "1e-3"), ("bearing_drop", "1e-4"),
    ("spin_drop", "1e-3"), ("spin_drop", "1e-4"), ("spin_sliding", "1e-3"),
    ("spin_levitated", "1e-3"), ("spin_rundown", "1e-3"))
"""(scene, step) run through the FMU as well (a spin_* scene with integrate_spin = true)."""
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
    "dry_whirl": ({"c": "0x1.2b53333333333p+9"}, ("0x0.0p+0",) * 5, math.inf, False),
    "drop": ({"c": "0x1.5e00000000000p+10", "g": _G981}, _DROP_START, 0.1, True),
}
BENCH_T_END = 1.0


def scene_spec(name: str, group: str, params: dict[str, str], start: Iterable[str],
               segments: list[list[float]], steady: bool, steps: tuple[str, ...],
               spin: tuple[str, str] | None = None) -> Spec:
    """One scene: params and start as hex, held-input segments [t_end, Omega, F_x, F_y,
    amb_on(, T_drive)] (t from 0, SI), whether it starts on the steady whirl, its steps;
    ``spin`` = (J, Omega0) as hex for a scene of the spin as a state (SpinCore; Omega of
    its segments is then Omega0, the FMU's initial speed)."""
    x, y, vx, vy, psi0 = start
    spec = {"name": name, "group": group, "params": params, "x0": x, "y0": y, "vx0": vx,
            "vy0": vy, "psi0": psi0, "segments": [[float(v).hex() for v in s] for s in segments],
            "steady": steady, "steps": list(steps)}
    if spin is not None:
        spec["J"], spec["Omega0"] = spin
    return spec


def is_spin(spec: Spec) -> bool:
    """A scene of the spin as a state (SpinCore, the FMU with integrate_spin)."""
    return "J" in spec


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


_C1400 = "0x1.5e00000000000p+10"
_J_HALF, _J_5 = "0x1.47ae147ae147bp-5", "0x1.999999999999ap-2"  # m R^2/2, 5 m R^2 (kg m^2)
_RUNDOWN_START = ("-0x1.d7e2361b552cbp-12", "-0x1.a644d8c1453c9p-13", "0x1.6ae32a4617801p-5",
                  "-0x1.9586667f7d326p-4", "0x0.0p+0")
_CIRCLE_START = ("0x0.0p+0", "0x0.0p+0", "0x1.797885238deffp-7", "-0x1.babea70ddc9f4p-5",
                 "0x0.0p+0")
SPIN: dict[str, tuple[str, tuple[str, ...], str, float, float, tuple[float, ...],
                      tuple[str, ...]]] = {
    # name: (g, start x y vx vy psi0, J, Omega0 (rad/s), t_end (s), held inputs F_x F_y
    # (N) amb_on T_drive (N m), steps); the chapter rotor with c = 1400 N s/m (RotorParams'
    # defaults), the scenes of docs/spin.md and docs/scripts/bench_spin.py, shortened.
    # The drop into dry whirl (rolling): levitated steady whirl, bearing failed at t = 0.
    "spin_drop": (_G981, _DROP_START, _J_HALF, OMEGA, 0.3, (0.0, 0.0, 0.0, 0.0),
                  ("1e-3", "1e-4")),
    "spin_drop_J5": (_G981, _DROP_START, _J_5, OMEGA, 0.3, (0.0, 0.0, 0.0, 0.0),
                     ("1e-3", "1e-4")),
    # pressed down by F_ext, the drive torque R mu N balancing the friction: sliding
    "spin_sliding": (_G981, ("0x0.0p+0",) * 5, _J_HALF, OMEGA, 0.2,
                     (0.0, -5000.0, 0.0, 0.04 * 0.15 * 5490.5), ("1e-3", "1e-4")),
    # the bearing on: the levitated whirl, integrated flight
    "spin_levitated": (_G981, _DROP_START, _J_HALF, OMEGA, 0.1, (0.0, 0.0, 1.0, 0.0),
                       ("1e-3", "1e-4")),
    # the bearing off, no gravity, mass centre at rest: closed-form flight (radius e_c)
    "spin_closed_flight": ("0x0.0p+0", _CIRCLE_START, _J_HALF, OMEGA, 0.1,
                           (0.0, 0.0, 0.0, 0.0), ("1e-3", "1e-4")),
    # the run-down with a braking drive through impacts and a forward rub (docs/spin.md)
    "spin_rundown": (_G981, _RUNDOWN_START, _J_HALF, 220.0, 0.9, (0.0, 0.0, 1.0, -4.0),
                     ("1e-3",)),
}


def spin_specs() -> list[Spec]:
    """(d) the scenes of the spin as a state (SPIN), one held-input segment each."""
    out = []
    for name, (g, start, J, omega0, t_end, (fx, fy, amb, torque), steps) in SPIN.items():
        params = {**_CHAPTER, "c": _C1400, "g": g}
        segs = [[t_end, omega0, fx, fy, amb, torque]]
        out.append(scene_spec(name, "spin", params, start, segs, False, steps,
                              (J, omega0.hex())))
    return out


def all_specs(root: Path, only: str | None) -> list[Spec]:
    """Every scene of the default set (or those whose name matches ``only``)."""
    specs = validation_specs(root) + bench_specs() + [drop_spec()] + spin_specs()
    return [s for s in specs if only is None or re.search(only, s["name"])]


# ------------------------------------------------------------------------------ schedules


def _fx(text: str) -> float:
    return float.fromhex(text)


class Held(NamedTuple):
    """The inputs held over a segment (SI): Omega (the held speed; with the spin as a state
    the initial speed), F_ext, amb_on, T_drive (used only with the spin as a state)."""

    Omega: float
    F_ext: complex
    amb_on: float
    T_drive: float


def segments_of(spec: Spec) -> list[tuple[float, Held]]:
    """(t_end, held inputs) of each held-input segment."""
    return [(_fx(s[0]), Held(_fx(s[1]), complex(_fx(s[2]), _fx(s[3])), _fx(s[4]),
                             _fx(s[5]) if len(s) > 5 else 0.0)) for s in spec["segments"]]


def omega_scale(spec: Spec) -> float:
    """|Omega| (rad/s) of the first segment: the unit of rates (1/time)."""
    return abs(segments_of(spec)[0][1].Omega)


def schedule(spec: Spec, h: float | None) -> list[tuple[float, float, Held]]:
    """The communication steps (t_start, h_j, held): h in each segment, the last step of a
    segment cut to its end (h when the segment is a multiple of h)."""
    out: list[tuple[float, float, Held]] = []
    t_a = 0.0
    for t_b, held in segments_of(spec):
        span = t_b - t_a
        step = span if h is None else h
        n = max(1, math.ceil(span / step - 1e-9))
        last = span - (n - 1) * step
        if abs(last - step) <= 1e-9 * step:
            last = step
        out += [(t_a + j * step, step if j < n - 1 else last, held) for j in range(n)]
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


# ------------------------------------------------------------------------------ tree adapter
# The one place that knows the tree's API: ``adapt`` (cores, steps, reads, state),
# ``steady_start`` and ``install_segment_hook``. Everything else in the recording uses
# only what these return, the StepReport fields (by name, getattr with a default) and the
# state's JSON. Fallbacks are for a refactored tree (classes in sub-packages, keyword-only
# constructors, views by name); when none fits, the adapter raises a message naming what
# it looked for, recorded as the job's error: extend the adapter, not the recording.

READ_HELD = ("t", "z", "v", "psi", "mode", "n_impacts", "E_diss", "t_last_impact",
             "v_last_impact", "t_contact_entry")
"""What ``Adapted.read`` returns for a held-speed core (and a spin core adds Omega)."""
_OUTPUT_FIELDS = {"z": ("x", "y"), "v": ("vx", "vy"), "Omega": ("Omega",), "mode": ("mode",),
                  "n_impacts": ("n_impacts",), "E_diss": ("E_diss",),
                  "t_last_impact": ("t_last_impact",), "v_last_impact": ("v_last_impact",)}
"""Fallback for a value the core has no attribute for: its ``core.outputs()`` fields."""
SEG_LOG: list[str] = []
"""Segment kinds (TAGS codes) logged by the segment hook, drained after every step."""


class Adapted(NamedTuple):
    """A scene's core behind the adapter: ``step(h, held)`` takes one communication step
    and returns its StepReport; ``read()`` the state now by name (READ_HELD, plus Omega for
    the spin as a state); ``state()`` the full state as JSON data; ``outputs()`` the
    state's outputs by name."""

    core: Any
    step: Callable[[float, Held], Any]
    read: Callable[[], dict[str, Any]]
    state: Callable[[], Any]
    outputs: Callable[[], dict[str, Any]]


def adapt(rotortd: Any, spec: Spec, z0: complex, v0: complex) -> Adapted:
    """Build the core of a scene (TouchdownCore, or SpinCore for a spin scene) at (z0 (m),
    v0 (m/s)) and bind its step, reads and state (module section "tree adapter")."""
    spin = is_spin(spec)
    params = _find(rotortd, "RotorParams")(**{k: _fx(v) for k, v in spec["params"].items()})
    kw: dict[str, Any] = {"params": params}
    if spin:
        kw["J"] = _fx(spec["J"])
    kw.update(z0=z0, v0=v0, psi0=_fx(spec["psi0"]))
    if spin:
        kw["Omega0"] = _fx(spec["Omega0"])
    kw["t0"] = 0.0
    core = _construct(_find(rotortd, "SpinCore" if spin else "TouchdownCore"), kw)
    step = _bind_step(core.step, spin)
    names = (*READ_HELD, "Omega") if spin else READ_HELD
    direct = [n for n in names if hasattr(core, n)]
    via_outputs = [n for n in names if n not in direct]

    def read() -> dict[str, Any]:
        out = {n: getattr(core, n) for n in direct}
        if via_outputs:
            o = outputs()
            for n in via_outputs:
                f = [o.get(x, NAN) for x in _OUTPUT_FIELDS.get(n, ())]
                out[n] = complex(*f) if len(f) == 2 else (f[0] if f else NAN)
        return out

    def outputs() -> dict[str, Any]:
        o = core.outputs()
        return o._asdict() if hasattr(o, "_asdict") else dict(o)

    def state() -> Any:
        if hasattr(core, "get_state"):
            return core.get_state()
        return core.state.to_json()

    return Adapted(core, step, read, state, outputs)


def _find(rotortd: Any, name: str) -> Any:
    """rotortd.<name>, else the first module of the package that defines it."""
    if hasattr(rotortd, name):
        return getattr(rotortd, name)
    import importlib
    import pkgutil

    for info in pkgutil.walk_packages(rotortd.__path__, "rotortd."):
        mod = importlib.import_module(info.name)
        if isinstance(getattr(mod, name, None), type):
            return getattr(mod, name)
    raise LookupError(f"adapter: no {name} in rotortd or its modules")


def _construct(cls: Any, kw: dict[str, Any]) -> Any:
    """cls(**kw) (keyword-only constructors), else positionally in kw's order (today's)."""
    try:
        return cls(**kw)
    except TypeError:
        return cls(*kw.values())


def _bind_step(method: Callable[..., Any], spin: bool) -> Callable[[float, Held], Any]:
    """core.step(h, Omega=, F_ext=, amb_on=) held, or (h, F_ext=, amb_on=, T_drive=) with
    the spin as a state; a missing keyword is an error naming it."""
    import inspect

    names = set(inspect.signature(method).parameters)
    want = ("F_ext", "amb_on", "T_drive") if spin else ("Omega", "F_ext", "amb_on")
    if missing := [n for n in want if n not in names]:
        raise TypeError(f"adapter: step() takes no {missing}; extend adapt()")
    if spin:
        return lambda h, u: method(h, F_ext=u.F_ext, amb_on=u.amb_on, T_drive=u.T_drive)
    return lambda h, u: method(h, Omega=u.Omega, F_ext=u.F_ext, amb_on=u.amb_on)


def steady_start(rotortd: Any, spec: Spec) -> list[complex]:
    """(z, v) of the held-speed steady whirl under the first segment's inputs (the FMU's
    start_steady): TouchdownCore.on_steady_whirl."""
    _t, u = segments_of(spec)[0]
    params = _find(rotortd, "RotorParams")(**{k: _fx(v) for k, v in spec["params"].items()})
    c = _find(rotortd, "TouchdownCore").on_steady_whirl(params, u.Omega, F_ext=u.F_ext,
                                                        amb_on=u.amb_on, psi0=_fx(spec["psi0"]))
    return [c.z, c.v]


HOOKED: dict[str, Callable[[Any], str]] = {
    "Flight": lambda seg: "F" if getattr(seg, "search", True) else "P",
    "Sliding": lambda _seg: "S",
    "Rolling": lambda _seg: "R",
    "LinearRub": lambda _seg: "L",
    "QuadraticRub": lambda _seg: "Q",
    "LockedRub": lambda _seg: "K",
    "SpinFlight": lambda seg: "C" if getattr(seg, "closed", False) else "I",
    "SpinContact": lambda seg: "r" if getattr(seg, "rolling", False) else "s",
}
"""The segment classes whose ``run`` the hook wraps (by class name, in any module of
rotortd) and the TAGS code of a segment (from public attributes of the segment object)."""


def install_segment_hook(rotortd: Any) -> list[str]:
    """Wrap ``run`` of every HOOKED class found so that each segment logs its kind in
    SEG_LOG before it runs (the wrapper only logs: the bits do not move). Returns the
    classes found; none found: the tags fall back to the modes the report shows."""
    import importlib
    import pkgutil

    mods = [rotortd] + [importlib.import_module(i.name)
                        for i in pkgutil.walk_packages(rotortd.__path__, "rotortd.")]
    found = []
    for mod in mods:
        for name, kind in HOOKED.items():
            cls = getattr(mod, name, None)
            if isinstance(cls, type) and "run" in vars(cls) and name not in found:
                _wrap_run(cls, kind)
                found.append(name)
    return found


def _wrap_run(cls: type, kind: Callable[[Any], str]) -> None:
    orig = vars(cls)["run"]

    def run(self: Any, *args: Any, **kwargs: Any) -> Any:
        SEG_LOG.append(kind(self))
        return orig(self, *args, **kwargs)

    cls.run = run  # type: ignore[attr-defined]


# ------------------------------------------------------------------------------ recording

TAGS = {"P": "proved-free flight", "F": "searched flight", "S": "sliding (integrated)",
        "R": "rolling (closed form)", "L": "rub, linear", "Q": "rub, quadratic",
        "K": "rub, locked", "C": "spin: closed-form flight", "I": "spin: integrated flight",
        "s": "spin: sliding", "r": "spin: rolling", "q": "spin: quiet step (integrated)",
        "f": "flight (no hook)",
        "d": "sliding (no hook)", "o": "rolling (no hook)"}
"""Segment kinds a job passed through (its tag), by code."""
CLOSED_FORM = frozenset("PRLQK")
"""Kinds carried by closed forms only: a job tagged by these alone must stay bit-identical
(issue 23)."""
_PUBLIC_KIND = {0: "f", 1: "d", 2: "o"}
_MODE_OF_NAME = (("lift", 0), ("free", 0), ("slid", 1), ("roll", 2))


def step_kinds(logged: list[str], hooked: bool, mode0: int, mode1: int,
               transitions: list[Any], quiet: str = "P") -> list[str]:
    """The segment kinds of one step: the hook's log; a hooked step that ran no segment
    from flight is one quiet step, ``quiet`` (P: the held core's proved-free whole step;
    q: the spin state's quiet step); unhooked, the modes the step passed through (start,
    transitions, end)."""
    if hooked:
        return logged or ([quiet] if mode0 == 0 else [])
    modes = {mode0, mode1, *(_mode_of(tr[1]) for tr in transitions if len(tr) > 1)}
    return [_PUBLIC_KIND[m] for m in sorted(m for m in modes if m in _PUBLIC_KIND)]


def _mode_int(value: Any) -> int:
    """A mode as an int (-1 when it is not a number)."""
    x = _num(value)
    return int(x) if math.isfinite(x) else -1


def _mode_of(name: Any) -> int:
    """The mode a transition's name (a string or an enum) enters, -1 if unknown."""
    text = str(getattr(name, "name", name)).lower()
    return next((m for key, m in _MODE_OF_NAME if key in text), -1)


ROW_COLS = ("t", "x", "y", "vx", "vy", "psi", "Omega", "h", "F_cx", "F_cy", "F_n",
            "F_n_peak", "P_n", "T_f", "T_imb", "E_diss_step", "mode_step", "status",
            "message", "work", "work_cap", "n_impacts_step", "n_transitions", "n_impacts",
            "E_diss", "t_last_impact", "v_last_impact", "mode")
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
    """A string (message, transition name) as a number: its crc32 (an enum by its name)."""
    return float(zlib.crc32(str(getattr(text, "name", text)).encode()))


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


def core_row(now: dict[str, Any], rep: Any, h: float, held: Held) -> list[float]:
    """One step's row (ROW_COLS) from the state after it (``Adapted.read``) and its report;
    Omega is the spin state, or the held input."""
    g = getattr
    fx, fy = _cplx(g(rep, "F_contact", NAN))
    x, y = _cplx(now.get("z", NAN))
    vx, vy = _cplx(now.get("v", NAN))
    return [_num(now.get("t", NAN)), x, y, vx, vy, _num(now.get("psi", NAN)),
            _num(now.get("Omega", held.Omega)), h, fx, fy,
            _num(g(rep, "F_n", NAN)), _num(g(rep, "F_n_peak", NAN)), _num(g(rep, "P_n", NAN)),
            _num(g(rep, "T_f", NAN)), _num(g(rep, "T_imb", NAN)), _num(g(rep, "E_diss", NAN)),
            _num(g(rep, "mode", now.get("mode", NAN))),  # (the report's mode: core.mode)
            _num(g(rep, "status", NAN)), _crc(g(rep, "message", "")), _num(g(rep, "work", NAN)),
            _num(g(rep, "work_cap", NAN)), float(len(g(rep, "impacts", ()) or ())),
            float(len(g(rep, "transitions", ()) or ())), _num(now.get("n_impacts", NAN)),
            _num(now.get("E_diss", NAN)), _num(now.get("t_last_impact", NAN)),
            _num(now.get("v_last_impact", NAN)), _num(now.get("mode", NAN))]


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


def start_of(spec: Spec, scale: float = 0.0, direction: int = -1) -> tuple[complex, complex]:
    """(z0, v0), optionally perturbed by ``scale`` (scaled units) along x, y, vx or vy
    (direction 0..3)."""
    x, y, vx, vy = (_fx(spec[k]) for k in ("x0", "y0", "vx0", "vy0"))
    c_r = _fx(spec["params"]["c_r"])
    vs = c_r * omega_scale(spec)
    if 0 <= direction < 4:
        d = [0.0] * 4
        d[direction] = scale * (c_r if direction < 2 else vs)
        x, y, vx, vy = x + d[0], y + d[1], vx + d[2], vy + d[3]
    return complex(x, y), complex(vx, vy)


StepHook = Callable[[int, dict[str, Any], Any, float, Held, list[str]], None]


def run_core(rotortd: Any, spec: Spec, label: str, z0: complex, v0: complex,
             on_step: StepHook, on_start: Callable[[dict[str, Any]], None] | None = None
             ) -> Adapted:
    """Run a scene's core, calling ``on_start(state)`` once and ``on_step(k, state after,
    report, h, held, segment kinds logged in the step)`` per step."""
    ad = adapt(rotortd, spec, z0, v0)
    if on_start is not None:
        on_start(ad.read())
    for k, (_t, h, held) in enumerate(schedule(spec, STEP_VALUES[label])):
        SEG_LOG.clear()
        rep = ad.step(h, held)
        on_step(k, ad.read(), rep, h, held, SEG_LOG[:])
    SEG_LOG.clear()
    return ad


def core_counters(rotortd: Any, ad: Adapted, spec: Spec) -> dict[str, Any]:
    """Final reads, outputs by name, and the steady-whirl start that TouchdownCore gives
    today (if the scene starts there)."""
    out = dict(ad.read())
    out["outputs"] = _try(ad.outputs)
    if spec["steady"]:
        out["steady_start"] = _try(lambda: steady_start(rotortd, spec))
    return out


def _try(fn: Callable[[], Any]) -> Any:
    try:
        return fn()
    except Exception as exc:
        return f"error: {type(exc).__name__}: {exc}"


class Recorder:
    """Rows, events, tag and summary of one job, written as <out>/<job>.{rows,imp,tr}.

    The summary (for the chaotic scenes' criteria): duration (s), impacts, contact time
    (s, from the transitions' times when their names tell the mode, else from the modes at
    the steps' ends), largest |z|/c_r at the steps' ends, steps ending in each mode, steps
    with a nonzero status."""

    def __init__(self, c_r: float = 1.0, hooked: bool = False, mode0: int = 0,
                 quiet: str = "P") -> None:
        self.rows = array.array("d")
        self.imps = array.array("d")
        self.trs = array.array("d")
        self.c_r, self.hooked, self.mode, self.quiet = c_r, hooked, mode0, quiet
        self.tags: dict[str, int] = {}
        self.summary = {"duration": 0.0, "impacts": 0, "contact_time": 0.0, "max_r": 0.0,
                        "modes": [0, 0, 0], "bad_status": 0}

    def core_step(self, k: int, now: dict[str, Any], rep: Any, h: float, held: Held,
                  logged: list[str]) -> None:
        self.rows.extend(core_row(now, rep, h, held))
        imps = getattr(rep, "impacts", ()) or ()
        trs = getattr(rep, "transitions", ()) or ()
        for imp in imps:
            self.imps.extend(impact_row(k, imp))
        for tr in trs:
            self.trs.extend(transition_row(k, tr))
        mode1 = _mode_int(now.get("mode"))
        for kind in step_kinds(logged, self.hooked, self.mode, mode1, list(trs), self.quiet):
            self.tags[kind] = self.tags.get(kind, 0) + 1
        self._summarise(now, rep, h, list(trs), mode1)

    def _summarise(self, now: dict[str, Any], rep: Any, h: float, trs: list[Any],
                   mode1: int) -> None:
        sm = self.summary
        t1 = _num(now.get("t", NAN))
        t0 = t1 - h
        t, mode, contact = t0, self.mode, 0.0
        for tr in trs:
            tt, m = (_num(tr[0]), _mode_of(tr[1])) if len(tr) > 1 else (NAN, -1)
            contact += (tt - t) if mode > 0 else 0.0
            t, mode = tt, m
        contact += (t1 - t) if mode > 0 else 0.0
        if mode != mode1 or not math.isfinite(contact):  # names unreadable: the end's mode
            contact = h if mode1 > 0 else 0.0
        sm["contact_time"] += contact
        sm["duration"] += h
        sm["impacts"] += len(getattr(rep, "impacts", ()) or ())
        sm["max_r"] = max(sm["max_r"], abs(complex(now.get("z", NAN))) / self.c_r)
        if 0 <= mode1 < 3:
            sm["modes"][mode1] += 1
        sm["bad_status"] += _num(getattr(rep, "status", 0)) != 0
        self.mode = mode1

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


def record_core_job(rotortd: Any, spec: Spec, label: str, out: Path,
                    hooked: bool) -> dict[str, Any]:
    """Record one core job; return its summary (hash, final state, counters, tag)."""
    t0 = time.perf_counter()
    z0, v0 = start_of(spec)
    rec = Recorder(_fx(spec["params"]["c_r"]), hooked, quiet="q" if is_spin(spec) else "P")
    ad = run_core(rotortd, spec, label, z0, v0, rec.core_step,
                  lambda now: setattr(rec, "mode", _mode_int(now.get("mode"))))
    return {"hash": rec.save(out, job_name("core", spec["name"], label)),
            "columns": [ROW_COLS, IMPACT_COLS, TRANSITION_COLS],
            "state": hexify(ad.state()),
            "counters": hexify(core_counters(rotortd, ad, spec)),
            "tags": rec.tags, "hooked": hooked, "summary": rec.summary,
            "seconds": time.perf_counter() - t0}


def record_core(specs: dict[str, Spec], jobs: list[list[str]], out: Path) -> dict[str, Any]:
    """Record every core job; exceptions are recorded as the job's error."""
    import rotortd

    hooked = install_segment_hook(rotortd)
    res: dict[str, Any] = {"_rotortd": str(Path(rotortd.__file__).resolve()),
                           "_hooked": hooked}
    for _kind, scene, label in jobs:
        res[job_name("core", scene, label)] = _guarded(
            lambda s=scene, lab=label: record_core_job(rotortd, specs[s], lab, out,
                                                       bool(hooked)))
    return res


def _guarded(fn: Callable[[], dict[str, Any]]) -> dict[str, Any]:
    try:
        return fn()
    except Exception as exc:
        return {"error": f"{type(exc).__name__}: {exc}"}


# ------------------------------------------------------------------------------ FMU


def fmu_start_values(spec: Spec) -> dict[str, Any]:
    """Start values of the FMU: parameters, the start (or start_steady), first inputs; a
    spin scene with integrate_spin, J and T_drive."""
    sv: dict[str, Any] = {k: _fx(v) for k, v in spec["params"].items()}
    if spec["steady"]:
        sv["start_steady"] = True
    else:
        sv.update({k: _fx(spec[k]) for k in ("x0", "y0", "vx0", "vy0")})
    sv["psi0"] = _fx(spec["psi0"])
    if is_spin(spec):
        sv.update(integrate_spin=True, J=_fx(spec["J"]))
    sv.update(fmu_inputs(spec, segments_of(spec)[0][1]))
    return sv


def fmu_inputs(spec: Spec, u: Held) -> dict[str, float]:
    """The FMU inputs of held inputs u (T_drive only for a spin scene: the base's FMU
    need not have it otherwise)."""
    out = {"Omega": u.Omega, "F_x": u.F_ext.real, "F_y": u.F_ext.imag, "amb_on": u.amb_on}
    if is_spin(spec):
        out["T_drive"] = u.T_drive
    return out


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
        last: Held | None = None
        for t, h, held in schedule(spec, STEP_VALUES[label]):
            if last is not None and held != last:
                self._set(fmu, fmu_inputs(spec, held))
            last = held
            fmu.doStep(t, h)  # (FMPy raises on a status worse than fmi2Warning)
            rows.append(t + h)
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


def fmu_summary(rows: array.array, columns: list[str], spec: Spec,
                label: str) -> dict[str, Any]:
    """Recorder's summary of an FMU run from its outputs (mode, r_rel, n_impacts; the
    contact time from the modes at the steps' ends; no status: a failed doStep raises, and
    the job records the error)."""
    n = len(columns)
    col = {c: i for i, c in enumerate(columns)}
    hs = [h for _t, h, _u in schedule(spec, STEP_VALUES[label])]
    sm = {"duration": sum(hs), "impacts": 0, "contact_time": 0.0, "max_r": 0.0,
          "modes": [0, 0, 0], "bad_status": 0}
    for k, h in enumerate(hs):
        row = rows[k * n:(k + 1) * n]
        mode = _mode_int(row[col["mode"]]) if "mode" in col else -1
        sm["contact_time"] += h if mode > 0 else 0.0
        if 0 <= mode < 3:
            sm["modes"][mode] += 1
        if "r_rel" in col:
            sm["max_r"] = max(sm["max_r"], row[col["r_rel"]])
        if "n_impacts" in col:
            sm["impacts"] = int(row[col["n_impacts"]])
    return sm


def record_fmu_job(runner: FmuRunner, spec: Spec, label: str, out: Path) -> dict[str, Any]:
    t0 = time.perf_counter()
    rows, final = runner.run(spec, label)
    rec = Recorder()
    rec.rows = rows
    return {"hash": rec.save(out, job_name("fmu", spec["name"], label)),
            "columns": [runner.columns, IMPACT_COLS, TRANSITION_COLS],
            "state": hexify(final), "counters": {},
            "summary": fmu_summary(rows, runner.columns, spec, label),
            "seconds": time.perf_counter() - t0}


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


def amplification_job(rotortd: Any, spec: Spec, label: str) -> dict[str, Any]:
    """Largest scaled state difference over the run at the job's steps (positions in c_r,
    velocities in c_r |Omega|, the spin in |Omega|), per AMP_DELTA start perturbation in
    each of x, y, vx, vy and, with the spin as a state, Omega0 (both signs); and whether a
    perturbed run's impact count differs."""
    c_r = _fx(spec["params"]["c_r"])
    w = omega_scale(spec)

    def trace(sp: Spec, z0: complex, v0: complex) -> tuple[list[tuple[Any, ...]], Any]:
        pts: list[tuple[Any, ...]] = []
        ad = run_core(rotortd, sp, label, z0, v0, lambda _k, now, *_a: pts.append(
            (now["z"], now["v"], now.get("Omega", 0.0))))
        return pts, ad.read()["n_impacts"]

    ref, n_ref = trace(spec, *start_of(spec))
    amp, counts = 0.0, set()
    for direction in range(5 if is_spin(spec) else 4):
        for sign in (1.0, -1.0):
            sp = spec
            if direction == 4:
                sp = {**spec, "Omega0": (_fx(spec["Omega0"]) * (1.0 + sign * AMP_DELTA)).hex()}
            pts, n = trace(sp, *start_of(spec, sign * AMP_DELTA, direction))
            counts.add(n)
            dev = max(max(abs(z - zr) / c_r, abs(v - vr) / (c_r * w), abs(W - Wr) / w)
                      for (z, v, W), (zr, vr, Wr) in zip(pts, ref))
            amp = max(amp, dev / AMP_DELTA)
    return {"amplification": amp, "count_changes": counts != {n_ref}}


def record_amplification(specs: dict[str, Spec], jobs: list[list[str]]) -> dict[str, Any]:
    import rotortd

    return {job_name(*j): _guarded(lambda s=specs[j[1]], lab=j[2]: amplification_job(
        rotortd, s, lab)) for j in jobs}


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
        res = record_amplification(specs, task["jobs"])
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
TORQUE_KEYS = {"T_f", "T_imb", "T_drive"}
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
    w = omega_scale(spec)
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
    """The comparison of one job between base and head, and the data to judge it: the
    base's tag and summary, the head's summary, the job's amplification (when measured)."""

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
        self.added_leaves: list[str] = []  # final-state leaves only the head has
        self.tags: dict[str, int] = {}  # the base's segment kinds (TAGS codes: count)
        self.summary: tuple[dict[str, Any], dict[str, Any]] = ({}, {})  # base, head
        self.amp: dict[str, Any] | None = None

    def note(self, at: float, what: str) -> None:
        """Keep the earliest difference (ties: the first noted)."""
        if not self.first or at < self.first_at:
            self.first_at, self.first = at, what

    def rounding_only(self) -> bool:
        return (not self.error and self.max_scaled <= ROUNDING and self.counts_equal
                and self.modes_equal and self.status_equal)

    def closed_form_only(self) -> bool:
        """Carried on the base by proved-free flight, closed-form rolling and the rub alone."""
        return bool(self.tags) and set(self.tags) <= CLOSED_FORM

    def stat_changes(self) -> dict[str, float]:
        """Relative change head vs base of the impact rate, the contact fraction and the
        largest r/c_r (the chaotic scenes' criterion)."""
        a, b = self.summary
        if not a or not b:
            return {}
        out = {}
        for key, fa, fb in (
                ("impact rate", a["impacts"] / a["duration"], b["impacts"] / b["duration"]),
                ("contact fraction", a["contact_time"] / a["duration"],
                 b["contact_time"] / b["duration"]),
                ("max r", a["max_r"], b["max_r"])):
            out[key] = 0.0 if fa == fb else abs(fa - fb) / max(abs(fa), abs(fb))
        return out

    def judge(self) -> tuple[str, bool | None]:
        """The issue-23 criterion that applies and whether it holds (None: unknown, the
        amplification not measured): identical; closed-form only -> bit-identical;
        amplification <= AMP_LOW -> rounding; else the statistics within STATS_TOL."""
        if self.error:
            return "error", False
        if self.identical:
            return "identical", True
        if self.closed_form_only():
            return "closed form: must be bit-identical", False
        amp = (self.amp or {}).get("amplification")
        if amp is None:
            return "amplification not measured", None
        if amp <= AMP_LOW:
            return f"amp <= {AMP_LOW:g}: rounding only", self.rounding_only()
        ch = self.stat_changes()
        text = ", ".join(f"{k} {100 * x:.2g} %" for k, x in ch.items())
        return (f"amp > {AMP_LOW:g}: {text}",
                bool(ch) and max(ch.values()) <= STATS_TOL and not self.error)


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


STATE_NAMES: dict[str, str | None] = {
    "schema": None, "version": None,  # the schema's bookkeeping: not compared
    # rotortd-state 2 (flat) -> 3 (one record per component, rotortd.step.state)
    "params": "params", "t": "clock.t", "t_lo": "clock.t_lo", "z": "rotor.z",
    "v": "rotor.v", "psi": "rotor.psi", "turns": "rotor.turns", "mode": "contact.mode",
    "theta": "contact.theta", "dtheta": "contact.dtheta", "slip": "contact.slip",
    "locked": "contact.locked", "on_wall": "contact.on_wall",
    "n_impacts": "counters.n_impacts", "t_last": "counters.t_last",
    "v_last": "counters.v_last", "E_diss": "counters.E_diss",
    "t_contact": "contact.t_contact", "H": "contact.slide_step",
    "inputs.0": "rotor.Omega", "inputs.1": "step.F_ext.0", "inputs.2": "step.F_ext.1",
    "inputs.3": "step.amb_on", "J": "rotor.J",
    "imb_h": None,  # a cache's choice between two roundings (rotortd-state 2)
    "step.imb_h": None,  # ... and its place in rotortd-state 3
}
"""The map of the core's state (``get_state()`` JSON) from the base's names to the head's:
the ONE place a new state layout is declared. Keys are dotted paths of the base's state (a
key covers everything below it; the longest key that matches a leaf wins), values the
head's path for the same quantity, None for a leaf not compared. Today it maps the flat
rotortd-state 2 (a base before the layout by component) onto rotortd-state 3, with an
index-level split of the inputs (``"inputs.0": "rotor.Omega"``); against a base that is
already version 3, the head's own paths are not keys of the map and keep their names
(``"step.imb_h"`` is a key only so that the cache is not compared and not listed as added);
the head's ``bearing.kind`` is listed as added against a version 2 base.

(a value must keep its representation: a complex as [re, im] maps leaf by leaf, "z.0":
"rotor.z.re"). Leaves the base has and the head lacks (after the map) are differences;
leaves only the head has are listed as added, not differences. Units come from the base's
name. The FMU's state takes the same map below its "core" key (FMU_STATE_NAMES)."""
FMU_STATE_NAMES: dict[str, str | None] = {
    "schema": None, "version": None, "variables": "variables", "adapter": "adapter",
    "core": "core",
}
"""The map of the FMU's serialised state (rotortd-fmu-state), as STATE_NAMES; its core's
state is renamed below "core" by STATE_NAMES."""
NULL_WHEN_HELD = ("J", "spin")
"""Leaves that a held-speed state holds as null or lacks, by schema version (the core's
J since rotortd-state 2, the adapter's spin until rotortd-fmu-state 1): left out when null
on one side and absent on the other."""


def state_names(fmu: bool) -> dict[str, str | None]:
    """The map of a core's (or with ``fmu`` an FMU's) state, flattened to one dict."""
    if not fmu:
        return STATE_NAMES
    core = FMU_STATE_NAMES["core"]
    return {**FMU_STATE_NAMES, **{f"core.{k}": (None if v is None or core is None
                                                else f"{core}.{v}")
                                  for k, v in STATE_NAMES.items()}}


def rename(path: str, names: dict[str, str | None]) -> str | None:
    """The head's path of a base leaf (``names``: the longest matching key wins; a leaf no
    key covers keeps its path); None when it is not compared."""
    parts = path.split(".")
    for i in range(len(parts), 0, -1):
        key = ".".join(parts[:i])
        if key in names:
            new = names[key]
            return None if new is None else ".".join([new, *parts[i:]])
    return path


IGNORED: set[str] = set()
"""Recorded columns left out of the comparison (``--ignore``): a column whose meaning a
change redefines on purpose (issue 24: F_n_peak no longer folds in the impacts' P/h)."""


def compare_final(v: Verdict, a: Any, b: Any, units: dict[str, float], what: str,
                  names: dict[str, str | None]) -> None:
    """Final state or counters, leaf by leaf through ``names`` (base -> head), floats
    bit-exact (as float.hex). A differing leaf that is not a float (a flag, an integer, a
    missing leaf) counts as infinitely different unless it is a count or a mode; leaves
    only the head has are added (v.added_leaves), not differences."""
    fa, fb = flatten(a), flatten(b)
    seen: set[str] = set()
    for key in sorted(fa):
        new = rename(key, names)
        if new is None:
            continue
        seen.add(new)
        if key.split(".")[-1] in IGNORED:  # (an FMU's output variable of that name)
            continue
        x, y = fa[key], fb.get(new, "<absent>")
        if x == y or (x is None and y == "<absent>" and key.split(".")[-1] in NULL_WHEN_HELD):
            continue
        v.note(math.inf, f"{what} {key}" + (f" (head {new})" if new != key else ""))
        name = [p for p in key.split(".") if not p.isdigit()][-1]
        flag_difference(v, name)
        fx, fy = _as_float(x), _as_float(y)
        if fx is not None and fy is not None:
            sized = bool(SIZED_KEYS & set(key.split(".")))
            v.max_scaled = max(v.max_scaled, scaled_diff(fx, fy, _unit_of(key, units), sized))
        elif name not in COUNT_KEYS | MODE_KEYS:
            v.max_scaled = math.inf
    v.added_leaves += [f"{what} {k}" for k in sorted(set(fb) - seen)
                       if not (fb[k] is None and k.split(".")[-1] in NULL_WHEN_HELD)
                       and not _covered(k, names)]


def _covered(head_path: str, names: dict[str, str | None]) -> bool:
    """A head leaf under a path the map leaves out (None) on both sides (schema, caches)."""
    return rename(head_path, names) is None


def compare_job(job: tuple[str, str, str], ra: dict[str, Any], rb: dict[str, Any],
                wa: Path, wb: Path, spec: Spec) -> Verdict:
    """Compare the recordings of one job in base (a) and head (b), every column but the
    ``IGNORED`` ones."""
    v = Verdict(job)
    v.tags = ra.get("tags", {})
    v.summary = (ra.get("summary", {}), rb.get("summary", {}))
    if "error" in ra or "error" in rb:
        v.error = f"base: {ra.get('error', 'ok')}; head: {rb.get('error', 'ok')}"
        v.first = "error"
        v.max_scaled = math.inf
        return v
    units = scales(spec)
    names = state_names(job[0] == "fmu")
    compare_final(v, ra["counters"], rb["counters"], units, "counter", {})
    compare_final(v, ra["state"], rb["state"], units, "state", names)
    if ra["hash"] == rb["hash"] and not v.first:
        v.identical = True
        if v.added_leaves:
            v.first = f"adds {len(v.added_leaves)} state leaves"
        return v
    name = job_name(*job)
    added: set[str] = set()
    for ext, ca, cb, label in zip(("rows", "imp", "tr"), ra["columns"], rb["columns"],
                                  ("step", "impact", "transition")):
        if not set(ca) <= set(cb):
            v.note(-1.0, f"recorded {label} columns removed: {sorted(set(ca) - set(cb))}")
            v.max_scaled = math.inf
            continue
        added |= set(cb) - set(ca)  # a new output: compared on the base's columns
        keep = [c for c in ca if c not in IGNORED]
        tb = load_table(wb, name, ext, len(cb))[:, [list(cb).index(c) for c in keep]]
        ta = load_table(wa, name, ext, len(ca))[:, [list(ca).index(c) for c in keep]]
        compare_tables(v, ta, tb, keep, units, label)
    v.added = sorted(added)
    if (added or IGNORED) and not v.first:  # identical on everything compared
        v.identical = True
        v.first = ", ".join(([f"adds {', '.join(v.added)}"] if added else [])
                            + ([f"ignores {', '.join(sorted(IGNORED))}"] if IGNORED else []))
    return v


# ------------------------------------------------------------------------------ report


def fmt_amp(amp: dict[str, Any] | None) -> str:
    if not amp:
        return ""
    if "error" in amp:
        return "error"
    mark = "*" if amp["count_changes"] else ""
    return f"{amp['amplification']:.2g}{mark}"


def fmt_tags(tags: dict[str, int]) -> str:
    """A tag as codes with counts, in TAGS order: "P812 F40 S3"."""
    return " ".join(f"{c}{tags[c]}" for c in TAGS if c in tags)


def fmt_counts(v: Verdict) -> tuple[str, str, str]:
    """Impacts, modes at the steps' ends (free/sliding/rolling) and nonzero statuses:
    the base's, "-> head's" where they differ."""
    a, b = v.summary

    def pair(key: str, fmt: Callable[[Any], str]) -> str:
        if not a:
            return ""
        xa, xb = fmt(a[key]), (fmt(b[key]) if b else "?")
        return xa if xa == xb else f"{xa}->{xb}"

    return (pair("impacts", str), pair("modes", lambda m: "/".join(map(str, m))),
            pair("bad_status", str))


def print_table(verdicts: list[Verdict]) -> None:
    print(f"{'kind':4s} {'scene':20s} {'step':>5s} {'same':4s} {'max scaled':>10s} "
          f"{'impacts':>9s} {'modes f/s/r':>16s} {'st!=0':>5s} {'amp':>7s}  "
          f"{'tag (base)':24s} criterion / first difference")
    for v in verdicts:
        kind, scene, label = v.job
        diff = "" if v.identical else f"{v.max_scaled:10.3g}"
        imp, modes, bad = fmt_counts(v)
        crit, ok = v.judge()
        mark = {True: "ok", False: "FAIL", None: "?"}[ok]
        line = (f"{kind:4s} {scene:20s} {label:>5s} {_yn(v.identical):4s} {diff:>10s} "
                f"{imp:>9s} {modes:>16s} {bad:>5s} {fmt_amp(v.amp):>7s}  "
                f"{fmt_tags(v.tags):24s} {mark}: {crit}")
        print(line)
        if v.error or v.first:
            print(f"{'':11s}{'error' if v.error else 'first difference'}: {v.error or v.first}"
                  + (f"; counts= {_yn(v.counts_equal)} modes= {_yn(v.modes_equal)} "
                     f"statuses= {_yn(v.status_equal)}" if not v.identical else ""))
    print("tags: " + ", ".join(f"{c} {n}" for c, n in TAGS.items()) + "; closed form: "
          + "".join(sorted(CLOSED_FORM)) + "; amp * = a perturbed run changed the impact count")


def _yn(flag: bool) -> str:
    return "yes" if flag else "NO"


def print_hashes(res: dict[str, Any], jobs: list[tuple[str, str, str]]) -> None:
    for job in jobs:
        r = res[job_name(*job)]
        tags = fmt_tags(r.get("tags", {}))
        print(f"{job[0]:4s} {job[1]:22s} {job[2]:>5s}  {r.get('hash', r.get('error'))}  {tags}")


# ------------------------------------------------------------------------------ main


def check_scenes() -> int:
    """Compare the frozen benchmark starts with benchmarks.make_scenes() of this tree, and
    the spin scenes' parameters and levitated starts with RotorParams and
    TouchdownCore.on_steady_whirl."""
    sys.path[:0] = [str(ROOT / "docs" / "scripts"), str(ROOT / "tests"), str(ROOT),
                    str(ROOT / "fmu_src")]
    import benchmarks as bm
    import rotortd

    bad = 0
    for spec, sc in zip(bench_specs(), bm.make_scenes()):
        fixed = start_of(spec)
        p = {k: getattr(sc.params, k).hex() for k in PARAM_NAMES}
        same = (spec["name"] == sc.name and fixed == (sc.z0, sc.v0) and p == spec["params"]
                and _fx(spec["psi0"]) == sc.psi0 and [(t, *u[:3]) for t, u in segments_of(
                    spec)] == [(a, b, c, d) for a, b, c, d in sc.segments()])
        print(f"{spec['name']:18s} {'frozen = benchmarks' if same else 'DIFFERS'}")
        bad += not same
    for spec in spin_specs():
        p = rotortd.RotorParams(g=_fx(spec["params"]["g"]))
        same = {k: getattr(p, k).hex() for k in PARAM_NAMES} == spec["params"]
        if spec["x0"] != "0x0.0p+0" and spec["name"] != "spin_closed_flight":
            held = rotortd.TouchdownCore.on_steady_whirl(p, _fx(spec["Omega0"]))
            same = same and start_of(spec) == (held.z, held.v)
        print(f"{spec['name']:18s} {'frozen = RotorParams, steady whirl' if same else 'DIFFERS'}")
        bad += not same
    return 1 if bad else 0


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", help="commit to compare the current tree with")
    ap.add_argument("--allow-rounding", action="store_true",
                    help=f"exit 0 also for differences <= {ROUNDING:g} scaled with equal "
                         "counts, modes and statuses")
    ap.add_argument("--criteria", action="store_true",
                    help="exit 0 iff every job meets its issue-23 criterion (needs the "
                         "amplification of the differing jobs: not with --no-amplification)")
    amp = ap.add_mutually_exclusive_group()
    amp.add_argument("--amplification", action="store_true",
                     help="measure every core job's amplification (slow), not only the "
                          "differing ones'")
    amp.add_argument("--no-amplification", action="store_true",
                     help="measure no amplification")
    ap.add_argument("--only", help="regular expression: scenes whose name matches")
    ap.add_argument("--ignore", default="",
                    help="comma-separated recorded columns to leave out of the comparison "
                         "(e.g. F_n_peak, redefined by issue 24)")
    ap.add_argument("--no-fmu", action="store_true", help="core only")
    ap.add_argument("--keep", action="store_true", help="keep the temporary directory")
    ap.add_argument("--check-scenes", action="store_true",
                    help="check the frozen scenes against benchmarks.py and rotortd")
    ap.add_argument("--record", type=Path, help=argparse.SUPPRESS)
    return ap.parse_args(argv)


def amp_jobs(verdicts: list[Verdict], jobs: list[tuple[str, str, str]],
             every: bool) -> list[tuple[str, str, str]]:
    """The core jobs to measure: all (``every``), else the differing ones and the core
    jobs of differing FMU jobs."""
    core = [j for j in jobs if j[0] == "core"]
    if every:
        return core
    want = {("core", *v.job[1:]) for v in verdicts if not v.identical}
    return [j for j in core if j in want]


def run(args: argparse.Namespace, tmp: Path) -> int:
    IGNORED.update(c for c in args.ignore.split(",") if c)
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
            res = {k: f.result() for k, f in futs.items()}
        secs = time.perf_counter() - t0
        if not args.base:
            amps = measure_amp(ROOT, specs, [j for j in jobs if j[0] == "core"], tmp) \
                if args.amplification else {}
            print_hashes(res["head"], jobs)
            print(f"{len(jobs)} jobs recorded in {secs:.0f} s (no --base: nothing compared)")
            print_amps(amps)
            return 0
        verdicts = [compare_job(j, res["base"][job_name(*j)], res["head"][job_name(*j)],
                                tmp / "base", tmp / "head", by_name[j[1]]) for j in jobs]
        share_core_tags(verdicts, res["base"])
        t1 = time.perf_counter()
        todo = [] if args.no_amplification else amp_jobs(verdicts, jobs, args.amplification)
        amps = measure_amp(trees["base"], specs, todo, tmp) if todo else {}
        amp_secs = time.perf_counter() - t1
    finally:
        if args.base:
            remove_worktree(trees["base"])
    for v in verdicts:
        v.amp = amps.get(job_name("core", *v.job[1:]))
    print(f"base {args.base} vs current tree {ROOT}")
    print(f"segment hook: base {res['base'].get('_hooked') or 'none (tags from modes)'}; "
          f"head {res['head'].get('_hooked') or 'none'}")
    print_table(verdicts)
    print_cpu(res, by_name)
    if todo:
        print(f"amplification of {len(todo)} core jobs on the base: {amp_secs:.0f} s")
    return summarise(verdicts, args, time.perf_counter() - t0)


def share_core_tags(verdicts: list[Verdict], base: dict[str, Any]) -> None:
    """An FMU job takes the base's tag of the core job of its scene and step."""
    for v in verdicts:
        if v.job[0] == "fmu":
            v.tags = base.get(job_name("core", *v.job[1:]), {}).get("tags", {})


def measure_amp(tree: Path, specs: list[Spec], jobs: list[tuple[str, str, str]],
                tmp: Path) -> dict[str, Any]:
    """The amplification of ``jobs`` on ``tree``, in two children on the tree's rotortd
    (every other job each, in parallel)."""
    def child(i: int) -> dict[str, Any]:
        work = tmp / f"amp{i}"
        work.mkdir(exist_ok=True)
        return run_child(tree, {"mode": "amp", "specs": specs, "out": str(work),
                                "jobs": [list(j) for j in jobs[i::2]]}, work)

    with ThreadPoolExecutor(max_workers=2) as pool:
        parts = list(pool.map(child, range(2 if len(jobs) > 1 else 1)))
    return {k: x for part in parts for k, x in part.items()}


def print_amps(amps: dict[str, Any]) -> None:
    for name, amp in amps.items():
        print(f"amplification {name}: {fmt_amp(amp)}")


def print_cpu(res: dict[str, Any], by_name: dict[str, Spec]) -> None:
    """CPU seconds of the recordings per tree: core jobs (of them the spin scenes'), FMU."""
    for tree, r in res.items():
        jobs = {k: x for k, x in r.items() if not k.startswith("_") and "seconds" in x}

        def cpu(kind: str, spin_only: bool, jobs: dict[str, Any] = jobs) -> float:
            return sum(x["seconds"] for k, x in jobs.items() if k.startswith(f"{kind}__")
                       and (not spin_only or is_spin(by_name[k.split("__")[1]])))

        print(f"{tree}: core jobs {cpu('core', False):.1f} s (spin scenes "
              f"{cpu('core', True):.1f} s), FMU jobs {cpu('fmu', False):.1f} s (spin scenes "
              f"{cpu('fmu', True):.1f} s), wall time per job")


def summarise(verdicts: list[Verdict], args: argparse.Namespace, secs: float) -> int:
    same = sum(v.identical for v in verdicts)
    rounding = [v for v in verdicts if not v.identical and v.rounding_only()]
    judged = [v.judge()[1] for v in verdicts]
    closed = [v for v in verdicts if v.closed_form_only()]
    print(f"{same}/{len(verdicts)} jobs identical, {len(rounding)} within rounding "
          f"(<= {ROUNDING:g} scaled, equal counts and modes); criteria: "
          f"{judged.count(True)} ok, {judged.count(False)} fail, {judged.count(None)} "
          f"unknown; {len(closed)} jobs closed-form only ({sum(v.identical for v in closed)} "
          f"identical); {secs:.0f} s")
    if same == len(verdicts):
        return 0
    if args.criteria:
        return 0 if all(judged) else 1
    return 0 if args.allow_rounding and same + len(rounding) == len(verdicts) else 1


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
