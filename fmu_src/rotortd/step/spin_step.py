"""The segments of a rotor whose spin is a state (docs/model.md §8): ``SpinSteps``.

Frame and units: inertial, SI. One core, ``simulator.TouchdownCore``, carries both rotors:
its spin held (J = inf; Omega an input of each step) or a state (J finite; the drive
torque T_drive held over a step). With the spin a state, translation and spin are solved
together as one rigid body (J the polar inertia about the mass centre), with T_drive,
F_ext and amb_on held; the core binds these segment choices in place of the held-spin ones
(``TouchdownCore._bind_rotor``), inside the same step loop (``TouchdownCore._segments``):

    free flight (segments.spin_flight.SpinFlight: closed form with the bearing off and no
    external force, else integrated; rigorous contact search)
    -> impacts (the contact pair's law, contact.pair.ContactPair.impact: Newton + Coulomb
       through the Delassus matrix, capped so that no impact creates energy)
    -> sustained contact (segments.spin_contact.SpinContact: sliding or rolling about the
       contact point) -> lift-off -> free flight.

The low-speed rule that turns an impact into contact is the one rule
(``flight_step.starts_contact``) with the restitution the impact used.
"""

from __future__ import annotations

import cmath
import math
from typing import Any, Protocol

from ..contact.impact import Impact
from ..contact.search import SEGMENT_WORK, WORK_MAX
from ..contact.wall import SegmentEnd, WallForces
from ..params import InputError, check_finite
from ..scaled import TWO_PI_HI, TWO_PI_LO
from ..segments.spin_contact import (
    ContactForces,
    ContactModel,
    HeldInputs,
    SpinContact,
    orbit_advance,
    rolling_forces,
    sliding_forces,
)
from ..segments.spin_flight import HORIZON, SpinFlight, free_acceleration
from ..segments.spin_quiet import QUIET_WORK, QuietSpinStep
from .flight_step import QuietStep, reference_rate, starts_contact
from .report import (
    MODE_FREE,
    MODE_ROLLING,
    MODE_SLIDING,
    StepContext,
    StepReport,
)


class SpinSteps:
    """The segments of the rotor whose spin is a state (mixin of ``simulator.TouchdownCore``,
    bound in place of the held-spin ones when J is finite: ``TouchdownCore._bind_rotor``)."""

    # ------------------------------------------------------------------ stepping

    def _spin_step(self, h: float, Omega: float | None = None, F_ext: complex = 0j,
                   amb_on: float = 1.0, budget: int | None = None, *,
                   T_drive: float = 0.0) -> StepReport:
        """``step`` with the spin a state (bound in its place by ``_bind_rotor``): advance by
        h (s) with T_drive (N m), F_ext (N) and amb_on held; ``Omega`` is ignored. Work bound
        as TouchdownCore.step."""
        F = complex(F_ext)
        if not (0.0 < h < math.inf and math.isfinite(T_drive) and 0.0 <= amb_on <= 1.0
                and math.isfinite(F.real) and math.isfinite(F.imag)):
            self._reject_inputs(h, 0.0, F, amb_on)
            check_finite("T_drive", T_drive, InputError)
        a, T = float(amb_on), float(T_drive)
        self._inputs = (self._inputs[0], F, a)
        cap = WORK_MAX if budget is None else max(0, min(budget, WORK_MAX))
        if self._mode == MODE_FREE and not self._on_wall:
            rep = self._spin_quiet_step(h, F, a, T, cap)
            if rep is not None:
                return rep
        held = HeldInputs(self._p, self._J, a, F, T)
        asked = (self._mode == MODE_ROLLING and self._race is None
                 and SpinContact.orbit_applies(held, True))
        if asked:
            rep = self._spin_roll_step(h, held, cap)
            if rep is not None:
                return rep
        rep = StepReport()  # (then work_cap: a keyword argument costs 110 ns)
        rep.work_cap = cap
        t0, W0 = self._t, self._inputs[0]
        st = StepContext(cap)
        st.held = held
        st.orbit_asked = asked
        s = self._segments(h, t0, rep, st)
        self._finish(rep, t0, s, h, True)
        self._spin_imbalance_torque(rep, W0, held.T_drive, h if s >= h else self._t - t0)
        return rep

    def _spin_roll_step(self, h: float, held: HeldInputs, cap: int) -> StepReport | None:
        """A rolling step that the dry whirl orbit takes whole, without the step loop: the
        loop's first segment (``_segments``, ``_spin_advance_contact``) asks the orbit
        (``orbit_advance``) with the same arguments, and the report is kept as
        the loop keeps it for that one segment (``_end_segment``, ``_finish``, the spin's
        balance): the same state and report to the bit. None where the orbit refuses; its
        answer is then the core's orbit, and the loop's segment does not ask again
        (``StepContext.orbit_asked``)."""
        W0 = self._inputs[0]
        end, self._orbit = orbit_advance(
            self._orbit, held, self._theta, self._psi, W0, h, cap - SEGMENT_WORK,
            self._slide_step)
        if end is None:
            return None
        self._slide_step = end.next_step
        return self._whole_report(h, W0, held.T_drive, cap, end.work, end)

    def _spin_quiet_step(self, h: float, F: complex, a: float, T_drive: float, cap: int
                         ) -> StepReport | None:
        """The quiet step: a flight off the wall proved clear of it over the whole step
        and advanced at once, without the step loop (docs/model.md 8, "Quiet steps"). First
        the declared accelerator ``QuietSpinStep`` (its own proof, the held-speed closed
        form plus the spin's collocation; cached for the inputs and h), else
        ``SpinFlight._run_quiet`` (one bound, one short Taylor expansion): the same result
        to rounding, with the report and work of the step loop's one flight segment. None
        when neither applies (the step loop then runs)."""
        W0, p = self._inputs[0], self._p
        if cap < SEGMENT_WORK + QUIET_WORK or (a == 0.0 and F == 0j):
            return None  # (no budget, or the closed form's flight: bearing off, no F_ext)
        q = self._quiet_spin
        if q is None or not q.matches(p, self._J, a, F, h):
            q = self._quiet_spin = QuietSpinStep(p, self._J, a, F, h)
        z, v = self._z, self._v
        if q.usable and q.covers(W0) and q.clear(z, v, W0, T_drive):
            end = q.step(z, v, self._psi, W0, T_drive)
            if end is not None:
                self._z, self._v = end[0], end[1]
                self._set_psi(end[2])
                self._set_spin(end[3])
                return self._whole_report(h, W0, T_drive, cap, QUIET_WORK)
        if h * abs(W0) > HORIZON:
            return None  # longer than one bound covers (the horizon is <= HORIZON/|W0|)
        fl = SpinFlight(p, self._J, a, F, T_drive, z, v, self._psi, W0)
        # (positional: built every quiet step, and keywords cost 0.85 us a call)
        if fl.closed or h > fl.horizon:
            return None
        end = fl._run_quiet(h, cap - SEGMENT_WORK)
        if end is None:
            return None
        self._z, self._v = end.z, end.v
        self._spin_advance_spin(end)
        return self._whole_report(h, W0, T_drive, cap, end.work)

    def _whole_report(self, h: float, W0: float, T_drive: float, cap: int, work: int,
                      end: SegmentEnd | None = None) -> StepReport:
        """The report of a step taken whole as the step loop's one segment (a quiet step,
        or ``end``, a contact segment's, applied first), which took ``work`` units; the
        clock advanced by h."""
        rep = StepReport()
        rep.work_cap = cap
        if end is not None:
            self._end_segment(end, rep, None, 1.0 + 0j)
        rep.work = SEGMENT_WORK + work
        self._finish(rep, self._t, h, h, True)
        self._spin_imbalance_torque(rep, W0, T_drive, h)
        return rep

    def _spin_quiet_lane(self, h: float, t_tol: float = 0.0) -> SpinQuietLane | None:
        """``quiet_lane`` with the spin a state (bound in its place by ``_bind_rotor``): the
        lane of the quiet step's first branch (``QuietSpinStep``) for steps of h seconds
        from times within t_tol (s) of the core's; None when the state is not in it
        (contact, a real bearing, no usable QuietSpinStep for the inputs and h: it exists
        after a quiet step of h; a spin too fast for it, ``QuietSpinStep.covers``).
        ``lane(core, t, h, T_drive)`` (``make_spin_quiet_lane``) takes that step under the
        drive torque T_drive (N m, the other inputs those of the last step) and returns
        ``(output_values(), T_imb)``; or None, doing nothing, when the step is not proved
        clear or the core has left the lane."""
        lane = self._lane
        if lane is not None and lane.h == h and lane.t_tol == t_tol:
            return lane
        _W, F, a = self._inputs
        q = self._quiet_spin
        if (self._mode != MODE_FREE or self._on_wall or self._race is not None or q is None
                or not q.usable or not q.matches(self._p, self._J, a, F, h)
                or not q.covers(_W)):
            return None
        self._lane = lane = make_spin_quiet_lane(q, t_tol)
        return lane

    def _spin_imbalance_torque(self, rep: StepReport, W0: float, T_drive: float,
                          span: float) -> None:
        """The imbalance reaction torque e_c Im(conj(F_amb + F_ext + F_c) E) over the step
        (docs/model.md 9), from the spin's balance J dOmega = int (T_drive + T_f + T_imb):
        P_imb = J (Omega - W0) - T_drive span + R P_t (N m s), T_imb = P_imb/span (N m);
        its rounding is about eps J |Omega| (N m s)."""
        if span > 0.0:
            rep.P_imb = self._J * (self._inputs[0] - W0) - T_drive * span + self._p.R * rep.P_t
            rep.T_imb = rep.P_imb / span

    def _set_psi(self, psi: float) -> None:
        """Set the spin angle from an unwrapped value psi = _psi + increment (rad)."""
        self._add_psi(psi - self._psi)

    # ------------------------------------------------------------------ flight and impacts

    def _spin_advance_free(self, s: float, h: float, t0: float, rep: StepReport,
                      st: StepContext) -> float:
        """A free-flight segment from s (s) into the step (``SpinFlight``); an impact or
        contact at its end."""
        rem = (h - s) - st.s_lo
        held = st.held
        end = SpinFlight(self._p, self._J, held.a, held.F_ext, held.T_drive, self._z, self._v,
                         self._psi, self._inputs[0]).run(rem, st.cap - st.work.total)
        st.work.iters += end.work
        self._orbit = None  # (a dry whirl orbit ends with the rolling)
        self._z, self._v = end.z, end.v
        self._spin_advance_spin(end)
        if end.event is None:
            return h
        s_wall = st.later(s, min(end.duration, rem))
        sticky = s_wall == s == st.sticky_at  # a second zero-length flight here
        if not self._spin_at_wall(t0 + s_wall + st.s_lo, held, rep, st, sticky):
            st.sticky_at = s_wall  # touched, but no contact force: flight again
        return s_wall

    def _spin_advance_spin(self, end: SegmentEnd) -> None:
        """The spin at a segment's end: its angle and speed, states of the segment."""
        self._set_psi(end.psi)
        self._set_spin(end.Omega)

    def _set_spin(self, W: float) -> None:
        self._inputs = (W, *self._inputs[1:])

    def _spin_at_wall(self, t: float, held: HeldInputs, rep: StepReport, st: StepContext,
                 sticky: bool) -> bool:
        """The flight reached the wall at t (s): an impact if it moves outward, then
        contact if the low-speed rule says so or it touched with zero normal speed. False
        when it touched and contact was refused (no positive normal force): the flight
        goes on. ``sticky``: the flight touched again at once at the same time, so the
        normal force is zero to its rounding band; contact is taken with that slack."""
        pair = self.contact_pair
        z, n = pair.on_circle(self._z)
        rdot, vrel = pair.velocities(n, self._v, self._inputs[0])
        if rdot > 0.0:
            if self._spin_impact(t, z, n, rdot, vrel, held, rep):
                self._enter_spin_contact(held, st, False)
            return True
        self._z = z
        return self._enter_spin_contact(held, st, sticky)

    def _spin_impact(self, t: float, z: complex, n: complex, rdot: float, vrel: float,
                     held: HeldInputs, rep: StepReport) -> bool:
        """Apply the impact law of the contact pair at z (on the circle) to the separation
        speed rdot > 0 and the slip vrel (m/s); True when the low-speed rule makes it
        plastic (contact starts)."""
        p, W, pair = self._p, self._inputs[0], self.contact_pair
        dl = pair.delassus(n, self._psi)
        r = pair.impact(dl, p.mu, p.d, rdot, vrel)
        v_minus = self._v
        v_plus = pair.rotor.velocity_after(v_minus, n, self._psi, r)
        A = self._outward_accel_spin(z, v_plus, W + r.dOmega, held)
        plastic = starts_contact(A, r.d_eff * rdot, r.d_eff, p.c_r, lambda: reference_rate(
            WallForces.build(p, W + r.dOmega, held.F_ext, held.a),
            (n.conjugate() * (v_plus - pair.bearing.velocity())).imag / p.c_r, A, p.c_r))
        if plastic:
            r = pair.impact(dl, p.mu, 0.0, rdot, vrel)
            v_plus = pair.rotor.velocity_after(v_minus, n, self._psi, r)
            d = r.d_eff
            self._t_contact = t + (2.0 * d * rdot / ((1.0 - d) * A) if 0.0 < d < 1.0
                                   else 0.0)
        self._record_impact(rep, Impact(t, z, v_minus, v_plus, rdot, r.P_n, r.P_t, r.stick,
                                        r.E_diss), n)
        pair.apply(r, n)
        self._z, self._v = z, v_plus
        self._set_spin(W + r.dOmega)
        return plastic

    def _outward_accel_spin(self, z: complex, v: complex, W: float,
                            held: HeldInputs) -> float:
        """Outward normal acceleration d^2|z|/dt^2 (m/s^2) at the wall of the free motion
        from (z, v) with spin W (rad/s)."""
        p = self._p
        E = cmath.exp(1j * (self._psi + p.phi))
        F = p.amb_force(held.a, z, v) + held.F_ext
        zdd, _ = free_acceleration(F, p.m, p.g, p.e_c, self._J, held.T_drive, W, E)
        n = z / abs(z)
        w = n.conjugate() * v
        return (n.conjugate() * zdd).real + w.imag * w.imag / abs(z)

    # ------------------------------------------------------------------ contact

    def _spin_contact_forces(self, held: HeldInputs, s: float) -> ContactForces:
        W = self._inputs[0]
        if s == 0.0:
            return rolling_forces(held, self._theta, self._psi, W)
        return sliding_forces(held, s, self._theta, self._dtheta, self._psi, W)

    def _enter_spin_contact(self, held: HeldInputs, st: StepContext, sticky: bool) -> bool:
        """Enter sustained contact from the wall state (z, v): rolling where the slip is
        zero and rolling holds, else sliding; stay in flight (False) if the normal force
        is not positive, or with ``sticky`` not above minus its rounding band (then the
        contact segment lifts off only below that band, StepContext.n_slack)."""
        p = self._p
        z, v = self._z, self._v
        n = z / abs(z)
        self._theta = cmath.phase(n)
        self._dtheta = (n.conjugate() * v).imag / p.c_r
        slack = (ContactModel(held).normal_tol(self._theta, self._dtheta, self._psi,
                                               self._inputs[0]) if sticky else 0.0)
        mode, s = self._spin_contact_mode(held, p.R * self._inputs[0] + p.c_r * self._dtheta,
                                     -slack)
        if mode == MODE_FREE:
            self._on_wall = True
            return False
        self._mode, self._slip = mode, s
        st.n_slack = slack
        return True

    def _spin_contact_mode(self, held: HeldInputs, vrel: float, n_min: float = 0.0
                      ) -> tuple[int, float]:
        """(mode, slip sign) of the contact at the current (theta, theta', psi, Omega);
        MODE_FREE when the normal force is not above n_min (N)."""
        p = self._p
        if vrel == 0.0:
            f = self._spin_contact_forces(held, 0.0)
            if n_min >= f.N:
                return MODE_FREE, 0.0
            if abs(f.F_t) <= p.mu * f.N:
                return MODE_ROLLING, 0.0
            s = 1.0 if f.F_t > 0.0 else -1.0
        else:
            s = 1.0 if vrel > 0.0 else -1.0
        f = self._spin_contact_forces(held, s)
        return (MODE_SLIDING, s) if n_min < f.N else (MODE_FREE, 0.0)

    def _spin_advance_contact(self, s: float, h: float, rep: StepReport, st: StepContext
                         ) -> float:
        """A contact segment from s (s) into the step (``SpinContact``); the transition at
        its end."""
        rem = (h - s) - st.s_lo
        slip = 0.0 if self._mode == MODE_ROLLING else self._slip
        seg = SpinContact(st.held, slip, self._theta, self._dtheta, self._psi,
                          self._inputs[0], self._slide_step,
                          st.n_slack if s == st.sticky_at else 0.0, self._orbit,
                          st.orbit_asked)
        st.orbit_asked = False
        end = seg.run(rem, st.cap - st.work.total)
        st.work.iters += end.work
        self._slide_step = end.next_step
        self._orbit = end.orbit
        self._end_segment(end, rep, st, 1.0 + 0j)  # (I_z = 0: T_imb from the spin balance)
        return st.later(s, end.duration) if end.duration < rem else h

    def _spin_roll_or_slide(self, st: StepContext) -> None:
        """At zero slip: rolling or sliding by the spin-state contact forces, or flight
        when the normal force is not positive there."""
        mode, s = self._spin_contact_mode(st.held, 0.0)
        if mode == MODE_FREE:
            self._lift_off()
        else:
            self._mode, self._slip = mode, s

    def _spin_cone_sign(self, st: StepContext) -> float:
        """The slip sign when rolling leaves the friction cone (spin-state forces)."""
        return 1.0 if self._spin_contact_forces(st.held, 0.0).F_t > 0.0 else -1.0


class SpinQuietLane(Protocol):
    """``lane(core, t, h, T_drive)``: one quiet step of h s from t (s) under the drive
    torque T_drive (N m) (``SpinSteps._spin_quiet_lane``)."""

    h: float
    t_tol: float

    def __call__(self, core: Any, t: float, h: float, T_drive: float
                 ) -> QuietStep | None: ...


def make_spin_quiet_lane(q: QuietSpinStep, t_tol: float) -> SpinQuietLane:
    """The spin state's quiet lane for the inputs and step of ``q``, from times within
    t_tol (s) of the core's: ``lane(core, t, h, T_drive)`` takes ``_spin_quiet_step``'s
    first branch (``q.clear``, ``q.step``) and the step's end as ``_whole_report`` does
    (``_set_psi``, the spin, the compensated clock of ``_finish``, T_imb of
    ``_spin_imbalance_torque`` with P_t = 0), then ``output_values()`` in flight, inlined
    as the held lane inlines them (``flight_step.make_quiet_lane``): the same operations
    in the same order, so the same state and values to the bit (tests/test_spin_quiet.py),
    without the step report and its checks. None, doing nothing, for another h, a clock
    off the core's, a core that left the lane (other inputs, parameters or J, contact),
    or a step ``q`` does not prove clear or take."""
    h, p, J, a, F = q.h, q.p, q.J, q.a, q.F_ext
    clear, advance, R0 = q.clear, q.step, p.R * 0.0
    c_r, R, c, k = p.c_r, p.R, p.c, p.k
    bx, by = p.bias_force.real, p.bias_force.imag
    rect, floor, pi, neg_pi = cmath.rect, math.floor, math.pi, -math.pi

    def lane(core: Any, t_start: float, h_: float, T: float) -> QuietStep | None:
        t0 = core._t
        W0, F_, a_ = core._inputs
        if (core._lane is not lane or h_ != h or not abs(t_start - t0) <= t_tol
                or core._mode or core._on_wall or F_ != F or a_ != a or core._p is not p
                or core._J != J):
            return None
        z, v, psi = core._z, core._v, core._psi
        if not clear(z, v, W0, T):
            return None
        end = advance(z, v, psi, W0, T)
        if end is None:
            return None
        z, v, psi1, W = end
        x = psi + (psi1 - psi)  # (_set_psi, _add_psi)
        q_ = x + pi
        if not 0.0 <= q_ < TWO_PI_HI:  # (floor(q_ / TWO_PI_HI) != 0: see make_quiet_lane)
            n = floor(q_ / TWO_PI_HI)
            x = (x - n * TWO_PI_HI) - n * TWO_PI_LO
            core._turns += n
        core._psi = x
        core._z, core._v = z, v
        core._inputs = (W, F_, a_)
        y = h - core._t_lo
        t = t0 + y
        core._t_lo = (t - t0) - y
        core._t = t
        core._E_at = E = rect(1.0, x)  # (_phasor: cmath.exp(1j x)'s bits)
        core._E_of = x
        rot = E.conjugate()
        U = z * rot
        den = c_r * W
        dU = (v - 1j * W * z) * rot / den if den != 0.0 else 0j
        if dU - dU != 0j:
            dU = 0j
        r = abs(z)
        rr = r * r
        x_, y_, vx, vy = z.real, z.imag, v.real, v.imag
        cross = x_ * vy - y_ * vx
        whirl = cross / rr if rr > 0.0 else (cross / r) / r if r > 0.0 else 0.0
        return (x_, y_, vx, vy, r / c_r, U.real / c_r, U.imag / c_r, dU.real, dU.imag,
                -x if x == neg_pi else x, whirl, R * W + c_r * whirl,
                a * (bx - c * vx - k * x_), a * (by - c * vy - k * y_), W,
                0, core._n_impacts, core._t_last, core._v_last, core._E_diss
                ), (J * (W - W0) - T * h + R0) / h

    lane.h, lane.t_tol = h, t_tol  # type: ignore[attr-defined]
    return lane  # type: ignore[return-value]
