"""The contact pair: the rotor and the counter-body it touches (docs/model.md §4, §8).

Frame and units: inertial, SI. The one place that defines, for the impact law and the
contact forces alike, the contact's geometry and kinematics between the rotor
(``rigid.RigidRotor``: geometric centre z, velocity v, spin Omega, spin angle psi) and the
counter-body (``rotortd.bodies.bearing``: race centre c, velocity v_b, surface speed u_b along
i n):

    gap        |z - c|^2 - c_r^2                      (m^2; contact at 0)
    normal     n = (z - c)/|z - c|                    (outward, from the race centre)
    rdot       Re(conj(n) (v - v_b))                  (m/s, separation speed along n)
    slip       v_rel = R Omega + Im(conj(n) (v - v_b)) - u_b
                                                      (m/s, rotor surface past the race's)
    W          W_rotor + W_bearing                    (1/kg, the (n, i n) frame)

An impulse -(P_n + i P_t) n on the rotor at the contact, and +(P_n + i P_t) n on the
counter-body, changes (rdot, v_rel) by -W (P_n, P_t). The held-speed rotor is the rotor
with J = inf (``RigidRotor.held``): its W is I/m and no impulse changes its spin.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..bodies.bearing import CounterBody
from ..bodies.rotor import Delassus, RigidRotor, SpinReset, spin_impact


@dataclass(frozen=True, slots=True)
class ContactPair:
    """The rotor and the counter-body it touches (SI, inertial)."""

    rotor: RigidRotor
    bearing: CounterBody

    def gap(self, z: complex) -> float:
        """|z - c|^2 - c_r^2 (m^2): negative inside the clearance, 0 at contact."""
        d = z - self.bearing.centre()
        return (d * d.conjugate()).real - self.bearing.c_r * self.bearing.c_r

    def on_circle(self, z: complex) -> tuple[complex, complex]:
        """(z projected onto the contact circle, the outward unit normal there)."""
        c, c_r = self.bearing.centre(), self.bearing.c_r
        d = z - c
        z_on = c + d * (c_r / abs(d))
        return z_on, (z_on - c) / c_r

    def velocities(self, n: complex, v: complex, Omega: float) -> tuple[float, float]:
        """(rdot, v_rel) (m/s): the separation speed along n and the slip along i n."""
        w = n.conjugate() * (v - self.bearing.velocity())
        return w.real, self.rotor.R * Omega + w.imag - self.bearing.surface_speed(n)

    def delassus(self, n: complex, psi: float) -> Delassus:
        """W = W_rotor + W_bearing (1/kg) at normal n and spin angle psi (rad)."""
        w = self.rotor.delassus(n, psi)
        bnn, bnt, btt = self.bearing.delassus(n)
        return Delassus(w.B, w.A, w.J, w.nn + bnn, w.nt + bnt, w.tt + btt)

    def impact(self, W: Delassus, mu: float, d: float, rdot: float, vrel: float
               ) -> SpinReset:
        """The impact law (``rigid.spin_impact``) through the pair's W; rdot > 0."""
        return spin_impact(W, mu, d, rdot, vrel)

    def apply(self, r: SpinReset, n: complex) -> None:
        """The impulse of ``r`` on the counter-body (the rotor's side is the caller's)."""
        self.bearing.apply_impulse(r.P_n, r.P_t, n)
