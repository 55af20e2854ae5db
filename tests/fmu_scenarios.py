"""FMU scenarios, each run in its own process by tests/test_fmu.py.

    python tests/fmu_scenarios.py SCENARIO FMU_PATH '{"json": "kwargs"}'

Prints one line ``RESULT:<json>`` and leaves with ``os._exit(0)``: a crash in the FMU (or
the rare heap corruption PythonFMU shows at interpreter shutdown) then cannot take pytest
down, and the exit-time teardown cannot turn a finished scenario into a failure.
"""

from __future__ import annotations

import gc
import json
import math
import os
import shutil
import sys
import tempfile
from collections.abc import Callable
from ctypes import byref
from pathlib import Path
from typing import Any

from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)

REAL_OUT = ("x", "y", "vx", "vy", "r_rel", "u_re", "u_im", "du_re", "du_im", "psi",
            "whirl_rate", "v_rel", "F_bx", "F_by", "F_n", "F_n_peak", "P_n", "T_f",
            "T_imb", "F_amb_x", "F_amb_y", "t_last_impact", "v_last_impact", "E_diss")
INT_OUT = ("mode", "n_impacts", "n_impacts_step")

MESSAGES: list[dict[str, Any]] = []
_KEEP: list[Any] = []          # ctypes callbacks must outlive the instances


def _logger(_component: Any, instance: bytes, status: int, category: bytes,
            message: bytes) -> None:
    MESSAGES.append({"instance": instance.decode(), "status": int(status),
                     "category": category.decode(), "message": message.decode()})


def _callbacks() -> fmi2CallbackFunctions:
    from fmpy import calloc, free

    cb = fmi2CallbackFunctions()
    cb.logger = fmi2CallbackLoggerTYPE(_logger)
    cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    try:
        from fmpy.logging import addLoggerProxy

        addLoggerProxy(byref(cb))
    except Exception:  # proxy only formats variadic messages
        pass
    _KEEP.append(cb)
    return cb


class Instance:
    """A FMU2Slave with name-based access, raw step status and captured log messages."""

    def __init__(self, fmu: str, name: str = "inst", unzipdir: str | None = None) -> None:
        self.md = read_model_description(fmu)
        self.unzipdir = unzipdir or extract(fmu)
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.types = {v.name: v.type for v in self.md.modelVariables}
        self.slave = FMU2Slave(guid=self.md.guid, unzipDirectory=self.unzipdir,
                               modelIdentifier=self.md.coSimulation.modelIdentifier,
                               instanceName=name)
        self.slave.instantiate(callbacks=_callbacks(), loggingOn=True)
        self.t = 0.0

    def set(self, values: dict[str, Any]) -> None:
        for name, value in values.items():
            kind = self.types[name]
            if kind == "Real":
                self.slave.setReal([self.vr[name]], [float(value)])
            elif kind == "Integer":
                self.slave.setInteger([self.vr[name]], [int(value)])
            elif kind == "Boolean":
                self.slave.setBoolean([self.vr[name]], [bool(value)])
            else:
                self.slave.setString([self.vr[name]], [str(value)])

    def init(self, params: dict[str, Any] | None = None, t0: float = 0.0) -> None:
        self.slave.setupExperiment(startTime=t0)
        self.slave.enterInitializationMode()
        self.set(params or {})
        self.slave.exitInitializationMode()
        self.t = t0

    def step(self, h: float) -> int:
        """doStep from self.t; returns the FMI status (0 ok, 2 discard, ...)."""
        try:
            self.slave.doStep(self.t, h)
        except FMICallException as exc:
            return _status_of(exc)
        self.t += h
        return 0

    def outputs(self) -> dict[str, Any]:
        reals = self.slave.getReal([self.vr[n] for n in REAL_OUT])
        ints = self.slave.getInteger([self.vr[n] for n in INT_OUT])
        (contact,) = self.slave.getBoolean([self.vr["in_contact"]])
        out: dict[str, Any] = dict(zip(REAL_OUT, reals, strict=True))
        out.update(zip(INT_OUT, ints, strict=True))
        out["in_contact"] = bool(contact)
        return out

    def free(self) -> None:
        self.slave.terminate()
        self.slave.freeInstance()


def _status_of(exc: FMICallException) -> int:
    text = str(exc)
    for code, label in enumerate(("ok", "warning", "discard", "error", "fatal")):
        if f"({label})" in text:
            return code
    return -1


def _run(inst: Instance, n: int, h: float, inputs: Callable[[float], dict] | None = None
         ) -> list[dict[str, Any]]:
    rows = []
    for _ in range(n):
        if inputs is not None:
            inst.set(inputs(inst.t))
        status = inst.step(h)
        if status != 0:
            raise RuntimeError(f"doStep at t={inst.t} returned status {status}: {MESSAGES}")
        rows.append(inst.outputs())
    return rows


def _run_restored(fmu: str, name: str, blob: bytes, t_saved: float, n: int, h: float,
                  inputs: Callable[[float], dict] | None) -> list[dict[str, Any]]:
    """A new instance restored from a serialized FMU state at t_saved, run n steps of h."""
    inst = Instance(fmu, name)
    inst.init({})
    restored = inst.slave.deSerializeFMUstate(blob)
    inst.slave.setFMUstate(restored)
    inst.slave.freeFMUstate(restored)
    inst.t = t_saved
    return _run(inst, n, h, inputs)


def _amb_switch(t_off: float) -> Callable[[float], dict]:
    return lambda t: {"amb_on": 0.0 if t >= t_off - 1e-12 else 1.0}


# ---------------------------------------------------------------------------- scenarios
def sc_default_scene(fmu: str, output_interval: float = 1e-4) -> dict[str, Any]:
    res = simulate_fmu(fmu, output_interval=output_interval,
                       output=["r_rel", "n_impacts", "mode", "E_diss"])
    md = read_model_description(fmu)
    return {"t_end": float(res["time"][-1]), "stop_time": float(md.defaultExperiment.stopTime),
            "rows": len(res), "r_max": float(max(res["r_rel"])),
            "n_impacts": int(res["n_impacts"][-1]), "E_diss": float(res["E_diss"][-1]),
            "mode_end": int(res["mode"][-1]),
            "finite": bool(all(math.isfinite(v) for v in res["r_rel"]))}


def sc_match_core(fmu: str, params: dict, n: int, h: float, t_off: float | None = None,
                  Omega: float = 184.2) -> dict[str, Any]:
    inst = Instance(fmu)
    inst.init({**params, "Omega": Omega})
    inputs = _amb_switch(t_off) if t_off is not None else None
    fmu_rows = _run(inst, n, h, inputs)
    import rotortd  # the module the FMU loaded (shared sys.modules)

    core_rows = _run_core(rotortd, params, n, h, Omega, t_off)
    mismatches = [(i, k, fmu_rows[i][k], core_rows[i][k]) for i in range(n)
                  for k in core_rows[i] if fmu_rows[i][k] != core_rows[i][k]]
    return {"mismatches": mismatches[:10], "n_mismatch": len(mismatches),
            "n_impacts": fmu_rows[-1]["n_impacts"], "core_file": rotortd.__file__,
            "modes": sorted({r["mode"] for r in fmu_rows})}


def _run_core(rotortd: Any, params: dict, n: int, h: float, Omega: float,
              t_off: float | None) -> list[dict[str, Any]]:
    names = ("m", "c", "k", "e_c", "phi", "c_r", "R", "mu", "d", "g")
    p = rotortd.RotorParams(**{k: float(v) for k, v in params.items() if k in names},
                            levitate=bool(params.get("levitate", True)))
    z0 = complex(params.get("x0", 0.0), params.get("y0", 0.0))
    v0 = complex(params.get("vx0", 0.0), params.get("vy0", 0.0))
    core = rotortd.TouchdownCore(p, z0=z0, v0=v0, psi0=float(params.get("psi0", 0.0)), t0=0.0)
    rows, t = [], 0.0
    for _ in range(n):
        amb = 0.0 if (t_off is not None and t >= t_off - 1e-12) else 1.0
        rep = core.step(h, Omega, F_ext=0j, amb_on=amb)
        t += h
        kin = core.kinematics(Omega, amb_on=amb)
        row = {k: float(getattr(kin, k)) for k in REAL_OUT if hasattr(kin, k)}
        row.update(psi=float(kin.psi_wrapped), F_bx=rep.F_contact.real,
                   F_by=rep.F_contact.imag, F_n=rep.F_n, F_n_peak=rep.F_n_peak, P_n=rep.P_n,
                   T_f=rep.T_f, T_imb=rep.T_imb, t_last_impact=float(core.t_last_impact),
                   v_last_impact=float(core.v_last_impact), E_diss=float(core.E_diss),
                   mode=int(core.mode), n_impacts=int(core.n_impacts),
                   n_impacts_step=len(rep.impacts))
        rows.append(row)
    return rows


def sc_step_independence(fmu: str, params: dict, T: float, n: int) -> dict[str, Any]:
    one, many = Instance(fmu, "one"), Instance(fmu, "many", unzipdir=None)
    one.init(params)
    many.init(params)
    if one.step(T) != 0:
        raise RuntimeError(f"single step failed: {MESSAGES}")
    for i in range(n):
        many.t = T * i / n
        if many.step(T / n) != 0:
            raise RuntimeError(f"step {i} failed: {MESSAGES}")
    a, b = one.outputs(), many.outputs()
    return {"one": a, "many": b}


def sc_state_roundtrip(fmu: str, params: dict, n1: int, n2: int, h: float,
                       t_off: float) -> dict[str, Any]:
    inputs = _amb_switch(t_off)
    inst = Instance(fmu, "orig")
    inst.init(params)
    _run(inst, n1, h, inputs)
    t_saved = inst.t
    n_at_save = inst.outputs()["n_impacts"]
    state = inst.slave.getFMUstate()
    blob = bytes(inst.slave.serializeFMUstate(state))
    run_a = _run(inst, n2, h, inputs)
    inst.slave.setFMUstate(state)
    inst.t = t_saved
    run_b = _run(inst, n2, h, inputs)
    inst.slave.freeFMUstate(state)
    run_c = _run_restored(fmu, "fresh", blob, t_saved, n2, h, inputs)
    doc = json.loads(blob.decode())
    return {"same_get_set": run_a == run_b, "same_serialized": run_a == run_c,
            "n_impacts": [run_a[-1]["n_impacts"], run_c[-1]["n_impacts"]],
            "n_impacts_at_save": n_at_save,
            "schema": doc.get("schema"), "version": doc.get("version"),
            "has_core": isinstance(doc.get("core"), dict),
            "core_schema": (doc.get("core") or {}).get("schema"),
            "modes": sorted({r["mode"] for r in run_a})}


def sc_old_state(fmu: str, blob_path: str, params: dict, n1: int, n2: int, h: float,
                 t_off: float) -> dict[str, Any]:
    """A serialised state saved by an older build after the recipe (params, n1 steps of h,
    AMB off at t_off), restored into a fresh instance of this FMU: does it continue as this
    FMU continues from the same recipe, every output of n2 steps?"""
    inputs = _amb_switch(t_off)
    inst = Instance(fmu, "live")
    inst.init(params)
    _run(inst, n1, h, inputs)
    t_saved = inst.t
    live_doc = json.loads(bytes(inst.slave.serializeFMUstate(inst.slave.getFMUstate())))
    run_a = _run(inst, n2, h, inputs)
    with open(blob_path, "rb") as fh:
        blob = fh.read()
    run_c = _run_restored(fmu, "old", blob, t_saved, n2, h, inputs)
    doc = json.loads(blob.decode())
    check = Instance(fmu, "check")  # the old state restored, then saved again at once
    check.init({})
    state = check.slave.deSerializeFMUstate(blob)
    check.slave.setFMUstate(state)
    check.slave.freeFMUstate(state)
    again = json.loads(bytes(check.slave.serializeFMUstate(check.slave.getFMUstate())))
    from rotortd.step.state import CoreState  # the core's reading of the old core state

    return {"same": run_a == run_c, "old_core_version": doc["core"]["version"],
            "live_core_version": live_doc["core"]["version"],
            "restored_core": again["core"],
            "old_core_read": CoreState.from_json(doc["core"]).to_json(),
            "modes": sorted({r["mode"] for r in run_a}),
            "restored_modes": sorted({r["mode"] for r in run_c}), "messages": MESSAGES}


def sc_amb_drop(fmu: str, n: int, h: float, t_off: float, g: float = 9.81) -> dict[str, Any]:
    inst = Instance(fmu)
    inst.init({"g": g})
    rows = _run(inst, n, h, _amb_switch(t_off))
    return {"t_end": inst.t, "any_contact": any(r["in_contact"] for r in rows),
            "n_impacts": rows[-1]["n_impacts"], "r_max": max(r["r_rel"] for r in rows),
            "final": rows[-1]}


def sc_bad_values(fmu: str, params: dict, inputs: dict | None = None,
                  after_init: dict | None = None) -> dict[str, Any]:
    inst = Instance(fmu)
    inst.init(params)
    if inputs:
        inst.set(inputs)
    statuses = [inst.step(1e-4)]
    if after_init:
        inst.set(after_init)
        statuses.append(inst.step(1e-4))
    return {"statuses": statuses, "messages": [m["message"] for m in MESSAGES],
            "levels": [m["status"] for m in MESSAGES]}


def sc_tunable(fmu: str, changes: dict, n: int = 20) -> dict[str, Any]:
    inst = Instance(fmu)
    inst.init({"g": 9.81})
    _run(inst, n, 1e-4)
    inst.set(changes)
    status = inst.step(1e-4)
    return {"status": status, "messages": [m["message"] for m in MESSAGES]}


def sc_multi_instance(fmu: str, n: int, h: float) -> dict[str, Any]:
    a, b = Instance(fmu, "a"), Instance(fmu, "b")
    a.init({})
    b.init({"g": 9.81, "c": 700.0})
    rows_a, rows_b = [], []
    for _ in range(n):
        rows_a += _run(a, 1, h)
        rows_b += _run(b, 1, h, lambda t: {"amb_on": 0.0})
    a.free()
    b.free()
    alone = Instance(fmu, "alone")
    alone.init({})
    ref_a = _run(alone, n, h)
    return {"a_equals_alone": rows_a == ref_a, "differ": rows_a[-1] != rows_b[-1]}


def sc_cycles(fmu: str, n_cycles: int, steps: int) -> dict[str, Any]:
    unzipdir = extract(fmu)
    finals = []
    for i in range(n_cycles):
        inst = Instance(fmu, f"cycle{i}", unzipdir=unzipdir)
        gc.collect()  # PythonFMU keeps the script's namespace alive only through its functions
        inst.init({})
        gc.collect()
        finals.append(_run(inst, steps, 1e-4)[-1]["x"])
        inst.free()
        gc.collect()
    shutil.rmtree(unzipdir, ignore_errors=True)
    return {"cycles": len(finals), "all_equal": len(set(finals)) == 1}


def sc_impact_log(fmu: str, n: int, h: float, t_off: float) -> dict[str, Any]:
    path = os.path.join(tempfile.mkdtemp(prefix="rotortd_log_"), "impacts.csv")
    inst = Instance(fmu)
    inst.init({"g": 9.81, "impact_log": path})
    rows = _run(inst, n, h, _amb_switch(t_off))
    text = Path(path).read_text(encoding="utf-8") if os.path.exists(path) else ""
    return {"n_impacts": rows[-1]["n_impacts"], "csv": text}


def sc_bad_state(fmu: str, blob: str) -> dict[str, Any]:
    inst = Instance(fmu)
    inst.init({})
    _run(inst, 5, 1e-4)
    state = inst.slave.deSerializeFMUstate(blob.encode())
    inst.slave.setFMUstate(state)
    inst.slave.freeFMUstate(state)
    return {"status": inst.step(1e-4), "messages": [m["message"] for m in MESSAGES]}


def sc_ranges(fmu: str, cases: dict[str, list[float]]) -> dict[str, Any]:
    """For each variable: statuses of init + one step with a value inside its range, and
    the error messages with a value outside (a parameter at init, an input mid-run)."""
    results = {}
    unzipdir = extract(fmu)
    for name, (inside, outside) in cases.items():
        inst = Instance(fmu, unzipdir=unzipdir)
        is_input = next(v.causality for v in inst.md.modelVariables if v.name == name) == "input"
        MESSAGES.clear()
        inst.init({name: inside})
        ok = [max((m["status"] for m in MESSAGES), default=0), inst.step(1e-4)]
        bad = Instance(fmu, unzipdir=unzipdir)
        MESSAGES.clear()
        bad.init({} if is_input else {name: outside})
        if is_input:
            bad.step(1e-4)
            bad.set({name: outside})
        bad.step(1e-4)
        results[name] = (ok, [m["message"] for m in MESSAGES if m["status"] >= 3])
    return {"results": results}


BEARING_OUT = ("omega_b", "x_b", "y_b", "vx_b", "vy_b", "F_sx", "F_sy", "P_fric", "E_fric",
               "E_drag", "Omega_out", "r_rel", "whirl_rate", "v_rel", "x", "y", "F_n_peak",
               "F_bx", "F_by", "E_diss")


def sc_bearing_match_core(fmu: str, bearing: dict, n: int, h: float) -> dict[str, Any]:
    """The drop onto the real bearing (docs/model.md §10): the FMU's outputs against the
    core's own (rotortd.SpinCore with the same BearingParams), every step, bit for bit."""
    import cmath

    import rotortd  # the module the FMU loaded (shared sys.modules)

    p = rotortd.RotorParams(g=9.81, d=0.9, mu=0.15)
    W = 184.2
    Z1 = p.m * p.e_c * W**2 * cmath.exp(1j * p.phi) / (p.k - p.m * W**2 + 1j * p.c * W)
    V1 = 1j * W * Z1
    inst = Instance(fmu)
    inst.init({"g": 9.81, "d": 0.9, "mu": 0.15, "J": 0.04, "integrate_spin": True,
               "Omega": W, "amb_on": 0.0, "x0": Z1.real, "y0": Z1.imag, "vx0": V1.real,
               "vy0": V1.imag, **bearing})
    core = rotortd.SpinCore(p, 0.04, z0=Z1, v0=V1, Omega0=W,
                            bearing=rotortd.BearingParams(**bearing))
    mismatches = []
    E_fric = 0.0
    for i in range(n):
        status = inst.step(h)
        rep = core.step(h, F_ext=0j, amb_on=0.0, T_drive=0.0)
        race = core.race
        kin = core.outputs()
        want = {"omega_b": race.omega_b, "x_b": race.z_b.real, "y_b": race.z_b.imag,
                "vx_b": race.v_b.real, "vy_b": race.v_b.imag, "F_sx": rep.F_support.real,
                "F_sy": rep.F_support.imag, "P_fric": rep.P_fric, "E_fric": race.E_fric,
                "E_drag": race.E_drag, "Omega_out": core.Omega, "r_rel": kin.r_rel,
                "whirl_rate": kin.whirl_rate, "v_rel": kin.v_rel, "x": kin.x, "y": kin.y,
                "F_n_peak": rep.F_n_peak, "F_bx": rep.F_contact.real,
                "F_by": rep.F_contact.imag, "E_diss": core.E_diss}
        got = dict(zip(BEARING_OUT, inst.slave.getReal([inst.vr[k] for k in BEARING_OUT]),
                       strict=True))
        E_fric = got["E_fric"]
        mismatches += [(i, k, got[k], want[k]) for k in BEARING_OUT if got[k] != want[k]]
        if status != 0:
            mismatches.append((i, "status", status, 0))
            break
    return {"mismatches": mismatches[:10], "n_mismatch": len(mismatches), "E_fric": E_fric,
            "omega_b": core.race.omega_b}


SCENARIOS: dict[str, Callable[..., dict[str, Any]]] = {
    name[3:]: fn for name, fn in globals().items() if name.startswith("sc_")
}


def main() -> None:
    name, fmu = sys.argv[1], sys.argv[2]
    kwargs = json.loads(sys.argv[3]) if len(sys.argv) > 3 else {}
    try:
        result = {"ok": True, **SCENARIOS[name](fmu, **kwargs)}
    except Exception as exc:  # report, do not crash
        result = {"ok": False, "error": f"{type(exc).__name__}: {exc}", "messages": MESSAGES}
    print("RESULT:" + json.dumps(result), flush=True)
    sys.stderr.flush()
    os._exit(0)


if __name__ == "__main__":
    main()
