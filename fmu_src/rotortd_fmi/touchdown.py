"""PythonFMU adapter of the FMU RotorTouchdown: a rotor hitting its touchdown bearing.

The FMU's script ``fmu_src/RotorTouchdown.py`` only subclasses ``RotorTouchdownAdapter``.

A thin layer over the physics core ``rotortd`` (see docs/core-api.md). It declares the FMI
variables, validates parameters and inputs, hands each communication step to
``TouchdownCore.step`` and publishes the step report and the kinematics.

Rules this file follows (see the project's FMI notes):
- ``__init__`` is cheap and free of side effects (the builder instantiates the class).
- Derived objects (RotorParams, TouchdownCore) are built in ``exit_initialization_mode``.
- No exception escapes into the PythonFMU C wrapper (``guard.GuardedSlave``): errors are
  logged with ``Fmi2Status.error`` and the next ``do_step`` returns False (fmi2Discard).
- The FMU state (get/set/serialize) holds the core's full state plus this adapter's own
  variables, as JSON with an explicit schema; never pickle.
- Only the standard library and ``rotortd`` are imported at run time.

The metadata table ``VARIABLE_META`` (unit, min, max per variable) is read by build.py to
post-process modelDescription.xml; it is plain data and costs nothing at run time.
"""

from __future__ import annotations

import copy
import json
import math
import operator
import os
from typing import Any

from pythonfmu import Boolean, DefaultExperiment, Integer, Real, String
from pythonfmu.enums import Fmi2Causality, Fmi2Initial, Fmi2Status, Fmi2Variability

from .guard import GuardedSlave

STATE_SCHEMA = "rotortd-fmu-state"
STATE_VERSION = 1

# name: (unit, min, max). min/max None = unbounded. FMI min/max are inclusive; strict
# bounds (m > 0, ...) are enforced at initialisation and stated in the descriptions.
VARIABLE_META: dict[str, tuple[str, float | None, float | None]] = {
    # parameters
    "m": ("kg", 0.0, None),
    "c": ("N.s/m", 0.0, None),
    "k": ("N/m", 0.0, None),
    "e_c": ("m", 0.0, None),
    "phi": ("rad", None, None),
    "c_r": ("m", 0.0, None),
    "R": ("m", 0.0, None),
    "mu": ("1", 0.0, None),
    "d": ("1", 0.0, 1.0),
    "g": ("m/s2", None, None),
    "x0": ("m", None, None),
    "y0": ("m", None, None),
    "vx0": ("m/s", None, None),
    "vy0": ("m/s", None, None),
    "psi0": ("rad", None, None),
    "J": ("kg.m2", 0.0, None),
    "h_spin": ("s", 0.0, None),
    # inputs
    "Omega": ("rad/s", None, None),
    "F_x": ("N", None, None),
    "F_y": ("N", None, None),
    "amb_on": ("1", 0.0, 1.0),
    "T_drive": ("N.m", None, None),
    # outputs
    "x": ("m", None, None),
    "y": ("m", None, None),
    "vx": ("m/s", None, None),
    "vy": ("m/s", None, None),
    "r_rel": ("1", 0.0, None),
    "u_re": ("1", None, None),
    "u_im": ("1", None, None),
    "du_re": ("1", None, None),
    "du_im": ("1", None, None),
    "psi": ("rad", None, None),
    "whirl_rate": ("rad/s", None, None),
    "v_rel": ("m/s", None, None),
    "F_bx": ("N", None, None),
    "F_by": ("N", None, None),
    "F_n": ("N", 0.0, None),
    "F_n_peak": ("N", 0.0, None),
    "P_n": ("N.s", 0.0, None),
    "T_f": ("N.m", None, None),
    "F_amb_x": ("N", None, None),
    "F_amb_y": ("N", None, None),
    "t_last_impact": ("s", None, None),
    "v_last_impact": ("m/s", 0.0, None),
    "E_diss": ("J", 0.0, None),
    "Omega_out": ("rad/s", None, None),
    # Integer outputs (unit ignored for non-Real types by build.py)
    "mode": ("", 0, 2),
    "n_impacts": ("", 0, None),
    "n_impacts_step": ("", 0, None),
}

# (name, start, description); tunable ones are marked in TUNABLE.
REAL_PARAMETERS: tuple[tuple[str, float, str], ...] = (
    ("m", 50.0, "Rotor mass [kg], > 0"),
    ("c", 1400.0, "AMB damping (PD controller) [N.s/m], >= 0; tunable"),
    ("k", 9.8e5, "AMB stiffness (PD controller) [N/m], >= 0; tunable"),
    ("e_c", 0.3e-3, "Imbalance eccentricity [m], >= 0; tunable"),
    ("phi", 0.21, "Imbalance phase [rad], finite; tunable"),
    ("c_r", 0.7e-3, "Radial clearance of the touchdown bearing [m], > 0"),
    ("R", 0.04, "Rotor radius at the touchdown bearing [m], > 0"),
    ("mu", 0.15, "Coulomb friction coefficient rotor/TDB [1], >= 0; tunable"),
    ("d", 0.95, "Newton coefficient of restitution [1], in [0, 1]; tunable"),
    ("g", 0.0, "Gravity acting in -y [m/s2], finite (9.81 for a horizontal rotor)"),
    ("x0", 0.0, "Initial position x [m], |(x0, y0)| <= c_r; ignored if start_steady"),
    ("y0", 0.0, "Initial position y [m], |(x0, y0)| <= c_r; ignored if start_steady"),
    ("vx0", 0.0, "Initial velocity x [m/s], finite; ignored if start_steady"),
    ("vy0", 0.0, "Initial velocity y [m/s], finite; ignored if start_steady"),
    ("psi0", 0.0, "Initial spin angle [rad], finite"),
    ("J", 0.04, "Polar inertia of the spin, used if integrate_spin [kg.m2], > 0"),
    ("h_spin", 1e-6, "Largest internal sub-step of the spin integration, used if "
                     "integrate_spin [s], > 0"),
)
TUNABLE: frozenset[str] = frozenset({"c", "k", "mu", "d", "e_c", "phi"})
FIXED: tuple[str, ...] = (*(n for n, _s, _d in REAL_PARAMETERS if n not in TUNABLE),
                          "levitate", "start_steady", "impact_log", "integrate_spin")
CORE_PARAMS: tuple[str, ...] = ("m", "c", "k", "e_c", "phi", "c_r", "R", "mu", "d", "g")

INPUTS: tuple[tuple[str, float, str], ...] = (
    ("Omega", 184.2, "Spin speed, held over the step [rad/s], finite"),
    ("F_x", 0.0, "External force on the rotor, x [N], finite"),
    ("F_y", 0.0, "External force on the rotor, y [N], finite"),
    ("amb_on", 1.0, "Magnetic bearing state: 1 on, 0 failed [1], in [0, 1]"),
    ("T_drive", 0.0, "Drive torque on the spin (motor minus drag), used if integrate_spin "
                     "[N.m], finite"),
)

REAL_OUTPUTS: tuple[tuple[str, str], ...] = (
    ("x", "Rotor centre position x, inertial [m], |(x, y)| <= c_r"),
    ("y", "Rotor centre position y, inertial [m], |(x, y)| <= c_r"),
    ("vx", "Rotor centre velocity x, inertial [m/s]"),
    ("vy", "Rotor centre velocity y, inertial [m/s]"),
    ("r_rel", "Radial position relative to clearance r/c_r [1], in [0, 1]"),
    ("u_re", "Co-rotating scaled position Re U, U = z exp(-i psi)/c_r [1], |U| <= 1"),
    ("u_im", "Co-rotating scaled position Im U [1], |U| <= 1"),
    ("du_re", "Co-rotating scaled velocity Re dU/dt, t = Omega tau [1]; 0 when Omega = 0"),
    ("du_im", "Co-rotating scaled velocity Im dU/dt, t = Omega tau [1]; 0 when Omega = 0"),
    ("psi", "Spin angle wrapped to (-pi, pi] [rad]"),
    ("whirl_rate", "Inertial whirl rate theta' (rate of the polar angle of z) [rad/s]"),
    ("v_rel", "Slip velocity at the contact point R Omega + c_r theta' [m/s]"),
    ("F_bx", "Bearing (contact) force on the rotor x, step-averaged, impulses as P/h [N]"),
    ("F_by", "Bearing (contact) force on the rotor y, step-averaged, impulses as P/h [N]"),
    ("F_n", "Normal contact force, step-averaged [N], >= 0"),
    ("F_n_peak", "Peak normal contact force within the step [N], >= 0"),
    ("P_n", "Normal contact impulse within the step [N.s], >= 0"),
    ("T_f", "Friction torque on the spin, step-averaged; < 0 brakes a positive spin [N.m]"),
    ("F_amb_x", "Magnetic bearing force x at the end of the step [N]"),
    ("F_amb_y", "Magnetic bearing force y at the end of the step [N]"),
    ("t_last_impact", "Time of the last impact [s]; 0 before any impact"),
    ("v_last_impact", "Normal speed rdot- of the last impact [m/s], >= 0; 0 before any"),
    ("E_diss", "Energy dissipated by contact, cumulative [J], >= 0"),
    ("Omega_out", "Spin speed at the end of the step: the integrated spin if "
                  "integrate_spin, else the input Omega [rad/s]"),
)

_get_fixed = operator.attrgetter(*FIXED)
_get_tunables = operator.attrgetter(*sorted(TUNABLE))
_get_inputs = operator.attrgetter(*(name for name, _s, _d in INPUTS))

STATUS_WORK_CAP = 1  # rotortd.STATUS_WORK_CAP: the step stopped early (see core-api.md)
IMPACT_LOG_HEADER = "time,x,y,vx_minus,vy_minus,vx_plus,vy_plus,rdot,P_n,P_t,stick\n"


class ModelError(ValueError):
    """A parameter, input or state problem detected by the adapter itself."""


def _check_finite(name: str, value: float) -> None:
    if not math.isfinite(value):
        raise ModelError(f"{name}={value!r} is not finite")


def _time_tolerance(t: float, step_size: float) -> float:
    """Allowed gap between the host's communication point and the model time: host clocks
    that add h up naively drift by rounding (the core's clock is compensated); a gap of a
    sizeable fraction of a step means a skipped, repeated or rolled-back step."""
    return 1e-9 * max(1.0, abs(t)) + 1e-2 * step_size


def _same(a: Any, b: Any) -> bool:
    """Equality that treats NaN as equal to NaN (for the fixed-parameter guard)."""
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return a == b


class RotorTouchdownAdapter(GuardedSlave):
    """Rotor in a touchdown bearing: AMB spring/damper, imbalance, impacts with friction."""

    author = "rotor-touchdown project"
    description = (
        "Rigid rotor in magnetic bearings hitting its touchdown bearing (impacts, Coulomb "
        "friction, sustained contact); exact propagation over each communication step."
    )
    version = "0.1.0"
    license = "MIT"
    default_experiment = DefaultExperiment(start_time=0.0, stop_time=0.5, step_size=1e-4)

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self._declare_parameters()
        self._declare_inputs()
        self._declare_outputs()
        self._core: Any = None
        self._t0 = 0.0
        self._failure = ""          # non-empty: the model is unusable, do_step refuses
        self._fixed_snapshot: dict[str, Any] = {}
        # values the last step found valid: a step re-checks only what changed since,
        # and nothing unless an FMI setter (or initialisation, or a state restore) ran
        self._changed = True
        self._step_inputs: tuple[float, complex, float, float] = (0.0, 0j, 1.0, 0.0)
        self._seen_fixed: tuple | None = None
        self._seen_tunables: tuple | None = None
        self._seen_inputs: tuple | None = None
        self._spin: Any = None      # rotortd_drive.SpinCoupler if integrate_spin

    # ------------------------------------------------------------------ declaration
    def _declare_parameters(self) -> None:
        for name, start, desc in REAL_PARAMETERS:
            setattr(self, name, start)
            var = Fmi2Variability.tunable if name in TUNABLE else Fmi2Variability.fixed
            self.register_variable(Real(name, causality=Fmi2Causality.parameter,
                                        variability=var, description=desc,
                                        setter=self._watched_setter(name)))
        self.levitate = True
        self.register_variable(Boolean(
            "levitate", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
            description="AMB bias force +i m g holds the rotor centred against gravity [-]",
            setter=self._watched_setter("levitate")))
        self.start_steady = False
        self.register_variable(Boolean(
            "start_steady", causality=Fmi2Causality.parameter,
            variability=Fmi2Variability.fixed,
            description="Start on the steady free whirl (error if not admissible) [-]; "
                        "overrides x0, y0, vx0, vy0",
            setter=self._watched_setter("start_steady")))
        self.integrate_spin = False
        self.register_variable(Boolean(
            "integrate_spin", causality=Fmi2Causality.parameter,
            variability=Fmi2Variability.fixed,
            description="Integrate the spin inside the FMU: J Omega' = T_drive + T_f, "
                        "sub-stepped at h_spin; the input Omega is then only the initial "
                        "speed and Omega_out the spin [-]",
            setter=self._watched_setter("integrate_spin")))
        self.impact_log = ""
        self.register_variable(String(
            "impact_log", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
            description="If not empty: CSV path; every impact is appended (time, x, y, vx-, "
                        "vy-, vx+, vy+, rdot, P_n, P_t, stick) [-]",
            setter=self._watched_setter("impact_log")))

    def _declare_inputs(self) -> None:
        for name, start, desc in INPUTS:
            setattr(self, name, start)
            self.register_variable(Real(name, causality=Fmi2Causality.input, description=desc,
                                        setter=self._watched_setter(name)))

    def _declare_outputs(self) -> None:
        exact = Fmi2Initial.exact
        for name, desc in REAL_OUTPUTS:
            setattr(self, name, 0.0)
            self.register_variable(Real(name, causality=Fmi2Causality.output, initial=exact,
                                        description=desc, setter=self._output_setter(name)))
        discrete = Fmi2Variability.discrete
        for name, desc in (
            ("mode", "Contact mode at the end of the step: 0 free, 1 sliding, 2 rolling [-]"),
            ("n_impacts", "Number of impacts since the start, cumulative [-], >= 0"),
            ("n_impacts_step", "Number of impacts within the last step [-], >= 0"),
        ):
            setattr(self, name, 0)
            self.register_variable(Integer(name, causality=Fmi2Causality.output,
                                           variability=discrete, initial=exact,
                                           description=desc,
                                           setter=self._output_setter(name)))
        self.in_contact = False
        self.register_variable(Boolean(
            "in_contact", causality=Fmi2Causality.output, variability=discrete, initial=exact,
            description="Rotor in sustained contact (mode != 0) at the end of the step [-]",
            setter=self._output_setter("in_contact")))

    def _watched_setter(self, name: str) -> Any:
        """FMI setter of a parameter or input: stores the value and marks the values as
        changed, so the next step validates them (and only then)."""
        def store(value: Any) -> None:
            setattr(self, name, value)
            self._changed = True
        return store

    def _output_setter(self, name: str) -> Any:
        def refuse(_value: Any) -> None:
            self.log(f"refused: output '{name}' cannot be set by the host", Fmi2Status.error)
        return refuse

    # ------------------------------------------------------------------ FMI calls
    def setup_experiment(self, start_time: float = 0.0, stop_time: float | None = None,
                         tolerance: float | None = None) -> None:
        self._t0 = float(start_time)

    # ------------------------------------------------------------------ initialisation
    def _initialise(self) -> None:
        import rotortd  # resources/rotortd inside the FMU

        self._failure = ""
        self._forget_checks()
        for name, _start, _desc in REAL_PARAMETERS:
            _check_finite(name, float(getattr(self, name)))
        self._check_inputs()
        params = self._make_params(rotortd)
        omega, f_ext, amb, _t_drive = self._input_values()
        if self.start_steady:
            core = rotortd.TouchdownCore.on_steady_whirl(
                params, omega, F_ext=f_ext, amb_on=amb, psi0=float(self.psi0), t0=self._t0)
        else:
            z0 = complex(float(self.x0), float(self.y0))
            if abs(z0) > params.c_r:
                raise ModelError(f"x0, y0: initial position |(x0, y0)|={abs(z0)!r} m lies "
                                 f"outside the clearance c_r={params.c_r!r} m")
            core = rotortd.TouchdownCore(params, z0=z0, v0=complex(float(self.vx0),
                                         float(self.vy0)), psi0=float(self.psi0), t0=self._t0)
        self._core = core
        self._spin = self._make_spin(omega)
        self.Omega_out = omega
        self._fixed_snapshot = self._fixed_values()
        self._publish_kinematics(omega, amb)
        self._publish_counters()
        self._publish_step_outputs(None, 0)

    def _make_spin(self, omega: float) -> Any:
        """The spin integrator (integrate_spin) or None."""
        if not self.integrate_spin:
            return None
        from rotortd_drive import SpinCoupler  # resources/rotortd_drive inside the FMU

        for name in ("J", "h_spin"):
            if not float(getattr(self, name)) > 0.0:
                raise ModelError(f"{name}={getattr(self, name)!r} must be > 0 "
                                 f"with integrate_spin")
        return SpinCoupler(float(self.J), float(self.h_spin), omega)

    def _make_params(self, rotortd: Any) -> Any:
        kwargs = {name: float(getattr(self, name)) for name in CORE_PARAMS}
        return rotortd.RotorParams(levitate=bool(self.levitate), **kwargs)

    def _fixed_values(self) -> dict[str, Any]:
        return dict(zip(FIXED, _get_fixed(self)))

    # ------------------------------------------------------------------ stepping
    def _input_values(self) -> tuple[float, complex, float, float]:
        """(Omega, F_ext, amb_on, T_drive) as the core takes them."""
        return (float(self.Omega), complex(float(self.F_x), float(self.F_y)),
                float(self.amb_on), float(self.T_drive))

    def _forget_checks(self) -> None:
        """Make the next step validate every group (after initialisation or a restore)."""
        self._seen_fixed = self._seen_tunables = self._seen_inputs = None
        self._changed = True

    def _check_inputs(self) -> None:
        for name, _start, _desc in INPUTS:
            _check_finite(name, float(getattr(self, name)))
        if not 0.0 <= float(self.amb_on) <= 1.0:
            raise ModelError(f"amb_on={self.amb_on!r} outside [0, 1]")

    def _check_fixed(self) -> None:
        for name, value in self._fixed_snapshot.items():
            if not _same(getattr(self, name), value):
                raise ModelError(f"parameter '{name}' is fixed: it cannot change after "
                                 f"initialisation (was {value!r}, now {getattr(self, name)!r})")

    def _apply_tunables(self) -> None:
        params = self._core.params
        changes = {n: float(getattr(self, n)) for n in TUNABLE
                   if not _same(float(getattr(self, n)), getattr(params, n))}
        if changes:
            for name, value in changes.items():
                _check_finite(name, value)
            self._core.set_params(params.replace(**changes))

    def _check_changes(self) -> None:
        """Validate fixed parameters, tunables and inputs, each only when its values
        differ from those the last step accepted (NaN never equals itself: re-checked)."""
        fixed, tunables, inputs = _get_fixed(self), _get_tunables(self), _get_inputs(self)
        if fixed != self._seen_fixed:
            self._check_fixed()
            self._seen_fixed = fixed
        if inputs != self._seen_inputs:
            self._check_inputs()
            self._seen_inputs = inputs
            self._step_inputs = self._input_values()
        if tunables != self._seen_tunables:
            self._apply_tunables()
            self._seen_tunables = tunables

    def _step(self, current_time: float, step_size: float) -> bool:
        core = self._core
        if core is None:
            raise ModelError("do_step before exitInitializationMode")
        if self._changed:
            self._check_changes()
            self._changed = False
        if not step_size > 0.0:
            raise ModelError(f"communication step size {step_size!r} must be > 0")
        tol = _time_tolerance(current_time, step_size)
        if abs(current_time - core.t) > tol:
            raise ModelError(f"communication point {current_time!r} does not match the "
                             f"model time {core.t!r}")
        omega, f_ext, amb, t_drive = self._step_inputs  # validated by _check_changes
        t_target = core.t + step_size
        if self._spin is not None:
            rep = self._spin.step(core, step_size, t_drive, F_ext=f_ext, amb_on=amb)
            omega = self._spin.Omega
        else:
            rep = core.step(step_size, omega, F_ext=f_ext, amb_on=amb)
        self.Omega_out = omega
        if self.impact_log and rep.impacts:
            self._append_impacts(rep.impacts)
        self._publish_kinematics(omega, amb)
        if rep.impacts or rep.transitions or rep.E_diss:  # else the counters stand
            self._publish_counters()
        self._publish_step_outputs(rep, len(rep.impacts))
        if rep.status == 0 and abs(core.t - t_target) <= tol:
            return True  # the common case, without a call
        return self._judge_report(rep, t_target, tol)

    def _judge_report(self, rep: Any, t_target: float, tol: float) -> bool:
        """A step the core could not finish (work cap) is refused: the outputs show the
        state where it stopped and the model time stays there (restore a saved FMU state or
        continue from core time). A completed step with a non-OK status is a warning."""
        reached = self._core.t
        short = abs(reached - t_target) > tol
        if rep.status == STATUS_WORK_CAP or short:
            self.log(f"step incomplete: core status {rep.status} ({rep.message}); model time "
                     f"stays at t={reached!r} instead of {t_target!r}", Fmi2Status.error)
            return False
        if rep.status != 0:
            self.log(f"t={reached!r}: core status {rep.status}: {rep.message}",
                     Fmi2Status.warning)
        return True

    # ------------------------------------------------------------------ publishing
    def _publish_kinematics(self, omega: float, amb: float) -> None:
        (self.x, self.y, self.vx, self.vy, self.r_rel, self.u_re, self.u_im, self.du_re,
         self.du_im, self.psi, self.whirl_rate, self.v_rel, self.F_amb_x,
         self.F_amb_y) = self._core.kinematics_values(omega, amb)

    def _publish_counters(self) -> None:
        core = self._core
        self.mode = core.mode
        self.in_contact = core.mode != 0
        self.n_impacts = core.n_impacts
        self.t_last_impact = core.t_last_impact
        self.v_last_impact = core.v_last_impact
        self.E_diss = core.E_diss

    def _publish_step_outputs(self, rep: Any, n_step: int) -> None:
        if rep is None:
            self.F_bx = self.F_by = self.F_n = self.F_n_peak = self.P_n = self.T_f = 0.0
        else:
            self.F_bx, self.F_by = rep.F_contact.real, rep.F_contact.imag
            self.F_n, self.F_n_peak, self.P_n, self.T_f = rep.F_n, rep.F_n_peak, rep.P_n, rep.T_f
        self.n_impacts_step = n_step

    def _append_impacts(self, impacts: list[Any]) -> None:
        path = str(self.impact_log)
        new = not os.path.exists(path) or os.path.getsize(path) == 0
        with open(path, "a", encoding="utf-8") as fh:
            if new:
                fh.write(IMPACT_LOG_HEADER)
            for imp in impacts:
                row = (imp.t, imp.z.real, imp.z.imag, imp.v_minus.real, imp.v_minus.imag,
                       imp.v_plus.real, imp.v_plus.imag, imp.rdot, imp.P_n, imp.P_t)
                fh.write(",".join(repr(float(v)) for v in row) + f",{int(bool(imp.stick))}\n")

    # ------------------------------------------------------------------ FMU state
    def _get_fmu_state(self) -> dict[str, Any]:
        try:
            values = {v.name: v.getter() for v in self.vars.values()}
            state = {
                "schema": STATE_SCHEMA,
                "version": STATE_VERSION,
                "variables": values,
                "core": None if self._core is None else self._core.get_state(),
                "adapter": {"t0": self._t0, "failure": self._failure,
                            "fixed_snapshot": self._fixed_snapshot,
                            "spin": None if self._spin is None else self._spin.Omega},
            }
            # JSON round trip: an independent deep copy, and proof that it serialises.
            return json.loads(json.dumps(state))
        except Exception as exc:
            self.log(f"getFMUstate failed: {exc}", Fmi2Status.error)
            return {"schema": STATE_SCHEMA, "version": STATE_VERSION, "invalid": str(exc)}

    def _set_fmu_state(self, state: dict[str, Any]) -> None:
        try:
            self._restore(state)
        except Exception as exc:
            self._fail(f"setFMUstate failed: {exc}")

    def _restore(self, state: dict[str, Any]) -> None:
        if not isinstance(state, dict) or state.get("schema") != STATE_SCHEMA:
            raise ModelError("not a rotortd FMU state (schema mismatch)")
        if state.get("version") != STATE_VERSION:
            raise ModelError(f"unsupported FMU state version {state.get('version')!r}")
        if "invalid" in state:
            raise ModelError(f"the saved state is invalid: {state['invalid']}")
        known = {v.name for v in self.vars.values()}
        values = state["variables"]
        if set(values) != known:
            raise ModelError("FMU state does not list exactly this model's variables")
        core_state = state["core"]
        if core_state is not None:
            if self._core is None:
                self._core = self._new_core_for_restore()
            self._core.set_state(copy.deepcopy(core_state))
        else:
            self._core = None
        for name, value in values.items():
            setattr(self, name, value)
        adapter = state["adapter"]
        self._t0 = float(adapter["t0"])
        self._failure = str(adapter["failure"])
        self._fixed_snapshot = dict(adapter["fixed_snapshot"])
        self._forget_checks()
        spin = adapter.get("spin")
        self._spin = None if spin is None else self._make_spin(float(spin))

    def _new_core_for_restore(self) -> Any:
        import rotortd

        return rotortd.TouchdownCore(rotortd.RotorParams(), z0=0j, v0=0j, psi0=0.0, t0=0.0)

    @staticmethod
    def _fmu_state_to_bytes(state: dict[str, Any]) -> bytes:
        return json.dumps(state, sort_keys=True).encode("utf-8")

    @staticmethod
    def _fmu_state_from_bytes(data: bytes) -> dict[str, Any]:
        try:
            state = json.loads(data.decode("utf-8"))
        except Exception as exc:  # must not raise into the C wrapper
            return {"schema": STATE_SCHEMA, "version": STATE_VERSION,
                    "invalid": f"undecodable: {exc}"}
        if not isinstance(state, dict):
            return {"schema": STATE_SCHEMA, "version": STATE_VERSION, "invalid": "not a dict"}
        return state
