"""The misuse table of the FMU RotorTouchdown: each invalid parameter and input, each
forbidden call order and each corrupt state, with the status the FMU returns and its message.

    python tests/fmu_misuse.py FMU_PATH            # prints RESULT:<json rows>
    python tests/fmu_misuse.py FMU_PATH --docs     # also rewrites the table in docs/fmu.md

``tests/test_fmu_misuse.py`` runs it in a subprocess and pins every row to ``CASES``; the
table in docs/fmu.md ("Misuse and edge cases") is rendered from the same rows.

PythonFMU 0.7.0 can return OK or, only through its unsafe exception path, Fatal from every
call but doStep, which can also return Discard (read in its C++ source,
``PySlaveInstance.cpp``: ``ExitInitializationMode``, ``SetReal``, ``SetFMUstate`` ignore the
Python return value; ``Step`` maps False to Discard). So a misuse that FMI answers with
fmi2Error is answered with OK plus a logged error, a line on stderr, and the instance failed:
the next doStep returns Discard with the message.
"""

from __future__ import annotations

import json
import math
import os
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from fmu_scenarios import MESSAGES, Instance

OK, DISCARD = 0, 2
NAMES = {0: "OK", 1: "Warning", 2: "Discard", 3: "Error", 4: "Fatal", None: "-"}


def _call(fn: Callable[[], Any]) -> int:
    """Status of an FMI call made through FMPy (which raises on non-OK)."""
    from fmpy.fmi1 import FMICallException
    from fmu_scenarios import _status_of

    try:
        fn()
    except FMICallException as exc:
        return _status_of(exc)
    return OK


def _init_case(params: dict[str, Any]) -> tuple[int, int]:
    inst = Instance(FMU)
    inst.slave.setupExperiment(startTime=0.0)
    inst.slave.enterInitializationMode()
    inst.set(params)
    return _call(inst.slave.exitInitializationMode), inst.step(1e-4)


def _running(params: dict[str, Any] | None = None) -> Instance:
    inst = Instance(FMU)
    inst.init(params or {})
    assert inst.step(1e-4) == OK
    return inst


def _input_case(values: dict[str, Any]) -> tuple[int, int]:
    inst = _running()
    return _call(lambda: inst.set(values)), inst.step(1e-4)


def _step_case(t_offset: float, h: float) -> tuple[int, int]:
    inst = _running()
    status = _call(lambda: inst.slave.doStep(inst.t + t_offset, h))
    return status, None if status == OK else inst.step(1e-4)


def _after_terminate() -> tuple[int, int]:
    inst = _running()
    inst.slave.terminate()
    return _call(lambda: inst.slave.doStep(inst.t, 1e-4)), None


def _before_init() -> tuple[int, int]:
    inst = Instance(FMU)
    inst.slave.setupExperiment(startTime=0.0)
    inst.slave.enterInitializationMode()
    return _call(lambda: inst.slave.doStep(0.0, 1e-4)), None


def _set_output() -> tuple[int, int]:
    inst = _running()
    return _call(lambda: inst.slave.setReal([inst.vr["x"]], [1.0])), inst.step(1e-4)


def _state_case(blob: bytes) -> tuple[int, int]:
    inst = _running()
    holder: list[Any] = []
    status = _call(lambda: holder.append(inst.slave.deSerializeFMUstate(blob)))
    if status == OK:
        status = max(status, _call(lambda: inst.slave.setFMUstate(holder[0])))
    return status, inst.step(1e-4)


def _state_missing_key() -> tuple[int, int]:
    inst = _running()
    state = inst.slave.getFMUstate()
    doc = json.loads(bytes(inst.slave.serializeFMUstate(state)).decode())
    del doc["core"]["counters"]["E_diss"]
    return _state_case(json.dumps(doc).encode())


def _state_restores_after_bad_one() -> tuple[int, int]:
    """A good state set after a corrupt one makes the instance usable again."""
    inst = _running()
    good = inst.slave.getFMUstate()
    bad = inst.slave.deSerializeFMUstate(b"not json")
    inst.slave.setFMUstate(bad)
    MESSAGES.clear()  # the bad state's own error is the row above
    return _call(lambda: inst.slave.setFMUstate(good)), inst.step(1e-4)


BAD_LOG = os.path.join(tempfile.gettempdir(), "no-such-dir-rotortd", "impacts.csv")
ON_WALL = 0.7e-3 * (1.0 + 2.0 ** -51)  # 2 ulp of c_r outside: projected, accepted

# id: (what, run, (status of the call, status of the next doStep), words of the message,
#      what FMI asks for)
CASES: dict[str, tuple[str, Callable[[], tuple[int, int]], tuple[int, int | None], str, str]] = {
    "param_below_min": ("parameter below its min (`m = -1`)",
                        lambda: _init_case({"m": -1.0}), (OK, DISCARD),
                        "m = -1.0 kg is out of range: it must lie in [0.001, 1e+06] kg",
                        "Error"),
    "param_above_max": ("parameter above its max (`c_r = 1`)",
                        lambda: _init_case({"c_r": 1.0}), (OK, DISCARD),
                        "c_r = 1.0 m is out of range", "Error"),
    "param_nan": ("parameter NaN (`k = NaN`)", lambda: _init_case({"k": math.nan}),
                  (OK, DISCARD), "k = nan N/m is not finite", "Error"),
    "params_several": ("several bad parameters at once (`g = -9.81`, `d = 2`, `mu = -1`)",
                       lambda: _init_case({"g": -9.81, "d": 2.0, "mu": -1.0}), (OK, DISCARD),
                       "mu = -1.0 is out of range: it must lie in [0, 10]; d = 2.0 is out of "
                       "range: it must lie in [0, 1]; g = -9.81 m/s2 is out of range", "Error"),
    "start_outside": ("start outside the clearance (`x0 = 1e-3 > c_r`)",
                      lambda: _init_case({"x0": 1e-3}), (OK, DISCARD),
                      "cross-parameter constraint: initial position", "Error"),
    "start_ulps_outside": ("start 2 ulp outside the clearance (`x0 = c_r (1 + 2^-51)`)",
                           lambda: _init_case({"x0": ON_WALL}), (OK, OK), "", "OK"),
    "steady_not_admissible": ("`start_steady` with an inadmissible whirl (`c = 460`)",
                              lambda: _init_case({"start_steady": True, "c": 460.0}),
                              (OK, DISCARD), "cross-parameter constraint: start_steady",
                              "Error"),
    "bearing_held_spin": ("a real bearing's option without `integrate_spin` "
                          "(`race_turns = true`)",
                          lambda: _init_case({"race_turns": True}), (OK, DISCARD),
                          "cross-parameter constraint: race_turns, support_compliant and "
                          "contact_compliant need integrate_spin = true", "Error"),
    "bearing_plastic_compliant": ("a compliant contact with `d = 0` "
                                  "(`contact_compliant = true`, `integrate_spin = true`)",
                                  lambda: _init_case({"contact_compliant": True, "d": 0.0,
                                                      "integrate_spin": True}),
                                  (OK, DISCARD),
                                  "cross-parameter constraint: d = 0.0 is refused under the "
                                  "compliant contact law", "Error"),
    "impact_log_unwritable": ("`impact_log` in a missing directory",
                              lambda: _init_case({"impact_log": BAD_LOG}), (OK, DISCARD),
                              "impact_log = ", "Error"),
    "input_nan": ("input NaN mid-run (`Omega = NaN`)",
                  lambda: _input_case({"Omega": math.nan}), (OK, DISCARD),
                  "Omega = nan rad/s is not finite", "Error"),
    "input_above_max": ("input above its max (`F_x = 2e12`)",
                        lambda: _input_case({"F_x": 2e12}), (OK, DISCARD),
                        "F_x = 2000000000000.0 N is out of range", "Error"),
    "fixed_changed": ("fixed parameter set mid-run (`m = 60`)",
                      lambda: _input_case({"m": 60.0}), (OK, DISCARD),
                      "parameter 'm' is fixed", "Error"),
    "tunable_out_of_range": ("tunable set out of range mid-run (`d = 2`)",
                             lambda: _input_case({"d": 2.0}), (OK, DISCARD),
                             "d = 2.0 is out of range", "Error"),
    "set_output": ("`fmi2SetReal` on an output (`x`)", _set_output, (OK, DISCARD),
                   "output 'x' cannot be set by the host", "Error"),
    "step_nan_time": ("`fmi2DoStep` at a NaN communication point",
                      lambda: _step_case(math.nan, 1e-4), (DISCARD, DISCARD),
                      "communication point nan does not match", "Error"),
    "step_skipped_time": ("`fmi2DoStep` at a communication point 1 s ahead",
                          lambda: _step_case(1.0, 1e-4), (DISCARD, DISCARD),
                          "does not match the model time", "Error"),
    "step_zero": ("`fmi2DoStep` with h = 0", lambda: _step_case(0.0, 0.0),
                  (DISCARD, DISCARD), "communication step size 0.0 s must be finite and > 0",
                  "Error"),
    "step_inf": ("`fmi2DoStep` with h = inf", lambda: _step_case(0.0, math.inf),
                 (DISCARD, DISCARD), "communication step size inf s", "Error"),
    "step_before_init": ("`fmi2DoStep` in initialisation mode", _before_init,
                         (DISCARD, None), "do_step before exitInitializationMode", "Error"),
    "step_after_terminate": ("`fmi2DoStep` after `fmi2Terminate`", _after_terminate,
                             (DISCARD, None), "called after fmi2Terminate", "Error"),
    "state_bytes_corrupt": ("`fmi2DeSerializeFMUstate` of corrupt bytes, then "
                            "`fmi2SetFMUstate`", lambda: _state_case(b"\x00garbage"),
                            (OK, DISCARD), "setFMUstate failed: the saved state is invalid",
                            "Error"),
    "state_foreign": ("`fmi2SetFMUstate` of another model's state",
                      lambda: _state_case(b'{"schema": "other"}'), (OK, DISCARD),
                      "setFMUstate failed: not a rotortd FMU state", "Error"),
    "state_missing_key": ("`fmi2SetFMUstate` of a state missing a key (`E_diss`)",
                          _state_missing_key, (OK, DISCARD),
                          "the state is incomplete, key 'E_diss' is missing", "Error"),
    "state_good_after_bad": ("a valid `fmi2SetFMUstate` after a corrupt one",
                             _state_restores_after_bad_one, (OK, OK), "", "OK"),
}

FMU = ""


def run_cases() -> list[dict[str, Any]]:
    rows = []
    for case_id, (_what, fn, _expected, _words, _fmi) in CASES.items():
        MESSAGES.clear()
        call, nxt = fn()
        errors = [m["message"] for m in MESSAGES if m["status"] >= 3]
        rows.append({"id": case_id, "call": call, "next": nxt,
                     "message": errors[0] if errors else ""})
    return rows


def render(rows: list[dict[str, Any]]) -> str:
    """The markdown table of docs/fmu.md."""
    lines = ["| misuse | FMI asks | the call returns | next doStep | message (logged, and the "
             "first one on stderr) |", "|---|---|---|---|---|"]
    for row in rows:
        what, _fn, _exp, _words, fmi = CASES[row["id"]]
        msg = row["message"].replace("|", "\\|")
        if len(msg) > 160:
            msg = msg[:157] + "..."
        lines.append(f"| {what} | {fmi} | {NAMES[row['call']]} | {NAMES[row['next']]} | "
                     f"{msg or '-'} |")
    return "\n".join(lines)


def main() -> None:
    global FMU
    FMU = sys.argv[1]
    rows = run_cases()
    if "--docs" in sys.argv:
        root = Path(__file__).resolve().parent.parent
        sys.path.insert(0, str(root / "docs" / "scripts"))
        from mdblock import replace_block

        replace_block(root / "docs" / "fmu.md", "misuse", render(rows))
    print("RESULT:" + json.dumps(rows), flush=True)
    sys.stderr.flush()
    os._exit(0)


if __name__ == "__main__":
    main()
