"""Sustained contact on the clearance circle: sliding and rolling (MODEL.md eq. (3)).

Frame and units: inertial, SI. On the circle z = c_r e^{i theta}; the state is the polar
angle theta (rad) and the whirl rate theta' (rad/s). Forces are written per unit m c_r
(1/s^2), so that with w = e^{-i theta}, Q(t) = q0 + eu e^{i psi(t)},

    Gn = N/(m c_r)            = Re(Q w) - kappa + theta'^2        (normal force, inward >= 0)
    Gt = Im(e^{-i theta}F)/(m c_r) = Im(Q w) - beta theta'        (free tangential force)
    theta'' = Gt - Ft,   Ft = F_t/(m c_r)

with q0 = (a F_bias - i m g + F_ext)/(m c_r), eu = e_c Omega^2 e^{i phi}/c_r, beta = a c/m,
kappa = a k/m. The slip of the contact point is v_rel = c_r (wr + theta'), wr = R Omega/c_r.

* Sliding (v_rel != 0): Ft = mu s Gn, s = sign(v_rel); integrated by extrapolation (gbs.py)
  at 1e-13 relative tolerance, with the step's contact integrals carried as quadratures.
* Rolling (v_rel = 0): theta' = -wr is constant and Ft = Gt (static friction); theta, Gn
  and Gt are sums of two rotating phasors, so the motion and its integrals are closed form.
* Transitions: lift-off when Gn reaches 0; sliding -> rolling when v_rel reaches 0 with
  |Gt| <= mu Gn, otherwise the slip reverses; rolling -> sliding when |Gt| reaches mu Gn.
* Synchronous forward rub: with q0 = 0 the sliding system is autonomous in the co-rotating
  frame and has equilibria theta' = Omega (forward_rub_equilibria). A state on a stable one
  is advanced in closed form (a rigid rotation) instead of being integrated.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass, field

from . import gbs
from .divdiff import dd2
from .events import G2_FLOOR
from .params import RotorParams

RTOL = 1e-13
"""Relative tolerance of the sliding integrator."""
K_MIN = 5
"""Fewest extrapolation columns before a step may be accepted (order >= 10). Accepting at
lower order lets the step-size controller settle on needlessly short steps."""
MAX_STEPS = 2000
"""Cap on integrator steps in one sliding segment, plus 50 per maximal step in it."""
MAX_ROOT_ITERS = 200
"""Cap on conservative-advancement iterations for one rolling exit search."""


class ContactWorkExceeded(RuntimeError):
    """A contact segment hit its work cap; ``work`` is what it had used."""

    def __init__(self, message: str, work: int = 0) -> None:
        super().__init__(message)
        self.work = work


def wrap_angle(x: float) -> float:
    """Reduce an angle (rad) to [-pi, pi) with a two-part 2 pi (no drift over long runs)."""
    k = math.floor((x + math.pi) / (2.0 * math.pi))
    if k == 0:
        return x
    return (x - k * 6.283185307179586) - k * 2.4492935982947064e-16


def phase_integral(nu: float, x: float) -> complex:
    """int_0^x e^{i nu u} du (s), accurate for nu -> 0."""
    return x * dd2(1j * nu * x, 0j)


@dataclass(frozen=True)
class WallForces:
    """Contact-free forces at the wall per unit m c_r (1/s^2), inertial frame, held inputs."""

    q0: complex
    eu: complex
    beta: float
    kappa: float
    Omega: float
    wr: float
    mu: float
    gn_floor: float = 0.0
    """Absolute part of Gn's rounding band (1/s^2): the underflow error of subnormal
    forces. A quarter of the free flight's band of g'' = 2 c_r^2 Gn (events.G2_FLOOR)."""

    @classmethod
    def build(cls, p: RotorParams, Omega: float, F_ext: complex, amb: float) -> WallForces:
        """Forces for parameters ``p`` and the inputs held over a step."""
        mc = p.m * p.c_r
        return cls(
            q0=(amb * p.bias_force + p.gravity_force + complex(F_ext)) / mc,
            eu=p.e_c * Omega * Omega * cmath.exp(1j * p.phi) / p.c_r,
            beta=amb * p.c / p.m,
            kappa=amb * p.k / p.m,
            Omega=Omega,
            wr=p.R * Omega / p.c_r,
            mu=p.mu,
            gn_floor=G2_FLOOR / (8.0 * p.c_r * p.c_r),
        )

    def gn_gt(self, theta: float, dtheta: float, E: complex) -> tuple[float, float]:
        """(Gn, Gt) in 1/s^2 at angle theta, whirl rate dtheta and phasor E = e^{i psi}."""
        P = (self.q0 + self.eu * E) * complex(math.cos(theta), -math.sin(theta))
        return P.real - self.kappa + dtheta * dtheta, P.imag - self.beta * dtheta

    def gn_rate(self, theta: float, dtheta: float, E: complex, ddtheta: float) -> float:
        """dGn/dt (1/s^3) along a contact motion with angular acceleration ddtheta."""
        w = complex(math.cos(theta), -math.sin(theta))
        Q = self.q0 + self.eu * E
        dP = (1j * self.Omega * self.eu * E - 1j * dtheta * Q) * w
        return dP.real + 2.0 * dtheta * ddtheta

    def cone_margin(self, theta: float, dtheta: float, E: complex) -> tuple[float, float]:
        """(mu Gn - |Gt|, its rate along rolling) in 1/s^2 and 1/s^3: rolling holds while > 0."""
        gn, gt = self.gn_gt(theta, dtheta, E)
        w = complex(math.cos(theta), -math.sin(theta))
        dP = (1j * self.Omega * self.eu * E - 1j * dtheta * (self.q0 + self.eu * E)) * w
        rate = self.mu * (dP.real) - math.copysign(1.0, gt) * dP.imag
        return self.mu * gn - abs(gt), rate

    def gn_tol(self, dtheta: float) -> float:
        """Rounding band of Gn (1/s^2): inside it the sign of dGn/dt decides lift-off."""
        return (
            64.0
            * 2.220446049250313e-16
            * (abs(self.q0) + abs(self.eu) + self.kappa + dtheta * dtheta)
            + self.gn_floor
        )

    def omega_ref(self, dtheta: float) -> float:
        """A frequency scale (rad/s) of the contact motion, for step limits and tolerances."""
        return max(
            abs(self.Omega),
            abs(dtheta),
            math.sqrt(self.kappa),
            self.beta,
            math.sqrt(abs(self.q0) + abs(self.eu)),
            1e-6,
        )


@dataclass
class ContactTally:
    """Integrals of the contact force over a segment, per unit m c_r (SI otherwise).

    I_n = int Gn (1/s), I_c = int of the contact force on the rotor / (m c_r) (complex,
    1/s), I_t = int Ft (1/s), I_e = int Ft (wr + theta') (1/s^2; times m c_r^2 gives J),
    peak = max Gn seen (1/s^2).
    """

    I_n: float = 0.0
    I_c: complex = 0j
    I_t: float = 0.0
    I_e: float = 0.0
    peak: float = 0.0
    work: int = 0


@dataclass
class SegmentEnd:
    """Where a contact segment stopped: after ``du`` seconds, state, and the event."""

    du: float
    theta: float
    dtheta: float
    event: str | None  # None (end), "lift_off", "slip_zero", "slip_stuck", "cone"
    tally: ContactTally = field(default_factory=ContactTally)


# --------------------------------------------------------------------------- sliding


class Sliding:
    """One sliding segment with slip sign ``s`` from (theta0, dtheta0, E0)."""

    def __init__(
        self,
        wf: WallForces,
        theta0: float,
        dtheta0: float,
        E0: complex,
        s: float,
        gn_slack: float = 0.0,
    ) -> None:
        self.wf = wf
        self.gn_slack = gn_slack  # lift-off only once Gn < -gn_slack (1/s^2)
        self.s = s
        self.mus = wf.mu * s
        self.theta0 = theta0
        self.dtheta0 = dtheta0
        self.E0 = E0
        w = wf.omega_ref(dtheta0)
        self.h_max = 0.5 / w
        self.scale = [RTOL * (1.0 + abs(theta0)), RTOL * w]

    def rhs(self, u: float, y: list[float]) -> list[float]:
        """d/du of (theta, theta', I_n, I_cx, I_cy, I_e)."""
        wf = self.wf
        th, dth = y[0], y[1]
        E = self.E0 * cmath.exp(1j * wf.Omega * u)
        c, sn = math.cos(th), math.sin(th)
        P = (wf.q0 + wf.eu * E) * complex(c, -sn)
        gn = P.real - wf.kappa + dth * dth
        ft = self.mus * gn
        force = -complex(gn, ft) * complex(c, sn)
        return [dth, P.imag - wf.beta * dth - ft, gn, force.real, force.imag, ft * (wf.wr + dth)]

    def events(self, y: list[float], u: float) -> tuple[float, float]:
        """(Gn, s v_rel/c_r) at state y and local time u: contact ends when either is <= 0."""
        E = self.E0 * cmath.exp(1j * self.wf.Omega * u)
        gn, _ = self.wf.gn_gt(y[0], y[1], E)
        gn += self.gn_slack
        if self.wf.mu == 0.0:  # frictionless: the slip direction carries no physics
            return gn, 1.0
        return gn, self.s * (self.wf.wr + y[1])

    def run(self, rem: float, H0: float) -> tuple[SegmentEnd, float]:
        """Integrate up to ``rem`` seconds or the first event; return (end, next step size)."""
        y = [self.theta0, self.dtheta0, 0.0, 0.0, 0.0, 0.0]
        u = 0.0
        H = min(H0, self.h_max)
        tally = ContactTally()
        tally.peak = max(0.0, self.events(y, 0.0)[0])
        for _ in range(MAX_STEPS + int(min(50.0 * rem / self.h_max, 1e9))):
            if u >= rem:
                break
            step = min(H, rem - u)
            cut = step < H  # cut short by the segment's end: accept from any column
            f0 = self.rhs(u, y)
            y_new, err, k, nfev = gbs.extrapolated_step(
                self.rhs, u, y, f0, step, self.scale, k_min=2 if cut else K_MIN
            )
            tally.work += nfev
            if not err <= 1.0:  # also rejects NaN (an overflowing trial step)
                H = gbs.next_step_size(step, err, k) if err == err else 0.1 * step
                continue
            gn, sv = self.events(y_new, u + step)
            if gn <= 0.0 or sv <= 0.0:
                x, y_ev, kind = self._locate(u, y, f0, step, k, tally)
                self._tally(tally, y_ev)
                return SegmentEnd(u + x, y_ev[0], y_ev[1], kind, tally), H
            tally.peak = max(tally.peak, gn)
            u_next = u + step if step < rem - u else rem
            u, y = u_next, y_new
            if not cut:  # a cut step says nothing about the step the motion allows
                H = min(gbs.next_step_size(step, err, k), self.h_max)
        else:
            raise ContactWorkExceeded("sliding segment exceeded its step cap", tally.work)
        self._tally(tally, y)
        return SegmentEnd(rem, y[0], y[1], None, tally), H

    def _tally(self, tally: ContactTally, y: list[float]) -> None:
        tally.I_n = y[2]
        tally.I_c = complex(y[3], y[4])
        tally.I_t = self.mus * y[2]
        tally.I_e = y[5]

    def _locate(
        self, u: float, y: list[float], f0: list[float], H: float, k: int, tally: ContactTally
    ) -> tuple[float, list[float], str]:
        """Earliest event in (0, H] by Illinois on re-integrated steps of fixed order.

        The two event functions are normalised by fixed physical scales (not by their
        value at the start, which is 0 when sliding restarts at zero slip).
        """
        wf = self.wf
        s_n = wf.gn_tol(y[1]) / (64.0 * 2.220446049250313e-16)  # force scale, 1/s^2
        s_v = abs(wf.wr) + abs(y[1]) + wf.omega_ref(y[1])  # rate scale, 1/s

        def at(x: float) -> tuple[list[float], float]:
            yx, _, _, nfev = gbs.extrapolated_step(
                self.rhs, u, y, f0, x, self.scale, k_fixed=max(k, 4)
            )
            tally.work += nfev
            gn, sv = self.events(yx, u + x)
            return yx, min(gn / s_n, sv / s_v)

        noise = 64.0 * 2.220446049250313e-16  # rounding band of the normalised events
        y_hi, fhi = at(H)
        gn0, sv0 = self.events(y, u)
        lo, flo = 0.0, min(gn0 / s_n, sv0 / s_v)
        if flo <= noise:  # starting on the event surface: step clearly off it first
            x = H * 2.0**-40
            while x < H:
                _, fx = at(x)
                if fx > noise:
                    lo, flo = x, fx
                    break
                x *= 2.0
            else:  # never off the surface: the event is immediate
                y_x, _ = at(H * 2.0**-40)
                kind = self._kind(y_x, u + H * 2.0**-40, s_n, s_v)
                stuck = kind == "slip_zero" and abs(sv0) <= noise * s_v
                return H * 2.0**-40, y_x, "slip_stuck" if stuck else kind
        hi, y_best = H, y_hi
        side = 0
        for _ in range(100):
            if hi - lo <= 2e-16 * (abs(u) + hi) + 1e-300:
                break
            x = (lo * fhi - hi * flo) / (fhi - flo) if fhi != flo else 0.5 * (lo + hi)
            if not lo < x < hi:
                x = 0.5 * (lo + hi)
            yx, fx = at(x)
            if fx > noise:
                lo, flo = x, fx
                if side == -1:
                    fhi *= 0.5
                side = -1
            else:
                hi, fhi, y_best = x, fx, yx
                if side == 1:
                    flo *= 0.5
                side = 1
        return hi, y_best, self._kind(y_best, u + hi, s_n, s_v)

    def _kind(self, y: list[float], u: float, s_n: float, s_v: float) -> str:
        gn, sv = self.events(y, u)
        return "lift_off" if gn / s_n <= sv / s_v else "slip_zero"


# --------------------------------------------------------------------------- rolling


@dataclass(frozen=True)
class TrigSum:
    """f(u) = C + Re(a1 e^{i nu1 u} + a2 e^{i nu2 u}) (rolling exit functions)."""

    C: float
    a1: complex
    a2: complex
    nu1: float
    nu2: float

    def value(self, u: float) -> tuple[float, float]:
        """(f, f') at u."""
        e1 = self.a1 * cmath.exp(1j * self.nu1 * u)
        e2 = self.a2 * cmath.exp(1j * self.nu2 * u)
        return self.C + (e1 + e2).real, (1j * (self.nu1 * e1 + self.nu2 * e2)).real

    def never_zero(self) -> bool:
        """True when f > 0 for all u (proved by the amplitude bound)."""
        return self.C - abs(self.a1) - abs(self.a2) > 0.0

    def first_zero(self, x_max: float, tally: ContactTally) -> float | None:
        """First u in (0, x_max] where f reaches 0 (f(0) > 0 assumed), or None.

        Conservative advancement with f(u + x) >= f + f' x - M x^2/2,
        M = |a1| nu1^2 + |a2| nu2^2 >= |f''|.
        """
        if self.never_zero():
            return None
        M = abs(self.a1) * self.nu1**2 + abs(self.a2) * self.nu2**2
        tol = 1e-15 * (abs(self.C) + abs(self.a1) + abs(self.a2))
        u = 0.0
        f0, df0 = self.value(0.0)
        if f0 <= tol and df0 > 0.0 and M > 0.0:  # on the boundary, moving inside: step off
            u = min(df0 / M, x_max)
            if self.value(u)[0] <= tol:
                return 0.0
        for _ in range(MAX_ROOT_ITERS):
            tally.work += 1
            f, df = self.value(u)
            if f <= tol:
                return u
            if M == 0.0:
                x = -f / df if df < 0.0 else math.inf
            else:
                x = (df + math.sqrt(df * df + 2.0 * M * f)) / M
            if u + x >= x_max:
                return None
            u += x
        raise ContactWorkExceeded(
            f"rolling exit search exceeded {MAX_ROOT_ITERS} iterations", tally.work
        )


class Rolling:
    """Rolling (v_rel = 0) from theta0 with phasor E0: closed form (see module docstring)."""

    def __init__(self, wf: WallForces, theta0: float, E0: complex) -> None:
        self.wf = wf
        self.theta0 = theta0
        self.E0 = E0
        self.dtheta = -wf.wr
        w0 = cmath.exp(-1j * theta0)
        self.A1 = wf.q0 * w0  # rotates at nu1 = -dtheta
        self.A2 = wf.eu * E0 * w0  # rotates at nu2 = Omega - dtheta
        self.nu1 = -self.dtheta
        self.nu2 = wf.Omega - self.dtheta
        self.C = self.dtheta**2 - wf.kappa
        self.Gt0 = -wf.beta * self.dtheta

    def exits(self) -> tuple[TrigSum, TrigSum, TrigSum]:
        """Gn, mu Gn - Gt and mu Gn + Gt as trigonometric sums (rolling lasts while all > 0)."""
        mu = self.wf.mu
        mk = (self.A1, self.A2, self.nu1, self.nu2)
        gn = TrigSum(self.C, *mk)
        plus = TrigSum(
            mu * self.C - self.Gt0, (mu + 1j) * self.A1, (mu + 1j) * self.A2, self.nu1, self.nu2
        )
        minus = TrigSum(
            mu * self.C + self.Gt0, (mu - 1j) * self.A1, (mu - 1j) * self.A2, self.nu1, self.nu2
        )
        return gn, plus, minus

    def gn_gt(self, u: float) -> tuple[float, float]:
        """(Gn, Gt) at local time u (1/s^2); Gt is the static friction needed (Ft = Gt)."""
        X = self.A1 * cmath.exp(1j * self.nu1 * u) + self.A2 * cmath.exp(1j * self.nu2 * u)
        return self.C + X.real, self.Gt0 + X.imag

    def run(self, rem: float, cone_slack: float = 0.0) -> SegmentEnd:
        """Roll up to ``rem`` seconds or until the first exit (lift-off or friction cone).

        ``cone_slack`` (1/s^2) > 0 ignores cone violations smaller than it: used after a
        sliding attempt proved unable to leave zero slip (a violation below resolution).
        """
        tally = ContactTally()
        names = ("lift_off", "cone", "cone")
        # an exit happens once its function is past the rounding band that the mode
        # choice (simulator: _leaves_wall, _choose_contact_mode) also uses
        band = self.wf.gn_tol(self.dtheta)
        shifts = (
            band,
            band * (1.0 + self.wf.mu) + cone_slack,
            band * (1.0 + self.wf.mu) + cone_slack,
        )
        x_end, kind = rem, None
        for fn, name, shift in zip(self.exits(), names, shifts):
            fn = TrigSum(fn.C + shift, fn.a1, fn.a2, fn.nu1, fn.nu2)
            x = fn.first_zero(x_end, tally)
            if x is not None and x < x_end:
                x_end, kind = x, name
        self._integrate(tally, x_end)
        theta = wrap_angle(self.theta0 + self.dtheta * x_end)
        return SegmentEnd(x_end, theta, self.dtheta, kind, tally)

    def _integrate(self, tally: ContactTally, x: float) -> None:
        wf = self.wf
        I1 = phase_integral(self.nu1, x)
        I2 = phase_integral(self.nu2, x)
        X = self.A1 * I1 + self.A2 * I2
        tally.I_n = self.C * x + X.real
        tally.I_t = self.Gt0 * x + X.imag
        e0 = cmath.exp(1j * self.theta0)
        tally.I_c = -(
            complex(self.C, self.Gt0) * e0 * phase_integral(self.dtheta, x)
            + wf.q0 * x
            + wf.eu * self.E0 * phase_integral(wf.Omega, x)
        )
        tally.I_e = 0.0
        samples = (self.gn_gt(x * j / 8.0)[0] for j in range(9))
        tally.peak = max(0.0, *samples)
        tally.work += 1


# --------------------------------------------------------------------------- forward rub


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
        out.append(RubEquilibrium(wrap_angle(phi - x), gn, stable, eig))
    return out
