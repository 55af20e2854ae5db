"""The compliant contact law of the real touchdown bearing (docs/model.md §10, (10.6)-(10.7)).

Units SI; the law is frame-free (scalars along the contact normal n). Penetration
delta = |z - z_b| - c_r (m, positive in contact), its rate ddelta = Re(conj(n)(z' - z_b'))
(m/s, positive closing), and the normal force on the rotor's contact point

    N = max(0, K delta^p (1 + chi ddelta))   while delta > 0,   0 otherwise      (10.6)

with K = k_c DELTA_REF^(1 - p) (``stiffness_coefficient``: k_c, N/m, is the secant
stiffness N/delta at delta = DELTA_REF), p in {1, 3/2}, chi = c_d/v_in (s/m), v_in =
max(closing speed when the contact closed, V_FLOOR) (``damping_factor``), and c_d the
positive root of

    ln((1 + c)/(1 - c d)) = c (1 + d)                                             (10.7)

(``restitution_damping``), which gives an isolated normal impact exactly the restitution d
whatever K, p and the mass. The elastic energy stored is ``contact_potential``.

Pure Python (math only).
"""

from __future__ import annotations

import math
from collections.abc import Callable

DELTA_REF = 1e-5
"""Reference penetration (m) at which k_c is the contact's secant stiffness N/delta."""

V_FLOOR = 1e-3
"""Floor of the closing speed v_in in chi = c_d/v_in (m/s): a contact that closes slower,
or is closed at the start, gets c_d/V_FLOOR."""

_EXP_D = 0.3  # d < this: (10.7) exponentiated, (1 + c) e^{-c(1+d)} = 1 - c d (c d -> 1)
_TINY_D = 1e-3  # d < this: c_d = (1 - u)/d with u < 1e-430: c_d rounds to 1/d


def _newton(fun: Callable[[float], tuple[float, float]], lo: float, hi: float,
            x: float) -> float:
    """The root of an increasing ``fun`` (returning (value, slope)) in the bracket
    [lo, hi] (fun(lo) < 0 < fun(hi)) from x: Newton's steps, bisection when a step leaves
    the bracket, until the step falls to rounding."""
    for _ in range(300):
        f, fp = fun(x)
        if f == 0.0:
            return x
        if f < 0.0:
            lo = x
        else:
            hi = x
        step = f / fp if fp > 0.0 else math.inf
        x_new = x - step
        if not lo < x_new < hi:
            x_new = 0.5 * (lo + hi)
            if x_new in (lo, hi):
                return x_new
        elif abs(step) <= 2.0 * math.ulp(x):
            return x_new
        x = x_new
    raise ArithmeticError(f"(10.7): no convergence in the bracket [{lo!r}, {hi!r}]")


def _atanh_minus(y: float) -> float:
    """atanh(y) - y = y^3/3 + y^5/5 + ... for 0 <= y <= 1, to a few ulp (series below
    0.7, where the direct difference would lose digits)."""
    if y >= 0.7:
        return math.atanh(y) - y if y < 1.0 else math.inf
    y2 = y * y
    term = y * y2
    total = 0.0
    k = 3
    while term > 1e-18 * total or total == 0.0:
        total += term / k
        term *= y2
        k += 2
        if term == 0.0:
            break
    return total


def _balance(d: float) -> Callable[[float], tuple[float, float]]:
    """(10.7) as f(c) = 2 (atanh(y) - y) - c^2 (1 + d) eps/(2 + c eps) with
    y = c (1 + d)/(2 + c eps), eps = 1 - d (exact for d >= 1/2): the same function as
    ln((1 + c)/(1 - c d)) - c (1 + d), written so that neither the O(c) terms nor 1 - d^2
    cancel (the root -> 3 eps/2 as d -> 1); and its slope
    f' = c (1 + d)(c d - eps)/((1 + c)(1 - c d))."""
    eps = 1.0 - d
    dp1 = 1.0 + d

    def f(c: float) -> tuple[float, float]:
        den = 2.0 + c * eps
        y = c * dp1 / den
        val = 2.0 * _atanh_minus(y) - c * c * dp1 * eps / den
        u = 1.0 - c * d
        slope = c * dp1 * (c * d - eps) / ((1.0 + c) * u) if u > 0.0 else math.inf
        return val, slope

    return f


def restitution_damping(d: float) -> float:
    """c_d (dimensionless), the positive root of ln((1 + c)/(1 - c d)) = c (1 + d)
    (docs/model.md (10.7)), to double precision for d in (0, 1]: 0 at d = 1; 0.0789266 at
    0.95, 0.1664820 at 0.9, 1.432751 at 0.5; -> 1/d as d -> 0 (inf once 1/d overflows).
    There is no root at d = 0 (a perfectly plastic compliant contact has no finite
    damping): ValueError outside (0, 1]."""
    d = float(d)
    if not 0.0 < d <= 1.0:
        raise ValueError(f"d = {d!r}: (10.7) has a positive root only for d in (0, 1]")
    if d == 1.0:
        return 0.0
    if d >= _EXP_D:
        c0 = 1.5 * (1.0 - d) * (1.0 + d) / (1.0 + d * d * d)  # the root's leading term
        return _newton(_balance(d), 0.0, 1.0 / d, c0)
    if d < _TINY_D:
        try:
            return 1.0 / d
        except (OverflowError, ZeroDivisionError):
            return math.inf
    dp1 = 1.0 + d

    def F(c: float) -> tuple[float, float]:
        e = math.exp(-c * dp1)
        return c * d - 1.0 + (1.0 + c) * e, d - e * (c + d + c * d)

    return _newton(F, 1.0, 1.0 / d, 1.0 / d)


def stiffness_coefficient(k_c: float, p: float) -> float:
    """K = k_c DELTA_REF^(1 - p) (N/m^p) of (10.6): K delta^p = k_c delta at delta =
    DELTA_REF. k_c (N/m), p in {1, 1.5}."""
    return k_c if p == 1.0 else k_c * DELTA_REF ** (1.0 - p)


def damping_factor(c_d: float, v_onset: float) -> float:
    """chi = c_d/v_in (s/m) of (10.6), v_in = max(v_onset, V_FLOOR): v_onset (m/s) the
    normal closing speed when the contact closed (0 for one closed at the start)."""
    return c_d / max(v_onset, V_FLOOR)


def _power(delta: float, p: float) -> float:
    """delta^p for p in {1, 1.5} (delta > 0, m)."""
    return delta if p == 1.0 else delta * math.sqrt(delta)


def compliant_normal_force(delta: float, ddelta: float, K: float, p: float,
                           chi: float) -> float:
    """N (N) of (10.6): max(0, K delta^p (1 + chi ddelta)) for delta > 0, else 0.
    delta (m) penetration, ddelta (m/s) its rate (closing > 0), K (N/m^p), p in {1, 1.5},
    chi (s/m)."""
    if not delta > 0.0:
        return 0.0
    N = K * _power(delta, p) * (1.0 + chi * ddelta)
    return N if N > 0.0 else 0.0


def contact_potential(delta: float, K: float, p: float) -> float:
    """V_c = K delta^(p+1)/(p + 1) (J), the elastic energy of (10.6) at penetration
    delta (m) > 0; 0 for delta <= 0 (docs/model.md §10, Balances)."""
    if not delta > 0.0:
        return 0.0
    return K * delta * _power(delta, p) / (p + 1.0)
