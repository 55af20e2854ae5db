"""The rotor as one rigid body with its spin as a state (docs/model.md §8): the contact point's
geometry, the Delassus matrix W and the impact law.

Frame and units: inertial, SI. The rotor's geometric centre is z, its mass centre
z_G = z + e_c E with E = e^{i(psi + phi)}; J is the polar inertia about the mass centre.
At the contact, n = z/|z| = e^{i theta} is the outward normal, and with
beta = psi + phi - theta (so conj(n) E = e^{i beta}) the lever of the contact point
about the mass centre, in the (n, i n) frame, gives

    B = e_c sin(beta),   A = R - e_c cos(beta).

An impulse -(P_n + i P_t) n on the rotor at the contact point (P_n inward normal, P_t
along -i n) changes the velocity by -(P_n + i P_t) n/m, the spin by -(B P_n + A P_t)/J, and
the contact point's normal and slip velocities (rdot, v_rel) by -W (P_n, P_t), with

    W = I/m + (B, A)(B, A)^T/J.

The impact law (docs/model.md 8): Newton's restitution d on rdot, Coulomb's friction mu on
v_rel with the direction set by the slip after the impact (stick when no admissible slip
remains), and an energetic cap: where Newton's restitution with W_nt != 0 would create
energy, the restitution is lowered to the largest value that does not.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass

from ..params import CrossParameterError, RotorParams

CAP_HALVINGS = 60
"""Bisection steps of the energetic cap when the impact's kind (stick, or the slide's
direction) at the closed form's restitution differs from the kind at d: the largest
restitution without gain is then bracketed between the two."""


@dataclass(frozen=True, slots=True)
class Delassus:
    """W at one contact configuration (1/kg), with the lever (B, A) (m)."""

    B: float
    A: float
    J: float
    nn: float
    nt: float
    tt: float

    @classmethod
    def at(cls, m: float, J: float, e_c: float, R: float, beta: float) -> Delassus:
        """W for mass m (kg), inertia J (kg m^2), eccentricity e_c (m), radius R (m) and the
        angle beta (rad) between the imbalance and the contact normal."""
        B = e_c * math.sin(beta)
        A = R - e_c * math.cos(beta)
        im, iJ = 1.0 / m, 1.0 / J
        return cls(B, A, J, im + B * B * iJ, A * B * iJ, im + A * A * iJ)


def check_well_posed(p: RotorParams, J: float) -> None:
    """Refuse J (kg m^2) for which sliding and impacts may be ill posed (Painleve):
    W_nn > mu |W_nt| at every beta holds when J > m mu e_c (R + e_c)."""
    bound = p.m * p.mu * p.e_c * (p.R + p.e_c)
    if not bound < J:
        raise CrossParameterError(
            f"J = {J!r} kg m^2 is too small for m = {p.m!r} kg, mu = {p.mu!r}, "
            f"e_c = {p.e_c!r} m, R = {p.R!r} m: with the spin as a state, contact is well "
            f"posed (no Painleve paradox) when J > m mu e_c (R + e_c) = {bound!r} kg m^2")


@dataclass(frozen=True, slots=True)
class SpinReset:
    """The outcome of one impact (SI): impulses P_n, P_t (N s, on the rotor
    -(P_n + i P_t) n), the post-impact normal and slip velocities (m/s), the spin change
    (rad/s), whether it sticks, the restitution used (d, or lower where capped) and the
    energy dissipated -dT (J)."""

    P_n: float
    P_t: float
    rdot_plus: float
    vrel_plus: float
    dOmega: float
    stick: bool
    d_eff: float
    E_diss: float


def _outcome(w: Delassus, mu: float, d: float, rdot: float, vrel: float
             ) -> tuple[float, float, float, bool]:
    """(P_n, P_t, v_rel+, stick) of Newton's restitution d with Coulomb friction, the slip's
    direction taken after the impact."""
    D = (1.0 + d) * rdot
    det = w.nn * w.tt - w.nt * w.nt
    Pn = (w.tt * D - w.nt * vrel) / det
    Pt = (w.nn * vrel - w.nt * D) / det
    if Pn >= 0.0 and abs(Pt) <= mu * Pn:
        return Pn, Pt, 0.0, True
    sig = 1.0 if Pt > 0.0 else -1.0
    Pn = D / (w.nn + mu * sig * w.nt)
    Pt = mu * sig * Pn
    vp = vrel - (w.nt * Pn + w.tt * Pt)
    if vp * sig < 0.0:  # rounding at the stick boundary: the slip stops
        vp = 0.0
    return Pn, Pt, vp, False


def _gain(Pn: float, Pt: float, rdot: float, d: float, vrel: float, vp: float) -> float:
    """dT (J) of an impact: the impulses' work on the contact point's mean velocity."""
    return -0.5 * (Pn * (1.0 - d) * rdot + Pt * (vrel + vp))


def _capped_restitution(w: Delassus, mu: float, d: float, rdot: float, vrel: float,
                        stick: bool, Pt: float) -> float:
    """The largest restitution in [0, d] for which the outcome's kind gives dT = 0."""
    if stick:
        det = w.nn * w.tt - w.nt * w.nt
        q = (w.tt * rdot * rdot - 2.0 * w.nt * rdot * vrel + w.nn * vrel * vrel) / det
        return min(d, math.sqrt(max(q, 0.0) / (w.tt / det)) / rdot)
    sig = 1.0 if Pt > 0.0 else -1.0
    c = (w.nt + mu * sig * w.tt) / (w.nn + mu * sig * w.nt)
    den = rdot * (1.0 + mu * sig * c)
    x = (rdot * (1.0 - mu * sig * c) + 2.0 * mu * sig * vrel) / den if den > 0.0 else 0.0
    return min(d, max(x, 0.0))


def spin_impact(w: Delassus, mu: float, d: float, rdot: float, vrel: float) -> SpinReset:
    """Apply the impact law to normal speed rdot > 0 (m/s, outward) and slip v_rel (m/s)
    at the contact configuration ``w``; restitution d in [0, 1], friction mu >= 0."""
    Pn, Pt, vp, stick = _outcome(w, mu, d, rdot, vrel)
    d_eff = d
    dT = _gain(Pn, Pt, rdot, d, vrel, vp)
    if dT > 0.0:  # Newton's restitution would create energy: cap it
        kind = (stick, Pt > 0.0)
        d_eff = _capped_restitution(w, mu, d, rdot, vrel, stick, Pt)
        Pn, Pt, vp, stick = _outcome(w, mu, d_eff, rdot, vrel)
        dT = _gain(Pn, Pt, rdot, d_eff, vrel, vp)
        if (stick, Pt > 0.0) != kind:  # the kind changed at the closed form's root:
            lo, hi = (d_eff, d) if dT <= 0.0 else (0.0, d_eff)  # bisect for the largest
            for _ in range(CAP_HALVINGS):
                mid = 0.5 * (lo + hi)
                o = _outcome(w, mu, mid, rdot, vrel)
                if _gain(o[0], o[1], rdot, mid, vrel, o[2]) > 0.0:
                    hi = mid
                else:
                    lo = mid
            d_eff = lo
            Pn, Pt, vp, stick = _outcome(w, mu, d_eff, rdot, vrel)
            dT = _gain(Pn, Pt, rdot, d_eff, vrel, vp)
    return SpinReset(Pn, Pt, -d_eff * rdot, vp, -(w.B * Pn + w.A * Pt) / w.J,
                     stick, d_eff, -dT)


@dataclass(frozen=True, slots=True)
class RigidRotor:
    """The rotor as one rigid body: mass m (kg), polar inertia J (kg m^2) about the mass
    centre (``math.inf``: the spin is held, an input), eccentricity e_c (m) at the phase phi
    (rad) from the spin angle, radius R (m)."""

    m: float
    J: float
    e_c: float
    phi: float
    R: float

    @classmethod
    def held(cls, m: float, e_c: float, phi: float, R: float) -> RigidRotor:
        """The rotor whose spin is held (J = inf)."""
        return cls(m, math.inf, e_c, phi, R)

    def delassus(self, n: complex, psi: float) -> Delassus:
        """The rotor's W (1/kg) at normal n with the spin angle psi (rad)."""
        return Delassus.at(self.m, self.J, self.e_c, self.R, psi + self.phi - cmath.phase(n))

    def velocity_after(self, v: complex, n: complex, psi: float, r: SpinReset) -> complex:
        """The centre's velocity (m/s) after the impulse -(P_n + i P_t) n of ``r`` at the
        contact: the translation's change and the mass centre's turn about the centre."""
        iE = 1j * self.e_c * cmath.exp(1j * (psi + self.phi))
        return v - complex(r.P_n, r.P_t) * n / self.m - r.dOmega * iE
