"""The error guard of the project's stateful adapters (RotorTouchdown, Drivetrain).

No exception may escape into PythonFMU's C wrapper (its fatal path). An adapter derives from
``GuardedSlave`` and implements ``_initialise()`` and ``_step(t, h) -> bool``; a failure is
logged with ``Fmi2Status.error``, the call returns False (fmi2Discard), and every later
``do_step`` is refused with the first failure's message. Standard library and pythonfmu only.

An error that leaves the instance usable (a step stopped at the work bound: the next step
goes on from where it stopped) is reported with ``_error``, which does not fail it.

PythonFMU 0.7.0 forwards log messages only when the host turned logging on, so the first
error of an instance, of either kind, is also written as one line on stderr
(``<instance>: error: <message>``): a user of ``fmpy simulate`` sees why the run stopped
without extra flags. ``do_step`` after ``terminate``
is refused (FMI allows only fmi2FreeInstance or fmi2Reset then).
"""

from __future__ import annotations

import sys
from typing import Any

from pythonfmu import Fmi2Slave
from pythonfmu.enums import Fmi2Status

from .exit_order import register_exit_order


class GuardedSlave(Fmi2Slave):
    """Fmi2Slave whose initialisation and steps report errors instead of raising them."""

    _failure = ""  # non-empty: the model is unusable and do_step refuses
    _terminated = False  # fmi2Terminate was called: do_step refuses
    _error_shown = False  # the instance's first error went to stderr (report_error)

    def _initialise(self) -> None:
        """Build the model from the parameters (exitInitializationMode); raise on error."""
        raise NotImplementedError

    def _step(self, current_time: float, step_size: float) -> bool:
        """One communication step; False refuses it (reported by the step itself with
        ``_error``)."""
        raise NotImplementedError

    def terminate(self) -> None:
        self._terminated = True

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        # Issue 18: PythonFMU 0.7.0's binary frees its `pyState` (PySlaveInstance.cpp:667)
        # from a static destructor at exit and then releases it again in onLibraryUnload
        # (:722-725 -> :695), a use-after-free that sometimes aborts the host after a clean
        # run. exit_order releases it first, at exit, so both later calls do nothing.
        register_exit_order(self.resources)

    def exit_initialization_mode(self) -> bool:
        try:
            self._initialise()
            return True
        except Exception as exc:  # nothing may escape into the C wrapper
            self._fail(f"initialisation failed: {exc}")
            return False

    def do_step(self, current_time: float, step_size: float) -> bool:
        if self._terminated:
            self._error(f"do_step at t={current_time!r} refused: called after fmi2Terminate")
            return False
        if self._failure:
            self.log(f"do_step refused, model unusable: {self._failure}", Fmi2Status.error)
            return False
        try:
            return self._step(current_time, step_size)
        except Exception as exc:
            self._step_failed(current_time, step_size, exc)
            return False

    def _step_failed(self, current_time: float, step_size: float, exc: Exception) -> None:
        """Fail the instance with the exception that stopped a step."""
        self._fail(f"do_step at t={current_time!r}, h={step_size!r} failed: {exc}")

    def _output_setter(self, name: str) -> Any:
        """fmi2SetReal on an output: FMI's answer is fmi2Error, which PythonFMU cannot
        return (only OK, or Fatal through its unsafe exception path); the value is ignored
        and the instance fails as fmi2Error would make it: the next do_step is refused."""
        def refuse(value: Any) -> None:
            self._fail(f"output '{name}' cannot be set by the host (fmi2SetXXX on an "
                       f"output is an error; the value {value!r} was ignored)")
        return refuse

    def _error(self, msg: str) -> None:
        """Report an error (logged as fmi2Error, the instance's first one also on stderr)
        without failing the instance: the caller decides what the call returns and whether
        later steps may go on (a work-bound stop: the next step continues)."""
        report_error(self, msg)

    def _fail(self, msg: str) -> None:
        """Report an error and fail the instance: every later do_step is refused with this
        message until initialisation or a valid state restore clears it."""
        self._failure = msg
        self._error(msg)


def report_error(slave: Fmi2Slave, msg: str) -> None:
    """Log msg on slave with Fmi2Status.error; the first error of the instance is also
    written as one line on stderr (``<instance>: error: <msg>``), since PythonFMU forwards
    log messages only when the host turned logging on. Never raises."""
    slave.log(msg, Fmi2Status.error)
    if not getattr(slave, "_error_shown", False):
        slave._error_shown = True  # type: ignore[attr-defined]
        _stderr_line(f"{slave.instance_name}: error: {msg}")


def _stderr_line(line: str) -> None:
    """One line on stderr, best effort (a host may have closed it)."""
    try:
        sys.stderr.write(" ".join(line.split()) + "\n")
        sys.stderr.flush()
    except Exception:
        pass
