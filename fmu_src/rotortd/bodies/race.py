"""The real touchdown bearing's race as a counter-body (docs/model.md §10): ``RealRace``.

Frame and units: inertial, SI. The race is a ring of bore R_b = R + c_r whose centre z_b
(m, from its static equilibrium) rests on an isotropic spring-damper to the frame
(``support_compliant``: m_b, k_b, c_b; else z_b = 0) and which turns at omega_b (rad/s)
against its drag T_b = -T_b0 sgn(omega_b) - c_bw omega_b (``race_turns``: J_b; else
omega_b = 0). A race at rest is ``held`` by static friction while the torque it needs stays
within T_b0. With the contact open both motions are closed forms:

- the support, m_b z_b'' + c_b z_b' + k_b z_b = 0: with sigma = c_b/(2 m_b) and
  q = k_b/m_b - sigma^2, z_b(t) = e^{-sigma t} (z_0 C + (v_0 + sigma z_0) S),
  z_b'(t) = e^{-sigma t} (v_0 C - (k_b z_0/m_b + sigma v_0) S), where C, S are cos and
  sin/sqrt(q) of sqrt(q) t (q > 0), 1 and t (q = 0), cosh and sinh/sqrt(-q) (q < 0; written
  as exponentials that do not overflow);
- the spin: omega_b(t) = s ((|w_0| + T_b0/c_bw) e^{-c_bw t/J_b} - T_b0/c_bw) until it stops
  at t_stop = (J_b/c_bw) ln(1 + c_bw |w_0|/T_b0) (|w_0| - T_b0 t/J_b at c_bw = 0); then held.

``BearingParams`` are the options and their parameters (the FMU's names).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any

from ..limits import LIMITS, CrossParameterError, ParameterError


@dataclass(frozen=True, slots=True)
class BearingParams:
    """The real bearing's options and parameters (SI; docs/model.md §10). ``race_turns``:
    J_b (kg m^2), T_b0 (N m), c_bw (N m s), omega_b0 (rad/s, the race's spin at the start);
    ``support_compliant``: m_b (kg), k_b (N/m), c_b (N s/m); ``contact_compliant``: k_c
    (N/m, the stiffness at delta_ref = 10 um), p_c (the exponent, in [1, 1.5]: 1 linear,
    10/9 Palmgren's line contact of a roller, 1.5 Hertz's point contact of a ball; the law
    and its exact restitution hold for any p, docs/model.md §10)."""

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

    @property
    def any_option(self) -> bool:
        """True when the bearing is not the chapter's fixed rigid one."""
        return self.race_turns or self.support_compliant or self.contact_compliant

    def check(self, d: float) -> None:
        """Raise ParameterError naming the first value outside its range (``limits.LIMITS``),
        CrossParameterError for d = 0 under the compliant law."""
        for f in fields(self):
            v = getattr(self, f.name)
            lim = LIMITS.get(f.name)
            if lim is None or isinstance(v, bool):
                continue
            if not (math.isfinite(v) and lim.lo <= v <= lim.hi):
                u = "" if lim.unit == "1" else f" {lim.unit}"
                raise ParameterError(
                    f"{f.name} = {v!r}{u} is out of range: it must lie in "
                    f"[{lim.lo:g}, {lim.hi:g}]{u}")
        if self.contact_compliant and d == 0.0:
            raise CrossParameterError(
                "d = 0 is refused under the compliant contact law (contact_compliant): the "
                "damping that gives an impact the restitution d (docs/model.md (10.7)) has no "
                "finite value at d = 0; use d > 0")


def _oscillator(sigma: float, q: float, t: float) -> tuple[float, float, float]:
    """(e^{-sigma t} C, e^{-sigma t} S, e^{-sigma t}) of the module docstring."""
    e = math.exp(-sigma * t)
    if q > 0.0:
        w = math.sqrt(q)
        return e * math.cos(w * t), e * math.sin(w * t) / w, e
    if q == 0.0:
        return e, e * t, e
    a = math.sqrt(-q)
    ep, em = math.exp((a - sigma) * t), math.exp(-(a + sigma) * t)
    return 0.5 * (ep + em), 0.5 * (ep - em) / a, e


class RealRace:
    """The race (module docstring): a counter-body of ``contact.pair.ContactPair``."""

    KIND = "real-race"
    """The "kind" of its state record (``rotortd.step.state``)."""

    def __init__(self, bp: BearingParams, *, c_r: float, R: float, z_b: complex = 0j,
                 v_b: complex = 0j, omega_b: float | None = None) -> None:
        self.params = bp
        self.c_r, self.R_b = c_r, R + c_r
        self.z_b, self.v_b = (complex(z_b), complex(v_b)) if bp.support_compliant else (0j, 0j)
        w = bp.omega_b0 if omega_b is None else float(omega_b)
        self.omega_b = w if bp.race_turns else 0.0
        self.held = bp.race_turns and bp.T_b0 > 0.0 and self.omega_b == 0.0
        self.E_drag = 0.0
        """Heat of the race's drag so far (J)."""
        self.E_support = 0.0
        """Heat of the support's damper so far (J)."""
        self.E_fric = 0.0
        """Friction heat put into the contact so far (J): sliding and impacts."""
        sup = bp.support_compliant
        self._sigma = 0.5 * bp.c_b / bp.m_b if sup else 0.0
        self._w2 = bp.k_b / bp.m_b if sup else 0.0
        self.rate = math.sqrt(self._w2) + 2.0 * self._sigma if sup else 0.0
        """Fastest rate of the centre's free motion (1/s)."""

    # ---------------------------------------------------------------- the contact pair's view

    def centre(self) -> complex:
        return self.z_b

    def velocity(self) -> complex:
        return self.v_b

    def surface_speed(self, n: complex) -> float:
        """R_b omega_b (m/s): the race surface's speed along i n."""
        return self.R_b * self.omega_b

    def delassus(self, n: complex) -> tuple[float, float, float]:
        """The race's share of W under an impulse (1/kg): 1/m_b on both axes with a compliant
        support, R_b^2/J_b tangentially when it turns (an impulse overcomes static friction)."""
        bp = self.params
        im = 1.0 / bp.m_b if bp.support_compliant else 0.0
        return (im, 0.0, im + (self.R_b * self.R_b / bp.J_b if bp.race_turns else 0.0))

    def apply_impulse(self, P_n: float, P_t: float, n: complex) -> None:
        """The impulse (P_n + i P_t) n (N s) on the race at its contact point."""
        bp = self.params
        if bp.support_compliant:
            self.v_b += complex(P_n, P_t) * n / bp.m_b
        if bp.race_turns:
            self.omega_b += self.R_b * P_t / bp.J_b
            self.held = self.held and self.omega_b == 0.0

    @property
    def moves(self) -> bool:
        """The centre moves with the contact open (a sprung race off its equilibrium)."""
        return self.z_b != 0j or self.v_b != 0j

    def motion(self) -> tuple[complex, complex, float, bool]:
        """(z_b, v_b, omega_b, held): the race's state, for ``set_motion``."""
        return self.z_b, self.v_b, self.omega_b, self.held

    def set_motion(self, z_b: complex, v_b: complex, omega_b: float,
                   held: bool | None = None) -> None:
        """Set the race's state (m, m/s, rad/s); ``held`` None: held when at rest against
        static friction."""
        bp = self.params
        if bp.support_compliant:
            self.z_b, self.v_b = z_b, v_b
        if bp.race_turns:
            self.omega_b = omega_b
            self.held = (bp.T_b0 > 0.0 and omega_b == 0.0) if held is None else held

    # ---------------------------------------------------------------- free motion

    def path(self, s: float) -> tuple[complex, complex, complex, complex]:
        """(z_b, z_b', z_b'', z_b''') s seconds from now with the contact open."""
        if not self.params.support_compliant:
            return (0j, 0j, 0j, 0j)
        sg, w2 = self._sigma, self._w2
        C, S, _ = _oscillator(sg, w2 - sg * sg, s)
        z0, v0 = self.z_b, self.v_b
        z = z0 * C + (v0 + sg * z0) * S
        v = v0 * C - (w2 * z0 + sg * v0) * S
        a = -(2.0 * sg * v + w2 * z)
        return z, v, a, -(2.0 * sg * a + w2 * v)

    def path_bounds(self, s: float, tau: float) -> tuple[float, float, float, float, float]:
        """Bounds of (|z_b|, |z_b'|, ..., |z_b''''|) on [s, s + tau]: the energy
        k_b |z_b|^2 + m_b |z_b'|^2 does not grow (c_b >= 0), and the ODE gives the rest."""
        if not self.params.support_compliant:
            return (0.0, 0.0, 0.0, 0.0, 0.0)
        z, v, _, _ = self.path(s)
        w2, c2 = self._w2, 2.0 * self._sigma
        e = (w2 * abs(z) ** 2 + abs(v) ** 2) * (1.0 + 1e-12)  # (per unit m_b)
        b0, b1 = math.sqrt(e / w2), math.sqrt(e)
        b2 = w2 * b0 + c2 * b1
        b3 = w2 * b1 + c2 * b2
        return b0, b1, b2, b3, w2 * b2 + c2 * b3

    def spin_at(self, s: float) -> float:
        """omega_b (rad/s) after s seconds with the contact open (the drag law)."""
        bp, w = self.params, self.omega_b
        if not bp.race_turns or w == 0.0 or (bp.T_b0 == 0.0 and bp.c_bw == 0.0):
            return w
        sg, a = (1.0 if w > 0.0 else -1.0), abs(w)
        if bp.c_bw == 0.0:
            return sg * max(a - bp.T_b0 * s / bp.J_b, 0.0)
        r = bp.T_b0 / bp.c_bw
        x = -bp.c_bw * s / bp.J_b
        val = a * math.exp(x) + r * math.expm1(x)  # (a + r) e^x - r
        return sg * max(val, 0.0)

    def advance(self, s: float) -> None:
        """Commit s seconds of free motion (the contact open), with the heats."""
        bp = self.params
        if bp.support_compliant and self.moves:
            z, v, _, _ = self.path(s)
            e0 = 0.5 * (bp.k_b * abs(self.z_b) ** 2 + bp.m_b * abs(self.v_b) ** 2)
            self.z_b, self.v_b = z, v
            self.E_support += e0 - 0.5 * (bp.k_b * abs(z) ** 2 + bp.m_b * abs(v) ** 2)
        if bp.race_turns:
            w = self.spin_at(s)
            self.E_drag += 0.5 * bp.J_b * (self.omega_b - w) * (self.omega_b + w)
            self.omega_b = w
            self.held = bp.T_b0 > 0.0 and w == 0.0

    def support_force(self) -> complex:
        """k_b z_b + c_b z_b' (N): the force the support passes to the frame (0 with a rigid
        support: the contact's force passes then)."""
        bp = self.params
        return bp.k_b * self.z_b + bp.c_b * self.v_b if bp.support_compliant else 0j

    # ---------------------------------------------------------------- record

    def record(self) -> dict[str, Any]:
        """The race's state as a plain dict (floats round-trip exactly)."""
        return {"kind": self.KIND, "x_b": self.z_b.real, "y_b": self.z_b.imag,
                "vx_b": self.v_b.real, "vy_b": self.v_b.imag, "omega_b": self.omega_b,
                "held": self.held, "E_drag": self.E_drag, "E_support": self.E_support,
                "E_fric": self.E_fric}

    @classmethod
    def from_record(cls, bp: BearingParams, rec: dict[str, Any], *, c_r: float, R: float
                    ) -> RealRace:
        """The race of ``record``."""
        race = cls(bp, c_r=c_r, R=R, z_b=complex(rec["x_b"], rec["y_b"]),
                   v_b=complex(rec["vx_b"], rec["vy_b"]), omega_b=float(rec["omega_b"]))
        race.held = bool(rec["held"])
        race.E_drag, race.E_support = float(rec["E_drag"]), float(rec["E_support"])
        race.E_fric = float(rec["E_fric"])
        return race
