"""Sustained contact: the contact segments of TouchdownCore.

Frame and units: inertial, SI; the contact state is (theta, theta') on the clearance
circle (``rotortd.segments``). A mixin of ``simulator.TouchdownCore``: each contact segment
is chosen from the state (lift-off, rolling, a rub in closed form, sliding), advanced
through the one segment interface ``run(rem, limit) -> SegmentEnd`` and its end applied.
"""

from __future__ import annotations

import cmath
import math

from ..contact.events import LIFT_OFF, SLIP_START, SLIP_STUCK, Event
from ..contact.wall import SegmentEnd, WallForces
from ..scaled import wrap_angle
from ..segments.rolling import Rolling
from ..segments.rub import (
    QUAD_TOL,
    LinearRub,
    LockedRub,
    QuadraticRub,
    RubEquilibrium,
    forward_rub_equilibria,
    rub_deviation,
)
from ..segments.sliding import Sliding
from .report import MODE_FREE, MODE_ROLLING, MODE_SLIDING, StepContext, StepReport

LOCK_TOL = 1e-14
"""A sliding state on the linearised rub (contact.LinearRub) whose snap_error is at most
LOCK_TOL is put exactly on the stable forward rub and advanced as a rigid rotation: the
snap changes the angle, the rate and the normal force by at most LOCK_TOL relative."""
RUB_RETRY = 4.0
"""Longest sliding segment, in units of 1/w (WallForces.omega_ref), integrated before the
linearised rub and the lock are tried again, when a stable forward rub exists. Without it
a long step integrated all of its sliding, however close to the rub it came (a 10 s step
at the rub cost 0.19 s CPU)."""


class ContactSteps:
    """Sustained contact (mixin of TouchdownCore)."""

    RUB_CLOSED_FORM = True
    """Take sliding on or near a stable forward rub in closed form (LockedRub, LinearRub,
    QuadraticRub). False integrates it like any sliding: the check of the closed forms
    (tests/test_contact.py) runs a core with it off beside one with it on."""

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

    def _advance_contact(self, s: float, h: float, rep: StepReport, st: StepContext) -> float:
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
            seg = Sliding(wf, self._theta, self._dtheta, E, self._slip, slack, self._slide_step,
                          self.imbalance_torque)  # (positional: built every segment)
            end = seg.run(self._slide_span(rem), st.cap - st.work.total)
            self._slide_step = end.next_step
        st.work.iters += end.work
        self._end_segment(end, rep, st, E)
        return st.later(s, end.duration) if end.duration < rem else h

    def _end_segment(self, end: SegmentEnd, rep: StepReport, st: StepContext | None,
                     E: complex) -> None:
        """Apply the end of a contact segment that started with e^{i psi} = E: its state,
        its contact integrals (into ``rep``) and its event (``st`` may be None only for an
        end without event)."""
        p = self._p
        rep.add_contact(end.tally, p.m * p.c_r, p.c_r)
        if self.imbalance_torque:
            self._imb_add(rep, E, p.c_r * end.tally.I_z)
        self._theta, self._dtheta = wrap_angle(end.theta), end.dtheta
        self._advance_spin(end)
        self._transition(end.event, st)

    def _advance_spin(self, end: SegmentEnd) -> None:
        """The spin angle at a segment's end: advanced at the held speed (SpinCore: the
        segment's own psi and Omega)."""
        self._advance_psi(end.duration)

    def _rub_step(self, h: float, rep: StepReport) -> bool:
        """A sliding step on or near a stable forward rub in closed form, without the step
        loop: the rigid rotation when locked, else the linearised motion when the state
        admits it (``_linear_rub``); False otherwise (the step loop integrates). The inputs
        are those the rub was found under (new inputs unlock it). ``_advance_contact``
        would take the same segment whole: the slip sign agrees with v_rel, and Gn stays
        above the lift-off test (constant on the rotation; bounded below by
        LinearRub.near on the linearised motion)."""
        E = self._phasor()
        rub = self._rub_choice(E, True)
        if rub is None:
            return False
        start = self._imb_start()  # (after a lock: its snap is not an impulse)
        end = rub.run(h)
        rep.work = end.work
        self._end_segment(end, rep, None, E)
        if self.imbalance_torque:
            self._imb_close(rep, start, h)
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

    def _transition(self, event: Event | None, st: StepContext | None) -> None:
        """The mode machine, one for both spin models: apply a contact segment's event.
        LIFT_OFF: to flight; SLIP_START: rolling gives way to sliding, with the slip sign
        of the friction rolling needed; SLIP_ZERO: the slip is zero, roll or slide (or
        leave the wall, with the spin a state) as the forces there say; SLIP_STUCK (held
        spin): zero slip that sliding cannot leave rolls, the cone violations below
        resolution ignored for the rest of the step. The forces at a state come from the
        rotor's model (``_roll_or_slide``, ``_cone_sign``: bound by ``_bind_rotor``)."""
        if event is None:
            return
        if event is LIFT_OFF:
            self._lift_off()
            return
        assert st is not None
        self._locked = False
        if event is SLIP_START:
            self._mode, self._slip = MODE_SLIDING, self._cone_sign(st)
            return
        p = self._p
        self._dtheta = -p.R * self._inputs[0] / p.c_r  # (= -WallForces.wr, bit for bit)
        if event is SLIP_STUCK:
            self._mode = MODE_ROLLING
            st.roll_lenient = True
        else:
            self._roll_or_slide(st)

    def _roll_or_slide(self, st: StepContext) -> None:
        """At zero slip: rolling or sliding by the held spin's wall forces."""
        self._choose_contact_mode()

    def _cone_sign(self, st: StepContext) -> float:
        """The slip sign when rolling leaves the friction cone: that of the static
        friction rolling needed (held spin's wall forces)."""
        _, gt = self._wf.gn_gt(self._theta, self._dtheta, self._phasor())
        return math.copysign(1.0, gt)

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
        if not self.RUB_CLOSED_FORM:
            return None
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

    def _may_linearise(self, s: float, sticky: bool, st: StepContext) -> bool:
        """May a sliding segment starting s seconds into the step try the linearised rub?
        Not when sticky, nor at the step's start when _rub_step has refused that state."""
        refused, st.rub_refused = st.rub_refused and s == 0.0, False
        return not (sticky or refused)

    def _linear_rub(self, E: complex) -> LinearRub | QuadraticRub | None:
        """``closed_form_rub`` at the current sliding state under the held inputs."""
        return closed_form_rub(self._wf, self._rub_equilibria(), self._theta, self._dtheta,
                               E, self._slip)


def closed_form_rub(wf: WallForces, equilibria: list[RubEquilibrium], theta: float,
                    dtheta: float, E: complex, slip: float) -> LinearRub | QuadraticRub | None:
    """The closed-form sliding near a stable forward rub from the sliding state (theta,
    theta', slip) with the phasor E under the wall forces ``wf`` and their rub
    ``equilibria``: linearised when within LINEAR_TOL and its error budget holds
    (LinearRub.admit), else to second order when within QUAD_TOL and its budget holds
    (QuadraticRub.admit); None otherwise."""
    for eq in equilibria:  # (none when q0 != 0)
        dev = rub_deviation(wf, eq, theta, dtheta, E, slip, QUAD_TOL)
        if dev is None:
            continue
        lin = LinearRub.admit(wf, eq, theta, dtheta, slip, dev)
        if lin is None:
            lin = QuadraticRub.admit(wf, eq, theta, dtheta, slip, dev)
        if lin is not None:
            return lin
    return None
