"""The segments: the motion between events, each in closed form or integrated with a
stated error.

Held spin, sustained contact on the clearance circle: sliding and rolling (docs/model.md §5).

Frame and units: inertial, SI. On the circle z = c_r e^{i theta}; the state is the polar
angle theta (rad) and the whirl rate theta' (rad/s). Forces are written per unit m c_r
(1/s^2), so that with w = e^{-i theta}, Q(t) = q0 + eu e^{i psi(t)},

    Gn = N/(m c_r)            = Re(Q w) - kappa + theta'^2        (normal force, inward >= 0)
    Gt = Im(e^{-i theta}F)/(m c_r) = Im(Q w) - beta theta'        (free tangential force)
    theta'' = Gt - Ft,   Ft = F_t/(m c_r)

with q0 = (a F_bias - i m g + F_ext)/(m c_r), eu = e_c Omega^2 e^{i phi}/c_r, beta = a c/m,
kappa = a k/m. The slip of the contact point is v_rel = c_r (wr + theta'), wr = R Omega/c_r.

* Sliding (v_rel != 0): Ft = mu s Gn, s = sign(v_rel); integrated by extrapolation (gbs.py)
  at 1e-13 relative tolerance, with the step's contact integrals carried as error-controlled
  quadratures (the contact force by parts near a steady whirl, Sliding.rhs).
* Rolling (v_rel = 0): theta' = -wr is constant and Ft = Gt (static friction); theta, Gn
  and Gt are sums of two rotating phasors, so the motion and its integrals are closed form.
* Transitions: lift-off when Gn reaches 0; sliding -> rolling when v_rel reaches 0 with
  |Gt| <= mu Gn, otherwise the slip reverses; rolling -> sliding when |Gt| reaches mu Gn.
* Synchronous forward rub: with q0 = 0 the sliding system is autonomous in the co-rotating
  frame and has equilibria theta' = Omega (forward_rub_equilibria). Near a stable one the
  motion is in closed form, to first (LinearRub) or second order (QuadraticRub) in the
  deviation, with the dropped terms bounded; on it, a rigid rotation.

The modules, one job each: ``rotortd.contact.wall`` (WallForces, ContactTally,
SegmentEnd: the segment interface), ``sliding``, ``rolling``, ``rub`` (LinearRub,
QuadraticRub, LockedRub); with the spin as a state, ``spin_flight`` and ``spin_contact``;
the exact flight ``flight`` and the integrators ``gbs`` and ``divdiff``.
"""
