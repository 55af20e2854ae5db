"""Work-precision benchmark of the rotor/touchdown-bearing core, the FMU and solve_ivp.

    python docs/scripts/benchmarks.py            # everything, ~8-9 min on 2 cores
    python docs/scripts/benchmarks.py --quick    # 3 repeats, fewer points (smoke test)

Writes ``docs/benchmarks.json`` (raw timings, errors, counts, machine, versions),
``docs/img/bench_<scene>.png`` (error vs wall time, log-log) and prints a table and the
target ratios. ``docs/benchmarks.md`` explains the method and the results.

Every scene covers 1 s of physical time at Omega = 184.2 rad/s (chapter parameters unless
noted). All methods of a scene are timed in this one process, one after another, each as
the median of ``--repeats`` runs, so ratios within a run are comparable:

- ``core``: ``TouchdownCore.step`` called directly, h = 1e-3 s;
- ``sim@h``: ``fmpy.simulate_fmu`` at communication step h recording all outputs (FMU
  extracted once, model description read once, ``validate=False``);
- ``lean@h/k``: a ``FMU2Slave`` loop, doStep at h, all outputs read every k-th step;
- ``floor-*``: the same host loops on a trivial PythonFMU FMU with the same variables whose
  ``do_step`` only publishes constant outputs the way RotorTouchdown publishes a quiet
  step's (the compiled state publisher, the report's outputs): the FMI/Python overhead
  floor;
- ``<METHOD>@rtol``: ``tests/reference/direct.py`` (solve_ivp with events, restart after
  each impact, Zeno cut-off), atol = rtol * (c_r, c_r Omega).

Errors are in scaled units (positions / c_r, velocities / (c_r Omega), times * Omega)
against mpmath references (``tests/reference/mp_reference.py``); see docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import ast
import cmath
import gc
import inspect
import json
import math
import multiprocessing as mproc
import os
import platform
import resource
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path[:0] = [str(ROOT), str(ROOT / "tests"), str(ROOT / "fmu_src")]

from mdblock import replace_block  # noqa: E402 (docs/scripts/mdblock.py)
from reference.direct import direct_simulate  # noqa: E402
from reference.mp_reference import mp_flight, mp_impact_sequence  # noqa: E402
from rotortd import RotorParams, TouchdownCore  # noqa: E402
from rotortd_tools.cycles import (  # noqa: E402
    OMEGA,
    chapter_params,
    find_period_one_cycle,
    rub_equilibria_scaled,
    si_params,
)

import build  # noqa: E402

W = OMEGA
T_END = 1.0
H_CORE = 1e-3
H_LONG = 0.1  # the core called once per 0.1 s (a divisor of the drop scene's t_off)
REAL_OUT = ("x", "y", "vx", "vy", "r_rel", "u_re", "u_im", "du_re", "du_im", "psi",
            "whirl_rate", "v_rel", "F_bx", "F_by", "F_n", "F_n_peak", "P_n", "T_f",
            "F_amb_x", "F_amb_y", "t_last_impact", "v_last_impact", "E_diss")
INT_OUT = ("mode", "n_impacts", "n_impacts_step")
BOOL_OUT = ("in_contact",)
ALL_OUT = REAL_OUT + INT_OUT + BOOL_OUT
METHODS = ("RK45", "DOP853", "LSODA", "Radau")
SLOW_RUN = 2.5
"""A direct run slower than this (s) is not repeated, and tighter rtols of that method
are skipped (the cost only grows): Radau at tight tolerances would take minutes."""
CPU_LIMIT = 8.0
"""CPU seconds after which a direct run is abandoned (reported as failed)."""
MAX_DIRECT_IMPACTS = 3000
"""Impact cap of a direct run (the core finds at most ~330 in these scenes)."""
V_PREFIX = 1e-2
"""Impact-prefix cut-off for the chattering scenes: impacts with rdot- >= V_PREFIX c_r Omega
before the first slower one (where mpmath can follow the motion)."""
K_PREFIX = 60
"""At most this many impacts in the mpmath prefix of the chattering scenes."""


# --------------------------------------------------------------------------- scenes
@dataclass
class Scene:
    """One benchmark scene: parameters, common initial state and input schedule."""

    name: str
    title: str
    params: RotorParams
    z0: complex
    v0: complex
    psi0: float
    t_off: float = math.inf  # amb_on -> 0 from this time on
    start_steady: bool = False
    prefix_only: bool = False  # error on an impact prefix (chattering scenes)
    ref: dict[str, Any] = field(default_factory=dict)

    def amb(self, t: float) -> float:
        return 0.0 if t >= self.t_off - 1e-12 else 1.0

    def segments(self) -> list[tuple[float, float, complex, float]]:
        if self.t_off < T_END:
            return [(self.t_off, W, 0j, 1.0), (T_END, W, 0j, 0.0)]
        return [(T_END, W, 0j, 1.0)]


def make_scenes() -> list[Scene]:
    p_whirl = si_params(chapter_params(gamma=0.3))
    whirl = TouchdownCore.on_steady_whirl(p_whirl, W)
    cyc = find_period_one_cycle(0.1)
    zm, vm = mp_flight(asdict(cyc.params), cyc.z0, cyc.v0, 0.0, W, 0j, 1.0, cyc.T_si / 2)
    p_drop = si_params(chapter_params()).replace(g=9.81)
    drop = TouchdownCore.on_steady_whirl(p_drop, W)
    return [
        Scene("free_whirl", "free whirl, gamma = 0.3, on the steady whirl", p_whirl,
              whirl.z, whirl.v, 0.0, start_steady=True),
        Scene("limit_cycle", "impacting limit cycle, gamma = 0.1, started mid-flight",
              cyc.params, complex(zm), complex(vm), W * cyc.T_si / 2),
        Scene("chattering", "chattering into rub, gamma = 0.3 from rest", p_whirl, 0j, 0j,
              0.0, prefix_only=True),
        Scene("dry_whirl", "dry whirl, gamma = 0.065 from rest",
              si_params(chapter_params(gamma=0.065)), 0j, 0j, 0.0, prefix_only=True),
        Scene("drop", "bearing-off drop, g = 9.81, amb_on -> 0 at 0.1 s (gamma = 0.152)",
              p_drop, drop.z, drop.v, 0.0, t_off=0.1, start_steady=True, prefix_only=True),
    ]


# --------------------------------------------------------------------------- references
def _mp_impacts(seq: dict[str, Any], t_shift: float) -> list[tuple[float, float]]:
    return [(float(i["t"]) + t_shift, float(i["rdot"])) for i in seq["impacts"]]


def mp_reference(sc: Scene) -> dict[str, Any]:
    """Reference impacts (t, rdot-) and final state from mpmath (dps 30)."""
    par, t0 = asdict(sc.params), time.perf_counter()
    dps = 30
    if sc.name == "free_whirl":
        z, v = mp_flight(par, sc.z0, sc.v0, sc.psi0, W, 0j, 1.0, T_END, dps=dps)
        out = {"impacts": [], "z": complex(z), "v": complex(v)}
    elif sc.name == "limit_cycle":
        seq = mp_impact_sequence(par, sc.z0, sc.v0, sc.psi0, W, 0j, 1.0, T_END,
                                 max_impacts=10_000, dps=dps)
        out = {"impacts": _mp_impacts(seq, 0.0), "z": complex(seq["z"]),
               "v": complex(seq["v"])}
    else:
        z0, v0, psi0, t_a, a = sc.z0, sc.v0, sc.psi0, 0.0, 1.0
        if sc.t_off < T_END:
            z, v = mp_flight(par, z0, v0, psi0, W, 0j, 1.0, sc.t_off, dps=dps)
            z0, v0, psi0, t_a, a = complex(z), complex(v), psi0 + W * sc.t_off, sc.t_off, 0.0
        seq = mp_impact_sequence(par, z0, v0, psi0, W, 0j, a, T_END - t_a,
                                 max_impacts=K_PREFIX, dps=dps,
                                 v_stop=V_PREFIX * sc.params.c_r * W)
        imps = _mp_impacts(seq, t_a)
        if seq["stopped"] == "v_stop":
            imps = imps[:-1]
        out = {"impacts": imps, "z": None, "v": None}
    if sc.name == "chattering":
        rub = rub_equilibria_scaled(chapter_params(gamma=0.3))[0]
        out["U_rub"] = cmath.exp(1j * rub.alpha)
    out["seconds"] = time.perf_counter() - t0
    return out


def _ref_worker(sc: Scene) -> tuple[str, dict[str, Any]]:
    return sc.name, mp_reference(sc)


# --------------------------------------------------------------------------- errors
@dataclass
class RunResult:
    """What one run of a method produced: final state and impacts (t, rdot-) by index."""

    z: complex
    v: complex
    psi: float
    n_impacts: int
    impacts: dict[int, tuple[float, float]]  # 1-based index -> (t, rdot-)
    ok: bool = True


def prefix_count(res: RunResult, v_cut: float, k_max: int) -> int | None:
    """Number of impacts before the first with rdot- < v_cut (None if unknown)."""
    for i in range(1, min(res.n_impacts, k_max) + 1):
        if i not in res.impacts:
            return None
        if res.impacts[i][1] < v_cut:
            return i - 1
    return min(res.n_impacts, k_max)


def errors(sc: Scene, res: RunResult) -> dict[str, Any]:
    """Scaled errors vs the reference: final state, impact times; impact count check."""
    c_r, ref = sc.params.c_r, sc.ref
    imps = ref["impacts"]
    n_ref = len(imps)
    t_err = max((abs(res.impacts[i][0] - imps[i - 1][0]) * W
                 for i in range(1, n_ref + 1) if i in res.impacts), default=0.0)
    out: dict[str, Any] = {"impact_time": t_err, "n_ref": n_ref, "n_impacts": res.n_impacts}
    if sc.prefix_only:
        n = prefix_count(res, V_PREFIX * c_r * W, K_PREFIX)
        out["count_ok"] = None if n is None else n == n_ref
        out["final"] = _rub_error(sc, res) if "U_rub" in ref else None
    else:
        out["count_ok"] = res.n_impacts == n_ref
        out["final"] = max(abs(res.z - ref["z"]) / c_r, abs(res.v - ref["v"]) / (c_r * W))
    parts = [t_err] + ([out["final"]] if out["final"] is not None else [])
    out["error"] = max(parts) if res.ok else math.inf
    if out["count_ok"] is False:
        out["error"] = math.inf
    return out


def _rub_error(sc: Scene, res: RunResult) -> float:
    """Distance of the final co-rotating state from the stable forward rub (U_rub, U' = 0)."""
    c_r = sc.params.c_r
    rot = cmath.exp(-1j * res.psi)
    U = res.z * rot / c_r
    dU = (res.v - 1j * W * res.z) * rot / (c_r * W)
    return max(abs(U - sc.ref["U_rub"]), abs(dU))


# --------------------------------------------------------------------------- timing
WALL: list[float] = []
"""Wall times of the runs timed by ``timed`` (cleared by the caller)."""


def cpu_run(fn: Callable[[], Any]) -> tuple[Any, float, float]:
    """(result, CPU seconds, wall seconds) of one call of fn. As timeit does, the garbage
    collector runs before the call and is paused during it: otherwise a collection of this
    script's own heap (every stored result) lands inside whichever run triggers it, and
    a 5 ms core run measured 5 to 8 ms."""
    gc.collect()
    gc.disable()
    try:
        w0, t0 = time.perf_counter(), time.process_time()
        res = fn()
        return res, time.process_time() - t0, time.perf_counter() - w0
    finally:
        gc.enable()


def timed(fn: Callable[[], RunResult], repeats: int) -> tuple[list[float], RunResult]:
    """CPU seconds of this process per run (robust on a shared machine); the wall-clock
    seconds are appended to WALL."""
    times, res = [], None
    for _ in range(repeats):
        res, cpu, wall = cpu_run(fn)
        times.append(cpu)
        WALL.append(wall)
    assert res is not None
    return times, res


def run_core(sc: Scene, h: float = H_CORE, t_end: float = T_END,
             step_times: list[float] | None = None) -> RunResult:
    core = TouchdownCore(sc.params, z0=sc.z0, v0=sc.v0, psi0=sc.psi0)
    imps: dict[int, tuple[float, float]] = {}
    ok, n = True, round(t_end / h)
    clock = time.perf_counter
    for j in range(n):
        t_a = clock() if step_times is not None else 0.0
        rep = core.step(h, W, 0j, sc.amb(j * h))
        if step_times is not None:
            step_times.append(clock() - t_a)
        ok = ok and rep.status == 0
        for imp in rep.impacts:
            imps[len(imps) + 1] = (imp.t, imp.rdot)
    return RunResult(core.z, core.v, core.psi, core.n_impacts, imps, ok)


def run_core_segments(sc: Scene) -> RunResult:
    """The core called once per held-input segment of the scene (Scene.segments), as the
    direct integrators take it: one call for the whole second, two for the drop."""
    core = TouchdownCore(sc.params, z0=sc.z0, v0=sc.v0, psi0=sc.psi0)
    imps: dict[int, tuple[float, float]] = {}
    ok, t = True, 0.0
    for t_end, omega, force, amb in sc.segments():
        rep = core.step(t_end - t, omega, force, amb)
        t = t_end
        ok = ok and rep.status == 0
        for imp in rep.impacts:
            imps[len(imps) + 1] = (imp.t, imp.rdot)
    return RunResult(core.z, core.v, core.psi, core.n_impacts, imps, ok)


class CpuLimit(Exception):
    """A direct run used more than CPU_LIMIT seconds of CPU time."""


def _on_cpu_limit(_sig: int, _frame: Any) -> None:
    raise CpuLimit


def run_direct(sc: Scene, method: str, rtol: float) -> RunResult:
    """One direct_simulate run; at most MAX_DIRECT_IMPACTS impacts and CPU_LIMIT s of CPU
    (LSODA can lose the chattering and produce thousands of spurious impacts)."""
    c_r = sc.params.c_r
    atol = [rtol * c_r] * 2 + [rtol * c_r * W] * 2
    signal.signal(signal.SIGPROF, _on_cpu_limit)
    signal.setitimer(signal.ITIMER_PROF, CPU_LIMIT)
    try:  # the one-shot timer may also fire inside the inner finally: catch it there too
        try:
            r = direct_simulate(asdict(sc.params), sc.z0, sc.v0, sc.psi0, 0.0,
                                sc.segments(), method=method, rtol=rtol, atol=atol,
                                max_impacts=MAX_DIRECT_IMPACTS)
        finally:
            signal.setitimer(signal.ITIMER_PROF, 0.0)
    except CpuLimit:
        return RunResult(0j, 0j, 0.0, 0, {}, ok=False)
    imps = {i + 1: (d["t"], d["rdot"]) for i, d in enumerate(r.impacts)}
    return RunResult(r.z, r.v, r.psi, len(r.impacts), imps,
                     r.status == "ok" and abs(r.t - T_END) < 1e-9)


# --------------------------------------------------------------------------- FMUs
FLOOR_TEMPLATE = '''"""Overhead floor: RotorTouchdown's variables, a do_step that only publishes.

Its do_step publishes constant outputs the way RotorTouchdown publishes a quiet step's: the
state outputs through the publisher compiled from the same source
(rotortd_fmi.touchdown.publisher_source) and the step report's outputs from a constant
report; so FMU/floor measures the model, not the publishing.

Packaged like RotorTouchdown: this module is resources/rotortd_floor/slave.py, and the FMU
script (FLOOR_SCRIPT) only subclasses it, since PythonFMU compiles the script per instance.
"""

from pythonfmu import Boolean, Fmi2Slave, Integer, Real, String
from pythonfmu.enums import Fmi2Causality, Fmi2Initial, Fmi2Variability

VARIABLE_META = {meta!r}
REAL_PARAMETERS = {params!r}
TUNABLE = {tunable!r}
INPUTS = {inputs!r}
REAL_OUTPUTS = {outputs!r}
FIXED_OTHER = {fixed_other!r}
PUBLISH_SOURCE = {publisher!r}
STATE_VALUES = {state_values!r}
REPORT_PUBLISH_SOURCE = {report_publisher!r}
_namespace = {{"Any": object}}
exec(compile(PUBLISH_SOURCE, "<rotortd_floor.state_publisher>", "exec"), _namespace)
exec(compile(REPORT_PUBLISH_SOURCE, "<rotortd_floor.report_publisher>", "exec"), _namespace)
_publish = _namespace["publish"]


class _QuietReport:
    """A quiet step's report, as the real adapter reads it."""
    F_contact = F_support = 0j
    F_n = F_n_peak = P_n = T_f = T_imb = P_fric = 0.0
    impacts = ()


_REPORT = _QuietReport()


class RotorTouchdownFloorAdapter(Fmi2Slave):
    """Same names and causalities as RotorTouchdown; do_step returns True."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        fixed, tun = Fmi2Variability.fixed, Fmi2Variability.tunable
        par, exact = Fmi2Causality.parameter, Fmi2Initial.exact
        for name, start, _d in REAL_PARAMETERS:
            setattr(self, name, start)
            self.register_variable(Real(name, causality=par,
                                        variability=tun if name in TUNABLE else fixed))
        for name, val, kind in FIXED_OTHER:
            setattr(self, name, val)
            cls = Boolean if kind == "Boolean" else String
            self.register_variable(cls(name, causality=par, variability=fixed))
        for name, start, _d in INPUTS:
            setattr(self, name, start)
            self.register_variable(Real(name, causality=Fmi2Causality.input))
        for name, _d in REAL_OUTPUTS:
            setattr(self, name, 0.0)
            self.register_variable(Real(name, causality=Fmi2Causality.output, initial=exact))
        disc = Fmi2Variability.discrete
        for name in ("mode", "n_impacts", "n_impacts_step"):
            setattr(self, name, 0)
            self.register_variable(Integer(name, causality=Fmi2Causality.output,
                                           variability=disc, initial=exact))
        self.in_contact = False
        self.register_variable(Boolean("in_contact", causality=Fmi2Causality.output,
                                       variability=disc, initial=exact))

    def do_step(self, current_time, step_size):
        self._publish_state(STATE_VALUES)
        self._publish_step_outputs(_REPORT)
        return True

    def _publish_state(self, out):
        """RotorTouchdown's publishing of the state outputs (touchdown.state_publisher, the
        same compiled source) with constant values."""
        _publish(self, out, False)
        return sum(out)

    _publish_step_outputs = _namespace["_publish_step_outputs"]  # RotorTouchdown's own
'''

FLOOR_SCRIPT = '''"""FMU script of the overhead floor (see rotortd_floor/slave.py)."""

from rotortd_floor import slave as _adapter

VARIABLE_META = _adapter.VARIABLE_META


class RotorTouchdownFloor(_adapter.RotorTouchdownFloorAdapter):
    def __init__(self, **kwargs):  # keeps PythonFMU's namespace of this script alive
        super().__init__(**kwargs)
'''


def _adapter_tables() -> dict[str, Any]:
    from rotortd_fmi import touchdown as mod
    from rotortd_fmi.touchdown_variables import TABLE

    def rows(causality: str) -> tuple:
        return tuple((v.name, v.start, v.description) for v in TABLE
                     if v.causality == causality and v.type == "Real")

    core = TouchdownCore(RotorParams())
    return {"meta": mod.VARIABLE_META, "params": rows("parameter"),
            "tunable": set(mod.TUNABLE), "inputs": rows("input"),
            "outputs": tuple((n, d) for n, _s, d in rows("output")),
            "fixed_other": tuple((v.name, v.start, v.type) for v in TABLE
                                 if v.causality == "parameter" and v.type != "Real"),
            "publisher": mod.publisher_source(core.outputs()._fields),
            "report_publisher": textwrap.dedent(
                inspect.getsource(mod.RotorTouchdownAdapter._publish_step_outputs)),
            "state_values": tuple(core.output_values())}


def build_fmus(tmp: Path) -> dict[str, tuple[str, Any]]:
    """Build RotorTouchdown and the floor FMU into tmp; return name -> (unzipdir, md)."""
    from fmpy import extract, read_model_description

    floor_pkg = tmp / "rotortd_floor"
    floor_pkg.mkdir()
    (floor_pkg / "__init__.py").write_text("")
    (floor_pkg / "slave.py").write_text(FLOOR_TEMPLATE.format(**_adapter_tables()))
    floor_script = tmp / "RotorTouchdownFloor.py"
    floor_script.write_text(FLOOR_SCRIPT)
    specs = [build.FMU_SPECS[0], build.FmuSpec(name="RotorTouchdownFloor", script=floor_script,
                                                project_dirs=(floor_pkg,))]
    out = {}
    for spec in specs:
        fmu = build.build_fmu(spec, tmp / "fmus")
        unzip = extract(str(fmu), str(tmp / spec.name))
        out[spec.name] = (unzip, read_model_description(str(fmu)))
    return out


def start_values(sc: Scene) -> dict[str, Any]:
    p = sc.params
    sv: dict[str, Any] = {n: getattr(p, n) for n in
                          ("m", "c", "k", "e_c", "phi", "c_r", "R", "mu", "d", "g")}
    if sc.start_steady:
        sv["start_steady"] = True
    else:
        sv.update(x0=sc.z0.real, y0=sc.z0.imag, vx0=sc.v0.real, vy0=sc.v0.imag)
    sv["psi0"] = sc.psi0
    return sv


def _rows_to_result(t: np.ndarray, get: Callable[[str], np.ndarray], n_steps: int,
                    ok: bool) -> RunResult:
    x, y, vx, vy = get("x"), get("y"), get("vx"), get("vy")
    n_imp, t_last, v_last = get("n_impacts"), get("t_last_impact"), get("v_last_impact")
    imps = {int(n): (float(tl), float(vl)) for n, tl, vl in zip(n_imp, t_last, v_last)
            if n > 0}
    psi = W * float(t[-1])  # psi0 is added by the caller
    return RunResult(complex(x[-1], y[-1]), complex(vx[-1], vy[-1]), psi,
                     int(n_imp[-1]), imps, ok)


def run_simulate(sc: Scene, fmu: tuple[str, Any], h: float) -> RunResult:
    from fmpy import simulate_fmu

    unzip, md = fmu
    inp = None
    if sc.t_off < T_END:  # every input listed: FMPy warns about each one left out
        held = (W, 0.0, 0.0, 0.0)  # Omega, F_x, F_y, T_drive at their start values
        inp = np.array([(0.0, 1.0, *held), (sc.t_off, 1.0, *held), (sc.t_off, 0.0, *held),
                        (T_END, 0.0, *held)],
                       dtype=[("time", float), ("amb_on", float), ("Omega", float),
                              ("F_x", float), ("F_y", float), ("T_drive", float)])
    res = simulate_fmu(unzip, validate=False, model_description=md, stop_time=T_END,
                       output_interval=h, start_values=start_values(sc), input=inp,
                       output=list(ALL_OUT))
    t = res["time"]
    out = _rows_to_result(t, lambda n: res[n], len(t), abs(t[-1] - T_END) < 1e-9)
    out.psi += sc.psi0
    return out


class LeanLoop:
    """A bare FMU2Slave loop: doStep at h, every k-th step all outputs are read."""

    def __init__(self, fmu: tuple[str, Any], name: str) -> None:
        self.unzip, self.md = fmu
        self.name = name
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}

    def run(self, sc: Scene, h: float, k: int, t_end: float = T_END) -> RunResult:
        from fmpy.fmi2 import FMU2Slave

        md = self.md
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=self.unzip,
                        modelIdentifier=md.coSimulation.modelIdentifier, instanceName="b")
        fmu.instantiate()
        self._set_start(fmu, sc)
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        rows = self._loop(fmu, sc, h, k, t_end)
        fmu.terminate()
        fmu.freeInstance()
        return self._result(rows, sc, h, k, t_end)

    def _set_start(self, fmu: Any, sc: Scene) -> None:
        for name, val in start_values(sc).items():
            if isinstance(val, bool):
                fmu.setBoolean([self.vr[name]], [val])
            else:
                fmu.setReal([self.vr[name]], [float(val)])

    def _loop(self, fmu: Any, sc: Scene, h: float, k: int, t_end: float) -> list[tuple]:
        rv = [self.vr[n] for n in REAL_OUT]
        iv = [self.vr[n] for n in INT_OUT]
        bv = [self.vr[n] for n in BOOL_OUT]
        amb_vr = [self.vr["amb_on"]]
        n, rows, amb = round(t_end / h), [], 1.0
        do_step, get_r, get_i, get_b = fmu.doStep, fmu.getReal, fmu.getInteger, fmu.getBoolean
        for j in range(n):
            t = j * h
            if sc.amb(t) != amb:
                amb = sc.amb(t)
                fmu.setReal(amb_vr, [amb])
            do_step(t, h)
            if (j + 1) % k == 0 or j == n - 1:
                rows.append((get_r(rv), get_i(iv), get_b(bv)))
        return rows

    def _result(self, rows: list[tuple], sc: Scene, h: float, k: int, t_end: float
                ) -> RunResult:
        reals = np.array([r[0] for r in rows])
        ints = np.array([r[1] for r in rows])
        cols = {n: reals[:, i] for i, n in enumerate(REAL_OUT)}
        cols.update({n: ints[:, i] for i, n in enumerate(INT_OUT)})
        t = np.arange(1, len(rows) + 1) * h * k
        out = _rows_to_result(t, lambda n: cols[n], round(t_end / h), True)
        out.psi = sc.psi0 + W * t_end
        return out


# --------------------------------------------------------------------------- one scene
def bench_scene(sc: Scene, fmus: dict[str, tuple[str, Any]], repeats: int,
                quick: bool) -> list[dict[str, Any]]:
    rows: list[dict[str, Any]] = []
    target = sc.name in ("free_whirl", "limit_cycle")

    def record(kind: str, label: str, fn: Callable[[], RunResult], reps: int = repeats,
               **extra: Any) -> float:
        WALL.clear()
        times, res = timed(fn, reps)
        row = {"scene": sc.name, "kind": kind, "label": label, "times": times,
               "median": statistics.median(times), "wall": list(WALL),
               "wall_median": statistics.median(WALL), **extra}
        if kind != "floor":
            row.update(errors(sc, res))
        rows.append(row)
        err = row.get("error", float("nan"))
        print(f"  {label:>22s}  {row['median'] * 1e3:10.2f} ms  err {err:.2e}", flush=True)
        return row["median"]

    record("core", "core h=1e-3", lambda: run_core(sc), steps=round(T_END / H_CORE))
    record("core", "core h=0.1", lambda: run_core(sc, H_LONG), steps=round(T_END / H_LONG))
    record("core", "core seg", lambda: run_core_segments(sc), steps=len(sc.segments()))
    fmu, floor = fmus["RotorTouchdown"], fmus["RotorTouchdownFloor"]
    fine = sc.name == "limit_cycle" and not quick
    sim_steps = [1e-5, 1e-4, 1e-3, 1e-2] if fine else [1e-4, 1e-3, 1e-2]
    for h in sim_steps:
        n = round(T_END / h)
        record("sim", f"sim@{h:g}", lambda h=h: run_simulate(sc, fmu, h), h=h, steps=n)
        record("floor", f"floor-sim@{h:g}", lambda h=h: run_simulate(sc, floor, h), h=h,
               steps=n)
    lean, lean_floor = LeanLoop(fmu, "fmu"), LeanLoop(floor, "floor")
    for h, k in ((1e-3, 1), (1e-4, 10)):
        n = round(T_END / h)
        record("lean", f"lean@{h:g}/{k}", lambda h=h, k=k: lean.run(sc, h, k), h=h, k=k,
               steps=n)
        record("floor", f"floor-lean@{h:g}/{k}", lambda h=h, k=k: lean_floor.run(sc, h, k),
               h=h, k=k, steps=n)
    coarse = [1e-3, 1e-6, 1e-9, 1e-12]
    full = [10.0**-e for e in range(3, 13)]
    for method in METHODS:
        grid = full if (method == "DOP853" and target and not quick) else coarse
        for rtol in grid:
            probe_t, _ = timed(lambda m=method, r=rtol: run_direct(sc, m, r), 1)
            reps = 1 if probe_t[0] > SLOW_RUN else repeats
            record("direct", f"{method}@{rtol:.0e}",
                   lambda m=method, r=rtol: run_direct(sc, m, r), reps=reps, method=method,
                   rtol=rtol, first_run=probe_t[0])
            if probe_t[0] > SLOW_RUN:
                break
    return rows


# --------------------------------------------------------------------------- scaling
def scaling_time(scenes: dict[str, Scene], quick: bool) -> list[dict[str, Any]]:
    """Core cost vs simulated time (1, 10, 100 s), h = 1e-3."""
    out = []
    for name in ("free_whirl", "limit_cycle"):
        for t_end in ((1.0, 10.0) if quick else (1.0, 10.0, 100.0)):
            reps = 5 if t_end <= 1.0 else (3 if t_end <= 10.0 else 1)
            times, res = timed(lambda n=name, te=t_end: run_core(scenes[n], t_end=te), reps)
            out.append({"scene": name, "t_end": t_end, "times": times,
                        "median": statistics.median(times), "n_impacts": res.n_impacts,
                        "per_sim_second": statistics.median(times) / t_end})
            print(f"  {name} {t_end:6g} s: {out[-1]['median']:.3f} s, "
                  f"{res.n_impacts} impacts", flush=True)
    return out


def scaling_impacts(sc: Scene) -> dict[str, Any]:
    """Per-step cost of the core vs impacts in the step (least squares, limit cycle)."""
    st: list[float] = []
    core = TouchdownCore(sc.params, z0=sc.z0, v0=sc.v0, psi0=sc.psi0)
    n_imp = []
    for _ in range(5):
        core = TouchdownCore(sc.params, z0=sc.z0, v0=sc.v0, psi0=sc.psi0)
        for _j in range(round(T_END / H_CORE)):
            t0 = time.perf_counter()
            rep = core.step(H_CORE, W)
            st.append(time.perf_counter() - t0)
            n_imp.append(len(rep.impacts))
    A = np.column_stack([np.ones(len(st)), n_imp])
    coef = np.linalg.lstsq(A, np.array(st), rcond=None)[0]
    by_n = {int(k): float(np.median([s for s, n in zip(st, n_imp) if n == k]))
            for k in sorted(set(n_imp))}
    return {"per_step_s": float(coef[0]), "per_impact_s": float(coef[1]),
            "median_step_by_impacts": by_n, "steps": len(st)}


def scaling_comm_step(sc: Scene, fmus: dict[str, tuple[str, Any]]) -> list[dict[str, Any]]:
    """Core and lean FMU loop over 0.02 s at h = 1e-6 ... 1e-2 (all outputs every step)."""
    out, t_end = [], 0.02
    lean = LeanLoop(fmus["RotorTouchdown"], "fmu")
    for h in (1e-6, 1e-5, 1e-4, 1e-3, 2e-2):
        tc, _ = timed(lambda h=h: run_core(sc, h=h, t_end=t_end), 3)
        tf, _ = timed(lambda h=h: lean.run(sc, h, 1, t_end=t_end), 3)
        n = round(t_end / h)
        out.append({"scene": sc.name, "h": h, "steps": n, "t_end": t_end,
                    "core": statistics.median(tc), "lean": statistics.median(tf),
                    "core_per_step": statistics.median(tc) / n,
                    "lean_per_step": statistics.median(tf) / n})
        print(f"  h={h:g}: core {out[-1]['core']:.3f} s, lean {out[-1]['lean']:.3f} s",
              flush=True)
    return out


MEM_CORE = """
import resource, sys
sys.path.insert(0, {src!r})
from rotortd import TouchdownCore
from rotortd_tools.cycles import chapter_params, si_params, OMEGA
core = TouchdownCore.on_steady_whirl(si_params(chapter_params(gamma=0.3)), OMEGA)
marks = {{}}
for j in range(1, {n} + 1):
    core.step(1e-6, OMEGA)
    if j in (10_000, 100_000, 1_000_000):
        marks[j] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print("RSS", marks, core.t)
"""


def start_memory_core(n: int) -> subprocess.Popen:
    """Start n core steps of 1e-6 s (free whirl) in a subprocess; it prints the peak RSS
    (kB) after 1e4, 1e5 and 1e6 steps. Runs while the timings run (CPU time is measured)."""
    code = MEM_CORE.format(src=str(ROOT / "fmu_src"), n=n)
    return subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)


def finish_memory_core(proc: subprocess.Popen, n: int) -> dict[str, Any]:
    out, _ = proc.communicate()
    line = next(ln for ln in out.splitlines() if ln.startswith("RSS"))
    marks = ast.literal_eval(line.split(" ", 1)[1].rsplit(" ", 1)[0])
    return {"steps": n, "h": 1e-6, "peak_rss_kB": {str(k): v for k, v in marks.items()},
            "t_final": float(line.split()[-1])}


def memory_fmu(fmu: tuple[str, Any], n: int) -> dict[str, Any]:
    """Peak RSS (kB) over a lean FMU loop of n steps of 1e-5 s (this process, all outputs
    read every step, nothing kept), at n/10 and n steps."""
    from fmpy.fmi2 import FMU2Slave

    unzip, md = fmu
    vr = {v.name: v.valueReference for v in md.modelVariables}
    rv = [vr[x] for x in REAL_OUT]
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzip,
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="m")
    slave.instantiate()
    slave.setBoolean([vr["start_steady"]], [True])
    slave.setReal([vr["c"]], [0.3 * 50.0 * W])
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    marks = {}
    for j in range(n):
        slave.doStep(j * 1e-5, 1e-5)
        slave.getReal(rv)
        if j + 1 in (n // 10, n):
            marks[str(j + 1)] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    slave.terminate()
    slave.freeInstance()
    return {"steps": n, "h": 1e-5, "peak_rss_kB": marks}


# --------------------------------------------------------------------------- report
def machine() -> dict[str, Any]:
    import fmpy
    import mpmath
    import pythonfmu
    import scipy

    cpu = ""
    try:
        cpu = next(ln.split(":", 1)[1].strip() for ln in
                   Path("/proc/cpuinfo").read_text().splitlines() if "model name" in ln)
    except (OSError, StopIteration):
        cpu = platform.processor()
    return {"cpu": cpu, "cores": os.cpu_count(), "platform": platform.platform(),
            "python": sys.version.split()[0], "numpy": np.__version__,
            "scipy": scipy.__version__, "fmpy": fmpy.__version__,
            "pythonfmu": getattr(pythonfmu, "__version__", "?"),
            "mpmath": mpmath.__version__}


def _find(rows: list[dict[str, Any]], scene: str, label: str) -> dict[str, Any]:
    return next(r for r in rows if r["scene"] == scene and r["label"] == label)


def interleaved(fa: Callable[[], Any], fb: Callable[[], Any], pairs: int) -> dict[str, Any]:
    """CPU seconds of A and B run alternately ``pairs`` times; the median of the pairs'
    ratios A_i/B_i.

    This machine's speed switches between phases that differ by up to 2x and last
    seconds. Two blocks timed one after the other can land in different phases, and so
    can the medians of interleaved runs; the two runs of one pair almost always share a
    phase, so the median of the pair ratios is what the target asks for."""
    ta, tb = [], []
    for _ in range(pairs):
        for fn, out in ((fa, ta), (fb, tb)):
            out.append(cpu_run(fn)[1])
    ratios = [a / b for a, b in zip(ta, tb)]
    return {"a": statistics.median(ta), "b": statistics.median(tb),
            "ratio": statistics.median(ratios), "pair_ratios": ratios,
            "a_times": ta, "b_times": tb}


def targets(rows: list[dict[str, Any]], scenes: dict[str, Scene],
            fmus: dict[str, tuple[str, Any]], pairs: int) -> dict[str, Any]:
    """The issue's target ratios, each measured by alternating its two runs (interleaved);
    the errors come from the scene tables of the same run."""
    lc, fw, ch = scenes["limit_cycle"], scenes["free_whirl"], scenes["chattering"]
    fmu, floor = fmus["RotorTouchdown"], fmus["RotorTouchdownFloor"]
    lean, lean_floor = LeanLoop(fmu, "fmu"), LeanLoop(floor, "floor")
    runs: dict[str, Callable[[Scene], Any]] = {
        "core h=1e-3": lambda sc: run_core(sc),
        "core h=0.1": lambda sc: run_core(sc, H_LONG),
        "core seg": run_core_segments,
        "sim@0.001": lambda sc: run_simulate(sc, fmu, 1e-3),
        "sim@0.0001": lambda sc: run_simulate(sc, fmu, 1e-4),
        "lean@0.001/1": lambda sc: lean.run(sc, 1e-3, 1),
        "floor-sim@0.001": lambda sc: run_simulate(sc, floor, 1e-3),
        "floor-sim@0.0001": lambda sc: run_simulate(sc, floor, 1e-4),
        "floor-lean@0.001/1": lambda sc: lean_floor.run(sc, 1e-3, 1),
        "DOP853@1e-12": lambda sc: run_direct(sc, "DOP853", 1e-12),
    }

    def ratio(a: str, sa: Scene, b: str, sb: Scene) -> dict[str, Any]:
        print(f"  {sa.name}:{a} / {sb.name}:{b}", flush=True)
        return interleaved(lambda: runs[a](sa), lambda: runs[b](sb), pairs)

    dop = _find(rows, "limit_cycle", "DOP853@1e-12")
    out: dict[str, Any] = {}
    for label in ("core h=1e-3", "core h=0.1", "core seg"):
        r = ratio("DOP853@1e-12", lc, label, lc)
        err = _find(rows, "limit_cycle", label)["error"]
        out[f"core_vs_dop853_{label}"] = {
            **r, "goal": ">= 50", "core_error": err, "dop853_error": dop["error"],
            "met": r["ratio"] >= 50 and err <= 1e-11}
    r = ratio("sim@0.001", lc, "DOP853@1e-12", lc)
    err = _find(rows, "limit_cycle", "sim@0.001")["error"]
    out["sim1e-3_vs_dop853"] = {**r, "goal": "<= 0.2", "fmu_error": err,
                                "met": r["ratio"] <= 0.2 and err <= 1e-10}
    for sc, goal in ((fw, 1.2), (lc, 1.5)):
        for host in ("lean@0.001/1", "sim@0.001", "sim@0.0001"):
            r = ratio(host, sc, f"floor-{host}", sc)
            out[f"fmu_vs_floor_{sc.name}_{host}"] = {**r, "goal": f"<= {goal}",
                                                     "met": r["ratio"] <= goal}
    for label in ("core h=1e-3", "sim@0.001", "lean@0.001/1"):
        r = ratio(label, ch, label, lc)
        out[f"chattering_vs_limit_cycle_{label}"] = {**r, "goal": "<= 3",
                                                    "met": r["ratio"] <= 3}
    return out


def plot_scene(sc: Scene, rows: list[dict[str, Any]], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    floor_err = 1e-17
    fig, ax = plt.subplots(figsize=(7.5, 5.2))
    mine = [r for r in rows if r["scene"] == sc.name]

    def err(r: dict[str, Any]) -> float:
        e = r["error"]
        return 1e2 if e is None or not math.isfinite(e) else max(e, floor_err)

    for method, marker in zip(METHODS, "os^v"):
        pts = [r for r in mine if r["kind"] == "direct" and r["method"] == method]
        ax.plot([r["median"] for r in pts], [err(r) for r in pts], marker=marker, ls="-",
                label=f"solve_ivp {method} (rtol 1e-3 ... 1e-12)", alpha=0.8)
    sim = [r for r in mine if r["kind"] == "sim"]
    ax.plot([r["median"] for r in sim], [err(r) for r in sim], "D-", color="k",
            label="FMU, simulate_fmu (h = 1e-5 ... 1e-2)")
    for r in sim:
        ax.annotate(f"{r['h']:g}", (r["median"], err(r)), fontsize=7,
                    textcoords="offset points", xytext=(4, 4))
    lean = [r for r in mine if r["kind"] == "lean"]
    ax.plot([r["median"] for r in lean], [err(r) for r in lean], "P", color="tab:purple",
            ls="none", label="FMU, FMU2Slave loop (h/k)")
    core = [r for r in mine if r["kind"] == "core"]
    ax.plot([r["median"] for r in core], [err(r) for r in core], "*", ms=16,
            color="tab:red", ls="none", label="core (h = 1e-3, 0.1, per segment)")
    for r in core:
        ax.annotate(r["label"].removeprefix("core "), (r["median"], err(r)), fontsize=7,
                    textcoords="offset points", xytext=(6, -10))
    for r in mine:
        if r["kind"] == "floor" and r["label"] == "floor-sim@0.001":
            ax.axvline(r["median"], color="gray", ls=":",
                       label="overhead floor, simulate_fmu h = 1e-3")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("CPU time of the run (s), median of repeats")
    ax.set_ylabel("error (scaled units; 1e2 = failed / wrong impact count)")
    ax.set_title(sc.title, fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def print_table(rows: list[dict[str, Any]]) -> None:
    print(f"\n{'scene':12s} {'method':>22s} {'median ms':>11s} {'error':>9s} "
          f"{'impacts':>8s} count")
    for r in rows:
        if r["kind"] == "floor":
            print(f"{r['scene']:12s} {r['label']:>22s} {r['median'] * 1e3:11.2f}")
            continue
        print(f"{r['scene']:12s} {r['label']:>22s} {r['median'] * 1e3:11.2f} "
              f"{r['error']:9.1e} {r['n_impacts']:8d} {r['count_ok']}")


def markdown_rows(rows: list[dict[str, Any]]) -> str:
    """The scene tables of docs/benchmarks.md (CPU and wall medians, errors, counts)."""
    out = ["| scene | method | CPU ms | wall ms | runs | error | impacts (ref. prefix) | "
           "count ok |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        head = (f"| {r['scene']} | {r['label']} | {r['median'] * 1e3:.1f} | "
                f"{r['wall_median'] * 1e3:.1f} | {len(r['times'])} |")
        if r["kind"] == "floor":
            out.append(head + " | | |")
            continue
        err = r["error"]
        err_s = f"{err:.1e}" if math.isfinite(err) else "—"
        ok = "yes" if r["count_ok"] is True else ("n/a" if r["count_ok"] is None else "**no**")
        out.append(f"{head} {err_s} | {r['n_impacts']} ({r['n_ref']}) | {ok} |")
    return "\n".join(out)


def markdown_targets(targets_: dict[str, Any]) -> str:
    """The target table of docs/benchmarks.md (interleaved ratios)."""
    out = ["| target | ratio (median of 7 pairs) | medians A / B (ms) | goal | verdict |",
           "|---|---|---|---|---|"]
    for key, t in targets_.items():
        verdict = "met" if t["met"] else "**missed**"
        out.append(f"| `{key}` | **{t['ratio']:.3g}** | {t['a'] * 1e3:.1f} / "
                   f"{t['b'] * 1e3:.1f} | {t['goal']} | {verdict} |")
    return "\n".join(out)


# --------------------------------------------------------------------------- main
def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="3 repeats, fewer points")
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "benchmarks.json")
    ap.add_argument("--img", type=Path, default=ROOT / "docs" / "img")
    ap.add_argument("--replot", action="store_true",
                    help="only redraw the plots from the JSON of the last run")
    args = ap.parse_args(argv)
    if args.replot:
        rows = json.loads(args.out.read_text())["rows"]
        for sc in make_scenes():
            plot_scene(sc, rows, args.img / f"bench_{sc.name}.png")
        return 0
    repeats = 3 if args.quick else args.repeats
    t_start = time.perf_counter()
    n_mem = 100_000 if args.quick else 1_000_000
    mem_proc = start_memory_core(n_mem)
    load0 = os.getloadavg()
    scenes = make_scenes()
    print("mpmath references (2 processes) ...", flush=True)
    with mproc.get_context("fork").Pool(2) as pool:
        refs = dict(pool.map(_ref_worker, scenes))
    for sc in scenes:
        sc.ref = refs[sc.name]
        print(f"  {sc.name}: {len(sc.ref['impacts'])} reference impacts, "
              f"{sc.ref['seconds']:.1f} s", flush=True)
    tmp = Path(tempfile.mkdtemp(prefix="rotortd_bench_"))
    result: dict[str, Any] = {"machine": machine(), "repeats": repeats, "quick": args.quick}
    try:
        fmus = build_fmus(tmp)
        rows: list[dict[str, Any]] = []
        for sc in scenes:
            print(f"scene {sc.name}", flush=True)
            rows += bench_scene(sc, fmus, repeats, args.quick)
        by_name = {sc.name: sc for sc in scenes}
        print("scaling: simulated time", flush=True)
        result["scaling_time"] = scaling_time(by_name, args.quick)
        print("scaling: impacts per step", flush=True)
        result["scaling_impacts"] = scaling_impacts(by_name["limit_cycle"])
        print("scaling: communication step", flush=True)
        result["scaling_comm_step"] = scaling_comm_step(by_name["limit_cycle"], fmus)
        print("memory", flush=True)
        result["memory_core"] = finish_memory_core(mem_proc, n_mem)
        result["memory_fmu"] = memory_fmu(fmus["RotorTouchdown"],
                                          20_000 if args.quick else 100_000)
        print("targets (interleaved)", flush=True)
        result["targets"] = targets(rows, by_name, fmus, 3 if args.quick else 7)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    result["rows"] = rows
    result["references"] = {sc.name: {"n_impacts": len(sc.ref["impacts"]),
                                      "seconds": sc.ref["seconds"]} for sc in scenes}
    args.img.mkdir(parents=True, exist_ok=True)
    for sc in scenes:
        plot_scene(sc, rows, args.img / f"bench_{sc.name}.png")
    print_table(rows)
    print("\ntargets:")
    for key, val in result["targets"].items():
        print(f"  {key}: ratio {val['ratio']:.3g} (goal {val['goal']}) "
              f"{'met' if val['met'] else 'MISSED'}")
    result["total_seconds"] = time.perf_counter() - t_start
    result["machine"]["loadavg_start_end"] = [load0, os.getloadavg()]
    text = json.dumps(_finite(result), indent=1, default=_json_default, allow_nan=False)
    args.out.write_text(text + "\n")
    if not args.quick:
        doc = ROOT / "docs" / "benchmarks.md"
        replace_block(doc, "bench-table", markdown_rows(rows))
        replace_block(doc, "bench-targets", markdown_targets(result["targets"]))
    print(f"\nwrote {args.out}; total {result['total_seconds']:.0f} s", flush=True)
    sys.stdout.flush()
    os._exit(0)  # PythonFMU instances can crash the interpreter at shutdown


def _finite(x: Any) -> Any:
    """Replace inf/nan floats by None (strict JSON)."""
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if isinstance(x, dict):
        return {k: _finite(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_finite(v) for v in x]
    return x


def _json_default(x: Any) -> Any:
    if isinstance(x, complex):
        return [x.real, x.imag]
    if isinstance(x, np.generic):
        return x.item()
    raise TypeError(type(x))


if __name__ == "__main__":
    sys.exit(main())
