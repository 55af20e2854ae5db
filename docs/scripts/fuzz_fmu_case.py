"""Run fuzz cases against the RotorTouchdown FMU in this process (the child side of
docs/scripts/fuzz_fmu.py).

    python docs/scripts/fuzz_fmu_case.py UNZIPDIR STEP_LIMIT ABANDON < cases.json

Reads a JSON list of case specs on stdin, runs them one after the other through FMPy's
low-level API (``FMU2Slave``, logging on, a logger callback that keeps every message, raw
``fmi2DoStep`` statuses) and prints one line ``CASE <json>`` per case. A watchdog thread
abandons a doStep still running after ABANDON seconds: it prints the case's partial result
(``abandoned``) and leaves with exit code HUNG_RC. The process ends with ``os._exit`` so
that PythonFMU's teardown at interpreter exit cannot turn finished cases into a crash.

A case spec (made by fuzz_fmu.draw_case) is plain JSON:
  {"id": int, "params": {name: value}, "ops": [{"h": float, "set": {name: value}}, ...],
   "roundtrips": [[first_op, n_ops, serialize], ...]}
``{tmp}`` in a String parameter is replaced by a fresh temporary directory.
"""

from __future__ import annotations

import json
import math
import os
import struct
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from fmpy import read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
    fmi2True,
)

HUNG_RC = 3            # exit code of a process whose watchdog abandoned a doStep
MAX_MESSAGES = 40      # messages kept per case (the first ones, then the last ones)
MAX_MESSAGE_CHARS = 600
OK_STATUSES = (0, 1)   # fmi2OK, fmi2Warning: the step's outputs are valid
RADIUS_TOL = 1e-12     # |(x, y) - (x_b, y_b)| <= c_r (1 + RADIUS_TOL) after every OK step,
                       # unless contact_compliant (a compliant contact penetrates)


# ---------------------------------------------------------------------------- results
@dataclass
class CaseResult:
    """What one case did; ``as_json`` is the line sent to the parent."""

    id: int
    init_status: int | None = None
    statuses: list[int] = field(default_factory=list)   # raw doStep statuses, in order
    steps_done: int = 0                                  # op steps run (replays excluded)
    messages: list[list[Any]] = field(default_factory=list)  # [phase, status, text]
    n_messages: int = 0
    max_step_wall: float = 0.0
    max_step_cpu: float = 0.0                            # CPU seconds of the longest doStep
    slow_step: dict[str, Any] | None = None              # the first step over the limit
    nonfinite_ok: list[dict[str, Any]] = field(default_factory=list)
    max_excess: float = -math.inf                        # max |(x, y)|/c_r - 1 after OK
    outside: dict[str, Any] | None = None                # first |z| > c_r (1 + 1e-12)
    refusal: dict[str, Any] | None = None                # {"phase", "status", "messages"}
    roundtrips: int = 0
    mismatch: list[dict[str, Any]] = field(default_factory=list)
    api_errors: list[str] = field(default_factory=list)  # non-OK state/get/set calls
    abandoned: dict[str, Any] | None = None
    wall: float = 0.0

    def as_json(self) -> str:
        data = dict(self.__dict__)
        if not math.isfinite(data["max_excess"]):
            data["max_excess"] = None
        return json.dumps(data, allow_nan=True)


# ---------------------------------------------------------------------------- the FMU
@dataclass(frozen=True)
class Layout:
    """Value references and types the runner needs, read from the model description."""

    vr: dict[str, int]
    types: dict[str, str]
    real_out: tuple[str, ...]
    int_out: tuple[str, ...]
    bool_out: tuple[str, ...]
    guid: str
    model_identifier: str
    starts: dict[str, Any]


def read_layout(unzipdir: str) -> Layout:
    md = read_model_description(os.path.join(unzipdir, "modelDescription.xml"))
    outs = [v for v in md.modelVariables if v.causality == "output"]
    return Layout(
        vr={v.name: v.valueReference for v in md.modelVariables},
        types={v.name: v.type for v in md.modelVariables},
        real_out=tuple(v.name for v in outs if v.type == "Real"),
        int_out=tuple(v.name for v in outs if v.type in ("Integer", "Enumeration")),
        bool_out=tuple(v.name for v in outs if v.type == "Boolean"),
        guid=md.guid, model_identifier=md.coSimulation.modelIdentifier,
        starts={v.name: v.start for v in md.modelVariables})


def _status(call: Callable[[], Any]) -> int:
    """Run an FMPy call; return its FMI status (FMPy raises above fmi2Warning)."""
    try:
        call()
    except FMICallException as exc:
        return int(exc.status)
    return 0


class Host:
    """One FMU2Slave per process; each case instantiates and frees its own component."""

    def __init__(self, unzipdir: str) -> None:
        self.layout = read_layout(unzipdir)
        self.slave = FMU2Slave(guid=self.layout.guid, unzipDirectory=unzipdir,
                               modelIdentifier=self.layout.model_identifier,
                               instanceName="fuzz")
        self.log: list[tuple[int, str]] = []
        self.callbacks = self._callbacks()  # kept alive as long as the host

    def _callbacks(self) -> fmi2CallbackFunctions:
        from fmpy import calloc, free

        def logger(_env: Any, _inst: bytes, status: int, _cat: bytes, msg: bytes) -> None:
            self.log.append((int(status), msg.decode("utf-8", "replace")))

        cb = fmi2CallbackFunctions()
        cb.logger = fmi2CallbackLoggerTYPE(logger)
        cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        return cb

    def instantiate(self) -> None:
        self.log.clear()
        self.slave.instantiate(callbacks=self.callbacks, loggingOn=True)

    def free(self) -> None:
        _status(self.slave.terminate)
        self.slave.fmi2FreeInstance(self.slave.component)  # keeps the library loaded

    def set(self, values: dict[str, Any]) -> None:
        s, vr = self.slave, self.layout.vr
        for name, value in values.items():
            kind = self.layout.types[name]
            if kind == "Real":
                s.setReal([vr[name]], [float(value)])
            elif kind in ("Integer", "Enumeration"):
                s.setInteger([vr[name]], [int(value)])
            elif kind == "Boolean":
                s.setBoolean([vr[name]], [bool(value)])
            else:
                s.setString([vr[name]], [str(value)])

    def do_step(self, t: float, h: float) -> int:
        s = self.slave
        return _status(lambda: s.fmi2DoStep(s.component, t, h, fmi2True))

    def outputs(self) -> tuple[list[float], list[int], list[int]]:
        s, vr, lay = self.slave, self.layout.vr, self.layout
        return (s.getReal([vr[n] for n in lay.real_out]),
                s.getInteger([vr[n] for n in lay.int_out]) if lay.int_out else [],
                s.getBoolean([vr[n] for n in lay.bool_out]) if lay.bool_out else [])


# ---------------------------------------------------------------------------- watchdog
WALL_BACKSTOP = 4.0
"""A doStep is also abandoned after this many times the limit in wall time, whatever CPU it
used (a step that waits without computing)."""


class Watchdog:
    """Abandons a doStep that has used more than ``limit`` s of CPU, or WALL_BACKSTOP times
    that in wall time: ``on_hang`` reports, then the process exits with HUNG_RC (a running
    doStep cannot be interrupted safely). CPU time is the FMU's own work; the wall time of
    the same step on this kind of machine scatters by 1.7x between runs (3.3 to 5.7 s
    measured for one step), with the other processes of the machine."""

    def __init__(self, limit: float, on_hang: Callable[[float], None]) -> None:
        self.limit, self.on_hang = limit, on_hang
        self.started: float | None = None  # wall clock at the step's start
        self.cpu_started = 0.0  # process CPU time at the step's start
        threading.Thread(target=self._watch, daemon=True).start()

    def start(self) -> None:
        self.cpu_started = time.process_time()
        self.started = time.perf_counter()

    def _watch(self) -> None:
        while True:
            time.sleep(0.05)
            started = self.started
            if started is None:
                continue
            wall = time.perf_counter() - started
            if (time.process_time() - self.cpu_started > self.limit
                    or wall > WALL_BACKSTOP * self.limit):
                self.on_hang(wall)
                sys.stdout.flush()
                os._exit(HUNG_RC)


# ---------------------------------------------------------------------------- a case
def _bits(values: list[float]) -> list[str]:
    return [struct.pack("<d", v).hex() for v in values]


class CaseRun:
    """Executes one case spec on a Host and fills its CaseResult."""

    def __init__(self, host: Host, spec: dict[str, Any], step_limit: float,
                 watchdog: Watchdog) -> None:
        self.host, self.spec, self.step_limit, self.watchdog = host, spec, step_limit, watchdog
        self.res = CaseResult(id=int(spec["id"]))
        self.c_r = float(spec["params"].get("c_r", host.layout.starts.get("c_r") or "nan"))
        self.compliant = bool(spec["params"].get("contact_compliant", False))
        self.t = 0.0
        self.phase = "init"
        self.stop = False
        self.current: dict[str, Any] = {}
        self.t_start = time.perf_counter()

    # ------------------------------------------------------------ logging and checks
    def _take_messages(self) -> list[tuple[int, str]]:
        new = list(self.host.log)
        self.host.log.clear()
        self.res.n_messages += len(new)
        for status, text in new:
            if len(self.res.messages) < MAX_MESSAGES or status >= 2:
                self.res.messages.append([self.phase, status, text[:MAX_MESSAGE_CHARS]])
        return new

    def _refuse(self, status: int, new: list[tuple[int, str]]) -> None:
        errors = [text[:MAX_MESSAGE_CHARS] for st, text in new if st >= 2]
        self.res.refusal = {"phase": self.phase, "status": status, "messages": errors}
        self.stop = True

    def _check_outputs(self, reals: list[float]) -> None:
        names = self.host.layout.real_out
        bad = [n for n, v in zip(names, reals) if not math.isfinite(v)]
        if bad and len(self.res.nonfinite_ok) < 5:
            self.res.nonfinite_ok.append({"phase": self.phase, "t": self.t, "names": bad})
        out = dict(zip(names, reals))
        if self.compliant:  # a compliant contact penetrates: no clearance to keep
            return
        if "x" in out and "y" in out and self.c_r > 0.0:
            # from the race's centre (x_b, y_b: 0 unless its support is compliant)
            x_b, y_b = out.get("x_b", 0.0), out.get("y_b", 0.0)
            excess = math.hypot(out["x"] - x_b, out["y"] - y_b) / self.c_r - 1.0
            # (a race far off the origin rounds its clearance at eps |z_b|)
            excess -= 8.0 * 2.0 ** -52 * math.hypot(x_b, y_b) / self.c_r
            if excess > self.res.max_excess:
                self.res.max_excess = excess
            if excess > RADIUS_TOL and self.res.outside is None:
                self.res.outside = {"phase": self.phase, "t": self.t, "excess": excess}

    # ------------------------------------------------------------ phases
    def initialise(self) -> None:
        host, params = self.host, self.spec["params"]
        host.instantiate()
        _status(lambda: host.slave.setupExperiment(startTime=0.0))
        _status(host.slave.enterInitializationMode)
        host.set(params)
        st = _status(host.slave.exitInitializationMode)
        self.res.init_status = st
        new = self._take_messages()
        if st >= 2 or any(s >= 3 for s, _ in new):
            self._refuse(st, new)
            return
        self._check_outputs(host.outputs()[0])

    def step(self, index: int, op: dict[str, Any], replay: bool = False) -> tuple:
        """Set the op's values, do its step; returns (status, outputs as bit strings)."""
        self.phase = f"{'replay ' if replay else ''}step {index}"
        if op.get("set"):
            self.host.set(op["set"])
        h = float(op["h"])
        self.current = {"op": index, "t": self.t, "h": h, "replay": replay}
        self.watchdog.start()
        st = self.host.do_step(self.t, h)
        wall = time.perf_counter() - self.watchdog.started
        cpu = time.process_time() - self.watchdog.cpu_started
        self.watchdog.started = None
        self.res.statuses.append(st)
        self._note_time(index, h, wall, cpu)
        new = self._take_messages()
        if st not in OK_STATUSES:
            self._refuse(st, new)
            return st, None
        self.t += h
        reals, ints, bools = self.host.outputs()
        self._check_outputs(reals)
        return st, (_bits(reals), ints, bools)

    def _note_time(self, index: int, h: float, wall: float, cpu: float) -> None:
        """A step over the limit in CPU time (its own work) is slow; wall is recorded."""
        self.res.max_step_wall = max(self.res.max_step_wall, wall)
        self.res.max_step_cpu = max(self.res.max_step_cpu, cpu)
        if cpu > self.step_limit and self.res.slow_step is None:
            self.res.slow_step = {"op": index, "t": self.t, "h": h, "wall": wall, "cpu": cpu}
            self.stop = True  # the next steps would only cost more time

    # ------------------------------------------------------------ state round trips
    def _save(self, serialize: bool) -> Any:
        s = self.host.slave
        state = s.getFMUstate()
        if not serialize:
            return state
        data = s.serializeFMUstate(state)
        s.freeFMUstate(state)
        return s.deSerializeFMUstate(data)

    def roundtrip(self, first: int, ops: list[dict[str, Any]], serialize: bool) -> None:
        """Save, run ops, restore, run them again: statuses and outputs must agree bit for
        bit. Skipped (not compared) when the first pass ends with a refusal."""
        t_saved = self.t
        try:
            state = self._save(serialize)
        except FMICallException as exc:
            self.res.api_errors.append(f"save before op {first}: {exc}")
            self.stop = True
            return
        first_pass = self._run_ops(first, ops)
        if self.stop:
            return
        try:
            self.host.slave.setFMUstate(state)
            self.host.slave.freeFMUstate(state)
        except FMICallException as exc:
            self.res.api_errors.append(f"restore before op {first}: {exc}")
            self.stop = True
            return
        self.t = t_saved
        second = self._run_ops(first, ops, replay=True)
        self.res.roundtrips += 1
        for k, (a, b) in enumerate(zip(first_pass, second)):
            if a != b:
                self.res.mismatch.append({"op": first + k, "serialize": serialize,
                                          "first": a[0], "replay": b[0],
                                          "outputs": self._differing(a[1], b[1])})
                break

    def _differing(self, a: tuple | None, b: tuple | None) -> list[str]:
        """Names of the Real outputs that differ between two passes (all if one failed)."""
        names = self.host.layout.real_out
        if a is None or b is None:
            return list(names)
        return [n for n, x, y in zip(names, a[0], b[0]) if x != y] or ["(Integer/Boolean)"]

    def _run_ops(self, first: int, ops: list[dict[str, Any]], replay: bool = False) -> list:
        out = []
        for k, op in enumerate(ops):
            if self.stop:
                break
            out.append(self.step(first + k, op, replay))
            if not replay:
                self.res.steps_done += 1
        return out

    # ------------------------------------------------------------ the whole case
    def run(self) -> CaseResult:
        t0 = self.t_start = time.perf_counter()
        self.initialise()
        ops, windows = self.spec["ops"], {w[0]: w for w in self.spec.get("roundtrips", [])}
        i = 0
        while i < len(ops) and not self.stop:
            if i in windows:
                _first, n, serialize = windows[i]
                self.roundtrip(i, ops[i:i + n], bool(serialize))
                i += max(1, n)
            else:
                self._run_ops(i, [ops[i]])
                i += 1
        self.host.free()
        self._take_messages()
        self.res.wall = time.perf_counter() - t0
        return self.res


def _fill_tmp(spec: dict[str, Any], tmp: str) -> dict[str, Any]:
    params = {k: (v.replace("{tmp}", tmp) if isinstance(v, str) else v)
              for k, v in spec["params"].items()}
    return {**spec, "params": params}


def run_cases(unzipdir: str, specs: list[dict[str, Any]], step_limit: float,
              abandon: float, emit: Callable[[str], None]) -> None:
    """Run the specs in order; ``emit`` gets one ``CASE <json>`` line per case."""
    host = Host(unzipdir)
    current: list[CaseRun] = []

    def on_hang(elapsed: float) -> None:
        run = current[0]
        cpu = time.process_time() - watchdog.cpu_started
        run.res.abandoned = {**run.current, "wall": elapsed, "cpu": cpu}
        run.res.wall = time.perf_counter() - run.t_start
        run.res.max_step_wall = max(run.res.max_step_wall, elapsed)
        run.res.max_step_cpu = max(run.res.max_step_cpu, cpu)
        if run.res.slow_step is None:
            run.res.slow_step = {**run.current, "wall": elapsed}
        emit("CASE " + run.res.as_json())

    watchdog = Watchdog(abandon, on_hang)
    with tempfile.TemporaryDirectory(prefix="fuzz_fmu_") as tmp:
        for spec in specs:
            case_tmp = tempfile.mkdtemp(dir=tmp)
            run = CaseRun(host, _fill_tmp(spec, case_tmp), step_limit, watchdog)
            current[:] = [run]
            emit("CASE " + run.run().as_json())


def _emit(line: str) -> None:
    sys.stdout.write(line + "\n")
    sys.stdout.flush()


def main(argv: list[str]) -> None:
    unzipdir, step_limit, abandon = argv[0], float(argv[1]), float(argv[2])
    specs = json.loads(sys.stdin.read())
    run_cases(unzipdir, specs, step_limit, abandon, _emit)
    sys.stdout.flush()
    os._exit(0)


if __name__ == "__main__":
    main(sys.argv[1:])
