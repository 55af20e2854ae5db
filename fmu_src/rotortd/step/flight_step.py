"""Free flight, the contact search and impacts: the flight segments of TouchdownCore.

Frame and units: inertial, SI. A mixin of ``simulator.TouchdownCore`` (it uses the core's
attributes; see there).

Low-speed rule (when an impact becomes sustained contact). At an impact with normal speed
v, let A > 0 be the outward normal acceleration the contact-free forces give at the wall
(the rotor would come back), v_b = d v the rebound speed, h_b = v_b^2/(2A) the rebound
height and tau_b = 2 v_b/A its flight time. The impact is made plastic and sustained
contact begins when

  (1) h_b <= ETA_HEIGHT c_r (the remaining chattering cascade is below resolution), or
  (2) the cascade to (1) would need more than N_CASCADE further impacts (d close to 1,
      or d = 1 where it never ends) and the bounce is short, tau_b <= ETA_TIME/w_ref,
      w_ref = max(|Omega|, |theta'|, sqrt(kappa), beta, sqrt(|q0| + |eu|), sqrt(A/c_r))
      (``reference_rate``, theta' of the rebound; docs/model.md §6).

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
from collections.abc import Callable
from typing import Any, Protocol

from ..contact.events import CLEAR, IMPACT
from ..contact.impact import Impact, reset
from ..contact.search import WORK_MAX, ContactLocator, Work, flight_is_clear
from ..contact.wall import SegmentEnd, WallForces
from ..scaled import TWO_PI_HI, TWO_PI_LO
from ..segments.flight import FlightModel
from .report import StepContext, StepReport

ETA_HEIGHT = 1e-14
"""Rule (1): rebound height below ETA_HEIGHT c_r counts as contact."""
ETA_TIME = 1e-3
"""Rule (2): rebound flight time below ETA_TIME / w_ref counts as contact (long cascades)."""
N_CASCADE = 1000
"""Rule (2) applies when more than N_CASCADE impacts would remain before rule (1)."""
_R_CLEAR = 1.0 - 1e-9
NAN, INF = math.nan, math.inf


class FlightSteps:
    """Free flight and impacts (mixin of TouchdownCore)."""

    def _proved_free_step(self, h: float, rep: StepReport) -> bool:
        """A free step proved contact-free without a search: by the envelope for all time
        under the held inputs (``_clear``), or by the cubic bound of ``flight_is_clear`` over
        the whole step. Then one closed-form propagation, nothing to tally; else None (the
        caller searches). Either way the step ends in the same state as a search that finds
        nothing, which also propagates once from the start. True when taken."""
        fm = self._fm
        psi = self._psi  # (_phasor, inline, storing nothing: in an FMU, output_values
        E = self._E_at if self._E_of is psi else cmath.rect(1.0, psi)  # cached this angle's)
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
        z0, v0 = self._z, self._v
        self._z, self._v = fm.propagate(z0, v0, E, h, cache=True)
        if not self.imbalance_torque:
            rep.P_imb = rep.T_imb = math.nan
        elif self._imb_free_h == h:  # the imbalance reaction's impulse, closed form (cached)
            bz, bv, b0, bE = self._imb_free
            rep.P_imb = P = (E.conjugate() * (bz * z0 + bv * v0 + b0)).imag + bE
            rep.T_imb = P / h
        else:
            rep.P_imb = P = self._imb_flight(z0, v0, E, h)
            rep.T_imb = P / h
        self._add_psi(self._inputs[0] * h)  # (_advance_psi, inline)
        self._on_wall = False
        rep.work = work
        return True

    def _imb_flight(self, z0: complex, v0: complex, E: complex, h: float) -> float:
        """P_imb (N m s) of a flight of h seconds from (z0, v0, E) that ended in (_z, _v):
        closed form, FlightModel.imb_impulse; its coefficients are computed once the
        length recurs under the same flight model, and kept on the core for the next such
        flight (forgotten with the flight model, _set_inputs); a first flight of a length,
        as when the held inputs change every step, takes FlightModel.imb_impulse_ends."""
        fm = self._fm
        if self._imb_free_h != h:
            if self._imb_seen_h != h:
                self._imb_seen_h = h
                return fm.imb_impulse_ends(z0, v0, E, self._z, self._v, h)
            c = fm.imb_impulse(h)
            self._imb_free_h, self._imb_free = h, (c.bz, c.bv, c.b0, c.bE.imag)
        bz, bv, b0, bE = self._imb_free
        return (E.conjugate() * (bz * z0 + bv * v0 + b0)).imag + bE

    _E_of: float | None = None
    """The spin angle object (``_psi``) whose phasor ``_E_at`` holds (identity, not value:
    a new angle is a new object; 0.0 and -0.0 are told apart)."""
    _E_at: complex = 1.0 + 0j

    def _phasor(self) -> complex:
        """e^{i psi}, computed once per spin angle: the quiet step and output_values share
        it. (cmath.rect(1, psi): complex(cos psi, sin psi), the bits of cmath.exp(1j psi),
        whose real part is exp(+-0) = 1, without forming 1j psi; the quiet lanes inline
        it.)"""
        psi = self._psi
        if self._E_of is not psi:
            self._E_at = cmath.rect(1.0, psi)
            self._E_of = psi
        return self._E_at

    def _advance_psi(self, ds: float) -> None:
        """Advance the spin angle over ds (s) at the held speed."""
        self._add_psi(self._inputs[0] * ds)

    def _add_psi(self, dpsi: float) -> None:
        """Add dpsi (rad) to the spin angle, kept in [-pi, pi) with whole turns apart."""
        x = self._psi + dpsi
        k = math.floor((x + math.pi) / TWO_PI_HI)
        if k:
            x = (x - k * TWO_PI_HI) - k * TWO_PI_LO
            self._turns += k
        self._psi = x

    def _advance_free(self, s: float, h: float, t0: float, rep: StepReport,
                      st: StepContext) -> float:
        """A flight segment from s seconds into the step: choose it (searched unless the
        flight is proved clear), advance it (``Flight.run``), apply its end."""
        rem = (h - s) - st.s_lo
        E = self._phasor()
        if not self._clear and not self._on_wall and t0 + s >= self._envelope_at:
            st.work.evals += 1  # (on the wall the bound is >= |z| = c_r: it cannot prove)
            self._check_envelope(self._fm, t0 + s, E)
        # (positional: a segment is built every flight, and 7 keywords cost 0.85 us)
        seg = Flight(self._fm, self._z, self._v, E, self._on_wall, not self._clear, s > 0.0)
        end = seg.run(rem, st.cap - st.work.total)
        st.work.iters += end.work
        return self._end_flight(end, seg, s, h, rem, t0, rep, st)

    def _end_flight(self, end: SegmentEnd, seg: Flight, s: float, h: float, rem: float,
                    t0: float, rep: StepReport, st: StepContext) -> float:
        """Apply the end of a flight segment ``seg`` begun s seconds into the step (rem
        seconds left): its state, its term of P_imb, and an impact or the entry into
        contact at its event. Returns how far into the step it got (s)."""
        fm, E, z0, v0 = self._fm, seg.E, seg.z0, seg.v0
        imb = self.imbalance_torque
        if end.event is None:  # the rest of the step is free
            self._z, self._v = end.z, end.v
            if imb and st.first:  # the whole step in one flight: as a proved-free one
                rep.P_imb = self._imb_flight(z0, v0, E, rem)  # (closed form)
                st.imb_whole = True
            elif imb:
                self._imb_add(rep, E, fm.imb_integral_ends(z0, v0, E, self._z, self._v, rem))
            self._advance_psi(rem)
            self._on_wall = False
            return h
        ds = min(end.duration, rem)
        if imb and ds == end.duration:  # the flight's end is the hit's state
            self._imb_add(rep, E, fm.imb_integral_ends(z0, v0, E, end.z, end.v, ds))
        elif imb:
            self._imb_add(rep, E, fm.imb_integral(z0, v0, E, ds))
        self._advance_psi(ds)
        if end.event is CLEAR:
            self._z, self._v = end.z, end.v
            self._on_wall = False
            return st.later(s, ds)
        z = end.z * (self._p.c_r / abs(end.z))
        self._forget_clear_proof()
        if end.event is IMPACT:
            self._impact(t0 + s + (st.s_lo + ds), z, end.v, rep)
        else:
            self._z, self._v = z, end.v
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
        """Forget the envelope proof, and the quiet lane built on it: the state jumped or
        the inputs changed."""
        self._clear = False
        self._envelope_at = -math.inf
        self._lane = None

    _lane: QuietLane | None = None
    """The quiet lane of the state (``quiet_lane``), None when it has none (forgotten with
    the envelope proof)."""

    def quiet_step(self, h: float, T_drive: float = 0.0) -> QuietStep | None:
        """A step of h seconds under the held inputs of the last step (and the drive torque
        T_drive, N m, with the spin a state), taken in the quiet lane (``quiet_lane``):
        ``(output_values(), T_imb)`` at its end; None (nothing done) when the state is not
        in the lane, and the caller takes ``step``."""
        lane = self.quiet_lane(h)
        if lane is None:
            return None
        return lane(self, self._t, h) if self._J == INF else lane(self, self._t, h, T_drive)

    def quiet_lane(self, h: float, t_tol: float = 0.0) -> QuietLane | None:
        """The quiet lane for steps of h seconds from times within t_tol (s) of the
        core's, or None when the state is not in it.

        In the lane the state is in flight, proved clear of the wall for all time under the
        held inputs (``_check_envelope``), with the spin held (J = inf), the bearing fixed
        and rigid and the imbalance torque's coefficients for h cached: every step of h
        under these inputs is then ``step``'s proved-free step (``_proved_free_step``). The
        lane, ``lane(core, t, h)``, takes that step from the time t (s) and returns
        ``(output_values(), T_imb)`` at its end, the same state and values as
        ``step(h, *inputs)`` and then ``output_values()``, to the bit, without the step
        report (its forces are zero) and without re-checking the held inputs (a declared
        accelerator: ``make_quiet_lane``). It returns None, doing nothing, once the core has
        left it (new inputs or parameters, a state set, a step that was not proved free),
        for another h, with the imbalance torque off, or when t is not the core's time to
        within t_tol (a host's clock: the host's own check then runs on its general path);
        a host may keep it while it answers."""
        lane = self._lane
        if lane is not None and lane.h == h and lane.t_tol == t_tol:
            return lane
        if not (self._clear and self._imb_free_h == h and self._J == INF
                and self._race is None and self._inputs[0] != 0.0):
            return None
        self._lane = lane = make_quiet_lane(self, h, t_tol)
        return lane

    def _impact(self, t: float, z: complex, v_minus: complex, rep: StepReport) -> None:
        p = self._p
        W = self._inputs[0]
        n = z / p.c_r
        r = reset(n, v_minus, p.m, p.d, p.mu, p.R, W)
        plastic = self._low_speed_contact(n, r.rdot, r.v_plus)
        if plastic:
            r = reset(n, v_minus, p.m, 0.0, p.mu, p.R, W)
        self._record_impact(rep, Impact(t, z, v_minus, r.v_plus, r.rdot, r.P_n, r.P_t,
                                        r.stick, r.E_diss), n)
        self._z, self._v = z, r.v_plus
        self._on_wall = True
        if plastic:
            A = self._outward_accel(n, r.v_plus)
            d = p.d
            self._t_contact = t + (2.0 * d * r.rdot / ((1.0 - d) * A) if d < 1.0 else 0.0)
            self._enter_contact()

    def _record_impact(self, rep: StepReport, imp: Impact, n: complex) -> None:
        """An impact at the unit normal n: into the step's report and the core's counters
        (both cores)."""
        rep.add_impact(imp, n)
        self._n_impacts += 1
        self._t_last, self._v_last = imp.t, imp.rdot

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
        return starts_contact(A, p.d * v, p.d, p.c_r, lambda: reference_rate(
            self._wf, (n.conjugate() * v_plus).imag / p.c_r, A, p.c_r))


class Flight:
    """A free flight under the held inputs from (z0 (m), v0 (m/s), E0 = e^{i psi}): the
    flight segment, ``run(rem, limit) -> SegmentEnd``. ``search``: look for the first
    contact (False when the flight is proved clear of the wall for all time);
    ``resumed``: the flight begins after an event inside the step, so its length will
    not recur and it ends by the search's modal state instead of the cached flight map."""

    __slots__ = ("E", "fm", "on_wall", "resumed", "search", "v0", "z0")

    def __init__(self, fm: FlightModel, z0: complex, v0: complex, E: complex, on_wall: bool,
                 search: bool, resumed: bool) -> None:
        self.fm, self.z0, self.v0, self.E = fm, z0, v0, E
        self.on_wall, self.search, self.resumed = on_wall, search, resumed

    def run(self, rem: float, limit: int = WORK_MAX) -> SegmentEnd:
        """Fly at most rem seconds; stop at the first contact ("impact", "touch"), or where
        the search used its advances ("clear"); at most ``limit`` work units of search."""
        fm, work = self.fm, Work()
        loc = hit = None
        if self.search:
            loc = ContactLocator(fm, self.z0, self.v0, self.E)
            hit = loc.find(rem, self.on_wall, work, limit)
        if hit is not None:
            return SegmentEnd(hit.s, NAN, NAN, hit.kind, None, INF, hit.z, hit.v, NAN, NAN,
                              work.total)  # (positional: a flight's end, cheaper)
        if loc is not None and self.resumed:
            # the rest of a step after an event: a length that will not recur, whose
            # flight map costs twelve times the search's modal state (measured)
            z, v, _ = loc.state(rem, work)
        else:  # a whole step: its length recurs and its flight map is cached
            work.evals += 1
            z, v = fm.propagate(self.z0, self.v0, self.E, rem, cache=not self.resumed)
        return SegmentEnd(rem, NAN, NAN, None, None, INF, z, v, NAN, NAN, work.total)


def reference_rate(wf: WallForces, dtheta: float, A: float, c_r: float) -> float:
    """Rule (2)'s reference rate w_ref (rad/s) of the module docstring, for both spin
    models: the largest rate of the wall forces ``wf`` (WallForces.omega_ref: |Omega|,
    |theta'|, sqrt(kappa), beta, sqrt(|q0| + |eu|)) at the rebound's whirl rate dtheta
    (rad/s), and sqrt(A/c_r) of the outward acceleration A (m/s^2)."""
    return max(wf.omega_ref(dtheta), math.sqrt(A / c_r))


def starts_contact(A: float, vb: float, d: float, c_r: float,
                   w_ref: Callable[[], float]) -> bool:
    """The low-speed rule of the module docstring for an impact whose rebound speed is
    vb (m/s) under the outward acceleration A (m/s^2) at the wall, restitution d, clearance
    c_r (m); w_ref() (rad/s) is the reference rate of rule (2), asked only if needed."""
    if A <= 0.0:
        return False
    if vb * vb <= 2.0 * A * ETA_HEIGHT * c_r:
        return True
    v1 = math.sqrt(2.0 * A * ETA_HEIGHT * c_r)
    if d < 1.0 and v1 > 0.0 and math.log(vb / v1) < -N_CASCADE * math.log(d):
        return False
    return 2.0 * vb / A <= ETA_TIME / w_ref()


QuietStep = tuple[tuple[Any, ...], float]
"""What a step in the quiet lane returns: (``output_values()``, T_imb in N m)."""


class QuietLane(Protocol):
    """``lane(core, t, h)``: one step of h s from t (s) in the quiet lane
    (``FlightSteps.quiet_lane``)."""

    h: float
    t_tol: float

    def __call__(self, core: Any, t: float, h: float) -> QuietStep | None: ...


def make_quiet_lane(core: Any, h: float, t_tol: float) -> QuietLane:
    """The quiet lane of ``core`` (a TouchdownCore whose state is in it: ``quiet_lane``)
    for steps of h seconds from times within t_tol (s) of the core's: ``lane(core, t, h)``
    advances it by one proved-free step and returns ``(core.output_values(), T_imb)``, or
    None while the core is not in it.

    A declared accelerator: ``_proved_free_step`` (the flight map ``FlightModel.propagate``,
    the cached impulse of ``_imb_flight``, ``_add_psi``), ``TouchdownCore._finish`` (the
    compensated clock) and ``TouchdownCore.output_values`` (in flight), inlined with the
    held inputs' constants bound once, each product formed as there, so the state and
    every output are the same to the bit (tests/test_quiet_lane.py checks it at random
    states against those definitions). Issue 26 item 3: a levitated step at constant
    inputs costs what its arithmetic costs (docs/benchmarks.md, "Quiet steps")."""
    W, _F, a = core._inputs
    fm, p = core._fm, core._p
    co = fm.coeffs(h, cache=True)
    F1, fz, fv = fm.F1, fm.f0 * co.qz0, fm.f0 * co.qv0
    # (complex(x) * z has the bits of x * z, which CPython computes as complex(x) * z after
    # float.__mul__ declines)
    p11, p12, p21, p22 = complex(co.p11), complex(co.p12), complex(co.p21), complex(co.p22)
    qzs, qvs = co.qzs, co.qvs
    bz, bv, b0, bE = core._imb_free
    dpsi, iW, c_r, den, RW = W * h, 1j * W, p.c_r, p.c_r * W, p.R * W
    bx, by, c, k = core._bias_force.real, core._bias_force.imag, p.c, p.k
    mode, n_imp, t_last, v_last, E_diss = (core._mode, core._n_impacts, core._t_last,
                                           core._v_last, core._E_diss)  # (fixed in flight)
    rect, floor, pi, neg_pi = cmath.rect, math.floor, math.pi, -math.pi
    E_of, E_at, Ec_at = None, 0j, 0j

    def lane(core: Any, t_start: float, h_: float) -> QuietStep | None:
        t0 = core._t
        if (core._lane is not lane or h_ != h or not abs(t_start - t0) <= t_tol
                or not core.imbalance_torque):
            return None
        nonlocal E_of, E_at, Ec_at
        psi, z0, v0 = core._psi, core._z, core._v
        if psi is E_of:  # (the phasor of the last lane step and its conjugate)
            E, Ec = E_at, Ec_at
        else:
            E = rect(1.0, psi)  # (cmath.exp(1j psi)'s bits, without forming 1j psi)
            Ec = E.conjugate()
        g = F1 * E
        z = p11 * z0 + p12 * v0 + fz + g * qzs
        v = p21 * z0 + p22 * v0 + fv + g * qvs
        P = (Ec * (bz * z0 + bv * v0 + b0)).imag + bE
        x = psi + dpsi
        q = x + pi
        if not 0.0 <= q < TWO_PI_HI:  # (_add_psi's floor(q / TWO_PI_HI) is not 0: the
            n = floor(q / TWO_PI_HI)  # quotient of a correctly rounded division is >= 1
            x = (x - n * TWO_PI_HI) - n * TWO_PI_LO  # exactly when q >= TWO_PI_HI)
            core._turns += n
        y = h - core._t_lo
        t = t0 + y
        core._t_lo = (t - t0) - y
        core._t = t
        core._z = z
        core._v = v
        core._psi = x
        E_at = E = rect(1.0, x)  # (not kept on the core: a step off the lane computes it)
        E_of = x
        Ec_at = rot = E.conjugate()
        U = z * rot
        dU = (v - iW * z) * rot / den
        if dU - dU != 0j:  # (W != 0 but tiny: c_r W may be too small for v's size)
            dU = 0j
        r = abs(z)
        rr = r * r
        x_ = z.real
        y_ = z.imag
        vx = v.real
        vy = v.imag
        cross = x_ * vy - y_ * vx
        whirl = cross / rr if rr > 0.0 else (cross / r) / r if r > 0.0 else 0.0
        return (x_, y_, vx, vy, r / c_r, U.real / c_r, U.imag / c_r,
                dU.real, dU.imag, -x if x == neg_pi else x, whirl, RW + c_r * whirl,
                a * (bx - c * vx - k * x_), a * (by - c * vy - k * y_), W, mode, n_imp,
                t_last, v_last, E_diss), P / h

    lane.h, lane.t_tol = h, t_tol  # type: ignore[attr-defined]
    return lane  # type: ignore[return-value]
