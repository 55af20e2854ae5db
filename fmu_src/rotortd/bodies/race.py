"""The real touchdown bearing's race: a counter-body that turns and sits on a compliant
support (docs/model.md §10, equations (10.3), (10.4), (10.8) and "Closed forms").

Frame and units: inertial, SI. The race is a ring of bore R_b = R + c_r (m) whose centre
z_b (m, measured from its static equilibrium, so gravity does not enter) moves with velocity
v_b (m/s) on an isotropic spring-damper to the frame (``support_compliant``: mass m_b (kg),
stiffness k_b (N/m), damping c_b (N s/m)), and which spins at omega_b (rad/s) against the
drag torque T_b = -T_b0 sgn(omega_b) - c_bw omega_b (N m) of its rolling elements and seals
(``race_turns``: polar inertia J_b (kg m^2)); at rest it is held by static friction up to
|T_b| = T_b0 (``held``). With an option off its states stay 0: a rigid support is
z_b = v_b = 0, a race that does not turn is omega_b = 0 (and ``held``, by the frame).

``RealRace`` implements ``rotortd.bodies.bearing.CounterBody``. With the contact open it
moves in closed form: the damped linear oscillator m_b z_b'' + c_b z_b' + k_b z_b = 0
(under-, critically and over-damped, each without cancellation or overflow) and the spin's
drag law (``spin_at``, ``spin_stop_time``); ``advance`` commits a free motion and
accumulates the heats ``E_drag`` (race drag) and ``E_support`` (support damper). The
contact's sustained forces are the contact segment's business (it sets the state back with
``set_state``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any

from ..contact.laws import restitution_damping
from ..limits import LIMITS, CrossParameterError
from ..params import check_range

_MARGIN = 1e-9
"""Relative margin of ``path_bounds`` over the energies it is built from (rounding)."""

_EPS = 2.0 ** -52
"""The double's machine epsilon (the rounding bounds of ``RealRace._derivs``)."""


@dataclass(frozen=True, slots=True)
class BearingParams:
    """Parameters of the real touchdown bearing (docs/model.md §10), SI.

    race_turns         the inner race spins (omega_b a state)
    J_b                race polar inertia, kg m^2
    T_b0               race drag: Coulomb part and static friction torque at rest, N m
    c_bw               race drag: viscous part, N m s
    omega_b0           race spin at the start, rad/s
    support_compliant  the race centre sits on an isotropic spring-damper
    m_b                race (and housing) mass on the support, kg
    k_b                support stiffness, N/m
    c_b                support damping, N s/m
    contact_compliant  the compliant contact law (10.6) instead of the rigid one
    k_c                contact stiffness at the reference penetration DELTA_REF = 10 um, N/m
    p_c                contact exponent in [1, 1.5]: 1 linear, 10/9 Palmgren's line contact
                       of a roller, 1.5 Hertz's point contact of a ball (the law and its
                       exact restitution hold for any p)
    """

    race_turns: bool = False
    J_b: float = 2e-4
    T_b0: float = 0.02
    c_bw: float = 1e-5
    omega_b0: float = 0.0
    support_compliant: bool = False
    m_b: float = 2.0
    k_b: float = 5e7
    c_b: float = 2e3
    contact_compliant: bool = False
    k_c: float = 1e9
    p_c: float = 1.0

    def __post_init__(self) -> None:
        for f in fields(self):
            conv = bool if f.type in (bool, "bool") else float
            object.__setattr__(self, f.name, conv(getattr(self, f.name)))

    @property
    def any_option(self) -> bool:
        """True when any of the three options is on (all off: the chapter's bearing)."""
        return self.race_turns or self.support_compliant or self.contact_compliant

    def check(self, d: float) -> None:
        """Raise ``ParameterError`` naming the variable, value, unit and range of the first
        value outside ``limits.LIMITS`` (every value is checked, whether its option is on or
        not); ``CrossParameterError`` for d = 0 (restitution, 1) under the compliant law."""
        for f in fields(self):
            if f.type in (bool, "bool"):
                continue
            lim = LIMITS[f.name]
            check_range(f.name, getattr(self, f.name), lim.lo, lim.hi,
                        unit="" if lim.unit == "1" else lim.unit)
        check_range("d", d, 0.0, 1.0)
        if self.contact_compliant:
            if d == 0.0:
                raise CrossParameterError(
                    "d = 0.0 is refused under the compliant contact law (contact_compliant):"
                    " equation (10.7) of docs/model.md §10 has no root at d = 0 (a perfectly"
                    " plastic compliant contact has no finite damping); use d in (0, 1], or"
                    " the rigid law")
            if not math.isfinite(restitution_damping(d)):
                raise CrossParameterError(
                    f"d = {d!r} is refused under the compliant contact law: its damping "
                    "c_d of (10.7) (about 1/d) overflows; use d >= 1e-300")


def _spin_after(omega: float, s: float, J_b: float, T_b0: float, c_bw: float) -> float:
    """omega_b (rad/s) after s (s) of J_b omega' = -T_b0 sgn(omega) - c_bw omega from
    omega, 0 once stopped, i.e. for s >= ``_stop_time`` (the closed forms of
    docs/model.md §10)."""
    if omega == 0.0 or s <= 0.0:
        return omega if s <= 0.0 else 0.0
    if s >= _stop_time(omega, J_b, T_b0, c_bw):
        return 0.0
    a = abs(omega)
    if c_bw == 0.0:
        if T_b0 == 0.0:
            return omega
        w = a - T_b0 * s / J_b
    elif T_b0 == 0.0:
        w = a * math.exp(-c_bw * s / J_b)
    else:
        x = -c_bw * s / J_b
        w = a * math.exp(x) + (T_b0 / c_bw) * math.expm1(x)
    return math.copysign(w, omega) if w > 0.0 else 0.0


def _stop_time(omega: float, J_b: float, T_b0: float, c_bw: float) -> float:
    """The time (s) the drag law takes to stop the spin omega (rad/s): inf if it never does
    (T_b0 = 0), 0 at rest."""
    a = abs(omega)
    if a == 0.0:
        return 0.0
    if T_b0 == 0.0:
        return math.inf
    if c_bw == 0.0:
        return J_b * a / T_b0
    return (J_b / c_bw) * math.log1p(c_bw * a / T_b0)


class RealRace:
    """The race of a real touchdown bearing (``CounterBody``; SI, inertial): centre
    ``z_b`` (m), velocity ``v_b`` (m/s), spin ``omega_b`` (rad/s), ``held`` (at rest, held by
    static friction, or by the frame when the race does not turn), bore ``R_b`` = R + c_r
    (m); the cumulative heats ``E_drag`` (J, race drag) and ``E_support`` (J, support damper).
    """

    __slots__ = (
        "E_drag",
        "E_fric",
        "E_support",
        "R",
        "R_b",
        "_beta",
        "_gam",
        "_kind",
        "_lam1",
        "_lam2",
        "_w2",
        "bp",
        "c_r",
        "held",
        "omega_b",
        "v_b",
        "z_b",
    )
    KIND = "real-race"
    """The "kind" of its state record (``rotortd.step.state``)."""

    def __init__(self, bp: BearingParams, *, c_r: float, R: float, z_b: complex = 0j,
                 v_b: complex = 0j, omega_b: float | None = None) -> None:
        self.bp = bp
        self.c_r = float(c_r)
        self.R = float(R)
        self.R_b = self.R + self.c_r
        self.E_drag = 0.0
        """Heat of the race's drag so far (J)."""
        self.E_support = 0.0
        """Heat of the support's damper so far (J)."""
        self.E_fric = 0.0
        """Friction heat put into the contact so far (J): sliding and impacts (the
        contact segments and the impacts add it)."""
        self.z_b, self.v_b, self.omega_b, self.held = 0j, 0j, 0.0, True
        self.set_state(z_b, v_b, bp.omega_b0 if omega_b is None else omega_b)
        # the support's oscillator: z'' + 2 gam z' + w2 z = 0
        self._w2 = w2 = bp.k_b / bp.m_b
        self._gam = gam = 0.5 * bp.c_b / bp.m_b
        w0 = math.sqrt(w2)
        b2 = (gam - w0) * (gam + w0)  # beta^2 = gam^2 - w0^2 (1/s^2)
        self._beta = math.sqrt(abs(b2))
        self._kind = "over" if b2 > 0.0 else "under" if b2 < 0.0 else "critical"
        self._lam1 = self._lam2 = 0.0
        if self._kind == "over":  # the two real rates, the slow one without cancellation
            self._lam2 = -(gam + self._beta)
            self._lam1 = -w2 / (gam + self._beta)

    # ------------------------------------------------------------------ state
    def motion(self) -> tuple[complex, complex, float, bool]:
        """(z_b, v_b, omega_b, held): the state ``set_state`` takes back."""
        return self.z_b, self.v_b, self.omega_b, self.held

    def set_state(self, z_b: complex, v_b: complex, omega_b: float,
                  held: bool | None = None) -> None:
        """Set the state (m, m/s, rad/s), 0 where an option is off; ``held`` defaults to
        "at rest" (omega_b == 0)."""
        bp = self.bp
        self.z_b, self.v_b = (complex(z_b), complex(v_b)) if bp.support_compliant else (0j, 0j)
        self.omega_b = float(omega_b) if bp.race_turns else 0.0
        if not bp.race_turns:
            self.held = True
        else:
            self.held = self.omega_b == 0.0 if held is None else bool(held)
            if self.omega_b != 0.0:
                self.held = False

    def centre(self) -> complex:
        """The race centre z_b (m)."""
        return self.z_b

    def velocity(self) -> complex:
        """The race centre's velocity v_b (m/s)."""
        return self.v_b

    def surface_speed(self, n: complex) -> float:
        """The race surface's speed along i n at the contact, R_b omega_b (m/s)."""
        return self.R_b * self.omega_b

    def delassus(self, n: complex) -> tuple[float, float, float]:
        """The race's share (W_nn, W_nt, W_tt) (1/kg) of an impact's Delassus matrix (10.8):
        1/m_b with a compliant support, + R_b^2/J_b tangentially for a turning race (held
        or not: an impulse overcomes any finite static friction torque)."""
        bp = self.bp
        wm = 1.0 / bp.m_b if bp.support_compliant else 0.0
        wj = self.R_b * self.R_b / bp.J_b if bp.race_turns else 0.0
        return (wm, 0.0, wm + wj)

    def sustained_delassus(self, n: complex) -> tuple[float, float, float]:
        """The share (1/kg) under sustained contact forces: as ``delassus``, without
        R_b^2/J_b while the race is held by static friction."""
        if self.held:
            wm = 1.0 / self.bp.m_b if self.bp.support_compliant else 0.0
            return (wm, 0.0, wm)
        return self.delassus(n)

    def apply_impulse(self, P_n: float, P_t: float, n: complex) -> None:
        """The race's response to the impulse (P_n + i P_t) n (N s) at its contact point:
        v_b += (P_n + i P_t) n/m_b, omega_b += R_b P_t/J_b (each with its option)."""
        bp = self.bp
        if bp.support_compliant:
            self.v_b += complex(P_n, P_t) * n / bp.m_b
        if bp.race_turns:
            self.omega_b += self.R_b * P_t / bp.J_b
            self.held = self.omega_b == 0.0

    # ------------------------------------------------------------- free motion
    @property
    def moves(self) -> bool:
        """The centre moves in free motion: a compliant support out of rest."""
        return self.bp.support_compliant and (self.z_b != 0j or self.v_b != 0j)

    @property
    def rate(self) -> float:
        """A rate (1/s) covering the centre path's fastest motion, sqrt(k_b/m_b) +
        c_b/m_b; 0 when it does not move."""
        if not self.moves:
            return 0.0
        return math.sqrt(self._w2) + 2.0 * self._gam

    def _propagator(self, t: float) -> tuple[float, float, float, float, float, float]:
        """(p11, p12, p21, p22, a11, a22): the oscillator's state (x, x') after t (s) is
        (p11 x0 + p12 x0', p21 x0 + p22 x0'); a11, a22 bound the magnitudes of the terms
        p11 and p22 are summed from (for the rounding bound of ``path_bounds``)."""
        gam, w2 = self._gam, self._w2
        if self._kind == "over":
            # the modes e1 = e^{lam1 t} (slow), e2 = e^{lam2 t}, S = (e1 - e2)/(2 beta):
            # p11 = e1 + |lam1| S, p22 = e2 - |lam1| S, without the cancellation of
            # e^{-gam t}(cosh -/+ gam sinh/beta) on the slow mode
            e1, e2 = math.exp(self._lam1 * t), math.exp(self._lam2 * t)
            S = -e1 * math.expm1(-2.0 * self._beta * t) / (2.0 * self._beta)
            a1S = -self._lam1 * S
            return (e1 + a1S, S, -w2 * S, e2 - a1S, e1 + a1S, e2 + a1S)
        e = math.exp(-gam * t)
        if self._kind == "under":
            E = e * math.cos(self._beta * t)
            S = e * math.sin(self._beta * t) / self._beta
        else:
            E, S = e, e * t
        mag = abs(E) + gam * abs(S)
        return (E + gam * S, S, -w2 * S, E - gam * S, mag, mag)

    def _derivs(self, s: float) -> tuple[list[complex], list[float]]:
        """([c, c', c'', c''', c''''] at s (s) from now (m ... m/s^4), and a bound of each
        one's rounding error: 8 ulp of the propagator's terms for (c, c') (none at s = 0,
        the state itself), then the error of each step of the ODE's recursion
        c^(k+2) = -(w2 c^(k) + 2 gam c^(k+1)) added to what it propagates."""
        g2, w2 = 2.0 * self._gam, self._w2
        z, v = self.z_b, self.v_b
        if s > 0.0:
            p11, p12, p21, p22, a11, a22 = self._propagator(s)
            d = [p11 * z + p12 * v, p21 * z + p22 * v]
            u = 8.0 * _EPS
            err = [u * (a11 * abs(z) + abs(p12) * abs(v)),
                   u * (abs(p21) * abs(z) + a22 * abs(v))]
        else:
            d, err = [z, v], [0.0, 0.0]
        for k in range(3):
            d.append(-(w2 * d[k] + g2 * d[k + 1]))
            err.append(4.0 * _EPS * (w2 * abs(d[k]) + g2 * abs(d[k + 1]))
                       + w2 * err[k] + g2 * err[k + 1])
        return d, err

    def path(self, s: float) -> tuple[complex, complex, complex, complex]:
        """(c, c', c'', c''') of the centre s (s) from now in free motion (m, m/s, m/s^2,
        m/s^3); the higher derivatives from the ODE at s (not propagated from now: a fast
        mode that has died out would leave its rounding in them)."""
        if not self.moves:
            return (0j, 0j, 0j, 0j)
        d = self._derivs(s)[0]
        return (d[0], d[1], d[2], d[3])

    def path_bounds(self, s: float, tau: float) -> tuple[float, float, float, float, float]:
        """Upper bounds of (|c|, |c'|, |c''|, |c'''|, |c''''|) on [s, s + tau] (m ... m/s^4)
        in free motion: every derivative y = c^(k) obeys the oscillator's equation, so
        E_k = k_b |y|^2 + m_b |y'|^2 does not increase (c_b >= 0); |c^(k)| <= sqrt(E_k/k_b)
        and |c^(k+1)| <= sqrt(E_k/m_b) after s. E_k is taken at s and now (the smaller),
        from the derivatives plus a bound of their rounding errors (``_derivs``), with a
        further relative margin of 1e-9."""
        if not self.moves:
            return (0.0, 0.0, 0.0, 0.0, 0.0)
        w2 = self._w2

        def amps(s: float) -> list[tuple[float, float]]:
            # k = 0..3: (sqrt(E_k/k_b), sqrt(E_k/m_b)), E_k = k_b|c^(k)|^2 + m_b|c^(k+1)|^2
            d, err = self._derivs(s)
            a = [abs(x) + e for x, e in zip(d, err, strict=True)]
            return [(math.sqrt(a[k] * a[k] + a[k + 1] * a[k + 1] / w2),
                     math.sqrt(w2 * a[k] * a[k] + a[k + 1] * a[k + 1])) for k in range(4)]

        A0 = amps(0.0)
        As = amps(s) if s > 0.0 else A0
        m = 1.0 + _MARGIN

        def bound(k: int, i: int) -> float:
            return m * min(A0[k][i], As[k][i])

        B = [bound(0, 0)]
        for k in range(1, 4):
            B.append(min(bound(k - 1, 1), bound(k, 0)))
        B.append(bound(3, 1))
        return (B[0], B[1], B[2], B[3], B[4])

    def spin_at(self, s: float) -> float:
        """omega_b (rad/s) after s (s) of free motion (the drag law alone)."""
        if not self.bp.race_turns or self.held:
            return 0.0
        bp = self.bp
        return _spin_after(self.omega_b, s, bp.J_b, bp.T_b0, bp.c_bw)

    def spin_stop_time(self) -> float:
        """The time (s) from now at which free motion stops the spin (0 when held; inf when
        it never stops exactly, T_b0 = 0)."""
        if not self.bp.race_turns or self.held:
            return 0.0
        bp = self.bp
        return _stop_time(self.omega_b, bp.J_b, bp.T_b0, bp.c_bw)

    def advance(self, s: float) -> None:
        """Commit s (s) of free motion (the contact open): the centre and spin in closed
        form, ``held`` once the spin stops; E_support += the drop of 1/2 m_b |v_b|^2 +
        1/2 k_b |z_b|^2, E_drag += the drop of 1/2 J_b omega_b^2 (J)."""
        bp = self.bp
        if self.moves:
            z0, v0 = self.z_b, self.v_b
            p11, p12, p21, p22, _, _ = self._propagator(s)
            z1, v1 = p11 * z0 + p12 * v0, p21 * z0 + p22 * v0
            self.z_b, self.v_b = z1, v1
            self.E_support += 0.5 * (bp.k_b * (abs(z0) ** 2 - abs(z1) ** 2)
                                     + bp.m_b * (abs(v0) ** 2 - abs(v1) ** 2))
        if bp.race_turns and not self.held:
            w0 = self.omega_b
            w1 = _spin_after(w0, s, bp.J_b, bp.T_b0, bp.c_bw)
            self.E_drag += 0.5 * bp.J_b * (w0 - w1) * (w0 + w1)
            self.omega_b = w1
            self.held = w1 == 0.0

    # ---------------------------------------------------------------- balances
    def energy(self) -> float:
        """The race's mechanical energy (J): 1/2 m_b |v_b|^2 + 1/2 k_b |z_b|^2 (with the
        support) + 1/2 J_b omega_b^2 (turning race); docs/model.md §10, Balances."""
        bp = self.bp
        E = 0.5 * bp.J_b * self.omega_b * self.omega_b if bp.race_turns else 0.0
        if bp.support_compliant:
            E += 0.5 * (bp.m_b * abs(self.v_b) ** 2 + bp.k_b * abs(self.z_b) ** 2)
        return E

    def angular_momentum(self) -> float:
        """The race's angular momentum about the frame origin (kg m^2/s):
        m_b Im(conj(z_b) v_b) + J_b omega_b (each with its option)."""
        bp = self.bp
        L = bp.J_b * self.omega_b if bp.race_turns else 0.0
        if bp.support_compliant:
            L += bp.m_b * (self.z_b.conjugate() * self.v_b).imag
        return L

    # ------------------------------------------------------------------ forces
    def support_force(self) -> complex:
        """The force k_b z_b + c_b v_b (N, inertial) the support passes to the frame; 0 with
        a rigid support (the contact force then goes to the frame directly)."""
        if not self.bp.support_compliant:
            return 0j
        return self.bp.k_b * self.z_b + self.bp.c_b * self.v_b

    def drag_torque(self) -> float:
        """T_b of (10.4) (N m) on the turning race, -T_b0 sgn(omega_b) - c_bw omega_b; 0
        while held (the holding torque is the contact's business) or not turning."""
        if not self.bp.race_turns or self.held or self.omega_b == 0.0:
            return 0.0
        return -math.copysign(self.bp.T_b0, self.omega_b) - self.bp.c_bw * self.omega_b

    # ------------------------------------------------------------------ record
    def record(self) -> dict[str, Any]:
        """Its state as a plain dict (m, m/s, rad/s, J; ``held`` a bool)."""
        return {"x_b": self.z_b.real, "y_b": self.z_b.imag, "vx_b": self.v_b.real,
                "vy_b": self.v_b.imag, "omega_b": self.omega_b, "held": self.held,
                "E_drag": self.E_drag, "E_support": self.E_support, "E_fric": self.E_fric}

    @classmethod
    def from_record(cls, bp: BearingParams, rec: dict[str, Any], *, c_r: float,
                    R: float) -> RealRace:
        """The race of ``record()`` (a "kind" key, if present, must be ``KIND``)."""
        kind = rec.get("kind", cls.KIND)
        if kind != cls.KIND:
            raise ValueError(f"bearing record of kind {kind!r}: expected {cls.KIND!r}")
        race = cls(bp, c_r=c_r, R=R, z_b=complex(rec["x_b"], rec["y_b"]),
                   v_b=complex(rec["vx_b"], rec["vy_b"]), omega_b=float(rec["omega_b"]))
        race.set_state(race.z_b, race.v_b, race.omega_b, bool(rec["held"]))
        race.E_drag = float(rec["E_drag"])
        race.E_support = float(rec["E_support"])
        race.E_fric = float(rec["E_fric"])
        return race
