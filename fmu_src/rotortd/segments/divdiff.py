"""Divided differences of the exponential on up to four complex nodes.

``exp[x0, ..., xn]`` is the n-th divided difference of ``x -> exp(x)``. With nodes
``x_j = lambda_j * s`` these give every coefficient of the exact flight (see flight.py):

    exp(A s)                = e^{l1 s} I + s exp[l1 s, l2 s] (A - l1 I)
    int_0^s exp(A r) dr     = ... s^2 exp[0, l1 s, l2 s] ...

They are entire functions of the nodes, so they stay finite and accurate when nodes
coincide (critical damping, resonance, k = 0, Omega = 0); the formulas below never
divide by a difference of nodes that can be small.

* one node: exp(x)
* two nodes: exp(c) * sinh(w)/w with c the midpoint and w the half difference, or the
  plain quotient when the nodes are far apart in real part (no cancellation then);
* three nodes: a Taylor series about the centroid when all nodes are within distance 0.5,
  otherwise the recurrence divided by the largest node distance;
* four nodes (``dd4``, the step integral of the imbalance torque, flight.py): the same two
  ways.

Nodes here always have real part <= 0 (the flight is dissipative or neutral), so no
exponential overflows; underflow to 0 is harmless.
"""

from __future__ import annotations

import cmath
import math

_TAYLOR_RADIUS = 0.5
"""Largest node distance for which the centred Taylor series is used (three nodes).
Beyond it the recurrence loses at most log2(2/0.5) bits to cancellation, well inside the
flight's error bound (tests/test_core_flight.py); the series costs more terms."""


def dd1(x: complex) -> complex:
    """exp[x] = exp(x)."""
    return cmath.exp(x)


def dd2(a: complex, b: complex) -> complex:
    """exp[a, b] = (e^a - e^b)/(a - b), accurate for all a, b (also a == b)."""
    w = 0.5 * (a - b)
    if w == 0:
        return cmath.exp(a)
    if abs(w.real) < 1.0:
        return cmath.exp(0.5 * (a + b)) * (cmath.sinh(w) / w)
    return (cmath.exp(a) - cmath.exp(b)) / (a - b)


_INV_FACT = tuple(1.0 / math.factorial(k + 2) for k in range(40))
"""1/(k+2)! for the terms of the three-node series."""


def _dd3_taylor(x0: complex, x1: complex, x2: complex) -> complex:
    """exp[x0, x1, x2] by the series about the centroid c (nodes within _TAYLOR_RADIUS).

    exp[x0,x1,x2] = e^c * sum_k h_k(w)/(k+2)!, w_j = x_j - c, where h_k are the complete
    homogeneous symmetric polynomials; with sum w_j = 0 they obey
    h_k = -e2 h_{k-2} + e3 h_{k-3}. With |w_j| <= 2/3 _TAYLOR_RADIUS the sum stays within
    10 % of its first term 1/2, so terms below 4e-18 no longer change it.
    """
    c = (x0 + x1 + x2) / 3.0
    w0, w1, w2 = x0 - c, x1 - c, x2 - c
    e2 = w0 * w1 + w0 * w2 + w1 * w2
    e3 = w0 * w1 * w2
    h_km3, h_km2, h_km1 = 0j, 1.0 + 0j, 0j  # h_{-1}, h_0, h_1
    total = 0.5 + 0j  # h_0/2!, then the (zero) h_1 term
    prev = 0.0
    for k in range(2, 40):
        h_k = e3 * h_km3 - e2 * h_km2
        term = h_k * _INV_FACT[k]
        total += term
        h_km3, h_km2, h_km1 = h_km2, h_km1, h_k
        mag = abs(term)
        if mag + prev <= 4e-18:
            break
        prev = mag
    return cmath.exp(c) * total


def dd3(x0: complex, x1: complex, x2: complex) -> complex:
    """exp[x0, x1, x2], accurate for all nodes with real part <= 0."""
    d01 = abs(x0 - x1)
    d02 = abs(x0 - x2)
    d12 = abs(x1 - x2)
    dmax = max(d01, d02, d12)
    if dmax <= _TAYLOR_RADIUS:
        return _dd3_taylor(x0, x1, x2)
    if dmax == d02:
        p, r, q = x0, x1, x2
    elif dmax == d01:
        p, r, q = x0, x2, x1
    else:
        p, r, q = x1, x0, x2
    return (dd2(p, r) - dd2(r, q)) / (p - q)


_INV_FACT3 = tuple(1.0 / math.factorial(k + 3) for k in range(40))
"""1/(k+3)! for the terms of the four-node series."""


def _dd4_taylor(x0: complex, x1: complex, x2: complex, x3: complex) -> complex:
    """exp[x0, x1, x2, x3] by the series about the centroid c (nodes within _TAYLOR_RADIUS):
    e^c * sum_k h_k(w)/(k+3)!, w_j = x_j - c, with h_k = -e2 h_{k-2} + e3 h_{k-3} - e4 h_{k-4}
    (e1 = 0). With |w_j| <= 3/4 _TAYLOR_RADIUS the sum stays near its first term 1/6."""
    c = (x0 + x1 + x2 + x3) / 4.0
    w0, w1, w2, w3 = x0 - c, x1 - c, x2 - c, x3 - c
    e2 = w0 * w1 + w0 * w2 + w0 * w3 + w1 * w2 + w1 * w3 + w2 * w3
    e3 = w0 * w1 * w2 + w0 * w1 * w3 + w0 * w2 * w3 + w1 * w2 * w3
    e4 = w0 * w1 * w2 * w3
    hm4, hm3, hm2, hm1 = 0j, 0j, 1.0 + 0j, 0j  # h_{k-4}, ..., h_{k-1} for k = 2
    total = _INV_FACT3[0] + 0j  # h_0/3!, then the (zero) h_1 term
    prev = 0.0
    for k in range(2, 40):
        h_k = e3 * hm3 - e2 * hm2 - e4 * hm4
        term = h_k * _INV_FACT3[k]
        total += term
        hm4, hm3, hm2, hm1 = hm3, hm2, hm1, h_k
        mag = abs(term)
        if mag + prev <= 1e-18:
            break
        prev = mag
    return cmath.exp(c) * total


def dd4(x0: complex, x1: complex, x2: complex, x3: complex) -> complex:
    """exp[x0, x1, x2, x3], accurate for all nodes with real part <= 0 (also coinciding)."""
    xs = (x0, x1, x2, x3)
    dmax, ip, iq = -1.0, 0, 1
    for i in range(4):
        for j in range(i + 1, 4):
            d = abs(xs[i] - xs[j])
            if d > dmax:
                dmax, ip, iq = d, i, j
    if dmax <= _TAYLOR_RADIUS:
        return _dd4_taylor(x0, x1, x2, x3)
    r1, r2 = (xs[i] for i in range(4) if i not in (ip, iq))
    p, q = xs[ip], xs[iq]
    return (dd3(p, r1, r2) - dd3(r1, r2, q)) / (p - q)
