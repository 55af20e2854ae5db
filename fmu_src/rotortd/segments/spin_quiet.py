"""The quiet step of the rotor whose spin is a state: the held-speed closed form at the
step's start speed plus Gauss collocation of what the turning spin adds (docs/model.md §8,
"Quiet steps"). A declared accelerator of ``SpinFlight.short_taylor`` (the one definition),
equal to it to rounding at random states (tests/test_spin_quiet.py).

Frame and units: inertial, SI. State as ``segments.spin_flight``: geometric centre ``z``
(m), ``v`` (m/s), spin angle ``psi`` (rad) and ``Omega`` (rad/s); E = e^{i(psi + phi)}.
Over one step of length h the inputs are held (amb_on ``a``, F_ext, T_drive) and the
rotor is in free flight, proved clear of the bearing by the caller.

With the mass centre z_G = z + e_c E the equations of motion are

    m z_G'' + cA z_G' + kA z_G = Q + e_c (kA + i cA Omega) E,    Q = a F_bias + F_ext - i m g,
    J Omega' = T + m e_c Im(conj(z_G'' + i g) E),                 psi' = Omega,

cA = a c, kA = a k. Freeze the spin at its start speed Omega0 in the forcing,
E_h(t) = E0 e^{i Omega0 t}: the reference z_R solves the first equation in closed form,
z_R = s + P E_h + u, s = Q/kA, P = e_c (kA + i cA Omega0)/(kA - m Omega0^2 + i cA Omega0),
u homogeneous (the fundamental solutions f_a, f_b of m u'' + cA u' + kA u = 0, cached per
h). What the turning spin adds, Delta = Omega - Omega0, delta = psi - psi0 - Omega0 t and
y = z_G - z_R, is small (relatively about 1e-6 of the whirl in the chapter's levitated
whirl) and solves, from zero,

    delta' = Delta,    J Delta' = T + m e_c Im(conj(z_R'' + y'' + i g) E_h e^{i delta}),
    m y'' + cA y' + kA y = f = e_c E_h ((kA + i cA (Omega0 + Delta)) e^{i delta}
                                         - (kA + i cA Omega0)).

It is solved by Gauss-Legendre collocation at S = 3 nodes c_i h (stage order 3, order 6 at
the step's end): the torque at the nodes from z_R and E_h (exact), Delta and delta at the
nodes by the collocation matrix A and A^2, the forcing f at the nodes, y and y' at the
step's end by the exact Green's weights of the interpolant of f (cached per h). The
second-order torque (e^{i delta} to O(delta^3), and y'' = (f - cA y' - kA y)/m at the
nodes by the same Green's weights) is iterated to its fixed point: a change of the nodes'
torque moves delta by about h^2/2 times it and the next torque by (m e_c/J) |X| times
that, so the step stops when the next pass would move Omega(h) by less than TOL_OMEGA of
its rate scale (one pass on the chapter's rotor; after PASSES it declines).

Error: the reference is exact to rounding. The collocation's error is that of a method of
order 6 on the spin's corrections, whose integrands turn at up to 2W (W = |Omega0| + the
modes' rate bound: y's forcing is E_h times the torque's oscillation). Measured against
``short_taylor`` at 3233 random flights with W h up to 0.3, the position's error (with h
times the velocity's) over the measure (2 W h)^6 (|y| + h |y'|) (m) is 3e-6 to 2.6e-3 at
the 341 where it shows above 2e-15 c_r (y grows with the drive torque and with a
transient's oscillating torque on a light rotor). The step declines (None) when TRUNC_K =
1e-2 times that measure exceeds TOL_Y c_r (1e-16 c_r, as the Taylor path's tail
criterion), and when W h > WH_MAX (0.2). Where it steps it equals ``short_taylor`` to
1e-15 of the scales (c_r, c_r w, |Omega|) at random levitated flights (speeds to 1800
rad/s at 1e-4 s, drive torques to 50 N m on J = 0.004 ... 0.4 kg m^2) and the 40-digit
reference to 1e-15 (2.5e-16 to 9.8e-16 measured; tests/test_spin_quiet.py). On the
chapter's levitated whirl (W h = 0.032 at 1e-4 s) the estimate is below 1e-23 m. The terms
left out (third order in delta) are below 1e-18 where |delta| <= DELTA_MAX at the step's
end (else None).

Work: a fixed number of operations per step (no loop depends on the data).
"""

from __future__ import annotations

import cmath
import math

from ..params import RotorParams
from .spin_flight import EPS

S = 3
"""Gauss-Legendre nodes of the collocation (the step is written out for three)."""
WH_MAX = 0.2
"""Largest W h (rad) the step takes (W the fastest rate of its integrands; module
docstring, Error)."""
DELTA_MAX = 1e-4
"""Largest |delta| (rad) at the step's end: e^{i delta} by its series to 1e-18."""
TOL_OMEGA = 2.0 ** -56
"""The fixed point's tolerance: what one more pass would move Omega by, relative to the
step's rate scale |Omega0| + the modes' rate (eps/16)."""
CLEAR_MARGIN = 32.0 * EPS
"""The proof's margin below c_r (relative): the contact resolution (|z| within about 8 eps
of c_r is at the wall) and the step's point error, as the general search's first bound."""
PASSES = 4
"""Passes of the second-order torque the step takes at most (the chapter's rotor: one)."""
TRUNC_K = 1e-2
"""The truncation estimate of the step's position: TRUNC_K (2 W h)^6 (|y| + h |y'|) (m), y
the spin's correction of the mass centre. Measured: the error over that measure is 3e-6 to
2.6e-3 at the 341 of 3233 random flights where the truncation shows above 2e-15 c_r
(module docstring, Error)."""
TOL_Y = 1e-16
"""The step declines when its truncation estimate exceeds TOL_Y c_r (the Taylor path's
TAYLOR_TOL: a truncation below rounding)."""
QUIET_WORK = 8
"""Work units of one quiet step (its fixed cost, about 20 us; the step loop's flight
segment charges SEGMENT_WORK besides)."""


def _legendre_nodes(n: int) -> tuple[list[float], list[float]]:
    """Gauss-Legendre nodes and weights on [0, 1] (Newton on P_n, to rounding)."""
    nodes, weights = [], []
    for k in range(n):
        x = math.cos(math.pi * (k + 0.75) / (n + 0.5))
        for _ in range(100):
            p0, p1 = 1.0, x
            for j in range(2, n + 1):
                p0, p1 = p1, ((2 * j - 1) * x * p1 - (j - 1) * p0) / j
            dp = n * (x * p1 - p0) / (x * x - 1.0)
            dx = p1 / dp
            x -= dx
            if abs(dx) < 1e-17:
                break
        nodes.append(0.5 * (1.0 - x))
        weights.append(1.0 / ((1.0 - x * x) * dp * dp))
    order = sorted(range(n), key=lambda i: nodes[i])
    return [nodes[i] for i in order], [weights[i] for i in order]


def _lagrange_coefficients(c: list[float]) -> list[list[float]]:
    """Monomial coefficients (ascending) of the Lagrange basis on the nodes c."""
    out = []
    for j, cj in enumerate(c):
        poly = [1.0]
        for k, ck in enumerate(c):
            if k != j:  # poly *= (x - ck)/(cj - ck)
                d = cj - ck
                poly = [(a - ck * b) / d for a, b in zip([0.0, *poly], [*poly, 0.0])]
        out.append(poly)
    return out


C, B = _legendre_nodes(S)
_L = _lagrange_coefficients(C)
A = [[sum(coef * ci ** (p + 1) / (p + 1) for p, coef in enumerate(_L[j])) for j in range(S)]
     for ci in C]
"""Collocation matrix: A[i][j] = int_0^{c_i} l_j (l_j the Lagrange basis on the nodes)."""
A2 = [[sum(A[i][k] * A[k][j] for k in range(S)) for j in range(S)] for i in range(S)]
"""A^2: the double integral of the interpolant at the nodes."""
BD = [b * (1.0 - c) for b, c in zip(B, C)]
"""Weights of int_0^1 (1 - s) g(s) ds (the double integral at the end)."""


def _series(m: float, cA: float, kA: float, x0: float, x1: float, n: int) -> list[float]:
    """Taylor coefficients of the solution of m x'' + cA x' + kA x = 0, x(0) = x0,
    x'(0) = x1."""
    co = [x0, x1]
    for k in range(n - 2):
        co.append(-(cA * (k + 1) * co[k + 1] + kA * co[k]) / (m * (k + 1) * (k + 2)))
    return co


def _poly(co: list[float], t: float, deriv: int = 0) -> float:
    """The deriv-th derivative of sum co[k] t^k at t."""
    total = 0.0
    for k in range(len(co) - 1, deriv - 1, -1):
        f = 1.0
        for j in range(deriv):
            f *= k - j
        total = total * t + f * co[k]
    return total


class QuietSpinStep:
    """The quiet step for one set of held inputs and one step length (module docstring).

    p: rotor parameters; J (kg m^2); a: AMB on; F_ext (N, inertial); h (s). ``usable`` is
    False where the closed form does not apply (the bearing off, the modes too fast for
    h); ``clear`` and ``step`` are then not to be called. The constants of the step are one
    tuple (``_k``), unpacked at once.
    """

    __slots__ = ("F_ext", "J", "_k", "_proof", "a", "h", "p", "rate", "usable")

    def __init__(self, p: RotorParams, J: float, a: float, F_ext: complex, h: float) -> None:
        m, e_c = p.m, p.e_c
        cA, kA = a * p.c, a * p.k
        self.p, self.J, self.a, self.F_ext, self.h = p, J, a, F_ext, h
        self.rate = max(math.sqrt(kA / m), cA / m)  # the modes' rate bound (rad/s)
        self.usable = kA > 0.0 and self.rate * h <= WH_MAX
        if not self.usable:
            return
        F0 = a * p.bias_force + F_ext
        Q = F0 - 1j * m * p.g
        kcr = kA * p.c_r
        self._proof = (p.c_r * (1.0 - CLEAR_MARGIN), abs(F0) + kcr, (abs(Q) + kcr) / m, cA,
                       cA / m, e_c, 1.0 / J, h, 2.0 * h, 0.5 * h * h)
        n = 40
        sa, sb = _series(m, cA, kA, 1.0, 0.0, n), _series(m, cA, kA, 0.0, 1.0, n)
        ends = (_poly(sa, h), _poly(sb, h), _poly(sa, h, 1), _poly(sb, h, 1))
        a2 = [_poly(sa, ci * h, 2) for ci in C]
        b2 = [_poly(sb, ci * h, 2) for ci in C]
        GE, GEp = _green(sb, h, m, 1.0)
        # y'' = (f - cA y' - kA y)/m at the nodes, by the Green's weights of f's interpolant
        Mpp = []
        for i, ci in enumerate(C):
            GN, GNp = _green(sb, h, m, ci)
            Mpp.append([((1.0 if i == j else 0.0) - cA * GNp[j] - kA * GN[j]) / m
                        for j in range(S)])
        hA = [[h * x for x in row] for row in A]
        h2A2 = [[h * h * x for x in row] for row in A2]
        self._k = (
            m, cA, kA, e_c, 1j * p.g, p.phi, m * e_c / J, 1.0 / J, Q / kA, *ends,
            *a2, *b2, *GE, *GEp, *(x for row in Mpp for x in row),
            *(x for row in hA for x in row), *(x for row in h2A2 for x in row),
            *(h * b for b in B), *(h * h * b for b in BD),
            0.5 * h, (C[2] - C[1]) * h, h * h * h * m * e_c / J, h, self.rate, WH_MAX / h,
            TOL_Y * p.c_r / TRUNC_K,
        )

    def matches(self, p: RotorParams, J: float, a: float, F_ext: complex, h: float) -> bool:
        """Whether this step was built for these parameters, inputs and step length."""
        return (self.h == h and self.a == a and self.F_ext == F_ext and self.p is p
                and self.J == J)

    def covers(self, Om0: float) -> bool:
        """Whether a step from the spin speed Omega0 (rad/s) is within WH_MAX: W h <= WH_MAX,
        W = |Omega0| + the modes' rate bound (``step`` declines otherwise)."""
        return (abs(Om0) + self.rate) * self.h <= WH_MAX

    def clear(self, z0: complex, v0: complex, Om0: float, T: float) -> bool:
        """Whether the flight from (z0, v0, Omega0) under the drive torque T stays inside
        the clearance circle over the whole step, |z| <= c_r (1 - CLEAR_MARGIN): an
        a-priori bound V, W, D of |v|, |Omega|, |Omega'| on the step (twice the increments
        of one sweep, then checked), A of |z''| from it, and |z(t)| <= max(|z0|,
        |z0 + v0 h|) + A h^2/2 (|z0 + v0 t| is convex in t)."""
        r_in, F0k, qk, cA, cAm, ec, iJ, h, h2, hh = self._proof
        V0, W0, Ta = abs(v0), abs(Om0), abs(T)
        D = (Ta + ec * (F0k + cA * V0)) * iJ
        A = qk + cAm * V0 + ec * (W0 * W0 + D)  # (> 0: kA > 0)
        V, W = V0 + h2 * A, W0 + h2 * D
        D = (Ta + ec * (F0k + cA * V)) * iJ
        A = qk + cAm * V + ec * (W * W + D)
        if V0 + h * A > V or W0 + h * D > W:
            return False
        return max(abs(z0), abs(z0 + h * v0)) + hh * A <= r_in

    def step(self, z0: complex, v0: complex, psi0: float, Om0: float, T: float
             ) -> tuple[complex, complex, float, float] | None:
        """(z, v, psi, Omega) at h from (z0, v0, psi0, Omega0) with the drive torque T
        (N m); None when the step is outside the method's range (module docstring)."""
        (m, cA, kA, ec, ig, phi, mJ, iJ, Qs, fa, fb, fap, fbp,
         a21, a22, a23, b21, b22, b23, G1, G2, G3, Gp1, Gp2, Gp3,
         M11, M12, M13, M21, M22, M23, M31, M32, M33,
         A11, A12, A13, A21, A22, A23, A31, A32, A33,
         D11, D12, D13, D21, D22, D23, D31, D32, D33,
         B1, B2, B3, BD1, BD2, BD3, h_half, h_d, lip_h, h, rate, W_lim, y_lim) = self._k
        Wt = abs(Om0) + rate
        if Wt > W_lim:  # (W h > WH_MAX)
            return None
        E0 = cmath.exp(1j * (psi0 + phi))
        iW = 1j * Om0
        ecE0 = ec * E0
        kc = complex(kA, cA * Om0)  # kA + i cA Omega0
        den = complex(kA - m * Om0 * Om0, cA * Om0)
        if den == 0j:
            return None
        PE0 = ec * kc / den * E0  # the synchronous whirl P E0 of the frozen spin
        u0 = z0 + ecE0 - Qs - PE0  # the homogeneous part's start (z_G0 - s - P E0)
        u1 = v0 + iW * (ecE0 - PE0)  # and its rate
        # E_h at the nodes 1/2 -+ d and 1/2, and at h
        em = cmath.exp(iW * h_half)
        ed = cmath.exp(iW * h_d)
        e1, e3 = em * ed.conjugate(), em * ed
        E1, E2, E3 = E0 * e1, E0 * em, E0 * e3
        W2P = Om0 * Om0 * PE0
        # X = conj(z_R'' + i g) E_h, and Omega' of the reference at the nodes
        X1 = (a21 * u0 + b21 * u1 + ig - W2P * e1).conjugate() * E1
        X2 = (a22 * u0 + b22 * u1 + ig - W2P * em).conjugate() * E2
        X3 = (a23 * u0 + b23 * u1 + ig - W2P * e3).conjugate() * E3
        TJ = T * iJ
        t1, t2, t3 = TJ + mJ * X1.imag, TJ + mJ * X2.imag, TJ + mJ * X3.imag
        ecE1, ecE2, ecE3 = ec * E1, ec * E2, ec * E3
        lip = lip_h * max(abs(X1), abs(X2), abs(X3))
        tol = TOL_OMEGA * Wt
        p1 = p2 = p3 = 0.0
        for k in range(PASSES + 1):
            # delta and Delta at the nodes (collocation), e^{i delta}, and the forcing f
            d1 = D11 * t1 + D12 * t2 + D13 * t3
            d2 = D21 * t1 + D22 * t2 + D23 * t3
            d3 = D31 * t1 + D32 * t2 + D33 * t3
            D1 = A11 * t1 + A12 * t2 + A13 * t3  # Delta at the nodes
            D2 = A21 * t1 + A22 * t2 + A23 * t3
            D3 = A31 * t1 + A32 * t2 + A33 * t3
            W1, W2, W3 = Om0 + D1, Om0 + D2, Om0 + D3
            s1, s2, s3 = 0.5 * d1 * d1, 0.5 * d2 * d2, 0.5 * d3 * d3  # e^{i d} = 1 - s + i d
            # f/(e_c E_h) = (kA + i cA W) e^{i delta} - (kA + i cA Omega0)
            #             = -kA s - cA W delta + i (kA delta + cA (Delta - W s))
            f1 = ecE1 * complex(-kA * s1 - cA * W1 * d1, kA * d1 + cA * (D1 - W1 * s1))
            f2 = ecE2 * complex(-kA * s2 - cA * W2 * d2, kA * d2 + cA * (D2 - W2 * s2))
            f3 = ecE3 * complex(-kA * s3 - cA * W3 * d3, kA * d3 + cA * (D3 - W3 * s3))
            if k and lip * max(abs(t1 - p1), abs(t2 - p2), abs(t3 - p3)) <= tol:
                break
            if k == PASSES:
                return None
            # the torque with e^{i delta} and y'': its fixed point (module docstring)
            p1, p2, p3 = t1, t2, t3
            y1 = (M11 * f1 + M12 * f2 + M13 * f3).conjugate() * E1 + X1
            y2 = (M21 * f1 + M22 * f2 + M23 * f3).conjugate() * E2 + X2
            y3 = (M31 * f1 + M32 * f2 + M33 * f3).conjugate() * E3 + X3
            t1 = TJ + mJ * (y1.imag * (1.0 - s1) + y1.real * d1)
            t2 = TJ + mJ * (y2.imag * (1.0 - s2) + y2.real * d2)
            t3 = TJ + mJ * (y3.imag * (1.0 - s3) + y3.real * d3)
        delta = BD1 * t1 + BD2 * t2 + BD3 * t3
        if not abs(delta) <= DELTA_MAX:
            return None
        Om = Om0 + (B1 * t1 + B2 * t2 + B3 * t3)
        e_h = em * em
        Eh = E0 * e_h
        PE = PE0 * e_h
        y = G1 * f1 + G2 * f2 + G3 * f3
        yp = Gp1 * f1 + Gp2 * f2 + Gp3 * f3
        w6 = 2.0 * Wt * h  # (the rate of y's forcing: the spin's and the modes' twice)
        w6 = w6 * w6 * w6
        if w6 * w6 * (abs(y) + h * abs(yp)) > y_lim:  # (the truncation estimate)
            return None
        zG = Qs + PE + fa * u0 + fb * u1 + y
        wG = iW * PE + fap * u0 + fbp * u1 + yp
        dd = delta * delta
        ecE = ec * Eh * complex(1.0 - 0.5 * dd, delta - delta * dd / 6.0)
        return zG - ecE, wG - 1j * Om * ecE, psi0 + (Om0 * h + delta), Om


def _green(sb: list[float], h: float, m: float, c: float) -> tuple[list[float], list[float]]:
    """The Green's weights at c h of f's interpolant on the nodes: y(c h) = sum_j G_j f_j and
    y'(c h) = sum_j G'_j f_j for m y'' + cA y' + kA y = f from rest, with f_b = sum sb_q t^q
    the solution from (0, 1): G_j = (h/m) int_0^c f_b(h(c - s)) l_j(s) ds, by
    int_0^c (c - s)^q s^r ds = c^(q+r+1) q! r!/(q+r+1)!."""
    G, Gp = [0.0] * S, [0.0] * S
    n = len(sb)
    for j in range(S):
        for q in range(n):
            for r, lr in enumerate(_L[j]):
                beta = (math.factorial(q) * math.factorial(r) / math.factorial(q + r + 1)
                        * c ** (q + r + 1))
                G[j] += sb[q] * h ** q * lr * beta
                if q + 1 < n:
                    Gp[j] += (q + 1) * sb[q + 1] * h ** q * lr * beta
    return [x * h / m for x in G], [x * h / m for x in Gp]
