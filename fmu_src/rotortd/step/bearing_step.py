"""The segments of a rotor in the real touchdown bearing (docs/model.md §10): ``BearingSteps``.

Frame and units: inertial, SI. With any of the bearing's options on (``BearingParams``: the
race turns, the support gives, the contact is compliant) the core (the spin a state) binds
these segment choices in place of the fixed bearing's (``TouchdownCore._bind_rotor``), in
the same step loop:

    free flight (segments.spin_flight.SpinFlight against the race's circle, which moves on
    its support in closed form: bodies.race.RealRace.path; the race's spin follows its
    drag law, also closed form)
    -> at the circle: under the rigid law the pair's impact law (contact.pair.ContactPair
       with the race as counter-body) and the low-speed rule; under the compliant law the
       contact closes with chi = c_d/max(delta', V_FLOOR) (contact.laws.damping_factor)
    -> sustained contact (segments.bearing_contact.BearingContact: sliding or sticking,
       the race turning or held at rest, the compliant law clamped or not)
    -> separation or lift-off -> free flight.

In contact the core keeps the rotor's own (z, z') (not the fixed bearing's (theta,
theta')), and the race's state lives in ``RealRace``. The contact's discrete state is
chosen by one classifier (``_bearing_classify``) at every entry and every event.
"""

from __future__ import annotations

from dataclasses import asdict
from typing import Any

from ..bodies.race import BearingParams, RealRace
from ..bodies.rotor import RigidRotor, SpinReset
from ..contact.events import Event
from ..contact.impact import Impact
from ..contact.laws import damping_factor, restitution_damping, stiffness_coefficient
from ..contact.pair import ContactPair
from ..contact.wall import ContactTally, WallForces
from ..segments.bearing_contact import (
    BearingContact,
    BearingEnd,
    BearingLaw,
    BearingModel,
    ContactState,
)
from ..segments.spin_contact import HeldInputs
from ..segments.spin_flight import SpinFlight
from .flight_step import reference_rate, starts_contact
from .report import MODE_FREE, MODE_ROLLING, MODE_SLIDING, StepContext, StepReport
from .spin_step import SpinSteps

MOVING_FLIGHT_WORK = 2
"""A flight against a moving race counts its work this many times: the race's path and
its bounds cost as much as the rotor's Taylor steps (measured on a chattering case of the
FMU fuzz: 13,500 flights in 7.3 s of CPU)."""
EVENT_WORK = 200
"""Work units charged at each arrival at the race's circle (the classifier, the pair's
impact law, the low-speed rule: about 0.2-0.3 ms measured, the core's units being
1.5-2 us)."""


def _sign(x: float) -> float:
    return 1.0 if x > 0.0 else -1.0


class BearingSteps:
    """The segments of the rotor in the real bearing (mixin of ``simulator.TouchdownCore``,
    bound in place of the fixed bearing's when a bearing option is on)."""

    _race: RealRace
    _law: BearingLaw
    _cstate: ContactState
    _c_d: float

    def _bearing_state(self) -> list[float]:
        """The eleven states of ``segments.bearing_contact`` now."""
        z, v, zb, vb = self._z, self._v, self._race.z_b, self._race.v_b
        return [z.real, z.imag, v.real, v.imag, self._psi, self._inputs[0], zb.real, zb.imag,
                vb.real, vb.imag, self._race.omega_b]

    def _bearing_wall_state(self) -> tuple[complex, complex]:
        """(z, v): the rotor's own state, in flight and in contact alike."""
        return self._z, self._v

    def _bearing_output_values(self, Omega: float | None = None, amb_on: float | None = None
                               ) -> tuple[float, ...]:
        """``TouchdownCore.output_values`` once the race moves (docs/model.md §10, "What the
        outputs mean"): x, y, vx, vy the rotor's centre in the frame; r_rel, U, dU/dt and
        the whirl rate of Delta = z - z_b; v_rel the slip (10.5)."""
        out = list(type(self).output_values(self, Omega, amb_on))
        race, p = self._race, self._p
        W = self._inputs[0] if Omega is None else Omega
        D, dD = self._z - race.z_b, self._v - race.v_b
        rot = self._phasor().conjugate()
        U = D * rot / p.c_r
        den = p.c_r * W
        dU = (dD - 1j * W * D) * rot / den if den != 0.0 else 0j
        r = abs(D)
        whirl = (D.conjugate() * dD).imag / (r * r) if r > 0.0 else 0.0
        n = D / r if r > 0.0 else 1.0 + 0j
        out[4:9] = [r / p.c_r, U.real, U.imag, dU.real, dU.imag]
        out[10] = whirl
        out[11] = p.R * W + (n.conjugate() * dD).imag - race.surface_speed(n)
        return tuple(out)

    def _bearing_quiet_step(self, h: float, F: complex, a: float, T_drive: float, cap: int
                            ) -> StepReport | None:
        """The quiet step of the fixed bearing (``SpinSteps._spin_quiet_step``) while the
        race's centre rests at the origin; the race's spin follows its drag law."""
        if self._race.moves:
            return None
        rep = SpinSteps._spin_quiet_step(self, h, F, a, T_drive, cap)
        if rep is not None:
            self._race.advance(h)
        return rep

    # ------------------------------------------------------------------ flight

    def _bearing_advance_free(self, s: float, h: float, t0: float, rep: StepReport,
                              st: StepContext) -> float:
        """A free flight from s (s) into the step against the race's (moving) circle; at its
        end the race is advanced in closed form, and at the circle the contact begins."""
        rem = (h - s) - st.s_lo
        held, race = st.held, self._race
        end = SpinFlight(self._p, self._J, held.a, held.F_ext, held.T_drive, self._z,
                         self._v, self._psi, self._inputs[0],
                         bearing=race if race.moves else None).run(rem, st.cap - st.work.total)
        st.work.iters += end.work * (MOVING_FLIGHT_WORK if race.moves else 1)
        self._z, self._v = end.z, end.v
        self._spin_advance_spin(end)
        vb0 = race.v_b
        race.advance(min(end.duration, rem))
        if self._law.support:  # int F_s dt = -m_b (change of v_b) with the contact open
            rep.P_support += self._law.m_b * (vb0 - race.v_b)
        if end.event is None:
            return h
        s_wall = st.later(s, min(end.duration, rem))
        st.work.iters += EVENT_WORK
        self._bearing_at_circle(t0 + s_wall + st.s_lo, held, rep)
        return s_wall

    def _bearing_at_circle(self, t: float, held: HeldInputs, rep: StepReport) -> None:
        """The flight reached the race's circle at t (s). Compliant law: the contact closes
        if the rotor moves (or, touching, accelerates) into the race. Rigid law: an impact
        if it moves outward, then contact by the low-speed rule. Where it touched and no
        contact force arises, the flight goes on."""
        race = self._race
        zb = race.centre()
        D = self._z - zb
        n = D / abs(D)
        self._z = zb + self._p.c_r * n  # onto the circle (the search ends within ulps)
        rdot = (n.conjugate() * (self._v - race.velocity())).real
        model = BearingModel(held, self._law, ContactState(1.0))
        if self._law.compliant:
            if not (rdot <= 0.0
                    and model.free_normal_acceleration(self._bearing_state()) <= 0.0):
                self._bearing_enter(held, damping_factor(self._c_d, rdot))
        elif not rdot > 0.0 or self._bearing_impact(t, n, rdot, held, rep):
            self._bearing_enter(held, 0.0)

    def _bearing_impact(self, t: float, n: complex, rdot: float, held: HeldInputs,
                        rep: StepReport) -> bool:
        """The pair's impact law with the race as counter-body at separation speed
        rdot > 0 (m/s); True when the low-speed rule makes it plastic (contact starts)."""
        p, W = self._p, self._inputs[0]
        race = self._race
        pair = ContactPair(RigidRotor(p.m, self._J, p.e_c, p.phi, p.R), race)
        _, vrel = pair.velocities(n, self._v, W)
        dl = pair.delassus(n, self._psi)
        v_minus, before = self._v, race.motion()
        r = pair.impact(dl, p.mu, p.d, rdot, vrel)
        self._bearing_apply_impulse(pair, r, n, W)
        A = BearingModel(held, self._law, ContactState(1.0)).free_normal_acceleration(
            self._bearing_state())
        wf = WallForces.build(p, self._inputs[0], held.F_ext, held.a)
        dth = (n.conjugate() * (self._v - race.velocity())).imag / p.c_r
        plastic = starts_contact(A, r.d_eff * rdot, r.d_eff, p.c_r, lambda: max(
            reference_rate(wf, dth, A, p.c_r), race.rate))
        if plastic:  # again from before the impact, with d = 0
            self._v = v_minus
            race.set_state(*before)
            r = pair.impact(dl, p.mu, 0.0, rdot, vrel)
            self._bearing_apply_impulse(pair, r, n, W)
        self._record_impact(rep, Impact(t, self._z, v_minus, self._v, rdot, r.P_n, r.P_t,
                                        r.stick, r.E_diss), n)
        if not self._law.support:  # a rigid support passes the impulse to the frame
            rep.P_support += complex(r.P_n, r.P_t) * n
        heat = 0.5 * r.P_t * (vrel + r.vrel_plus)  # the tangential impulse's work
        rep.E_fric += heat
        race.E_fric += heat
        return plastic

    def _bearing_apply_impulse(self, pair: ContactPair, r: SpinReset, n: complex,
                               W: float) -> None:
        """The impulse of the impact ``r`` on both bodies (spin W (rad/s) before it)."""
        self._v = pair.rotor.velocity_after(self._v, n, self._psi, r)
        pair.apply(r, n)
        self._set_spin(W + r.dOmega)

    # ------------------------------------------------------------------ contact

    def _bearing_enter(self, held: HeldInputs, chi: float) -> None:
        """Enter sustained contact from the state at the circle: the classifier's state, or
        flight on the wall when there is no contact force."""
        cs = self._bearing_classify(held, chi)
        if cs is None:
            self._on_wall = True
        else:
            self._bearing_set_contact(cs)

    def _bearing_set_contact(self, cs: ContactState) -> None:
        self._cstate = cs
        self._mode = MODE_ROLLING if cs.s == 0.0 else MODE_SLIDING
        self._slip = cs.s

    def _bearing_classify(self, held: HeldInputs, chi: float, clamped: bool = False
                          ) -> ContactState | None:
        """The contact's discrete state at the current state (None: no contact force, the
        rotor is in flight). The race at rest is held while the static torque it needs is
        within T_b0; at zero slip the contact sticks while |F_t| <= mu N, else slides in the
        direction of the sticking force; both at once: the race breaks away first."""
        law, p = self._law, self._p
        y = self._bearing_state()
        wb = y[10]
        hold = law.turns and law.T_b0 > 0.0 and wb == 0.0
        s_b = _sign(wb) if wb != 0.0 else 1.0

        def forces(s: float, race_held: bool, sb: float):
            cs = ContactState(s, clamped, chi, race_held, sb)
            return cs, BearingModel(held, law, cs).forces(y)

        vrel = forces(1.0, hold, s_b)[1].vrel
        if p.mu == 0.0:
            s = 1.0
        elif vrel != 0.0:
            s = _sign(vrel)
        else:
            s = 0.0
        cs, f = forces(s, hold, s_b)
        if s == 0.0 and abs(f.F_t) > p.mu * f.N:
            s = _sign(f.F_t)
            cs, f = forces(s, hold, s_b)
        if hold and law.R_b * abs(f.F_t) > law.T_b0:  # the race breaks away
            cs, f = forces(s, False, _sign(f.F_t))
            if s == 0.0 and abs(f.F_t) > p.mu * f.N:
                s = _sign(f.F_t)
                cs, f = forces(s, False, cs.s_b)
        if law.compliant:
            if f.delta <= 0.0 and f.ddelta <= 0.0 and not (f.delta == 0.0 and chi > 0.0):
                return None
            if not clamped and f.N_law <= 0.0 and f.delta > 0.0:
                return ContactState(s, True, chi, cs.race_held, cs.s_b)
            return cs
        return cs if f.N > 0.0 else None

    def _bearing_advance_contact(self, s: float, h: float, rep: StepReport, st: StepContext
                                 ) -> float:
        """A contact segment from s (s) into the step (``BearingContact``); the transition
        at its end."""
        rem = (h - s) - st.s_lo
        seg = BearingContact(st.held, self._law, self._cstate, self._bearing_state(),
                             self._slide_step)
        end = seg.run(rem, st.cap - st.work.total)
        st.work.iters += end.work
        self._slide_step = end.next_step
        self._bearing_apply_end(end, rep)
        self._bearing_transition(end.event, st)
        return st.later(s, end.duration) if end.duration < rem else h

    def _bearing_apply_end(self, end: BearingEnd, rep: StepReport) -> None:
        """The segment's end state into the core and the race; its integrals into ``rep``."""
        p, y, q = self._p, end.y, end.q
        self._z, self._v = complex(y[0], y[1]), complex(y[2], y[3])
        self._set_psi(y[4])
        self._set_spin(y[5])
        race = self._race
        race.set_state(complex(y[6], y[7]), complex(y[8], y[9]), y[10])
        race.E_drag += q[6]
        race.E_support += q[7]
        mc = p.m * p.c_r
        rep.add_contact(ContactTally(I_n=q[0] / mc, I_c=complex(q[2], q[3]) / mc,
                                     I_t=q[1] / mc, I_e=(q[4] + q[5]) / (mc * p.c_r),
                                     peak=end.N_peak / mc, work=end.work), mc, p.c_r)
        rep.P_support += complex(q[8], q[9])
        rep.E_fric += q[4]
        race.E_fric += q[4]

    def _bearing_transition(self, event: Event | None, st: StepContext) -> None:
        """The contact's next discrete state after ``event`` (None: the step's end)."""
        if event is None:
            return
        cs = self._cstate
        if event == Event.SEPARATE or (event == Event.LIFT_OFF and not self._law.compliant):
            self._bearing_lift_off()
            return
        if event == Event.RACE_STOP:
            self._race.set_state(self._race.z_b, self._race.v_b, 0.0)
        clamped = {Event.LIFT_OFF: True, Event.CLAMP_END: False}.get(event, cs.clamped)
        if event == Event.SLIP_ZERO:
            self._v_rel_zero()
        nxt = self._bearing_classify(st.held, cs.chi, clamped)
        if nxt is None:
            self._bearing_lift_off()
        else:
            self._bearing_set_contact(nxt)

    def _v_rel_zero(self) -> None:
        """At SLIP_ZERO the slip is zero to the location's resolution: make it exactly 0
        through the spin (an O(ulp) change), so that the classifier sees zero slip."""
        race, p = self._race, self._p
        D = self._z - race.z_b
        n = D / abs(D)
        w = (n.conjugate() * (self._v - race.v_b)).imag
        self._set_spin((race.surface_speed(n) - w) / p.R)

    def _bearing_lift_off(self) -> None:
        """Into flight: the rotor onto the circle if the located end left it inside the
        penetration by rounding."""
        race = self._race
        D = self._z - race.z_b
        if abs(D) > self._p.c_r:
            self._z = race.z_b + D * (self._p.c_r / abs(D))
        self._mode, self._slip = MODE_FREE, 0.0
        self._on_wall = True
        self._cstate = ContactState(1.0)
        self._forget_clear_proof()

    def _bearing_law(self) -> BearingLaw:
        """The segment's view of the bearing's parameters (SI)."""
        bp, p = self._race.bp, self._p
        return BearingLaw(bp.race_turns, bp.J_b, bp.T_b0, bp.c_bw, p.R + p.c_r,
                          bp.support_compliant, bp.m_b, bp.k_b, bp.c_b,
                          bp.contact_compliant, stiffness_coefficient(bp.k_c, bp.p_c),
                          bp.p_c)

    def _bearing_c_d(self) -> float:
        """c_d of (10.7) for the restitution d under the compliant law (else 0)."""
        return restitution_damping(self._p.d) if self._race.bp.contact_compliant else 0.0

    # ------------------------------------------------------------------ state record

    def _bearing_record(self) -> dict[str, Any]:
        """The state's "bearing" record (``step.state``): the race's own record, the
        bearing's parameters and the contact's discrete state."""
        cs = self._cstate
        return {**self._race.record(), "kind": RealRace.KIND,
                "params": asdict(self._race.bp),
                "contact": {"s": cs.s, "clamped": cs.clamped, "chi": cs.chi,
                            "race_held": cs.race_held, "s_b": cs.s_b}}

    def _restore_bearing(self, rec: dict[str, Any]) -> None:
        """Restore the real bearing from a "bearing" record of ``_bearing_record``
        (ParameterError, nothing changed, for a record that is not one)."""
        from ..limits import ParameterError
        try:
            bp = BearingParams(**rec["params"])
            race = RealRace.from_record(bp, rec, c_r=self._p.c_r, R=self._p.R)
            c = rec["contact"]
            cs = ContactState(float(c["s"]), bool(c["clamped"]), float(c["chi"]),
                              bool(c["race_held"]), float(c["s_b"]))
        except (KeyError, TypeError, ValueError) as exc:
            raise ParameterError(f"the state's bearing record is not readable: {exc}") from exc
        self._use_bearing(bp)
        self._race, self._cstate = race, cs
