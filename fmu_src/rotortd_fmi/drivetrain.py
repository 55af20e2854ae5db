"""PythonFMU adapter of the FMU Drivetrain: ``J Omega' = T_motor - b Omega + T_bearing``.

The FMU's script ``fmu_src/Drivetrain.py`` only subclasses ``DrivetrainAdapter``.

The motor is a held torque input (``motor = 0``) or a PI speed controller with set-point
``Omega_set`` and torque limit ``T_max`` (``motor = 1``). The physics lives in the
pure-Python package ``rotortd_drive`` (shipped as ``resources/rotortd_drive``), which
advances the drivetrain exactly for inputs held over a communication step.

The recommended coupling (docs/cosimulation.md, the project's scenes) lets the bearing own
the spin: ``follow_speed = true``, ``RotorTouchdown.Omega_out`` to ``Omega_in`` and
``T_drive`` (motor plus drag at the held ``Omega_in``, step-averaged) to
``RotorTouchdown.T_drive``, with ``RotorTouchdown.integrate_spin`` and its ``J`` the whole
spinning inertia; this drivetrain's ``J`` is then unused. For a drivetrain that owns the
inertia (held-speed coupling, unstable in rolling for J < m R^2): ``Omega`` to
``RotorTouchdown.Omega`` and ``RotorTouchdown.T_f`` to ``T_bearing``.

Cumulative angular impulses ``H_motor``, ``H_drag``, ``H_bearing`` [N m s] close the
momentum balance ``J (Omega - Omega0) = H_motor + H_drag + H_bearing`` to round-off.
Errors are logged (fmi2Error) and the step returns fmi2Discard; nothing escapes into the
C wrapper. Only the standard library and ``rotortd_drive`` are imported at run time.
"""

from __future__ import annotations

import json
import math
from typing import Any

from pythonfmu import DefaultExperiment

from . import drivetrain_variables as dv
from .guard import GuardedSlave
from .variables import meta, register

STATE_SCHEMA = "rotortd-drivetrain-fmu-state"

VARIABLE_META = meta(dv.TABLE)  # read by build.py
TUNABLE, FIXED = dv.TUNABLE, dv.FIXED


def _wrap(angle: float) -> float:
    """Angle wrapped to (-pi, pi] [rad]."""
    w = math.remainder(angle, 2.0 * math.pi)
    return math.pi if w == -math.pi else w


class DrivetrainAdapter(GuardedSlave):
    """Drivetrain J Omega' = T_motor - b Omega + T_bearing; torque motor or limited PI."""

    author = "rotor-touchdown project"
    description = ("Drivetrain of the rotor: inertia, drag, torque motor or PI speed "
                   "controller with torque limit; exact for inputs held over a step.")
    version = "0.1.0"
    license = "MIT"
    default_experiment = DefaultExperiment(start_time=0.0, stop_time=1.0, step_size=1e-4)

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self._declare()
        self._core: Any = None
        self._failure = ""
        self._fixed: dict[str, Any] = {}

    # ------------------------------------------------------------------ declaration
    def _declare(self) -> None:
        register(self, dv.TABLE, lambda _name: None, self._output_setter,
                 getters={"Omega": self._omega_getter})

    def _omega_getter(self) -> float:
        """Omega: the state once initialised, before that the start value (hosts that
        propagate outputs during initialisation then see the right speed)."""
        if self._core is not None:
            return float(self._core.Omega)
        return float(self.Omega_in if self.follow_speed else self.Omega0)

    # ------------------------------------------------------------------ FMI calls
    # ------------------------------------------------------------------ model
    def _params(self) -> Any:
        from rotortd_drive import DriveParams

        kw = {n: float(getattr(self, n)) for n in ("J", *TUNABLE)}
        return DriveParams(motor=int(self.motor), **kw).validate()

    def _initialise(self) -> None:
        from rotortd_drive import DriveCore

        for name in dv.REAL_PARAMETERS + dv.INPUTS:
            if not math.isfinite(float(getattr(self, name))):
                raise ValueError(f"{name}={getattr(self, name)!r} is not finite")
        omega0 = float(self.Omega_in) if self.follow_speed else float(self.Omega0)
        self._core = DriveCore(self._params(), omega0, psi0=float(self.psi0))
        self._fixed = {n: getattr(self, n) for n in FIXED}
        self._publish(None)

    def _step(self, current_time: float, step_size: float) -> bool:
        core = self._core
        if core is None:
            raise ValueError("do_step before exitInitializationMode")
        for name, value in self._fixed.items():
            if getattr(self, name) != value:
                raise ValueError(f"parameter '{name}' is fixed: it cannot change after "
                                 f"initialisation")
        params = self._params()
        if params != core.params:
            core.params = params
        if self.follow_speed:
            core.Omega = float(self.Omega_in)
        rep = core.step(step_size, float(self.T_bearing), float(self.T_motor_in),
                        float(self.Omega_set), hold_speed=bool(self.follow_speed))
        self._publish(rep)
        return True

    def _publish(self, rep: Any) -> None:
        core = self._core
        self.psi, self.pi_integral = _wrap(core.psi), core.I
        self.H_motor, self.H_drag, self.H_bearing = core.H_motor, core.H_drag, core.H_bearing
        self.T_motor = 0.0 if rep is None else rep.T_motor
        self.T_drag = 0.0 if rep is None else rep.T_drag
        self.T_drive = self.T_motor + self.T_drag
        self.pi_regime = 0 if rep is None else int(rep.regime)

    # ------------------------------------------------------------------ FMU state
    def _get_fmu_state(self) -> dict[str, Any]:
        """The state as JSON-ready data; a state that cannot be captured is logged and
        returned marked invalid (as ``touchdown.RotorTouchdownAdapter`` does), so that
        restoring it fails the instance instead of restoring half a state."""
        try:
            values = {v.name: v.getter() for v in self.vars.values()}
            core = None if self._core is None else self._core.get_state()
            return json.loads(json.dumps({"schema": STATE_SCHEMA, "variables": values,
                                          "core": core, "failure": self._failure,
                                          "fixed": self._fixed}))
        except Exception as exc:
            self._error(f"getFMUstate failed: {exc}")
            return {"schema": STATE_SCHEMA, "invalid": str(exc)}

    def _set_fmu_state(self, state: dict[str, Any]) -> None:
        try:
            if state.get("schema") != STATE_SCHEMA:
                raise ValueError("not a drivetrain FMU state")
            if "invalid" in state:
                raise ValueError(f"the saved state is invalid: {state['invalid']}")
            for name, value in state["variables"].items():
                if name != "Omega":
                    setattr(self, name, value)
            self._failure, self._fixed = str(state["failure"]), dict(state["fixed"])
            if state["core"] is not None:
                from rotortd_drive import DriveCore

                self._core = DriveCore(self._params(), 0.0)
                self._core.set_state(state["core"])
        except Exception as exc:
            self._fail(f"setFMUstate failed: {exc}")
