"""The compliant contact law (docs/model.md §10, (10.6)-(10.7)).

Units: SI. N = K delta^p (1 + chi delta') while delta > 0 (N), K = k_c delta_ref^{1-p}, and
chi = c_d/v_in with c_d the positive root of ln((1 + c)/(1 - c d)) = c (1 + d), which gives
an isolated impact exactly the restitution d whatever K and p.
"""

from __future__ import annotations

import math

DELTA_REF = 1e-5
"""The penetration (m) at which k_c is the contact's stiffness."""
V_FLOOR = 1e-3
"""The least closing speed (m/s) in chi = c_d/v_in: a contact that closes slower (or starts
closed) gets c_d/V_FLOOR."""


def stiffness_coefficient(k_c: float, p: float) -> float:
    """K = k_c delta_ref^{1-p} (N/m^p) for the stiffness k_c (N/m) at delta_ref."""
    return k_c * DELTA_REF ** (1.0 - p)


def _residual(c: float, d: float) -> float:
    """ln((1 + c)/(1 - c d)) - c (1 + d)."""
    return math.log1p(c) - math.log1p(-c * d) - c * (1.0 + d)


def restitution_damping(d: float) -> float:
    """c_d (1) of (10.7) for the restitution d in (0, 1]: 0 at d = 1; ValueError at d <= 0
    (no root: a compliant contact cannot be perfectly plastic). Bisection on the bracket
    (0, 1/d), where the residual is negative below the root and positive above it, to
    adjacent floats (the lower one)."""
    if not 0.0 < d <= 1.0:
        raise ValueError(f"d = {d!r} must lie in (0, 1] for the compliant law's damping")
    if d == 1.0:
        return 0.0
    lo, hi = 0.0, 1.0 / d
    guess = 1.5 * (1.0 - d * d) / (1.0 + d ** 3)  # the root's leading term as d -> 1
    if 0.0 < guess < hi and _residual(guess, d) < 0.0:
        lo = guess
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if not lo < mid < hi:
            break
        if _residual(mid, d) < 0.0:
            lo = mid
        else:
            hi = mid
    return lo
