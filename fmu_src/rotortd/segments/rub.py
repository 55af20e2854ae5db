"""The synchronous forward rub: its equilibria and the closed-form segments near and on it.

With q0 = 0 the sliding system is autonomous in the co-rotating frame and has equilibria
theta' = Omega (forward_rub_equilibria). Near a stable one the motion is in closed form, to
first (LinearRub) or second order (QuadraticRub) in the deviation, with the dropped terms
bounded; on it, a rigid rotation (LockedRub). Frame and units as in ``rotortd.segments``.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass

from ..contact.search import WORK_MAX
from ..contact.wall import ContactTally, SegmentEnd, WallForces, phase_integral
from ..scaled import wrap_angle


@dataclass(frozen=True)
class RubEquilibrium:
    """A synchronous forward-rub sliding equilibrium (theta' = Omega, q0 = 0).

    alpha: co-rotating angle theta - psi (rad); Gn: normal force per m c_r (1/s^2);
    stable: both eigenvalues of the linearised co-rotating sliding motion in the left
    half plane; eig: those eigenvalues (1/s).
    """

    alpha: float
    Gn: float
    stable: bool
    eig: tuple[complex, complex]
    a1: float = 0.0
    """Restoring coefficient (1/s^2) of the linearised motion x'' + b1 x' + a1 x = 0 of the
    deviation x = theta - psi - alpha."""
    b1: float = 0.0
    """Its damping coefficient (1/s)."""
    gx: float = 0.0
    """dGn/dx (1/s^2) at the equilibrium; dGn/dtheta' = 2 theta'."""


def forward_rub_equilibria(wf: WallForces) -> list[RubEquilibrium]:
    """The synchronous forward-rub equilibria with N >= 0 (empty when none or q0 != 0).

    With x = phi - alpha, Gt - mu s Gn = 0 reads
    |eu| (sin x - mu s cos x) = beta Omega + mu s (Omega^2 - kappa), s = sign(Omega).
    """
    W = wf.Omega
    if wf.q0 != 0 or W == 0.0 or wf.eu == 0:
        return []
    s = math.copysign(1.0, wf.wr + W)
    A = abs(wf.eu)
    phi = cmath.phase(wf.eu)
    rhs = wf.beta * W + wf.mu * s * (W * W - wf.kappa)
    S = rhs / (A * math.hypot(1.0, wf.mu))
    if abs(S) > 1.0:
        return []
    delta = math.atan(wf.mu * s)
    out = []
    for x in (delta + math.asin(S), delta + math.pi - math.asin(S)):
        gn = A * math.cos(x) - wf.kappa + W * W
        if gn < 0.0:
            continue
        a1 = A * (math.cos(x) + wf.mu * s * math.sin(x))
        b1 = wf.beta + 2.0 * wf.mu * s * W
        root = cmath.sqrt(b1 * b1 / 4.0 - a1)
        eig = (-b1 / 2.0 + root, -b1 / 2.0 - root)
        stable = max(e.real for e in eig) < 0.0
        out.append(RubEquilibrium(wrap_angle(phi - x), gn, stable, eig, a1, b1, A * math.sin(x)))
    return out


LINEAR_TOL = 1e-6
"""Largest deviation from a stable forward rub (rad, and rad per 1/w in the rate) at which
``LinearRub.near`` weighs the linearisation's errors against LINEAR_BUDGET."""
LINEAR_BUDGET = 1e-14
"""Bound on the linearisation's errors (``LinearRub``), relative: its state error over all
later time (rad, and rad per 1/w in the rate) and the terms it drops from a step's contact
integrals. A tenth of the sliding integrator's RTOL, which bounds each of its steps."""


def rub_deviation(
    wf: WallForces, eq: RubEquilibrium, theta0: float, dtheta0: float, E0: complex, s: float,
    tol: float,
) -> tuple[float, float, float, float, float, float, float] | None:
    """(x0, y0, w, X, Y, Ix, Iy) of a sliding state (theta0, dtheta0) with e^{i psi} = E0 and
    slip sign s near the stable forward rub eq, or None when eq is not a stable rub of
    this slip, or the deviation exceeds tol (rad, and rad per 1/w in the rate).

    x0 = theta - psi - alpha (rad), y0 = theta' - Omega (rad/s), w = omega_ref (rad/s);
    X = sqrt(V/a1) and Y = sqrt(V) bound |x| and |y| along the linear flow (V = a1 x^2 + y^2
    never grows); Ix and Iy are int_0^inf x^2 dt and y^2 dt along it (closed form)."""
    a1, b1, W = eq.a1, eq.b1, wf.Omega
    if not (eq.stable and a1 > 0.0 and b1 > 0.0) or s * (wf.wr + W) <= 0.0:
        return None
    y0 = dtheta0 - W
    w = wf.omega_ref(dtheta0)
    if abs(y0) > tol * w:  # (implied by the test of Y below: a cheap shortcut)
        return None
    x0 = wrap_angle(theta0 - cmath.phase(E0) - eq.alpha)
    V0 = a1 * x0 * x0 + y0 * y0
    xm, ym = math.sqrt(V0 / a1), math.sqrt(V0)
    if xm > tol or ym > tol * w:
        return None
    Ix = ((b1 * b1 + a1) * x0 * x0 + 2.0 * b1 * x0 * y0 + y0 * y0) / (2.0 * a1 * b1)
    Iy = V0 / (2.0 * b1)
    return x0, y0, w, xm, ym, Ix, Iy


def _rub_propagator(a1: float, sig: float, u: float) -> tuple[float, float]:
    """(e^{-sig u} C, e^{-sig u} S) with C = cosh(q u), S = sinh(q u)/q, q^2 = sig^2 - a1:
    the flow of x'' + 2 sig x' + a1 x = 0 over u seconds is e^{-sig u} [C I + S (A + sig I)]
    (any damping; overdamped over a long step as two decaying exponentials, so that
    cosh(q u) cannot overflow)."""
    d = sig * sig - a1
    if d > 0.0 and math.sqrt(d) * u > 1.0:  # overdamped and long: no cosh overflow
        q = math.sqrt(d)
        slow, fast = math.exp((q - sig) * u), math.exp(-(q + sig) * u)  # q < sig
        return 0.5 * (slow + fast), 0.5 * (slow - fast) / q
    q = math.sqrt(abs(d))
    if d > 0.0:
        ch, s_ = math.cosh(q * u), math.sinh(q * u) / q
    else:
        ch, s_ = math.cos(q * u), (math.sin(q * u) / q if q > 0.0 else u)
    decay = math.exp(-sig * u)
    return decay * ch, decay * s_


class _RubStep:
    """What LinearRub and QuadraticRub share: ``near`` measures the deviation of a sliding
    state from the rub with the class's DEV_TOL (``rub_deviation``) and hands it to the
    class's ``admit``, which weighs the dropped terms against LINEAR_BUDGET."""

    __slots__ = ()
    DEV_TOL: float

    @classmethod
    def near(
        cls, wf: WallForces, eq: RubEquilibrium, theta0: float, dtheta0: float, E0: complex,
        s: float,
    ) -> _RubStep | None:
        """The closed-form rub step from (theta0, dtheta0) with e^{i psi} = E0 and slip sign
        s, or None when the state is not close enough (the class docstring)."""
        dev = rub_deviation(wf, eq, theta0, dtheta0, E0, s, cls.DEV_TOL)
        return None if dev is None else cls.admit(wf, eq, theta0, dtheta0, s, dev)

    @classmethod
    def admit(cls, wf: WallForces, eq: RubEquilibrium, theta0: float, dtheta0: float,
              s: float, dev: tuple[float, ...]) -> _RubStep | None:
        """``near`` on a state's ``rub_deviation``: the step, or None (the class docstring)."""
        raise NotImplementedError


class LinearRub(_RubStep):
    """Sliding within LINEAR_TOL of a stable forward rub ``eq`` (q0 = 0), in closed form.

    Frame: co-rotating, SI. The deviation x = theta - psi - alpha (rad) and y = theta' -
    Omega (rad/s) obey x'' + b1 x' + a1 x = R with the remainder |R| <= |eu| sqrt(1 + mu^2)
    x^2/2 + mu y^2. The linear flow does not expand V = a1 x^2 + y^2 (dV/dt = -2 b1 y^2),
    so |x| <= X = sqrt(V/a1) and |y| <= Y = sqrt(V) from now on, and the state error of
    dropping R over all later time is at most B = int |R| dt, which the integrals of x^2
    and y^2 along the linear flow bound in closed form. ``near`` admits a state only when
    B is below LINEAR_BUDGET and the deviation cannot reach lift-off or zero slip. The
    contact integrals keep the terms linear in (x, y); ``near`` also bounds the dropped
    ones, (|eu| X^2/2 + Y^2)/Gn of the normal force and X^2/2 of its direction, by
    LINEAR_BUDGET.
    """

    __slots__ = ("X", "Y", "eq", "gx", "mus", "theta0", "wf", "x0", "y0")
    DEV_TOL = LINEAR_TOL

    def __init__(self, wf: WallForces, eq: RubEquilibrium, theta0: float, x0: float,
                 y0: float, mus: float, X: float, Y: float, gx: float) -> None:
        self.wf, self.eq, self.theta0, self.x0, self.y0, self.mus = wf, eq, theta0, x0, y0, mus
        self.X, self.Y = X, Y  # bounds of |x| (rad) and |y| (rad/s) from now on
        self.gx = gx  # dGn/dx at the rub (1/s^2); dGn/dy = 2 Omega

    @classmethod
    def admit(
        cls, wf: WallForces, eq: RubEquilibrium, theta0: float, dtheta0: float, s: float,
        dev: tuple[float, ...],
    ) -> LinearRub | None:
        """``near`` on the state's ``rub_deviation`` (computed with any tolerance)."""
        x0, y0, w, X, Y, Ix, Iy = dev
        if X > LINEAR_TOL or LINEAR_TOL * w < Y:
            return None
        a1, W = eq.a1, wf.Omega
        spread = 0.5 * abs(wf.eu) * math.hypot(1.0, wf.mu) * Ix + wf.mu * Iy  # B
        drop = (0.5 * abs(wf.eu) * X * X + Y * Y) / eq.Gn + 0.5 * X * X  # in the integrals
        bound = LINEAR_BUDGET * min(w, math.sqrt(a1))
        if spread > bound or drop > LINEAR_BUDGET:
            return None
        gx = eq.gx
        dip = abs(gx) * X + 2.0 * abs(W) * Y + 0.5 * abs(wf.eu) * X * X + Y * Y
        if eq.Gn - dip <= wf.gn_tol(dtheta0) or abs(wf.wr + W) <= Y:
            return None
        return cls(wf, eq, theta0, x0, y0, wf.mu * s, X, Y, gx)

    def snap_error(self) -> float:
        """Largest relative change, now or later, of the angle (rad), the rate and the
        normal force if the state were put exactly on the rub."""
        W = self.wf.Omega
        return max(self.X, self.Y / abs(W), (abs(self.gx) * self.X + 2.0 * abs(W) * self.Y)
                   / self.eq.Gn)

    def flow(self, u: float) -> tuple[float, float]:
        """(x, y) after u seconds of the linear flow: e^{-sig u} [C I + S (A + sig I)] with
        sig = b1/2, C = cosh(q u), S = sinh(q u)/q, q^2 = sig^2 - a1 (any damping)."""
        a1, sig = self.eq.a1, 0.5 * self.eq.b1
        c, sh = _rub_propagator(a1, sig, u)
        x0, y0 = self.x0, self.y0
        return x0 * (c + sig * sh) + y0 * sh, y0 * (c - sig * sh) - a1 * x0 * sh

    def run(self, rem: float, limit: int = WORK_MAX) -> SegmentEnd:
        """Advance rem seconds: the end state and the contact integrals (ContactTally).
        One closed-form evaluation (work 1), whatever ``limit``."""
        wf, eq, mus = self.wf, self.eq, self.mus
        W, a1, b1 = wf.Omega, eq.a1, eq.b1
        x0, y0 = self.x0, self.y0
        x1, y1 = self.flow(rem)
        dx, dy = x1 - x0, y1 - y0
        int_y, int_x = dx, -(dy + b1 * dx) / a1  # from x' = y and y' = -a1 x - b1 y
        gx, gy = self.gx, 2.0 * W
        # K = int e^{i W u} (x, y) du solves (A + i W) K = e^{i W rem} (x1, y1) - (x0, y0)
        rot = cmath.exp(1j * W * rem)
        rx, ry = rot * x1 - x0, rot * y1 - y0
        det = complex(a1 - W * W, -b1 * W)
        Kx = (complex(-b1, W) * rx - ry) / det
        Ky = (a1 * rx + 1j * W * ry) / det
        tal = ContactTally()
        tal.I_n = eq.Gn * rem + gx * int_x + gy * int_y
        tal.I_t = mus * tal.I_n
        ring = eq.Gn * phase_integral(W, rem) + complex(gx, eq.Gn) * Kx + gy * Ky
        e0 = cmath.exp(1j * (self.theta0 - x0))  # e^{i(theta - Omega u - x)}
        tal.I_c = -complex(1.0, mus) * e0 * ring
        tal.I_e = mus * ((wf.wr + W) * tal.I_n + eq.Gn * int_y)
        tal.peak = eq.Gn + max(gx * x0 + gy * y0, gx * x1 + gy * y1)
        # theta - Omega u = theta0 - x0 + x: e^{ix} to first order, as the force's direction
        tal.I_z = e0 * complex(rem, int_x)
        return SegmentEnd(rem, self.theta0 + W * rem + dx, W + y1, None, tal, work=1)


QUAD_TOL = 1e-4
"""Largest deviation from a stable forward rub (rad, and rad per 1/w in the rate) at which
``QuadraticRub.near`` weighs its errors against LINEAR_BUDGET."""


class QuadraticRub(_RubStep):
    """Sliding near a stable forward rub ``eq`` (q0 = 0) to second order, in closed form.

    Frame: co-rotating, SI; x, y, a1, b1, gx, X, Y, Ix, Iy as in LinearRub. Exactly,
    x'' + b1 x' + a1 x = R with R = a1 (x - sin x) - k2 (1 - cos x) - mu s y^2 and
    k2 = gx (1 + mu^2) - mu s a1. Along the linear flow (x1, y1) the quadratic part of R,
    f = c1 x1^2 + c3 y1^2 (c1 = -k2/2, c3 = -mu s), is a combination of the monomials
    Q = (x1^2, x1 y1, y1^2), which obey Q' = M Q, M = [[0, 2, 0], [-a1, -b1, 1],
    [0, -2 a1, -2 b1]]. So x2 = p.Q, y2 = r.Q with p (M^2 + b1 M + a1 I) = (c1, 0, c3) and
    r = p M solve x2'' + b1 x2' + a1 x2 = f, and the second-order motion is
    (x, y) = (x1, y1) + (p.Q, r.Q) - Phi (p.Q0, r.Q0), Phi the linear propagator. The
    contact integrals keep the terms of second order; they need int Q and
    int e^{i Omega u} Q, which the monomial system gives in closed form (3x3 solves).

    Admission (``near``) bounds what is dropped, by third-order terms, over all later time:
    with F2 = int |f| <= |k2| Ix/2 + mu Iy, the correction obeys |x2| <= F2/sqrt(a1),
    |y2| <= F2, int y2^2 <= F2^2/b1 and int x2^2 <= F2^2 (1/b1 + 1/sqrt(a1))/a1 (from
    d(a1 x2^2 + y2^2)/dt = -2 b1 y2^2 + 2 y2 f and d(x2 y2)/dt); the state error
    int |R - f| <= a1/6 int |x|^3 + |k2|/24 int x^4 + |k2| int |x1 x2| + ... (Cauchy-
    Schwarz) must stay below LINEAR_BUDGET as in LinearRub, and so must the dropped
    third-order terms of the normal force and its direction. Refused near the resonance
    9 a1 = 2 b1^2 (overdamped, one eigenvalue twice the other), where p diverges.
    """

    __slots__ = ("eq", "k2", "mus", "pr", "theta0", "wf", "x0", "y0")
    DEV_TOL = QUAD_TOL

    def __init__(self, wf: WallForces, eq: RubEquilibrium, theta0: float, x0: float,
                 y0: float, mus: float, k2: float, pr: tuple[float, ...]) -> None:
        self.wf, self.eq, self.theta0, self.x0, self.y0 = wf, eq, theta0, x0, y0
        self.mus, self.k2 = mus, k2  # mu times the slip sign; k2 (1/s^2)
        self.pr = pr  # (p1, p2, p3, r1, r2, r3): x2 = p.Q (s^2), y2 = r.Q (s)

    @classmethod
    def admit(
        cls, wf: WallForces, eq: RubEquilibrium, theta0: float, dtheta0: float, s: float,
        dev: tuple[float, ...],
    ) -> QuadraticRub | None:
        """``near`` on the state's ``rub_deviation`` with QUAD_TOL."""
        x0, y0, w, X, Y, Ix, Iy = dev
        a1, b1, mu, mus = eq.a1, eq.b1, wf.mu, wf.mu * s
        gap = 9.0 * a1 - 2.0 * b1 * b1
        if abs(gap) <= 1e-6 * (9.0 * a1 + 2.0 * b1 * b1):
            return None
        k2 = eq.gx * (1.0 + mu * mu) - mus * a1
        F2 = 0.5 * abs(k2) * Ix + mu * Iy
        ra = math.sqrt(a1)
        X2, Y2 = F2 / ra, F2
        Ix2, Iy2 = F2 * F2 * (1.0 / b1 + 1.0 / ra) / a1, F2 * F2 / b1
        Xt, Yt = X + X2, Y + Y2
        Ixx = (math.sqrt(Ix) + math.sqrt(Ix2)) ** 2  # int (x1 + x2)^2
        spread = (Xt * Ixx * (a1 / 6.0 + abs(k2) * Xt / 24.0)
                  + abs(k2) * (math.sqrt(Ix * Ix2) + 0.5 * Ix2)
                  + mu * (2.0 * math.sqrt(Iy * Iy2) + Iy2))
        if spread > LINEAR_BUDGET * min(w, ra):
            return None
        if _quadratic_drop(wf, eq, mus, X, Y, X2, Y2) > LINEAR_BUDGET:
            return None
        W, A = wf.Omega, abs(wf.eu)
        dip = abs(eq.gx) * Xt + 2.0 * abs(W) * Yt + 0.5 * A * Xt * Xt + Yt * Yt
        if eq.Gn - dip <= wf.gn_tol(dtheta0) or abs(wf.wr + W) <= Yt:
            return None
        c1, c3 = -0.5 * k2, -mus
        p3 = 3.0 * (a1 * c3 + 2.0 * c1) / (a1 * gap)
        p1, p2 = 2.0 * a1 * p3 - c1 / a1, (4.0 / 3.0) * b1 * p3
        pr = (p1, p2, p3, -a1 * p2, 2.0 * p1 - b1 * p2 - 2.0 * a1 * p3, p2 - 2.0 * b1 * p3)
        return cls(wf, eq, theta0, x0, y0, mus, k2, pr)

    def snap_error(self) -> float:
        """Never locked from here (LinearRub takes over closer to the rub)."""
        return math.inf

    def run(self, rem: float, limit: int = WORK_MAX) -> SegmentEnd:
        """Advance rem seconds: the end state and the contact integrals (ContactTally).
        One closed-form evaluation (work 1), whatever ``limit``."""
        wf, eq = self.wf, self.eq
        W, a1, b1, mus = wf.Omega, eq.a1, eq.b1, self.mus
        x0, y0 = self.x0, self.y0
        sig = 0.5 * b1
        c, sh = _rub_propagator(a1, sig, rem)
        m11, m12, m21, m22 = c + sig * sh, sh, -a1 * sh, c - sig * sh
        x1, y1 = m11 * x0 + m12 * y0, m21 * x0 + m22 * y0
        p1, p2, p3, r1, r2, r3 = self.pr
        q0 = (x0 * x0, x0 * y0, y0 * y0)
        q = (x1 * x1, x1 * y1, y1 * y1)
        u0 = p1 * q0[0] + p2 * q0[1] + p3 * q0[2]
        v0 = r1 * q0[0] + r2 * q0[1] + r3 * q0[2]
        x = x1 + (p1 * q[0] + p2 * q[1] + p3 * q[2]) - (m11 * u0 + m12 * v0)
        y = y1 + (r1 * q[0] + r2 * q[1] + r3 * q[2]) - (m21 * u0 + m22 * v0)
        c1, c3 = -0.5 * self.k2, -mus
        S1, S2, S3 = _monomial_integrals(a1, b1, 0.0, [b - a for a, b in zip(q0, q)])
        int_y = x - x0
        int_x = (-(y - y0) - b1 * int_y + (c1 * S1 + c3 * S3).real) / a1
        rot = cmath.exp(1j * W * rem)
        K1, K2, K3 = _monomial_integrals(a1, b1, W, [rot * b - a for a, b in zip(q0, q)])
        rx, ry = rot * x - x0, rot * y - y0 - (c1 * K1 + c3 * K3)
        det = complex(a1 - W * W, -b1 * W)
        Kx = (complex(-b1, W) * rx - ry) / det
        Ky = (a1 * rx + 1j * W * ry) / det
        Gn, gx, gy = eq.Gn, eq.gx, 2.0 * W
        gxx = -0.5 * (a1 - mus * gx)  # d2Gn/dx2 / 2
        tal = ContactTally()
        tal.I_n = Gn * rem + gx * int_x + gy * int_y + (gxx * S1 + S3).real
        tal.I_t = mus * tal.I_n
        ring = (Gn * phase_integral(W, rem) + complex(gx, Gn) * Kx + gy * Ky
                + complex(gxx - 0.5 * Gn, gx) * K1 + 1j * gy * K2 + K3)
        e0 = cmath.exp(1j * (self.theta0 - x0))  # e^{i(theta - Omega u - x)}
        tal.I_c = -complex(1.0, mus) * e0 * ring
        tal.I_e = mus * ((wf.wr + W) * tal.I_n + Gn * int_y + (gx * S2 + gy * S3).real)
        tal.peak = Gn + max(gx * x0 + gy * y0 + gxx * q0[0] + q0[2],
                            gx * x + gy * y + gxx * q[0] + q[2])
        # e^{ix} to second order: int (1 + i x - x^2/2), int x^2 = S1 to that order
        tal.I_z = e0 * complex(rem - 0.5 * S1.real, int_x)
        return SegmentEnd(rem, self.theta0 + W * rem + (x - x0), W + y, None, tal, work=1)


class LockedRub:
    """Sliding exactly on a forward rub: a rigid rotation theta' = Omega with Gn constant,
    in closed form (``TouchdownCore`` locks a state within LOCK_TOL of the rub onto it)."""

    __slots__ = ("E0", "dtheta0", "slip", "theta0", "wf")

    def __init__(self, wf: WallForces, theta0: float, dtheta0: float, E0: complex,
                 slip: float) -> None:
        self.wf, self.theta0, self.dtheta0, self.E0, self.slip = wf, theta0, dtheta0, E0, slip

    def run(self, rem: float, limit: int = WORK_MAX) -> SegmentEnd:
        """Rotate rem seconds (work 1, whatever ``limit``)."""
        wf, theta, dtheta = self.wf, self.theta0, self.dtheta0
        gn, _ = wf.gn_gt(theta, dtheta, self.E0)
        ft = wf.mu * self.slip * gn
        tal = ContactTally()
        tal.I_n = gn * rem
        tal.I_t = ft * rem
        e0 = cmath.exp(1j * theta)
        tal.I_c = -complex(gn, ft) * e0 * phase_integral(wf.Omega, rem)
        tal.I_e = ft * (wf.wr + dtheta) * rem
        tal.peak = gn
        tal.I_z = e0 * phase_integral(dtheta - wf.Omega, rem)
        return SegmentEnd(rem, theta + wf.Omega * rem, dtheta, None, tal, work=1)


def _quadratic_drop(wf: WallForces, eq: RubEquilibrium, mus: float, X: float, Y: float,
                    X2: float, Y2: float) -> float:
    """Bound of the third-order terms QuadraticRub drops from the normal force and its
    direction, relative to Gn: Gn e^{ix} / Gn_eq = (1 + n1 + n2 + n3)(1 + e1 + e2 + e3) keeps
    1 + n1 + e1 + n2 + e2 + n1 e1 (n1, e1 first order, n2, e2 second, |n3| <= Dn,
    |e3| <= De). X, Y bound the linear deviation, X2, Y2 its second-order correction."""
    W, A, Gn, gx = wf.Omega, abs(wf.eu), eq.Gn, abs(eq.gx)
    gxx = 0.5 * abs(eq.a1 - mus * eq.gx)
    Xt = X + X2
    cross = 2.0 * X * X2 + X2 * X2
    Dn = (gxx * cross + 2.0 * Y * Y2 + Y2 * Y2 + A * Xt**3 / 6.0 * (1.0 + 0.25 * Xt)) / Gn
    De = 0.5 * cross + Xt**3 / 6.0
    N1 = (gx * X + 2.0 * abs(W) * Y) / Gn
    N2 = (gx * X2 + 2.0 * abs(W) * Y2 + gxx * X * X + Y * Y) / Gn
    E1, E2 = X, X2 + 0.5 * X * X
    return Dn * (1.0 + E1 + E2 + De) + (1.0 + N1 + N2) * De + N1 * E2 + N2 * (E1 + E2)


def _monomial_integrals(a1: float, b1: float, W: float, d: list) -> tuple[complex, ...]:
    """K = (M + i W I)^{-1} d for the monomial matrix M of QuadraticRub (by elimination;
    iW - 2 b1 != 0 and det(M + iW) = (iW - 2 l1)(iW - l1 - l2)(iW - 2 l2) != 0 for a
    stable rub). With d = e^{iWu} Q(u) - Q(0) it is int_0^u e^{iWu'} Q du'; W = 0 gives
    int Q."""
    d1, d2, d3 = d
    iw = 1j * W
    e = iw - 2.0 * b1
    D = -a1 - 0.5 * iw * (iw - b1) - a1 * iw / e
    K1 = (d2 - 0.5 * (iw - b1) * d1 - (d3 + a1 * d1) / e) / D
    K2 = 0.5 * (d1 - iw * K1)
    K3 = (d3 + 2.0 * a1 * K2) / e
    return K1, K2, K3
