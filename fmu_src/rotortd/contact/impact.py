"""Impact reset law with restitution and Coulomb friction (docs/model.md §4).

Frame and units: inertial, SI. At an impact the rotor centre z lies on the clearance
circle (|z| = c_r), n = z/|z| is the outward normal and i n the tangent. With normal speed
rdot- = Re(conj(n) v-) > 0 and tangential speed vt- = Im(conj(n) v-) = c_r theta',

    rdot+ = -d rdot-,        vt+ = vt- - mu (1 + d) rdot- s,    s = sign(v_rel-),

where v_rel = R Omega + vt is the slip velocity of the contact point. Coulomb caps the
tangential impulse: when the friction impulse would reverse v_rel, it stops at v_rel+ = 0
(the contact sticks). With v_rel- = 0, s = 0 and there is no tangential impulse.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Impact:
    """One impact. SI, inertial frame.

    t (s), z (m, on the circle), v_minus / v_plus (m/s), rdot = rdot- (m/s, > 0),
    P_n (N s) normal impulse on the rotor, inward; P_t (N s) tangential friction impulse
    magnitude along -s (i n), signed with s, so that the impulse on the rotor is
    -(P_n + i P_t) n; stick: the Coulomb cap fired; E_diss (J) energy dissipated.
    """

    t: float
    z: complex
    v_minus: complex
    v_plus: complex
    rdot: float
    P_n: float
    P_t: float
    stick: bool
    E_diss: float


@dataclass(slots=True)
class Reset:
    """Result of the reset law at a point on the circle (SI, inertial)."""

    v_plus: complex
    rdot: float
    P_n: float
    P_t: float
    stick: bool
    E_diss: float


def slip_velocity(R: float, Omega: float, vt: float) -> float:
    """v_rel = R Omega + vt (m/s): slip of the rotor surface at the contact, along i n."""
    return R * Omega + vt


def reset(
    n: complex, v_minus: complex, m: float, d: float, mu: float, R: float, Omega: float
) -> Reset:
    """Apply the reset law at unit normal ``n`` to the incoming velocity ``v_minus`` (m/s).

    The low-speed rule passes ``d = 0`` for the impact that starts sustained contact.
    """
    w = n.conjugate() * v_minus
    rdot, vt = w.real, w.imag
    vrel_m = slip_velocity(R, Omega, vt)
    s = math.copysign(1.0, vrel_m) if vrel_m != 0.0 else 0.0
    dvt = mu * (1.0 + d) * rdot * s
    stick = abs(dvt) > abs(vrel_m)
    if stick:
        dvt = vrel_m
    vt_p = vt - dvt
    vrel_p = 0.0 if stick else vrel_m - dvt
    v_plus = complex(-d * rdot, vt_p) * n
    P_n = m * (1.0 + d) * rdot
    P_t = m * dvt
    E = 0.5 * m * (1.0 - d * d) * rdot * rdot + 0.5 * P_t * (vrel_m + vrel_p)
    return Reset(v_plus, rdot, P_n, P_t, stick, E)
