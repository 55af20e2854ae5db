"""PythonFMU adapter of the FMU RotorTouchdown: a rotor hitting its touchdown bearing.

The FMU's script ``fmu_src/RotorTouchdown.py`` only subclasses ``RotorTouchdownAdapter``.

A thin layer over the physics core ``rotortd`` (see docs/core-api.md). It declares the FMI
variables, validates parameters and inputs, hands each communication step to
``TouchdownCore.step`` and publishes the step report (what happened over the step) and
``TouchdownCore.output_values`` (what the state shows at its end). While the state is in the
core's quiet lane (``TouchdownCore.quiet_lane``: a levitated whirl proved clear at held
inputs; with the spin a state, the quiet step proved clear step by step, under a drive
torque that may change every step), ``do_step`` takes the step in it with one call
(docs/architecture.md, frame 0).

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
from dataclasses import fields
from typing import Any

from pythonfmu import DefaultExperiment
from pythonfmu.enums import Fmi2Status

from . import touchdown_variables as tv
from .guard import GuardedSlave
from .variables import meta, range_violations, register

STATE_SCHEMA = "rotortd-fmu-state"
STATE_VERSION = 3
"""Version 3: the real bearing's variables (``touchdown_variables.REAL_BEARING``); states of
versions 1 and 2 lack them and restore with their start values (all options off). Version
2: the spin state (integrate_spin) is in the core's state; version 1 states of a
held-speed instance still load, those of the former sub-stepped spin coupler do not. The
core's state under "core" carries its own schema and version (``rotortd.step.state``: written
as rotortd-state 3, by component; FMU states embedding rotortd-state 1 or 2 still load)."""

VARIABLE_META = meta(tv.TABLE)  # read by build.py
TUNABLE, FIXED, INPUTS = tv.TUNABLE, tv.FIXED, tv.INPUTS

_get_fixed = operator.attrgetter(*FIXED)
_get_tunables = operator.attrgetter(*sorted(TUNABLE))
_get_inputs = operator.attrgetter(*INPUTS)

STATUS_WORK_CAP = 1  # rotortd.STATUS_WORK_CAP: the step stopped early (see core-api.md)
_INF = math.inf
_EPS = 2.220446049250313e-16
CLOCK_STEPS = 1e-2
"""A host's communication point may be off the model time by CLOCK_STEPS of the step (plus
1e-9 of the time: ``_time_tolerance``)."""
HOST_STEP_ULPS = 8.0
"""A host's step within HOST_STEP_ULPS eps of its time of the last step taken is that step
(``RotorTouchdownAdapter._host_step``)."""
IMPACT_LOG_HEADER = "time,x,y,vx_minus,vy_minus,vx_plus,vy_plus,rdot,P_n,P_t,stick\n"


ON_EVENTS = frozenset({"mode", "n_impacts", "t_last_impact", "v_last_impact", "E_diss"})
"""The StateOutputs fields published only after a step with impacts or mode changes, or in
contact (they change only then); in_contact follows mode."""
_publishers: dict[tuple[str, ...], Any] = {}


def state_publisher(fields: tuple[str, ...]) -> Any:
    """``publish(adapter, values, events)``: assign the core's ``output_values`` (whose
    order is ``fields``, the core's ``StateOutputs._fields``) to the outputs that show
    them, by name from the variable table (``Var.shows``). Compiled once per field order
    into one unpacking assignment: the doStep hot path pays no lookup. RuntimeError when
    the table and the core do not name the same fields."""
    if fields in _publishers:
        return _publishers[fields]
    namespace: dict[str, Any] = {}
    exec(compile(publisher_source(fields), "<rotortd_fmi.touchdown.state_publisher>",
                 "exec"), namespace)
    _publishers[fields] = namespace["publish"]
    return namespace["publish"]


def publisher_source(fields: tuple[str, ...]) -> str:
    """The source of ``state_publisher``'s ``publish`` for the field order ``fields``
    (docs/scripts/benchmarks.py compiles the same into the floor FMU, so that both publish
    alike). RuntimeError when the table and the fields do not name the same set."""
    by_field = {v.shows: v.name for v in tv.TABLE if v.shows}
    if set(by_field) != set(fields) or len(by_field) != len(fields):
        raise RuntimeError(f"the variable table shows {sorted(by_field)}, the core's state "
                           f"outputs are {sorted(fields)}")
    targets = ", ".join(f"_{f}" if f in ON_EVENTS else f"self.{by_field[f]}" for f in fields)
    return (f"def publish(self, out, events):\n    ({targets}) = out\n"
            "    if events or _mode:\n        self.in_contact = _mode != 0\n"
            + "".join(f"        self.{by_field[f]} = _{f}\n" for f in fields
                      if f in ON_EVENTS))


class _QuietReport:
    """What ``_publish_step_outputs`` reads of a step taken in the core's quiet lane
    (``TouchdownCore.quiet_lane``): a flight proved clear, whose forces and impulses are
    zero (as in its StepReport); T_imb is set per step."""

    __slots__ = ("T_f", "T_imb")
    F_contact = 0j
    F_n = F_n_peak = P_n = 0.0
    impacts = ()

    def __init__(self, T_f: float = 0.0) -> None:
        self.T_imb = 0.0
        self.T_f = T_f  # (-0.0 with the spin a state: -R * 0.0 / h, as its StepReport)


class ModelError(ValueError):
    """A parameter, input or state problem detected by the adapter itself."""


def _time_tolerance(t: float, step_size: float) -> float:
    """Allowed gap between the host's communication point and the model time: host clocks
    that add h up naively drift by rounding (the core's clock is compensated); a gap of a
    sizeable fraction of a step means a skipped, repeated or rolled-back step."""
    return 1e-9 * max(1.0, abs(t)) + CLOCK_STEPS * step_size


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
    # 0.7 s: the default scene's impacts, then from 0.59 s the forward sliding rub
    # (docs/fmu.md "The default scene")
    default_experiment = DefaultExperiment(start_time=0.0, stop_time=0.7, step_size=1e-4)

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        register(self, tv.TABLE, self._watched_setter, self._output_setter)
        self._core: Any = None
        self._t0 = 0.0
        self._failure = ""          # non-empty: the model is unusable, do_step refuses
        self._fixed_snapshot: dict[str, Any] = {}
        # values the last step found valid: a step re-checks only what changed since,
        # and nothing unless an FMI setter (or initialisation, or a state restore) ran
        self._changed = True
        self._T_only = False  # and what changed since is T_drive alone (the spin's lane)
        self._step_inputs: tuple[float, complex, float, float] = (0.0, 0j, 1.0, 0.0)
        self._seen_fixed: tuple | None = None
        self._seen_tunables: tuple | None = None
        self._seen_inputs: tuple | None = None
        self._h_spin_warned = False  # h_spin is deprecated: warned once if set
        self._spin_state = False  # the core's spin_is_state, read once per core
        self._race_outputs = False  # a real bearing's outputs to publish (core.race)
        self._quiet = _QuietReport()  # the report of a step in the core's quiet lane
        self._quiet_spin = _QuietReport(-0.0)  # the same with the spin a state
        t_drive = tv.BY_NAME["T_drive"]
        self._T_range = (t_drive.lo, t_drive.hi)  # (N m) its declared range
        self._lane: Any = None  # the core's quiet lane, while held (do_step)
        self._h_taken = math.nan  # the last step size taken (s): _host_step

    def _watched_setter(self, name: str) -> Any:
        """FMI setter of a parameter or input: stores the value and marks the values as
        changed, so the next step validates them (and only then)."""
        def store(value: Any) -> None:
            setattr(self, name, value)
            self._T_only = name == "T_drive" and (self._T_only or not self._changed)
            self._changed = True
            if name == "h_spin" and not self._h_spin_warned:
                self._h_spin_warned = True
                self.log("h_spin is deprecated and has no effect: with integrate_spin the "
                         "spin is an exact state of the core (docs/model.md 8)",
                         Fmi2Status.warning)
        return store

    # ------------------------------------------------------------------ FMI calls
    def setup_experiment(self, start_time: float = 0.0, stop_time: float | None = None,
                         tolerance: float | None = None) -> None:
        self._t0 = float(start_time)

    # ------------------------------------------------------------------ initialisation
    def _initialise(self) -> None:
        import rotortd  # resources/rotortd inside the FMU

        self._failure = ""
        self._forget_checks()
        self._require_ranges(tv.RANGED_PARAMETERS + INPUTS)  # every invalid value at once
        self._check_impact_log()
        try:
            self._core = self._make_core(rotortd)
            self._spin_state = self._core.spin_is_state
            self._race_outputs = self._core.race is not None
            self._publish = state_publisher(self._core.outputs()._fields)
        except rotortd.CrossParameterError as exc:
            raise ModelError(f"cross-parameter constraint: {exc}") from exc
        self._fixed_snapshot = self._fixed_values()
        self._publish_state(self._input_values()[0], float(self.amb_on))
        self._publish_step_outputs(None)

    def _make_core(self, rotortd: Any) -> Any:
        """The core on the steady whirl or at (x0, y0, vx0, vy0); a start within a few ulp
        outside the clearance is projected onto it (rotortd.limits.start_position)."""
        params = self._make_params(rotortd)
        omega, f_ext, amb, _t_drive = self._input_values()
        bearing = self._make_bearing(rotortd)
        if bearing is not None and not self.integrate_spin:
            raise rotortd.CrossParameterError(
                "race_turns, support_compliant and contact_compliant need integrate_spin = "
                "true: the real bearing's race brakes or spins up the rotor, which a held "
                "spin cannot show (docs/model.md §10)")
        if self.integrate_spin:  # the spin is a state; Omega is its initial value
            J = float(self.J)
            if self.start_steady:
                return rotortd.SpinCore.on_steady_whirl(
                    params, omega, F_ext=f_ext, amb_on=amb, psi0=float(self.psi0),
                    t0=self._t0, J=J, bearing=bearing)
            return rotortd.SpinCore(
                params, J, z0=complex(float(self.x0), float(self.y0)),
                v0=complex(float(self.vx0), float(self.vy0)), psi0=float(self.psi0),
                Omega0=omega, t0=self._t0, bearing=bearing)
        if self.start_steady:
            return rotortd.TouchdownCore.on_steady_whirl(
                params, omega, F_ext=f_ext, amb_on=amb, psi0=float(self.psi0), t0=self._t0)
        return rotortd.TouchdownCore(
            params, z0=complex(float(self.x0), float(self.y0)),
            v0=complex(float(self.vx0), float(self.vy0)), psi0=float(self.psi0), t0=self._t0)

    def _require_ranges(self, names: tuple[str, ...]) -> None:
        """Raise one ModelError naming every value outside its declared range."""
        found = range_violations((tv.BY_NAME[n] for n in names), self)
        if found:
            raise ModelError("; ".join(found))

    def _check_impact_log(self) -> None:
        """An impact log that cannot be written is refused at initialisation, not at the
        first impact."""
        path = str(self.impact_log)
        if not path:
            return
        try:
            self._open_impact_log().close()
        except OSError as exc:
            raise ModelError(f"impact_log = {path!r} cannot be written: {exc}") from exc

    def _open_impact_log(self) -> Any:
        """The impact log opened for appending, with its header if it was empty."""
        fh = open(str(self.impact_log), "a", encoding="utf-8")  # noqa: SIM115
        if fh.tell() == 0:
            fh.write(IMPACT_LOG_HEADER)
        return fh

    def _make_params(self, rotortd: Any) -> Any:
        kwargs = {f.name: float(getattr(self, f.name)) for f in fields(rotortd.RotorParams)
                  if f.name != "levitate"}
        return rotortd.RotorParams(levitate=bool(self.levitate), **kwargs)

    def _make_bearing(self, rotortd: Any) -> Any:
        """The real bearing's options (``rotortd.BearingParams``), None when all are off
        (the chapter's fixed rigid bearing). d = 0 under the compliant law is refused as a
        cross-parameter constraint (CrossParameterError, from ``BearingParams.check``)."""
        kwargs = {f.name: getattr(self, f.name) for f in fields(rotortd.BearingParams)}
        bp = rotortd.BearingParams(**{k: bool(v) if isinstance(v, bool) else float(v)
                                      for k, v in kwargs.items()})
        if not bp.any_option:
            return None
        bp.check(float(self.d))  # (the ranges were checked with every parameter's)
        return bp

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
        self._T_only = False
        self._h_taken = math.nan

    def _check_inputs(self) -> None:
        self._require_ranges(INPUTS)

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
            self._require_ranges(tuple(changes))
            import rotortd

            try:
                self._core.set_params(params.replace(**changes))
            except rotortd.CrossParameterError as exc:  # (J with new mu, e_c: ill posed)
                raise ModelError(f"cross-parameter constraint: {exc}") from exc

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
            self._changed = self._T_only = False
        if not 0.0 < step_size < _INF:
            raise ModelError(f"communication step size {step_size!r} s must be finite "
                             f"and > 0")
        if step_size != self._h_taken:
            step_size = self._host_step(current_time, step_size)
        t = core.t
        tol = _time_tolerance(current_time, step_size)
        if not abs(current_time - t) <= tol:  # also refuses a NaN or infinite time
            raise ModelError(f"communication point {current_time!r} does not match the "
                             f"model time {t!r}")
        omega, f_ext, amb, t_drive = self._step_inputs  # validated by _check_changes
        t_target = t + step_size
        if self._spin_state:
            rep = core.step(step_size, F_ext=f_ext, amb_on=amb, T_drive=t_drive)
        else:
            rep = core.step(step_size, omega, f_ext, amb)
        if self.impact_log and rep.impacts:
            self._append_impacts(rep.impacts)
        # (the spin: the held input or the core's state)
        events = bool(rep.impacts or rep.transitions)
        total = self._publish_state(None, amb, events) + self._publish_step_outputs(rep)
        if self._race_outputs:  # a real bearing (docs/model.md §10)
            total += self._publish_race(rep)
        if total - total != 0.0:  # inf or NaN somewhere (or an overflowing sum: checked)
            self._refuse_non_finite()
        self._h_taken = step_size
        if rep.status == 0 and abs(core.t - t_target) <= tol:
            if not events:  # the quiet lane, if the state is in it
                self._lane = core.quiet_lane(step_size, CLOCK_STEPS * step_size)
            return True  # the common case, without a call
        return self._judge_report(rep, t_target, tol)

    def do_step(self, current_time: float, step_size: float) -> bool:
        """A step in the core's quiet lane (``TouchdownCore.quiet_lane``) while it is held,
        else the guarded step (``GuardedSlave.do_step`` -> ``_step``). The lane is held
        after a completed step without events whose state it takes, and dropped by any FMI
        setter (``_changed``; with the spin a state, a setter of T_drive alone is taken by
        the lane: ``_spin_lane_do_step``), a failure or terminate (``_fail``, ``terminate``)
        and by a step it declines (another step size, a host clock off the model time, the
        core changed, a step not proved clear); so a lane step needs none of ``_step``'s
        checks: its inputs and parameters are those the last step validated, and the lane
        checks h and the clock itself."""
        lane = self._lane
        if lane is not None:
            if self._spin_state:
                if not self._changed or self._T_only:
                    return self._spin_lane_do_step(lane, current_time, step_size)
            elif not self._changed:
                try:
                    quiet = lane(self._core, current_time, step_size if step_size ==
                                 self._h_taken else self._host_step(current_time, step_size))
                    if quiet is not None:
                        out, self._quiet.T_imb = quiet
                        self._publish(self, out, False)
                        total = sum(out) + self._publish_step_outputs(self._quiet)
                        if total - total != 0.0:
                            self._refuse_non_finite()
                        return True
                except Exception as exc:
                    self._step_failed(current_time, step_size, exc)
                    return False
            self._lane = None
        return GuardedSlave.do_step(self, current_time, step_size)

    def _spin_lane_do_step(self, lane: Any, current_time: float, step_size: float) -> bool:
        """``do_step`` in the spin state's quiet lane (``TouchdownCore.quiet_lane`` with the
        spin a state) under the drive torque of the step, publishing as the held lane does;
        the guarded step when the lane declines. When T_drive alone was set since the last
        step (``_T_only``: a drive controller's every step) it is taken here if it lies in
        its declared range, as ``_check_changes`` would; else the guarded step checks it and
        says what is wrong."""
        try:
            if self._changed:
                T = self.T_drive
                if not self._T_range[0] <= T <= self._T_range[1]:  # (NaN: not)
                    self._lane = None
                    return GuardedSlave.do_step(self, current_time, step_size)
                self._step_inputs = (*self._step_inputs[:3], float(T))
                self._seen_inputs = None  # (the next change re-checks every input)
                self._changed = self._T_only = False
            quiet = lane(self._core, current_time, step_size if step_size == self._h_taken
                         else self._host_step(current_time, step_size), self._step_inputs[3])
            if quiet is not None:
                out, self._quiet_spin.T_imb = quiet
                self._publish(self, out, False)
                total = sum(out) + self._publish_step_outputs(self._quiet_spin)
                if total - total != 0.0:
                    self._refuse_non_finite()
                return True
        except Exception as exc:
            self._step_failed(current_time, step_size, exc)
            return False
        self._lane = None
        return GuardedSlave.do_step(self, current_time, step_size)

    def _host_step(self, t: float, step_size: float) -> float:
        """The step to take for the host's step_size at its time t (s): the last one taken
        when they differ by no more than the rounding of the host's clock (HOST_STEP_ULPS
        eps of t or of the step: libcosim's steps of 1e-3 s, differences of times in
        integer ns, jitter by 3e-16 s at t = 2 s), so that a recurring step stays one
        length for the core's caches and the quiet lane; else step_size."""
        h = self._h_taken
        if abs(step_size - h) <= HOST_STEP_ULPS * _EPS * max(abs(t), step_size):
            return h
        return step_size

    def _fail(self, msg: str) -> None:
        """GuardedSlave._fail, and the quiet lane dropped (do_step)."""
        self._lane = None
        super()._fail(msg)

    def terminate(self) -> None:
        """GuardedSlave.terminate, and the quiet lane dropped (do_step)."""
        self._lane = None
        super().terminate()

    def _refuse_non_finite(self) -> None:
        """Raise (the step is refused) if an output is NaN or infinite: no non-finite
        output is ever published with status OK."""
        bad = [f"{n} = {getattr(self, n)!r}" for n in tv.OUTPUTS
               if not math.isfinite(getattr(self, n))]
        if bad:
            raise ModelError(f"non-finite outputs at t = {self._core.t!r} s: {', '.join(bad)}"
                             f"; the model cannot continue")

    def _judge_report(self, rep: Any, t_target: float, tol: float) -> bool:
        """A step the core could not finish (work cap) is refused and reported as an error
        (the instance's first one also on stderr) without failing the instance: the outputs
        show the state where it stopped and the model time stays there (restore a saved FMU
        state or continue from core time). A completed step with a non-OK status is a
        warning."""
        reached = self._core.t
        short = abs(reached - t_target) > tol
        if rep.status == STATUS_WORK_CAP or short:  # an error, but the instance goes on
            self._error(f"step incomplete: core status {rep.status} ({rep.message}); model "
                        f"time stays at t={reached!r} instead of {t_target!r}")
            return False
        if rep.status != 0:
            self.log(f"t={reached!r}: core status {rep.status}: {rep.message}",
                     Fmi2Status.warning)
        return True

    # ------------------------------------------------------------------ publishing
    def _publish_state(self, omega: float | None, amb: float, events: bool = True) -> float:
        """Publish what the state shows (``TouchdownCore.output_values``: kinematics, spin
        speed, mode, counters) for the spin speed omega (None: the core's own) and amb;
        return their sum (inf or NaN if any is). The mode and the impact counters change
        only with ``events`` (impacts or mode changes in the step); E_diss also in a
        contact segment (mode != 0)."""
        out = self._core.output_values(omega, amb)
        self._publish(self, out, events)  # (state_publisher: by name from the table)
        return sum(out)

    def _publish_step_outputs(self, rep: Any) -> float:
        """Publish what the step report shows (its averages, its impact count; zeros before
        the first step, rep None); return the sum of the averages (inf or NaN if any is)."""
        if rep is None:
            self.F_bx = self.F_by = self.F_n = self.F_n_peak = self.P_n = self.T_f = 0.0
            self.T_imb = self.F_sx = self.F_sy = self.P_fric = 0.0
            self.n_impacts_step = 0
            return self._publish_race(None)
        F = rep.F_contact
        self.F_bx = fx = F.real
        self.F_by = fy = F.imag
        self.F_n = F_n = rep.F_n
        self.F_n_peak = peak = rep.F_n_peak
        self.P_n = P_n = rep.P_n
        self.T_f = T_f = rep.T_f
        self.T_imb = T_imb = rep.T_imb
        self.n_impacts_step = len(rep.impacts)
        self.F_sx, self.F_sy = -fx, -fy  # the fixed bearing passes the contact force on
        return fx + fy + F_n + peak + P_n + T_f + T_imb

    def _publish_race(self, rep: Any) -> float:
        """Publish the real bearing's outputs after ``_publish_step_outputs`` (zeros for the
        fixed bearing; its F_sx, F_sy are -F_contact); return their sum (for the non-finite
        check)."""
        race = None if self._core is None else self._core.race
        if race is None:
            self.omega_b = self.x_b = self.y_b = self.vx_b = self.vy_b = 0.0
            self.E_fric = self.E_drag = 0.0
            return 0.0
        self.omega_b = race.omega_b
        self.x_b, self.y_b = race.z_b.real, race.z_b.imag
        self.vx_b, self.vy_b = race.v_b.real, race.v_b.imag
        self.E_fric, self.E_drag = race.E_fric, race.E_drag
        if rep is not None:
            self.F_sx, self.F_sy = rep.F_support.real, rep.F_support.imag
            self.P_fric = rep.P_fric
        return (self.omega_b + self.x_b + self.y_b + self.vx_b + self.vy_b + self.E_fric
                + self.E_drag + self.F_sx + self.F_sy + self.P_fric)

    def _append_impacts(self, impacts: list[Any]) -> None:
        with self._open_impact_log() as fh:
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
                            "fixed_snapshot": self._fixed_snapshot},
            }
            # JSON round trip: an independent deep copy, and proof that it serialises.
            return json.loads(json.dumps(state))
        except Exception as exc:
            self._error(f"getFMUstate failed: {exc}")
            return {"schema": STATE_SCHEMA, "version": STATE_VERSION, "invalid": str(exc)}

    def _set_fmu_state(self, state: dict[str, Any]) -> None:
        """Restore a state, all or nothing. A state that cannot be restored should get
        fmi2Error, which PythonFMU cannot return: the call returns OK, the current state is
        kept untouched, and the instance fails (the next do_step is refused), as after
        fmi2Error; restoring a valid state afterwards makes it usable again."""
        try:
            self._restore(state)
        except KeyError as exc:
            self._fail(f"setFMUstate failed: the state is incomplete, key {exc} is missing")
        except Exception as exc:
            self._fail(f"setFMUstate failed: {exc}")

    def _restore(self, state: dict[str, Any]) -> None:
        if not isinstance(state, dict) or state.get("schema") != STATE_SCHEMA:
            raise ModelError("not a rotortd FMU state (schema mismatch)")
        if state.get("version") not in (1, 2, STATE_VERSION):
            raise ModelError(f"unsupported FMU state version {state.get('version')!r}")
        if state["version"] == 1 and state.get("adapter", {}).get("spin") is not None:
            raise ModelError("the state was saved by the former sub-stepped spin coupler "
                             "(FMU state version 1 with integrate_spin); it cannot be "
                             "restored into the exact spin state of version 2")
        if "invalid" in state:
            raise ModelError(f"the saved state is invalid: {state['invalid']}")
        known = {v.name for v in self.vars.values()}
        values = state["variables"]
        if isinstance(values, dict) and state["version"] < 3:  # before the real bearing
            values = {**{n: tv.BY_NAME[n].start for n in tv.REAL_BEARING}, **values}
        if not isinstance(values, dict) or set(values) != known:
            raise ModelError("FMU state does not list exactly this model's variables")
        core_state, adapter = state["core"], state["adapter"]
        core = None
        if core_state is not None:  # built aside: a bad core state changes nothing
            import rotortd

            core = rotortd.restore_core(copy.deepcopy(core_state))
            if bool(values["integrate_spin"]) != core.spin_is_state:
                raise ModelError("the core state does not match integrate_spin")
            real = any(bool(values[n]) for n in ("race_turns", "support_compliant",
                                                  "contact_compliant"))
            if real != (core.race is not None):
                raise ModelError("the core state does not match the bearing's options")
        t0, failure = float(adapter["t0"]), str(adapter["failure"])
        fixed_snapshot = dict(adapter["fixed_snapshot"])
        self._core = core
        if core is not None:
            self._spin_state = core.spin_is_state
            self._race_outputs = core.race is not None
            self._publish = state_publisher(core.outputs()._fields)
        for name, value in values.items():
            setattr(self, name, value)
        self._t0, self._failure, self._fixed_snapshot = t0, failure, fixed_snapshot
        self._forget_checks()

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
