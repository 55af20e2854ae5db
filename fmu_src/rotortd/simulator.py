"""The event-driven simulator: exact flight, located impacts, sustained contact.

Frame and units: inertial, SI, unless a name says otherwise. ``TouchdownCore.step``
advances the rotor by one communication step with inputs held (Omega, F_ext, a) and
returns a ``StepReport``. The story it resolves:

    free flight -> impacts -> chattering -> sliding <-> rolling -> lift-off -> free flight

Low-speed rule (when an impact becomes sustained contact). At an impact with normal speed
v, let A > 0 be the outward normal acceleration the contact-free forces give at the wall
(the rotor would come back), v_b = d v the rebound speed, h_b = v_b^2/(2A) the rebound
height and tau_b = 2 v_b/A its flight time. The impact is made plastic and sustained
contact begins when

  (1) h_b <= ETA_HEIGHT c_r (the remaining chattering cascade is below resolution), or
  (2) the cascade to (1) would need more than N_CASCADE further impacts (d close to 1,
      or d = 1 where it never ends) and the bounce is short, tau_b <= ETA_TIME/w_ref,
      w_ref = max(|Omega|, |theta'|, sqrt(kappa), beta, sqrt(A/c_r)).

Rule (1) replaces a cascade with total normal momentum m(1+d)v/(1-d) by a plastic impact
m v plus sliding, which delivers the rest in the accumulation time 2 d v/((1-d) A): the
same momentum and friction impulse, so the state after the accumulation point is off by
O(h_b) in position and O(v_b^2/((1-d)A c_r)) in phase. Rule (2) replaces bounces of height
at most ETA_TIME^2 c_r/8 by sliding; the bounce energy 1/2 m v_b^2 (which d < 1 would
dissipate later, d = 1 never) is dissipated at once. Neither threshold depends on the
communication step.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass, field
from typing import NamedTuple

from .contact import (
    QUAD_TOL,
    ContactTally,
    ContactWorkExceeded,
    LinearRub,
    LockedRub,
    QuadraticRub,
    Rolling,
    RubEquilibrium,
    SegmentEnd,
    Sliding,
    WallForces,
    forward_rub_equilibria,
    rub_deviation,
)
from .events import SEGMENT_WORK, WORK_MAX, ContactLocator, Work, flight_is_clear
from .flight import FlightModel
from .impact import Impact, reset
from .limits import CrossParameterError, start_position
from .params import InputError, ParameterError, RotorParams, check_finite, check_range
from .scaled import TWO_PI_HI, TWO_PI_LO, to_inertial, wrap_angle
from .state import CoreState

MODE_FREE, MODE_SLIDING, MODE_ROLLING = 0, 1, 2
STATUS_OK, STATUS_WORK_CAP = 0, 1
_MODE_NAMES = {MODE_FREE: "lift_off", MODE_SLIDING: "sliding", MODE_ROLLING: "rolling"}

ETA_HEIGHT = 1e-14
"""Rule (1): rebound height below ETA_HEIGHT c_r counts as contact."""
ETA_TIME = 1e-3
"""Rule (2): rebound flight time below ETA_TIME / w_ref counts as contact (long cascades)."""
N_CASCADE = 1000
"""Rule (2) applies when more than N_CASCADE impacts would remain before rule (1)."""
LOCK_TOL = 1e-14
"""A sliding state on the linearised rub (contact.LinearRub) whose snap_error is at most
LOCK_TOL is put exactly on the stable forward rub and advanced as a rigid rotation: the
snap changes the angle, the rate and the normal force by at most LOCK_TOL relative."""
RUB_RETRY = 4.0
"""Longest sliding segment, in units of 1/w (WallForces.omega_ref), integrated before the
linearised rub and the lock are tried again, when a stable forward rub exists. Without it
a long step integrated all of its sliding, however close to the rub it came (a 10 s step
at the rub cost 0.19 s CPU)."""
_R_CLEAR = 1.0 - 1e-9


class WorkCapExceeded(RuntimeError):
    """A step exceeded its work cap."""


@dataclass(slots=True)
class StepReport:
    """What happened in one step (SI, inertial). Forces are step averages (impulse/h).

    Also the step's accumulator: while the step runs, impacts and contact segments add
    their impulses to P_contact, P_n, P_t, E_diss and F_n_peak (the contact force's peak;
    the impacts' P_n/h join it at the end), and the step's end turns the impulses into the
    averages F_contact, F_n and T_f (``TouchdownCore._finish``)."""

    status: int = STATUS_OK
    message: str = ""
    impacts: list[Impact] = field(default_factory=list)
    F_contact: complex = 0j
    F_n: float = 0.0
    F_n_peak: float = 0.0
    P_n: float = 0.0
    T_f: float = 0.0
    E_diss: float = 0.0
    mode: int = MODE_FREE
    work: int = 0
    work_cap: int = 0
    transitions: list[tuple[float, str]] = field(default_factory=list)
    """Mode changes in the step: (t, "sliding" | "rolling" | "lift_off")."""
    P_contact: complex = 0j
    """Impulse of the contact on the rotor over the step (N s): F_contact = P_contact/h."""
    P_t: float = 0.0
    """Signed friction impulse (N s): T_f = -R P_t/h."""

    def add_contact(self, tal: ContactTally, mc: float, c_r: float) -> None:
        """Add a contact segment's integrals (per unit m c_r; mc = m c_r)."""
        self.P_contact += mc * tal.I_c
        self.P_n += mc * tal.I_n
        self.P_t += mc * tal.I_t
        self.E_diss += mc * c_r * tal.I_e
        self.F_n_peak = max(self.F_n_peak, mc * tal.peak)


class Kinematics(NamedTuple):
    """Outputs derived from the state (SI; u_*, du_* scaled co-rotating, t = Omega tau).

    x, y (m), vx, vy (m/s), r_rel = |z|/c_r, u = z e^{-i psi}/c_r, du = dU/dt (0 when
    Omega = 0), psi_wrapped (rad, (-pi, pi]), whirl_rate theta' (rad/s, inertial),
    v_rel = R Omega + c_r theta' (m/s), F_amb = a (F_bias - c v - k z) (N). A named tuple:
    the fields unpack in this order.
    """

    x: float
    y: float
    vx: float
    vy: float
    r_rel: float
    u_re: float
    u_im: float
    du_re: float
    du_im: float
    psi_wrapped: float
    whirl_rate: float
    v_rel: float
    F_amb_x: float
    F_amb_y: float


class _Step:
    """The context of a step taken segment by segment, passed down the step loop and
    never stored on the core: its work and work bound, the rounding error of its local
    time, and the flags that live for one step only. (Its impulses go to the StepReport.)"""

    __slots__ = ("cap", "roll_lenient", "rub_refused", "s_lo", "sticky_at", "work")

    def __init__(self, cap: int, rub_refused: bool = False) -> None:
        self.work = Work()
        self.cap = cap  # work bound (units)
        self.s_lo = 0.0  # rounding error of the step-local time (later), s
        self.roll_lenient = False  # zero slip proved stuck (_transition)
        self.sticky_at = math.nan  # where flight and contact swapped at N = 0
        self.rub_refused = rub_refused  # the start state is not near a rub (_rub_step)

    def later(self, s: float, ds: float) -> float:
        """Step-local time s + ds (s), its rounding error kept in s_lo (2Sum): a long step
        of many events would otherwise drift by one rounding per event."""
        t = s + ds
        r = t - s
        self.s_lo += (s - (t - r)) + (ds - r)
        return t


def work_cap(*_args: object) -> int:
    """The work bound of one step (units): the constant WORK_MAX, whatever the scene and
    the step length (docs/model.md 7). The arguments (parameters, h, Omega, F_ext, amb_on,
    speed, as the former rate-based cap took them) are accepted and ignored."""
    return WORK_MAX


_SEGMENT_NAMES = {MODE_FREE: "free flight", MODE_SLIDING: "sliding", MODE_ROLLING: "rolling"}
_PROVED_FREE, _RUB = "proved free flight", "rub in closed form"  # _whole_step's choices


class TouchdownCore:
    """Rotor in a touchdown bearing, advanced step by step (see the module docstring)."""

    def __init__(
        self,
        params: RotorParams,
        z0: complex = 0j,
        v0: complex = 0j,
        psi0: float = 0.0,
        t0: float = 0.0,
    ) -> None:
        z0, v0 = complex(z0), complex(v0)
        for name, val in (
            ("x0", z0.real),
            ("y0", z0.imag),
            ("vx0", v0.real),
            ("vy0", v0.imag),
            ("psi0", psi0),
            ("t0", t0),
        ):
            check_finite(name, val)
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
        self._set_inputs(0.0, 0j, 1.0)  # the flight and wall models of the held inputs

    # ------------------------------------------------------------------ constructors

    @classmethod
    def from_scaled(
        cls,
        params: RotorParams,
        Omega: float,
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
        return cls(params, z0, v0, psi0, t0)

    @classmethod
    def on_steady_whirl(
        cls,
        params: RotorParams,
        Omega: float,
        F_ext: complex = 0j,
        amb_on: float = 1.0,
        psi0: float = 0.0,
        t0: float = 0.0,
    ) -> TouchdownCore:
        """Start on the steady free whirl z = Z0 + Z1 e^{i psi} (the regular equilibrium U*).

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
        return cls(params, Z0 + Z1, 1j * fm.Omega * Z1, psi0, t0)

    # ------------------------------------------------------------------ state access

    @property
    def params(self) -> RotorParams:
        """Current parameters."""
        return self._p

    def set_params(self, params: RotorParams) -> None:
        """Change parameters (tunables); takes effect from the next step."""
        if params.c_r != self._p.c_r:
            raise ParameterError("c_r is fixed after initialisation; it cannot change mid-run")
        self._p = params
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
        return Kinematics._make(self.kinematics_values(Omega, amb_on))

    def kinematics_values(
        self, Omega: float | None = None, amb_on: float | None = None
    ) -> tuple[float, ...]:
        """The fields of ``kinematics`` as a plain tuple, in the same order (cheaper)."""
        W = self._inputs[0] if Omega is None else Omega
        a = self._inputs[2] if amb_on is None else amb_on
        if self._mode:  # in contact the state is (theta, theta')
            z, v = self._wall_state()
        else:
            z, v = self._z, self._v
        p, psi = self._p, self._psi
        c_r = p.c_r
        rot = cmath.exp(-1j * psi)
        zr = z * rot
        r = abs(z)
        rr = r * r
        whirl = (z.real * v.imag - z.imag * v.real) / rr if rr > 0.0 else (
            ((z.real * v.imag - z.imag * v.real) / r) / r if r > 0.0 else 0.0)
        den = c_r * W
        dU = (v - 1j * W * z) * rot / den if den != 0.0 else 0j
        if not (math.isfinite(dU.real) and math.isfinite(dU.imag)):
            dU = 0j  # |Omega| so small that dU/dt overflows: the Omega = 0 convention
        F_amb = a * (p.bias_force - p.c * v - p.k * z)
        return (
            z.real, z.imag, v.real, v.imag, r / c_r, zr.real / c_r, zr.imag / c_r,
            dU.real, dU.imag, -psi if psi == -math.pi else psi, whirl,
            p.R * W + c_r * whirl, F_amb.real, F_amb.imag,
        )

    # ------------------------------------------------------------------ stepping

    def step(self, h: float, Omega: float, F_ext: complex = 0j, amb_on: float = 1.0,
             budget: int | None = None) -> StepReport:
        """Advance by h seconds with Omega (rad/s), F_ext (N) and amb_on held.

        The step's work is bounded by ``budget`` work units (default and at most WORK_MAX;
        SpinCoupler passes what its sub-steps have left). A step that would need more stops
        where it is with STATUS_WORK_CAP and a message saying where (docs/model.md 7)."""
        F = complex(F_ext)
        if not (0.0 < h < math.inf and math.isfinite(Omega) and 0.0 <= amb_on <= 1.0
                and math.isfinite(F.real) and math.isfinite(F.imag)):
            self._reject_inputs(h, Omega, F, amb_on)
        W, a = float(Omega), float(amb_on)
        if (W, F, a) != self._inputs:
            self._set_inputs(W, F, a)
        cap = WORK_MAX if budget is None else max(0, min(budget, WORK_MAX))
        rep = StepReport(work_cap=cap)
        t0, s = self._t, h
        whole = self._whole_step(h, rep)  # choose: the whole step in one closed form?
        if whole is None:  # else segment by segment, each chosen where the last ended
            s = self._segments(h, t0, rep, _Step(cap, self._mode == MODE_SLIDING))
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

    def _segments(self, h: float, t0: float, rep: StepReport, st: _Step) -> float:
        """The step loop: choose the next segment from the state, advance it, apply its
        end (``_advance``), until the step is done or its work bound is reached. Returns
        how far (s) into the step it got."""
        work, cap, s = st.work, st.cap, 0.0
        try:
            while s < h:
                if work.total > cap:
                    raise WorkCapExceeded("before the next segment")
                work.segs += SEGMENT_WORK
                mode, s_before = self._mode, s
                s = self._advance(s, h, t0, rep, st)
                if self._mode != mode:
                    rep.transitions.append((t0 + s, _MODE_NAMES[self._mode]))
                    if s == s_before and MODE_FREE in (mode, self._mode):
                        st.sticky_at = s  # N = 0 to rounding: contact holds past it
        except (WorkCapExceeded, ContactWorkExceeded) as exc:
            work.iters += getattr(exc, "work", 0)
            rep.status, rep.message = STATUS_WORK_CAP, (
                f"work bound reached: {work.total} > {cap} work units; the core stopped at "
                f"t = {t0 + s!r} s, {s!r} s into the step of {h!r} s, in "
                f"{_SEGMENT_NAMES[self._mode]} (segment {work.segs // SEGMENT_WORK}, "
                f"{len(rep.impacts)} impacts in the step): {exc}")
        rep.work = work.total
        return s

    def _finish(self, rep: StepReport, t0: float, s: float, h: float, tallied: bool) -> None:
        """The one place a step ends: advance the clock to where the step got (s of h) and
        turn the report's impulses into step averages (not after a flight proved free,
        whose report holds nothing to average)."""
        self._advance_clock(h if s >= h else s)
        if tallied:
            self._fill_report(rep, self._t - t0 if s < h else h)

    def _proved_free_step(self, h: float, rep: StepReport) -> bool:
        """A free step proved contact-free without a search: by the envelope for all time
        under the held inputs (``_clear``), or by the cubic bound of ``flight_is_clear`` over
        the whole step. Then one closed-form propagation, nothing to tally; else None (the
        caller searches). Either way the step ends in the same state as a search that finds
        nothing, which also propagates once from the start. True when taken."""
        fm = self._fm
        E = self._phasor()
        work = 1
        if not self._clear:
            if self._on_wall:
                return False
            if self._t >= self._envelope_at:
                work += 1
                self._check_envelope(fm, self._t, E)
            if not self._clear:
                work += 1
                if not flight_is_clear(fm, self._z, self._v, E, h):
                    return False
        self._z, self._v = fm.propagate(self._z, self._v, E, h, cache=True)
        self._advance_psi(h)
        self._on_wall = False
        rep.work = work
        return True

    @staticmethod
    def _reject_inputs(h: float, Omega: float, F: complex, amb_on: float) -> None:
        """Raise the InputError that names the first invalid input of a step."""
        check_range("h", h, 0.0, lo_open=True, error=InputError, unit="s")
        check_finite("Omega", Omega, InputError)
        check_finite("F_x", F.real, InputError)
        check_finite("F_y", F.imag, InputError)
        check_range("amb_on", amb_on, 0.0, 1.0, error=InputError)

    def _advance_clock(self, dt: float) -> None:
        """Advance the clock by dt with compensated summation (no drift over 1e6 steps)."""
        y = dt - self._t_lo
        t = self._t + y
        self._t_lo = (t - self._t) - y
        self._t = t

    def _set_inputs(self, W: float, F: complex, a: float) -> None:
        """New held inputs (or parameters): rebuild the flight and wall models."""
        self._inputs: tuple[float, complex, float] = (W, F, a)
        self._fm = FlightModel(self._p, W, F, a)
        self._wf = WallForces.build(self._p, W, F, a)
        self._rub_eqs: list[RubEquilibrium] | None = None  # forward_rub_equilibria, lazily
        self._forget_clear_proof()
        self._locked = False

    def _fill_report(self, rep: StepReport, h: float) -> None:
        """Averages over h (s) of the impulses the step added to ``rep``; the mode."""
        inv = 1.0 / h if h > 0.0 else 0.0
        rep.F_contact = rep.P_contact * inv
        rep.F_n = rep.P_n * inv
        for imp in rep.impacts:
            rep.F_n_peak = max(rep.F_n_peak, imp.P_n * inv)
        rep.T_f = -self._p.R * rep.P_t * inv
        rep.mode = self._mode
        self._E_diss += rep.E_diss

    def _advance(self, s: float, h: float, t0: float, rep: StepReport, st: _Step) -> float:
        """One segment from s seconds into the step: flight or contact, by the mode."""
        if self._mode == MODE_FREE:
            return self._advance_free(s, h, t0, rep, st)
        return self._advance_contact(s, h, rep, st)

    # ------------------------------------------------------------------ free flight

    def _phasor(self) -> complex:
        return cmath.exp(1j * self._psi)

    def _advance_psi(self, ds: float) -> None:
        x = self._psi + self._inputs[0] * ds
        k = math.floor((x + math.pi) / TWO_PI_HI)
        if k:
            x = (x - k * TWO_PI_HI) - k * TWO_PI_LO
            self._turns += k
        self._psi = x

    def _advance_free(self, s: float, h: float, t0: float, rep: StepReport,
                      st: _Step) -> float:
        fm = self._fm
        work = st.work
        rem = (h - s) - st.s_lo
        E = self._phasor()
        if not self._clear and not self._on_wall and t0 + s >= self._envelope_at:
            work.evals += 1  # (on the wall the bound is >= |z| = c_r: it cannot prove)
            self._check_envelope(fm, t0 + s, E)
        hit = loc = None
        if not self._clear:
            loc = ContactLocator(fm, self._z, self._v, E)
            hit = loc.find(rem, self._on_wall, work, st.cap - work.total)
        if hit is None:
            if loc is not None and s > 0.0:
                # the rest of a step after an event: a length that will not recur, whose
                # flight map costs twelve times the search's modal state (measured)
                self._z, self._v, _ = loc.state(rem, work)
            else:  # a whole step: its length recurs and its flight map is cached
                work.evals += 1
                self._z, self._v = fm.propagate(self._z, self._v, E, rem, cache=(s == 0.0))
            self._advance_psi(rem)
            self._on_wall = False
            return h
        ds = min(hit.s, rem)
        self._advance_psi(ds)
        if hit.kind == "clear":
            self._z, self._v = hit.z, hit.v
            self._on_wall = False
            return st.later(s, ds)
        z = hit.z * (self._p.c_r / abs(hit.z))
        self._forget_clear_proof()
        if hit.kind == "impact":
            self._impact(t0 + s + (st.s_lo + ds), z, hit.v, rep)
        else:
            self._z, self._v = z, hit.v
            self._enter_contact()
        return st.later(s, ds)

    def _check_envelope(self, fm: FlightModel, t: float, E: complex) -> None:
        """Try to prove the flight clear of the wall for all time under the held inputs
        (``_clear``). If that fails, schedule the next try for when the transient bound,
        decaying like e^{-decay_rate t}, could have fallen below the margin left by the
        steady whirl; never, if the steady whirl alone reaches the wall. The schedule only
        saves work: a flight that is not proved clear is searched, which is always exact.
        Not tried from the wall (after an impact or lift-off): sup |z| >= |z(0)| = c_r there,
        so the proof must fail; the next step that starts off the wall tries again."""
        steady, transient = fm.radius_bound_parts(self._z, self._v, E)
        limit = self._p.c_r * _R_CLEAR
        if steady + transient < limit:
            self._clear = True
        elif steady < limit and fm.decay_rate > 0.0 and math.isfinite(transient):
            self._envelope_at = t + math.log(transient / (limit - steady)) / fm.decay_rate
        else:
            self._envelope_at = math.inf

    def _forget_clear_proof(self) -> None:
        """Forget the envelope proof: the state jumped or the inputs changed."""
        self._clear = False
        self._envelope_at = -math.inf

    def _impact(self, t: float, z: complex, v_minus: complex, tally: StepReport) -> None:
        p = self._p
        W = self._inputs[0]
        n = z / p.c_r
        r = reset(n, v_minus, p.m, p.d, p.mu, p.R, W)
        plastic = self._low_speed_contact(n, r.rdot, r.v_plus)
        if plastic:
            r = reset(n, v_minus, p.m, 0.0, p.mu, p.R, W)
        imp = Impact(t, z, v_minus, r.v_plus, r.rdot, r.P_n, r.P_t, r.stick, r.E_diss)
        tally.impacts.append(imp)
        tally.P_contact -= complex(r.P_n, r.P_t) * n
        tally.P_n += r.P_n
        tally.P_t += r.P_t
        tally.E_diss += r.E_diss
        self._n_impacts += 1
        self._t_last, self._v_last = t, r.rdot
        self._z, self._v = z, r.v_plus
        self._on_wall = True
        if plastic:
            A = self._outward_accel(n, r.v_plus)
            d = p.d
            self._t_contact = t + (2.0 * d * r.rdot / ((1.0 - d) * A) if d < 1.0 else 0.0)
            self._enter_contact()

    def _outward_accel(self, n: complex, v: complex) -> float:
        """A (m/s^2): outward normal acceleration at the wall from contact-free forces."""
        wf = self._wf
        vt = (n.conjugate() * v).imag
        gn, _ = wf.gn_gt(cmath.phase(n), vt / self._p.c_r, self._phasor())
        return gn * self._p.c_r

    def _low_speed_contact(self, n: complex, v: float, v_plus: complex) -> bool:
        """The low-speed rule of the module docstring: does this impact start contact?"""
        p = self._p
        A = self._outward_accel(n, v_plus)
        if A <= 0.0:
            return False
        vb = p.d * v
        if vb * vb <= 2.0 * A * ETA_HEIGHT * p.c_r:
            return True
        v1 = math.sqrt(2.0 * A * ETA_HEIGHT * p.c_r)
        if p.d < 1.0 and v1 > 0.0 and math.log(vb / v1) < -N_CASCADE * math.log(p.d):
            return False
        wf = self._wf
        vt = (n.conjugate() * v_plus).imag
        w_ref = max(wf.omega_ref(vt / p.c_r), math.sqrt(A / p.c_r))
        return 2.0 * vb / A <= ETA_TIME / w_ref

    # ------------------------------------------------------------------ contact

    def _enter_contact(self) -> None:
        """Switch to sustained contact at the current (on-wall) state."""
        z, v = self._z, self._v
        self._theta = cmath.phase(z)
        self._dtheta = ((z / abs(z)).conjugate() * v).imag / self._p.c_r
        self._locked = False
        self._choose_contact_mode()

    def _choose_contact_mode(self) -> None:
        """Pick sliding (with slip sign) or rolling from the current contact state."""
        wf = self._wf
        vrel = wf.wr + self._dtheta
        if vrel != 0.0 or wf.mu == 0.0:  # frictionless contact always 'slides'
            self._mode, self._slip = MODE_SLIDING, math.copysign(1.0, vrel)
            return
        E = self._phasor()
        _, gt = wf.gn_gt(self._theta, self._dtheta, E)
        margin, rate = wf.cone_margin(self._theta, self._dtheta, E)
        tol = wf.gn_tol(self._dtheta) * (1.0 + wf.mu)
        # inside the cone, entering it, or on its edge with no tendency to leave: roll
        if margin > tol or (margin >= -tol and rate > 0.0) or (margin >= 0.0 and rate == 0.0):
            self._mode = MODE_ROLLING
        else:
            self._mode, self._slip = MODE_SLIDING, math.copysign(1.0, gt)

    def _wall_state(self) -> tuple[complex, complex]:
        """(z (m), v (m/s)) of the contact state (theta, theta'): in contact the core holds
        the state only as (theta, theta'), and (z, v) follow from it."""
        e = cmath.exp(1j * self._theta)
        return self._p.c_r * e, 1j * self._p.c_r * self._dtheta * e

    def _advance_contact(self, s: float, h: float, rep: StepReport, st: _Step) -> float:
        """A contact segment from s seconds into the step: choose it (lift-off, rolling,
        a rub in closed form, sliding), advance it, apply its end."""
        wf = self._wf
        rem = (h - s) - st.s_lo
        E = self._phasor()
        vrel = wf.wr + self._dtheta
        if (self._mode == MODE_ROLLING and vrel != 0.0) or (
            self._mode == MODE_SLIDING and vrel * self._slip <= 0.0 and wf.mu != 0.0
        ):
            self._choose_contact_mode()  # the host changed Omega: the slip follows v_rel
        sticky = s == st.sticky_at
        if not sticky and self._leaves_wall(E):
            self._lift_off()
            return s
        if self._mode == MODE_ROLLING:
            slack = 2.0 * wf.gn_tol(self._dtheta) * (1.0 + wf.mu) if st.roll_lenient else 0.0
            end = Rolling(wf, self._theta, E, slack).run(rem)
        elif (rub := self._rub_choice(E, self._may_linearise(s, sticky, st))) is not None:
            end = rub.run(rem)
        else:
            slack = 2.0 * wf.gn_tol(self._dtheta) if sticky else 0.0
            seg = Sliding(wf, self._theta, self._dtheta, E, self._slip, slack, self._slide_step)
            end = seg.run(self._slide_span(rem), st.cap - st.work.total)
            self._slide_step = end.next_step
        st.work.iters += end.tally.work
        self._end_segment(end, rep, st)
        return st.later(s, end.duration) if end.duration < rem else h

    def _end_segment(self, end: SegmentEnd, rep: StepReport, st: _Step | None) -> None:
        """Apply the end of a contact segment: its state, its contact integrals (into
        ``rep``) and its event (``st`` may be None only for an end without event)."""
        p = self._p
        rep.add_contact(end.tally, p.m * p.c_r, p.c_r)
        self._theta, self._dtheta = wrap_angle(end.theta), end.dtheta
        self._advance_psi(end.duration)
        self._transition(end.event, st)

    def _rub_step(self, h: float, rep: StepReport) -> bool:
        """A sliding step on or near a stable forward rub in closed form, without the step
        loop: the rigid rotation when locked, else the linearised motion when the state
        admits it (``_linear_rub``); False otherwise (the step loop integrates). The inputs
        are those the rub was found under (new inputs unlock it). ``_advance_contact``
        would take the same segment whole: the slip sign agrees with v_rel, and Gn stays
        above the lift-off test (constant on the rotation; bounded below by
        LinearRub.near on the linearised motion)."""
        rub = self._rub_choice(self._phasor(), True)
        if rub is None:
            return False
        end = rub.run(h)
        rep.work = end.tally.work
        self._end_segment(end, rep, None)
        return True

    def _leaves_wall(self, E: complex) -> bool:
        """Lift-off at the start of a contact segment: N < 0, or N = 0 to rounding and
        decreasing (the same tie-break as the free flight's touch test, so the two never
        disagree and hand the state back and forth)."""
        wf = self._wf
        gn, gt = wf.gn_gt(self._theta, self._dtheta, E)
        tol = wf.gn_tol(self._dtheta)
        if gn > tol:
            return False
        if gn < -tol:
            return True
        dd = 0.0 if self._mode == MODE_ROLLING else gt - wf.mu * self._slip * gn
        return wf.gn_rate(self._theta, self._dtheta, E, dd) <= 0.0

    def _transition(self, event: str | None, st: _Step | None) -> None:
        wf = self._wf
        if event is None:
            return
        if event == "lift_off":
            self._lift_off()
        elif event == "slip_zero":
            self._dtheta = -wf.wr
            self._choose_contact_mode()
            self._locked = False
        elif event == "slip_stuck":  # sliding cannot leave zero slip: it rolls, and
            self._dtheta = -wf.wr  # cone violations below resolution are ignored this step
            self._mode = MODE_ROLLING
            self._locked = False
            assert st is not None
            st.roll_lenient = True
        elif event == "cone":
            _, gt = wf.gn_gt(self._theta, self._dtheta, self._phasor())
            self._mode, self._slip = MODE_SLIDING, math.copysign(1.0, gt)

    def _lift_off(self) -> None:
        self._z, self._v = self._wall_state()
        self._mode = MODE_FREE
        self._on_wall = True
        self._locked = False
        self._forget_clear_proof()

    def _lock(self, lin: LinearRub | QuadraticRub, E: complex) -> LockedRub:
        """Put the state on the rub of ``lin`` (lock it): the rigid rotation from there."""
        self._theta = wrap_angle(lin.eq.alpha + cmath.phase(E))
        self._dtheta = lin.wf.Omega
        self._locked = True
        return LockedRub(lin.wf, self._theta, self._dtheta, E, self._slip)

    def _rub_equilibria(self) -> list[RubEquilibrium]:
        """forward_rub_equilibria of the held inputs (computed once per inputs)."""
        if self._rub_eqs is None:
            self._rub_eqs = forward_rub_equilibria(self._wf)
        return self._rub_eqs

    def _rub_choice(self, E: complex, linearise: bool
                    ) -> LockedRub | LinearRub | QuadraticRub | None:
        """The sliding segment on or near a stable forward rub in closed form: the rigid
        rotation when locked; else, if ``linearise``, the linearised motion when the
        state admits it (locking first when the snap is below LOCK_TOL); else None."""
        if self._locked:
            return LockedRub(self._wf, self._theta, self._dtheta, E, self._slip)
        lin = self._linear_rub(E) if linearise else None
        if lin is None:
            return None
        return self._lock(lin, E) if lin.snap_error() <= LOCK_TOL else lin

    def _slide_span(self, rem: float) -> float:
        """How long (s) to integrate sliding before the rub's closed form is tried again:
        rem, or RUB_RETRY/w if shorter when a stable forward rub exists."""
        wf = self._wf
        if any(eq.stable for eq in self._rub_equilibria()):
            return min(rem, RUB_RETRY / wf.omega_ref(self._dtheta))
        return rem

    def _may_linearise(self, s: float, sticky: bool, st: _Step) -> bool:
        """May a sliding segment starting s seconds into the step try the linearised rub?
        Not when sticky, nor at the step's start when _rub_step has refused that state."""
        refused, st.rub_refused = st.rub_refused and s == 0.0, False
        return not (sticky or refused)

    def _linear_rub(self, E: complex) -> LinearRub | QuadraticRub | None:
        """The closed-form sliding near a stable forward rub: linearised when within
        LINEAR_TOL and its error budget holds (LinearRub.near), else to second order when
        within QUAD_TOL and its budget holds (QuadraticRub.near); None otherwise."""
        wf = self._wf
        th, dth, slip = self._theta, self._dtheta, self._slip
        for eq in self._rub_equilibria():  # (none when q0 != 0)
            dev = rub_deviation(wf, eq, th, dth, E, slip, QUAD_TOL)
            if dev is None:
                continue
            lin = LinearRub.admit(wf, eq, th, dth, slip, dev)
            if lin is None:
                lin = QuadraticRub.admit(wf, eq, th, dth, slip, dev)
            if lin is not None:
                return lin
        return None

    # ------------------------------------------------------------------ state (de)serialisation

    @property
    def wall_forces(self) -> WallForces:
        """The contact-free forces at the wall under the held inputs (per unit m c_r)."""
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
            inputs=self._inputs,
        )

    def get_state(self) -> dict:
        """All internal state as a JSON-serialisable dict (floats round-trip exactly):
        ``CoreState.to_json`` of ``state``."""
        return self.state.to_json()

    def set_state(self, st: dict | CoreState) -> None:
        """Restore a state produced by get_state (same or compatible version), or a
        CoreState; ParameterError for another schema or version (nothing changes)."""
        cs = st if isinstance(st, CoreState) else CoreState.from_json(st)
        self._p = cs.params
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
