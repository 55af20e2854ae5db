"""The event-driven simulator: exact flight, located impacts, sustained contact.

Frame and units: inertial, SI, unless a name says otherwise. One core, ``TouchdownCore``,
for the one model: the rotor is a rigid body with polar inertia J whose spin is a state
(docs/model.md §8); the held-spin rotor is its J = inf case, with Omega an input of each
step (docs/model.md §1-§7). ``TouchdownCore.step`` advances the rotor by one communication
step with its inputs held (F_ext, a, and Omega with the spin held or T_drive with the spin
a state) and returns a ``StepReport``. The story it resolves:

    free flight -> impacts -> chattering -> sliding <-> rolling -> lift-off -> free flight

One step loop (``_segments``) strings the segments together; each segment is chosen where
the last ended. The segment choices live in mixins, by job: ``flight_step.FlightSteps``
(free flight, the contact search, impacts and the low-speed rule), ``contact_step.
ContactSteps`` (sustained contact: the mode choice, lift-off, sliding, rolling, the rub in
closed form, the lock), both the held spin's declared accelerators (closed-form flight
and rolling, the rub), and ``spin_step.SpinSteps``, bound in their place when the spin is
a state (``_bind_rotor``). ``SpinCore`` is this core with J required. The report and the
step context are in ``report``, the state record in ``state``.
"""

from __future__ import annotations

import cmath
import math

from ..bodies.bearing import FixedRigidBearing
from ..bodies.race import BearingParams, RealRace
from ..bodies.rotor import RigidRotor, check_well_posed
from ..contact.pair import ContactPair
from ..contact.search import SEGMENT_WORK, WORK_MAX
from ..contact.wall import ContactWorkExceeded, WallForces, phase_integral
from ..limits import CrossParameterError, start_position
from ..params import InputError, ParameterError, RotorParams, check_finite, check_range
from ..scaled import TWO_PI_HI, TWO_PI_LO, to_inertial, wrap_angle
from ..segments.bearing_contact import ContactState
from ..segments.dry_whirl_orbit import Orbit, orbit_key
from ..segments.flight import FlightModel
from ..segments.rub import RubEquilibrium
from ..segments.spin_contact import OrbitLike
from ..segments.spin_quiet import QuietSpinStep
from .bearing_step import BearingSteps
from .contact_step import LOCK_TOL, RUB_RETRY, ContactSteps
from .flight_step import ETA_HEIGHT, ETA_TIME, N_CASCADE, FlightSteps
from .report import (
    _MODE_NAMES,
    _PROVED_FREE,
    _RUB,
    _SEGMENT_NAMES,
    MODE_FREE,
    MODE_ROLLING,
    MODE_SLIDING,
    N_KINEMATICS,
    STATUS_OK,
    STATUS_WORK_CAP,
    Kinematics,
    StateOutputs,
    StepContext,
    StepReport,
    WorkCapExceeded,
    stop_at_work_bound,
    work_cap,
)
from .spin_step import SpinSteps
from .state import CoreState, fixed_bearing_record

__all__ = [
    "ETA_HEIGHT", "ETA_TIME", "LOCK_TOL", "MODE_FREE", "MODE_ROLLING", "MODE_SLIDING",
    "N_CASCADE", "RUB_RETRY", "STATUS_OK", "STATUS_WORK_CAP", "WORK_MAX", "Kinematics",
    "SpinCore", "StateOutputs", "StepReport", "TouchdownCore", "WorkCapExceeded",
    "restore_core", "work_cap",
]
INF = math.inf
_NEG_PI = -math.pi


class TouchdownCore(FlightSteps, ContactSteps, SpinSteps, BearingSteps):
    """Rotor in a touchdown bearing, advanced step by step (see the module docstring).

    J (kg m^2, > 0): the polar inertia about the mass centre; inf (the default) holds the
    spin (Omega an input of each step), a finite J makes it a state starting at Omega0
    (rad/s; CrossParameterError when J is too small for the contact to be well posed).
    z0 (m), v0 (m/s): the rotor centre's start (inertial); psi0 (rad) the spin angle;
    t0 (s) the clock. ``bearing``: the real touchdown bearing's options (docs/model.md §10;
    ``bodies.race.BearingParams``); None or all options off is the chapter's fixed rigid
    bearing. The options need the spin as a state (J finite)."""

    _race: RealRace | None = None  # the real bearing's race (None: the fixed rigid one)
    _pair: ContactPair | None = None  # the contact pair, built for _pair_of (params, J)
    _pair_of: tuple[RotorParams, float] | None = None

    def __init__(
        self,
        params: RotorParams,
        *,
        J: float = INF,
        z0: complex = 0j,
        v0: complex = 0j,
        psi0: float = 0.0,
        Omega0: float = 0.0,
        t0: float = 0.0,
        bearing: BearingParams | None = None,
    ) -> None:
        z0, v0 = complex(z0), complex(v0)
        for name, val in (
            ("x0", z0.real),
            ("y0", z0.imag),
            ("vx0", v0.real),
            ("vy0", v0.imag),
            ("psi0", psi0),
            ("Omega0", Omega0),
            ("t0", t0),
        ):
            check_finite(name, val)
        self._J = INF
        if J != INF:  # (a NaN too: check_range names it)
            self._J = check_range("J", J, 0.0, lo_open=True, unit="kg m^2")
            check_well_posed(params, self._J)
        z0 = start_position(z0, params.c_r)
        self._p = params
        self._t = float(t0)
        self._t_lo = 0.0  # compensation of the clock (Kahan), s
        self._z, self._v = z0, v0  # the state in flight (m, m/s); in contact: _theta, _dtheta
        self._psi, self._turns = wrap_angle(float(psi0)), 0
        self._turns = round((float(psi0) - self._psi) / TWO_PI_HI)
        self._mode = MODE_FREE
        self._theta = 0.0
        self._dtheta = 0.0
        self._slip = 0.0
        self._locked = False
        self._on_wall = abs(z0) >= params.c_r * (1.0 - 1e-15)
        self._forget_clear_proof()
        self._n_impacts = 0
        self._t_last = 0.0
        self._v_last = 0.0
        self._E_diss = 0.0
        self._t_contact = math.nan
        self._slide_step = math.inf
        self._orbit: OrbitLike = None  # rolling with the spin a state: its dry whirl orbit
        # (or level table, ``dry_whirl_driven``: not part of the state, a function of it)
        self._quiet_spin: QuietSpinStep | None = None  # the spin state's quiet step (a cache)
        self.imbalance_torque = True
        """Compute the imbalance reaction torque (StepReport.P_imb, T_imb) with the spin
        held. False skips that work (5 to 7 % of the core's instructions in the limit-cycle
        and chattering benchmark scenes) and reports NaN; the motion is the same to the last
        bit. A setting of the object, not of the
        state (get_state and set_state leave it as it is)."""
        self._set_inputs(float(Omega0), 0j, 1.0)  # the flight and wall models of the inputs
        if bearing is not None and bearing.any_option:
            self._use_bearing(bearing)
        self._bind_rotor()

    def _use_bearing(self, bp: BearingParams) -> None:
        """Put the rotor in the real bearing ``bp`` (its race at rest at the origin,
        turning at omega_b0)."""
        if self._J == INF:
            raise CrossParameterError(
                "the real bearing's options (race_turns, support_compliant, "
                "contact_compliant) need the spin as a state (a finite J): a held spin "
                "would make the race's catching up, which brakes the rotor, do no work on it")
        bp.check(self._p.d)
        self._race = RealRace(bp, c_r=self._p.c_r, R=self._p.R)
        self._law = self._bearing_law()
        self._c_d = self._bearing_c_d()
        self._cstate = ContactState(1.0)

    _SPIN_STATE_CHOICES = (("step", "_spin_step"), ("_advance_free", "_spin_advance_free"),
                           ("_advance_contact", "_spin_advance_contact"),
                           ("_advance_spin", "_spin_advance_spin"),
                           ("_roll_or_slide", "_spin_roll_or_slide"),
                           ("_cone_sign", "_spin_cone_sign"),
                           ("quiet_lane", "_spin_quiet_lane"))
    """The choices bound in place of the held spin's when the spin is a state."""
    _BEARING_CHOICES = (("_advance_free", "_bearing_advance_free"),
                        ("_advance_contact", "_bearing_advance_contact"),
                        ("_wall_state", "_bearing_wall_state"),
                        ("_spin_quiet_step", "_bearing_quiet_step"),
                        ("output_values", "_bearing_output_values"))
    """The choices bound in place of the fixed bearing's when a real bearing's option is on
    (after the spin state's)."""

    def _bind_rotor(self) -> None:
        """Bind the segment choices of the rotor's spin model: the held spin's are the
        class's own (FlightSteps, ContactSteps); with the spin a state (J finite) the
        instance takes SpinSteps' in their place (``_SPIN_STATE_CHOICES``: its step entry
        and segment choices), and with a real bearing BearingSteps' after them
        (``_BEARING_CHOICES``), for the same step loop."""
        for name, _ in self._SPIN_STATE_CHOICES + self._BEARING_CHOICES:
            self.__dict__.pop(name, None)
        choices = () if self._J == INF else self._SPIN_STATE_CHOICES
        if self._race is not None:
            choices += self._BEARING_CHOICES
        for name, choice in choices:
            setattr(self, name, getattr(self, choice))

    @classmethod
    def from_scaled(
        cls,
        params: RotorParams,
        Omega: float,
        *,
        U0: complex = 0j,
        dU0: complex = 0j,
        psi0: float = 0.0,
        t0: float = 0.0,
    ) -> TouchdownCore:
        """Start from the scaled co-rotating state: z = c_r U e^{i psi}, dU/dt, t = Omega tau."""
        W = check_finite("Omega", Omega)
        if W == 0.0:
            raise ParameterError("Omega = 0.0 rad/s: a scaled initial state needs Omega != 0")
        z0, v0 = to_inertial(U0, dU0, W, params.c_r, psi0)
        return cls(params, z0=z0, v0=v0, psi0=psi0, Omega0=W, t0=t0)

    @classmethod
    def on_steady_whirl(
        cls,
        params: RotorParams,
        Omega: float,
        *,
        F_ext: complex = 0j,
        amb_on: float = 1.0,
        psi0: float = 0.0,
        t0: float = 0.0,
        J: float = INF,
        bearing: BearingParams | None = None,
    ) -> TouchdownCore:
        """Start on the steady free whirl z = Z0 + Z1 e^{i psi} (the regular equilibrium U*)
        of the held spin Omega (rad/s); with J finite the spin is a state starting there
        (``bearing``: a real bearing's options, its race at rest at the origin).

        Raises ParameterError when it does not exist (no stiffness, undamped resonance) or
        is not admissible (it leaves the clearance).
        """
        fm = FlightModel(
            params,
            check_finite("Omega", Omega),
            complex(F_ext),
            check_range("amb_on", amb_on, 0.0, 1.0),
        )
        den = complex(fm.kappa - fm.Omega**2, fm.beta * fm.Omega)
        if fm.kappa <= 0.0 or den == 0:
            raise CrossParameterError(
                "start_steady: no steady whirl exists without stiffness (k*amb_on > 0) "
                "or at undamped resonance (c = 0 and Omega^2 = k/m)"
            )
        E0 = cmath.exp(1j * psi0)
        Z0, Z1 = fm.f0 / fm.kappa, fm.F1 * E0 / den
        if abs(Z0) + abs(Z1) >= params.c_r:
            raise CrossParameterError(
                f"start_steady: the steady whirl is not admissible, its radius reaches "
                f"|Z0| + |Z1| = {(abs(Z0) + abs(Z1)) / params.c_r:.6g} c_r; it must be < 1 c_r"
            )
        return cls(params, J=J, z0=Z0 + Z1, v0=1j * fm.Omega * Z1, psi0=psi0, Omega0=Omega,
                   t0=t0, bearing=bearing)

    # ------------------------------------------------------------------ state access

    @property
    def params(self) -> RotorParams:
        """Current parameters."""
        return self._p

    @property
    def J(self) -> float:
        """Polar inertia about the mass centre (kg m^2); inf with the spin held."""
        return self._J

    @property
    def race(self) -> RealRace | None:
        """The real bearing's race (``bodies.race.RealRace``: its centre, spin, heats);
        None for the chapter's fixed rigid bearing."""
        return self._race

    @property
    def spin_is_state(self) -> bool:
        """The spin speed is a state (J finite) or a held input (J = inf)."""
        return self._J != INF

    @property
    def Omega(self) -> float:
        """Spin speed (rad/s): the state, or the last held input."""
        return self._inputs[0]

    @property
    def contact_pair(self) -> ContactPair:
        """The rotor (``bodies.rotor.RigidRotor`` with this J; inf: the held spin) and the
        bearing it touches (the chapter's ``bodies.bearing.FixedRigidBearing``): gap,
        normal, speeds, W, impact law."""
        p, J = self._p, self._J
        key = self._pair_of
        if self._race is not None:
            return ContactPair(RigidRotor(p.m, J, p.e_c, p.phi, p.R), self._race)
        if key is None or key[0] is not p or key[1] != J:
            self._pair = ContactPair(RigidRotor(p.m, J, p.e_c, p.phi, p.R),
                                     FixedRigidBearing(c_r=p.c_r))
            self._pair_of = (p, J)
        assert self._pair is not None
        return self._pair

    def set_params(self, params: RotorParams) -> None:
        """Change parameters (tunables); takes effect from the next step (the spin, held
        or a state, is kept)."""
        if params.c_r != self._p.c_r:
            raise ParameterError("c_r is fixed after initialisation; it cannot change mid-run")
        if self._J != INF:
            check_well_posed(params, self._J)
        if self._race is not None:
            self._race.bp.check(params.d)  # (d = 0 under the compliant law)
        self._p = params
        if self._race is not None:
            self._c_d = self._bearing_c_d()  # the compliant law's damping follows d
        self._set_inputs(*self._inputs)  # rebuilds the models; forgets the proof and the lock

    @property
    def t(self) -> float:
        """Time (s)."""
        return self._t

    @property
    def z(self) -> complex:
        """Position of the rotor centre (m), inertial."""
        return self._wall_state()[0] if self._mode else self._z

    @property
    def v(self) -> complex:
        """Velocity of the rotor centre (m/s), inertial."""
        return self._wall_state()[1] if self._mode else self._v

    @property
    def psi(self) -> float:
        """Spin angle (rad), unwrapped."""
        return self._turns * TWO_PI_HI + (self._psi + self._turns * TWO_PI_LO)

    @property
    def mode(self) -> int:
        """0 free, 1 sliding, 2 rolling."""
        return self._mode

    @property
    def n_impacts(self) -> int:
        """Impacts so far."""
        return self._n_impacts

    @property
    def t_last_impact(self) -> float:
        """Time of the last impact (s); 0 before any."""
        return self._t_last

    @property
    def v_last_impact(self) -> float:
        """Normal speed rdot- of the last impact (m/s); 0 before any."""
        return self._v_last

    @property
    def E_diss(self) -> float:
        """Energy dissipated by contact so far (J)."""
        return self._E_diss

    @property
    def t_contact_entry(self) -> float:
        """Estimated accumulation point (s) of the last chattering that became contact.

        The plastic impact time plus the geometric remainder 2 d v/((1-d) A) for d < 1,
        the impact time for d = 1; NaN before any.
        """
        return self._t_contact

    def kinematics(self, Omega: float | None = None, amb_on: float | None = None) -> Kinematics:
        """Derived outputs at the current state, for the given (or last) inputs."""
        return Kinematics._make(self.output_values(Omega, amb_on)[:N_KINEMATICS])

    def outputs(self, Omega: float | None = None, amb_on: float | None = None) -> StateOutputs:
        """Everything an FMU publishes of the current state: the kinematics for the given
        (or last) inputs, the spin speed and the counters (``StateOutputs``)."""
        return StateOutputs._make(self.output_values(Omega, amb_on))

    def output_values(
        self, Omega: float | None = None, amb_on: float | None = None
    ) -> tuple[float, ...]:
        """The fields of ``outputs`` as a plain tuple, in the same order (cheaper): what
        the state shows, as the step report shows what happened over the step."""
        W = self._inputs[0] if Omega is None else Omega
        a = self._inputs[2] if amb_on is None else amb_on
        mode = self._mode
        if mode:  # in contact the state is (theta, theta')
            z, v = self._wall_state()
        else:
            z, v = self._z, self._v
        p, psi = self._p, self._psi
        c_r = p.c_r
        # scaled.to_scaled inline, bit for bit (test_scaled.py): e^{-i psi} = conj(e^{i psi})
        rot = self._phasor().conjugate()
        U = z * rot
        den = c_r * W
        dU = (v - 1j * W * z) * rot / den if den != 0.0 else 0j
        if dU - dU != 0j:  # (an infinite or NaN part: inf - inf is NaN)
            dU = 0j
        r = abs(z)
        rr = r * r
        whirl = (z.real * v.imag - z.imag * v.real) / rr if rr > 0.0 else (
            ((z.real * v.imag - z.imag * v.real) / r) / r if r > 0.0 else 0.0)
        bias, c, k = self._bias_force, p.c, p.k  # (RotorParams.amb_force inline, by parts)
        return (
            z.real, z.imag, v.real, v.imag, r / c_r, U.real / c_r, U.imag / c_r,
            dU.real, dU.imag, -psi if psi == _NEG_PI else psi, whirl,
            p.R * W + c_r * whirl, a * (bias.real - c * v.real - k * z.real),
            a * (bias.imag - c * v.imag - k * z.imag),
            W, mode, self._n_impacts, self._t_last, self._v_last, self._E_diss,
        )

    # ------------------------------------------------------------------ stepping

    def step(self, h: float, Omega: float | None = None, F_ext: complex = 0j,
             amb_on: float = 1.0, budget: int | None = None, *,
             T_drive: float = 0.0) -> StepReport:
        """Advance by h seconds with F_ext (N) and amb_on held, and Omega (rad/s) held with
        the spin held, or T_drive (N m) held with the spin a state (Omega is then ignored;
        a drive torque on a held spin is refused, InputError).

        The step's work is bounded by ``budget`` work units (default and at most WORK_MAX).
        A step that would need more stops where it is with STATUS_WORK_CAP and a message
        saying where (docs/model.md 7)."""
        if self._J != INF:  # (an instance with the spin a state has step bound to it)
            return self._spin_step(h, Omega, F_ext, amb_on, budget, T_drive=T_drive)
        if T_drive or Omega is None:
            self._reject_held_spin_inputs(Omega, T_drive)
        F = complex(F_ext)
        if (Omega, F, amb_on) != self._inputs:  # new held inputs (NaN never equals)
            if not (math.isfinite(Omega) and 0.0 <= amb_on <= 1.0
                    and math.isfinite(F.real) and math.isfinite(F.imag)):
                self._reject_inputs(h, Omega, F, amb_on)
            self._set_inputs(float(Omega), F, float(amb_on))
        if not 0.0 < h < math.inf:
            self._reject_inputs(h, Omega, F, amb_on)
        cap = WORK_MAX if budget is None else max(0, min(budget, WORK_MAX))
        rep = StepReport()  # (then work_cap: a keyword argument costs 110 ns)
        rep.work_cap = cap
        t0, s = self._t, h
        whole = self._whole_step(h, rep)  # choose: the whole step in one closed form?
        if whole is None:  # else segment by segment, each chosen where the last ended
            imb = self.imbalance_torque
            start = self._imb_start() if imb else None
            st = StepContext(cap, self._mode == MODE_SLIDING)
            s = self._segments(h, t0, rep, st)
            if imb and not st.imb_whole:
                self._imb_close(rep, start, s)
        self._finish(rep, t0, s, h, whole is not _PROVED_FREE)
        return rep

    def _whole_step(self, h: float, rep: StepReport) -> str | None:
        """The step's first choice: a whole step in one closed form, advanced and tallied
        into ``rep``: _PROVED_FREE (a flight proved clear of the wall, nothing to tally) or
        _RUB (a rub in closed form); None when the state admits neither (the step is
        taken segment by segment; a sliding state refused here is not asked again)."""
        if self._mode == MODE_FREE:
            return _PROVED_FREE if self._proved_free_step(h, rep) else None
        if self._mode == MODE_SLIDING:
            return _RUB if self._rub_step(h, rep) else None
        return None

    def _segments(self, h: float, t0: float, rep: StepReport, st: StepContext) -> float:
        """The step loop, one for every core: choose the next segment from the state,
        advance it, apply its end (``_advance``), until the step is done or its work bound
        is reached. Returns how far (s) into the step it got."""
        work, cap, s = st.work, st.cap, 0.0
        try:
            while s < h:
                if work.total > cap:
                    raise WorkCapExceeded("before the next segment")
                work.segs += SEGMENT_WORK
                mode = self._mode
                s = self._advance(s, h, t0, rep, st)
                st.first = False
                if self._mode != mode:
                    rep.transitions.append((t0 + s, _MODE_NAMES[self._mode]))
        except (WorkCapExceeded, ContactWorkExceeded) as exc:
            spin = " with the spin as a state" if self._J != INF else ""
            stop_at_work_bound(rep, st, exc, t0, s, h, (
                f"{_SEGMENT_NAMES[self._mode]}{spin} (segment {work.segs // SEGMENT_WORK}, "
                f"{len(rep.impacts)} impacts in the step)"))
        rep.work = work.total
        return s

    def _finish(self, rep: StepReport, t0: float, s: float, h: float, tallied: bool) -> None:
        """The one place a step ends: advance the clock to where the step got (s of h) and
        turn the report's impulses into step averages (not after a flight proved free,
        whose report holds nothing to average). The clock is advanced with compensated
        summation (Kahan; no drift over 1e6 steps)."""
        y = (h if s >= h else s) - self._t_lo
        t = self._t + y
        self._t_lo = (t - self._t) - y
        self._t = t
        if tallied:
            self._fill_report(rep, self._t - t0 if s < h else h)

    @staticmethod
    def _reject_held_spin_inputs(Omega: float | None, T_drive: float) -> None:
        """Raise the InputError of a held-spin step given no Omega or a drive torque."""
        if Omega is None:
            raise InputError("Omega is missing: the spin is held (J = inf), so each step "
                             "needs the spin speed Omega (rad/s)")
        raise InputError(f"T_drive = {T_drive!r} N m: the spin is held (J = inf), a drive "
                         f"torque has no effect on it; make the spin a state (J finite) "
                         f"or pass T_drive = 0")

    @staticmethod
    def _reject_inputs(h: float, Omega: float, F: complex, amb_on: float) -> None:
        """Raise the InputError that names the first invalid input of a step."""
        check_range("h", h, 0.0, lo_open=True, error=InputError, unit="s")
        check_finite("Omega", Omega, InputError)
        check_finite("F_x", F.real, InputError)
        check_finite("F_y", F.imag, InputError)
        check_range("amb_on", amb_on, 0.0, 1.0, error=InputError)

    def _set_inputs(self, W: float, F: complex, a: float) -> None:
        """New held inputs (or parameters): rebuild the flight and wall models."""
        self._inputs: tuple[float, complex, float] = (W, F, a)
        self._fm = FlightModel(self._p, W, F, a)
        self._bias_force = self._p.bias_force  # (N; output_values, every FMU step)
        self._imb_free_h = math.nan  # FlightSteps._imb_flight: for this flight model
        self._imb_seen_h = math.nan
        self._imb_free: tuple[complex, complex, complex, float] = (0j, 0j, 0j, 0.0)
        self._imb_pint = (math.nan, 0j)  # _imb_close: (dur, int_0^dur e^{i Omega u} du)
        self._wf = WallForces.build(self._p, W, F, a)
        self._rub_eqs: list[RubEquilibrium] | None = None  # forward_rub_equilibria, lazily
        self._forget_clear_proof()
        self._locked = False

    def _fill_report(self, rep: StepReport, h: float) -> None:
        """Averages over h (s) of the impulses the step added to ``rep``."""
        inv = 1.0 / h if h > 0.0 else 0.0
        rep.F_contact = rep.P_contact * inv
        rep.F_n = rep.P_n * inv
        rep.T_f = -self._p.R * rep.P_t * inv
        if self._race is not None:
            rep.F_support, rep.P_fric = rep.P_support * inv, rep.E_fric * inv
        if self.imbalance_torque:
            rep.T_imb = rep.P_imb * inv
        else:
            rep.P_imb = rep.T_imb = math.nan
        self._E_diss += rep.E_diss

    # ------------------------------------------------------------------ imbalance torque
    # P_imb = int e_c Im(conj(F_amb + F_ext + F_c) E) dt, E = e^{i(psi + phi)}, held Omega
    # (docs/model.md 9). A step that is one flight (proved free, or searched and finding
    # nothing) takes it in closed form (FlightModel.imb_impulse); every other step by the
    # identity m z'' = F_amb + F_ext + F_c + G + m e_c Omega^2 E (G = -i m g), integrated
    # by parts (z' may jump: impacts are included as impulses):
    #   P_imb = e_c m ([B]_0^h - Omega^2 Im int conj(z) E dt) - e_c Im(conj(G) int E dt),
    #   B = Im(conj(z') E) - Omega Re(conj(z) E)   (_imb_boundary),
    # with int conj(z) E dt = sum over the segments of e^{i phi} E_seg conj(K_seg),
    # K_seg = int z e^{-i Omega u} du from the segment's start (_imb_add): from the ends
    # of a flight (closed form near resonance), closed form in rolling and the rub, the
    # error-controlled auxiliary quadrature in sliding.

    def _imb_start(self) -> tuple[int, complex, complex, float, float, float]:
        """The state now, as _imb_boundary takes it (a step's start, for _imb_close)."""
        return self._mode, self._z, self._v, self._theta, self._dtheta, self._psi

    def _imb_boundary(self, mode: int, z: complex, v: complex, theta: float, dtheta: float,
                      psi: float, A: complex | None = None) -> float:
        """B (m^2/s), the identity's boundary term Im(conj(z') A) - Omega Re(conj(z) A),
        A = e^{i(psi + phi)}, of a state: (z, v) in flight; on the wall (mode != 0;
        z = c_r e^{i theta}, z' = i theta' z) B = -(theta' + Omega) c_r cos(psi + phi -
        theta); ``A`` is e^{i(psi + phi)} when the caller has it."""
        W, phi = self._inputs[0], self._p.phi
        if mode:
            return -(dtheta + W) * self._p.c_r * math.cos(psi + phi - theta)
        if A is None:
            A = cmath.exp(1j * (psi + phi))
        return (v.conjugate() * A).imag - W * (z.conjugate() * A).real

    def _imb_add(self, rep: StepReport, E: complex, K: complex) -> None:
        """Add a segment's term -e_c m Omega^2 Im(e^{i phi} E conj(K)) (N m s) to P_imb: K =
        int z e^{-i Omega u} du (m s) over the segment, E = e^{i psi} at its start."""
        if K != 0:
            p, W = self._p, self._inputs[0]
            rep.P_imb -= p.e_c * p.m * W * W * (self._fm.imb_eph * E * K.conjugate()).imag

    def _imb_close(self, rep: StepReport,
                   start: tuple[int, complex, complex, float, float, float], dur: float
                   ) -> None:
        """Add the identity's boundary and gravity terms (N m s) of a step that started in
        ``start`` (``_imb_start``) and lasted dur seconds to P_imb: e_c m (B1 - B0) -
        e_c Im(conj(-i m g) e^{i(psi0 + phi)} int_0^dur e^{i Omega u} du)."""
        p = self._p
        A0 = cmath.exp(1j * (start[5] + p.phi))
        P = p.m * (self._imb_boundary(*self._imb_start()) - self._imb_boundary(*start, A0))
        if p.g != 0.0:  # conj(-i m g) = i m g: Im(i m g X) = m g Re(X)
            if self._imb_pint[0] != dur:
                self._imb_pint = (dur, phase_integral(self._inputs[0], dur))
            P -= p.m * p.g * (A0 * self._imb_pint[1]).real
        rep.P_imb += p.e_c * P

    def _advance(self, s: float, h: float, t0: float, rep: StepReport, st: StepContext) -> float:
        """One segment from s seconds into the step: flight or contact, by the mode. Where
        flight and contact swap at N = 0 (a mode change in no time), contact holds past
        that point (StepContext.sticky_at)."""
        mode = self._mode
        if mode == MODE_FREE:
            s_end = self._advance_free(s, h, t0, rep, st)
        else:
            s_end = self._advance_contact(s, h, rep, st)
        if s_end == s and self._mode != mode and MODE_FREE in (mode, self._mode):
            st.sticky_at = s  # N = 0 to rounding: contact holds past it
        return s_end

    # ------------------------------------------------------------------ state (de)serialisation

    @property
    def wall_forces(self) -> WallForces:
        """The contact-free forces at the wall under the last inputs and the spin speed now
        (per unit m c_r)."""
        if self._J != INF:  # the spin moves within a step: built for the speed now
            return WallForces.build(self._p, *self._inputs)
        return self._wf

    @property
    def state(self) -> CoreState:
        """The state as a plain record (read-only; ``set_state`` restores one)."""
        return CoreState(
            params=self._p, t=self._t, t_lo=self._t_lo, z=self.z, v=self.v, psi=self._psi,
            turns=self._turns, mode=self._mode, theta=self._theta, dtheta=self._dtheta,
            slip=self._slip, locked=self._locked, on_wall=self._on_wall,
            n_impacts=self._n_impacts, t_last=self._t_last, v_last=self._v_last,
            E_diss=self._E_diss, t_contact=self._t_contact, slide_step=self._slide_step,
            orbit_energy=(self._orbit.E if isinstance(self._orbit, Orbit)
                          and self._mode == MODE_ROLLING else math.nan),
            orbit_step=(self._orbit.last_rem if isinstance(self._orbit, Orbit)
                        and self._mode == MODE_ROLLING else math.nan),
            imb_h=(self._imb_seen_h, self._imb_free_h),
            Omega=self._inputs[0], F_ext=self._inputs[1], amb_on=self._inputs[2],
            bearing=(fixed_bearing_record() if self._race is None
                     else self._bearing_record()),
            J=None if self._J == INF else self._J,
        )

    def get_state(self) -> dict:
        """All internal state as a JSON-serialisable dict (floats round-trip exactly):
        ``CoreState.to_json`` of ``state``."""
        return self.state.to_json()

    def set_state(self, st: dict | CoreState) -> None:
        """Restore a state produced by get_state (same or compatible version), or a
        CoreState; ParameterError for another schema or version (nothing changes)."""
        cs = st if isinstance(st, CoreState) else CoreState.from_json(st)
        spin = self._J != INF
        if (cs.J is not None) != spin:
            raise ParameterError(
                "the state is of a core whose spin is "
                f"{'a state (J set)' if cs.J is not None else 'held (no J)'}; this core's "
                f"spin is {'a state' if spin else 'held'}: restore it into a "
                f"{'SpinCore' if cs.J is not None else 'TouchdownCore'} (rotortd.restore_core)")
        if cs.J is not None:
            check_well_posed(cs.params, cs.J)
        real = dict(cs.bearing).get("kind") == RealRace.KIND
        if not real and dict(cs.bearing) != fixed_bearing_record():
            raise ParameterError(
                f"the state's bearing record {dict(cs.bearing)!r} is neither the fixed "
                f"rigid bearing's {fixed_bearing_record()!r} nor a real bearing's")
        p_old, race_old = self._p, self._race
        self._p = cs.params
        try:
            if real:
                self._restore_bearing(dict(cs.bearing))
        except ParameterError:
            self._p = p_old
            raise
        if not real:
            self._race = None
        if self._race is not race_old:
            self._bind_rotor()
        if cs.J is not None:
            self._J = cs.J
        self._t, self._t_lo = cs.t, cs.t_lo
        self._z, self._v = cs.z, cs.v
        self._psi, self._turns = cs.psi, cs.turns
        self._mode = cs.mode
        self._theta, self._dtheta = cs.theta, cs.dtheta
        self._set_inputs(*cs.inputs)  # clears _locked: restored next
        self._slip, self._locked = cs.slip, cs.locked
        self._on_wall = cs.on_wall
        self._n_impacts = cs.n_impacts
        self._t_last, self._v_last = cs.t_last, cs.v_last
        self._E_diss = cs.E_diss
        self._t_contact = cs.t_contact
        self._slide_step = cs.slide_step
        self._orbit = (None if math.isnan(cs.orbit_energy) or cs.J is None else Orbit(
            cs.orbit_energy, orbit_key(cs.params, cs.J, cs.amb_on, cs.F_ext, cs.Omega),
            cs.orbit_step))
        self._imb_seen_h = cs.imb_h[0]  # the imbalance closed form's choice continues
        if not math.isnan(cs.imb_h[1]):  # (its coefficients: the same bits again)
            c = self._fm.imb_impulse(cs.imb_h[1])
            self._imb_free_h, self._imb_free = cs.imb_h[1], (c.bz, c.bv, c.b0, c.bE.imag)


class SpinCore(TouchdownCore):
    """``TouchdownCore`` with the spin as a state: J (kg m^2, finite, > 0) required. It adds
    no physics and no state of its own (the one core; ``TouchdownCore(params, J=J)`` is
    the same model); the name says which rotor a caller built."""

    def __init__(self, params: RotorParams, J: float, *, z0: complex = 0j,
                 v0: complex = 0j, psi0: float = 0.0, Omega0: float = 0.0,
                 t0: float = 0.0, bearing: BearingParams | None = None) -> None:
        check_range("J", J, 0.0, lo_open=True, unit="kg m^2")  # (finite: check_finite)
        super().__init__(params, J=J, z0=z0, v0=v0, psi0=psi0, Omega0=Omega0, t0=t0,
                         bearing=bearing)

    @classmethod
    def on_steady_whirl(cls, params: RotorParams, Omega: float, *, F_ext: complex = 0j,
                        amb_on: float = 1.0, psi0: float = 0.0, t0: float = 0.0,
                        J: float = INF, bearing: BearingParams | None = None) -> SpinCore:
        """Start on the held-spin steady whirl at Omega (rad/s) with the spin a state
        (TouchdownCore.on_steady_whirl; J required)."""
        core = TouchdownCore.on_steady_whirl(params, Omega, F_ext=F_ext, amb_on=amb_on,
                                             psi0=psi0, t0=t0)
        return cls(params, J, z0=core.z, v0=core.v, psi0=psi0, Omega0=Omega, t0=t0,
                   bearing=bearing)


def restore_core(st: dict | CoreState) -> TouchdownCore:
    """A core restored from a state record or its JSON: a SpinCore when the state has J,
    else a TouchdownCore (ParameterError for an unreadable state)."""
    cs = st if isinstance(st, CoreState) else CoreState.from_json(st)
    core = TouchdownCore(cs.params) if cs.J is None else SpinCore(cs.params, cs.J)
    core.set_state(cs)
    return core
