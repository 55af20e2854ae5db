"""The error guard of the adapters (fmu_src/rotortd_fmi/guard.py): its abstract hooks, the
first error of an instance as one line on stderr, and a work-bound stop that reaches the
user of ``fmpy simulate`` (one line naming the time and the bound) while the instance stays
usable."""

from __future__ import annotations

import re
import subprocess
import sys
import types
from pathlib import Path
from typing import Any

import pytest
from pythonfmu.enums import Fmi2Status
from rotortd_fmi import guard
from rotortd_fmi.events import TouchdownEventsAdapter
from rotortd_fmi.guard import GuardedSlave

ROOT = Path(__file__).resolve().parent.parent


def test_abstract_hooks_are_methods_of_the_guard() -> None:
    """_initialise and _step are GuardedSlave's own methods and raise NotImplementedError
    (they were once indented under the module function _stderr_line: dead code)."""
    for name, args in (("_initialise", ()), ("_step", (0.0, 1e-4))):
        assert name in vars(GuardedSlave), name
        with pytest.raises(NotImplementedError):
            getattr(GuardedSlave, name)(object(), *args)
    nested = [c for c in guard._stderr_line.__code__.co_consts if isinstance(c, types.CodeType)]
    assert nested == []


class _Steps(GuardedSlave):
    """A guarded slave whose step reports an error without failing (as a work-bound stop)
    or raises (a failure), as told."""

    mode = "error"

    def _initialise(self) -> None:
        pass

    def _step(self, current_time: float, step_size: float) -> bool:
        if self.mode == "raise":
            raise ValueError("boom")
        self._error(f"stopped at t = {current_time!r} s")
        return False


def _errors(slave: Any) -> list[str]:
    return [m.msg for m in slave.log_queue if m.status == Fmi2Status.error]


def test_error_is_logged_and_first_one_on_stderr_without_failing(
        capsys: pytest.CaptureFixture[str]) -> None:
    slave = _Steps(instance_name="g")
    assert slave.exit_initialization_mode()
    assert slave.do_step(0.0, 1e-4) is False
    assert slave._failure == ""  # still usable: the next step runs again
    assert slave.do_step(0.0, 1e-4) is False
    assert _errors(slave) == ["stopped at t = 0.0 s"] * 2
    assert capsys.readouterr().err == "g: error: stopped at t = 0.0 s\n"
    slave.mode = "raise"  # a failure after an error: logged, no second stderr line
    assert slave.do_step(0.0, 1e-4) is False
    assert slave._failure.endswith("failed: boom")
    assert capsys.readouterr().err == ""
    assert slave.do_step(0.0, 1e-4) is False
    assert _errors(slave)[-1] == "do_step refused, model unusable: " + slave._failure


def test_failure_first_is_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    slave = _Steps(instance_name="h")
    slave.mode = "raise"
    slave.exit_initialization_mode()
    slave.do_step(0.0, 1e-4)
    slave.do_step(1e-4, 1e-4)
    assert capsys.readouterr().err == "h: error: do_step at t=0.0, h=0.0001 failed: boom\n"


def test_terminated_step_is_an_error_on_stderr(capsys: pytest.CaptureFixture[str]) -> None:
    slave = _Steps(instance_name="t")
    slave.exit_initialization_mode()
    slave.terminate()
    assert slave.do_step(0.0, 1e-4) is False
    assert capsys.readouterr().err == ("t: error: do_step at t=0.0 refused: called after "
                                       "fmi2Terminate\n")


def test_event_source_output_set_reaches_stderr(capsys: pytest.CaptureFixture[str]) -> None:
    """TouchdownEvents is not guarded, but its errors reach stderr the same way."""
    slave = TouchdownEventsAdapter(instance_name="ev")
    var = next(v for v in slave.vars.values() if v.name == "amb_on")
    var.setter(0.5)
    var.setter(0.5)
    assert _errors(slave) == ["output 'amb_on' cannot be set by the host"] * 2
    assert capsys.readouterr().err == "ev: error: output 'amb_on' cannot be set by the host\n"


def test_work_bound_stop_reaches_stderr_in_fmpy_simulate(fmu_path: Path,
                                                         tmp_path: Path) -> None:
    """The scene of issue 25: one long step with integrate_spin, the rotor dropped into
    rolling (100 s with a drive torque of 0.01 N m: since the dry-whirl accelerator a 10 s
    step fits the work bound, and without a drive a step of any length on the orbit of
    segments.dry_whirl_orbit costs the same). FMPy still exits 0 with a truncated result
    (its own behaviour), but stderr now has exactly one line naming the instance, the time
    reached and the work bound."""
    out = tmp_path / "wb.csv"
    proc = subprocess.run(
        [sys.executable, "-m", "fmpy", "simulate", str(fmu_path), "--start-values",
         "integrate_spin", "true", "amb_on", "0", "g", "9.81", "T_drive", "0.01",
         "--stop-time", "100",
         "--output-interval", "100", "--output-file", str(out)],
        capture_output=True, text=True, timeout=300, cwd=str(tmp_path))
    assert proc.returncode == 0, proc.stderr[-2000:]
    lines = proc.stderr.splitlines()
    assert len(lines) == 1, proc.stderr[-3000:]
    m = re.fullmatch(r"RotorTouchdown: error: step incomplete: core status 1 \(work bound "
                     r"reached: \d+ > 1600000 work units; the core stopped at t = (\S+) s.*"
                     r"model time stays at t=(\S+) instead of 100\.0", lines[0])
    assert m, lines[0]
    assert 0.0 < float(m.group(1)) == float(m.group(2)) < 100.0


def test_drivetrain_failure_reaches_stderr(capsys: pytest.CaptureFixture[str]) -> None:
    """The Drivetrain adapter shares the guard: a bad parameter is one line on stderr."""
    from Drivetrain import Drivetrain

    slave = Drivetrain(instance_name="drive")
    slave.J = -1.0
    slave.setup_experiment(0.0, None, None)
    slave.enter_initialization_mode()
    assert slave.exit_initialization_mode() is False
    assert slave.do_step(0.0, 1e-3) is False
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith("drive: error: initialisation failed: ")
    assert "J" in err[0]


def test_drivetrain_state_that_cannot_be_captured_fails_on_restore(
        capsys: pytest.CaptureFixture[str]) -> None:
    """A Drivetrain state whose capture raises is logged and marked invalid; restoring it
    fails the instance (the next step is refused) instead of restoring part of it."""
    from Drivetrain import Drivetrain

    slave = Drivetrain(instance_name="drive")
    slave.setup_experiment(0.0, None, None)
    slave.enter_initialization_mode()
    assert slave.exit_initialization_mode() is not False
    assert slave.do_step(0.0, 1e-3) is not False

    class Broken:
        def __getattr__(self, name: str) -> Any:
            raise RuntimeError("no state here")

    good = slave._get_fmu_state()
    core, slave._core = slave._core, Broken()
    bad = slave._get_fmu_state()
    slave._core = core
    assert bad.get("invalid") == "no state here" and "variables" not in bad
    slave._set_fmu_state(bad)
    assert slave.do_step(1e-3, 1e-3) is False
    err = capsys.readouterr().err.splitlines()
    assert err[0] == "drive: error: getFMUstate failed: no state here", err
    slave._set_fmu_state(good)
    assert "invalid" not in good and good["core"] is not None
