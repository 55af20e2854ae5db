"""PythonFMU adapter of the source FMU TouchdownEvents: a scene's event schedule.

The FMU's script ``fmu_src/TouchdownEvents.py`` only subclasses ``TouchdownEventsAdapter``.

FMPy's SSP master sets only inputs, never parameters mid-run, and every engine must run the
same SSP; a tiny source FMU is the portable way to step ``amb_on`` at the failure time and
to switch an external force on and off. Outputs are piecewise constant in time:

    amb_on = amb_before for t < t_fail, amb_after from t_fail on        [1]
    F_x, F_y = F_x_step, F_y_step for t_force_on <= t < t_force_off, else 0   [N]

The output published after ``doStep(t, h)`` is the schedule's value at ``t + h``, so the
component it feeds holds, over the step starting at T, the value at T (a Jacobi master then
applies the switch exactly at the communication point at or after the event time).
Standard library only; no state beyond the parameters.
"""

from __future__ import annotations

from typing import Any

from pythonfmu import DefaultExperiment, Fmi2Slave

from .exit_order import register_exit_order
from .guard import report_error
from .variables import OUTPUT, PARAMETER, Var, meta, output, register

TIME_EPS = 1e-9  # s: host clocks that add h repeatedly may land just before an event time


def _param(name: str, start: float, unit: str, description: str, lo: float | None = None,
           hi: float | None = None) -> Var:
    return Var(name, PARAMETER, "Real", start, unit, lo, hi, description, tunable=True)


TABLE: tuple[Var, ...] = (  # the variable table of this FMU (see .variables)
    _param("t_fail", 1e30, "s", "Time of the bearing failure"),
    _param("amb_before", 1.0, "1", "amb_on before t_fail", 0.0, 1.0),
    _param("amb_after", 0.0, "1", "amb_on from t_fail on", 0.0, 1.0),
    _param("t_force_on", 1e30, "s", "Start of the external force step"),
    _param("t_force_off", 1e30, "s", "End of the external force step"),
    _param("F_x_step", 0.0, "N", "External force x during the step"),
    _param("F_y_step", 0.0, "N", "External force y during the step"),
    output("amb_on", "1", "Magnetic bearing state for the step that starts now", 0.0, 1.0),
    output("F_x", "N", "External force x for the step that starts now"),
    output("F_y", "N", "External force y for the step that starts now"),
)
VARIABLE_META = meta(TABLE)  # read by build.py


class TouchdownEventsAdapter(Fmi2Slave):
    """Schedule of amb_on (bearing failure) and of an external force step."""

    author = "rotor-touchdown project"
    description = "Event schedule of a touchdown scene: amb_on step and external force step."
    version = "0.1.0"
    license = "MIT"
    default_experiment = DefaultExperiment(start_time=0.0, stop_time=1.0, step_size=1e-4)

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        register_exit_order(self.resources)  # issue 18, see guard.GuardedSlave.__init__
        self._t_now = 0.0   # the outputs are the schedule at this time [s]
        register(self, TABLE, lambda _name: None, self._refuse,
                 getters={v.name: self._getter(v.name) for v in TABLE if v.causality == OUTPUT})
        self._t0 = 0.0

    def _refuse(self, name: str) -> Any:
        return lambda _value: report_error(self, f"output '{name}' cannot be set by the host")

    def _getter(self, name: str) -> Any:
        return lambda: self.schedule(self._t_now)[name]

    def setup_experiment(self, start_time: float = 0.0, stop_time: float | None = None,
                         tolerance: float | None = None) -> None:
        self._t0 = float(start_time)

    def exit_initialization_mode(self) -> bool:
        self._t_now = self._t0
        return True

    def do_step(self, current_time: float, step_size: float) -> bool:
        try:
            self._t_now = current_time + step_size
            return True
        except Exception as exc:
            report_error(self, f"do_step failed: {exc}")
            return False

    def schedule(self, t: float) -> dict[str, float]:
        """The outputs at time t [s]: amb_on [1], F_x, F_y [N]."""
        te = t + TIME_EPS
        force_on = self.t_force_on <= te < self.t_force_off
        return {"amb_on": float(self.amb_before if te < self.t_fail else self.amb_after),
                "F_x": float(self.F_x_step) if force_on else 0.0,
                "F_y": float(self.F_y_step) if force_on else 0.0}
