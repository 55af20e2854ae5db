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
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass, field

from . import gbs
from .divdiff import dd2
from .events import G2_FLOOR, WORK_MAX
from .params import RotorParams
from .scaled import wrap_angle

RTOL = 1e-13
"""Relative tolerance of the sliding integrator."""
K_MIN = 5
"""Fewest extrapolation columns before a step may be accepted (order >= 10). Accepting at
lower order lets the step-size controller settle on needlessly short steps."""
NU_MIN = 0.1
"""Least |theta'| * span (rad) for a sliding segment to integrate its contact force by parts
(``Sliding.run``): the boundary terms then round to at most ~8 eps/NU_MIN ~ 2e-14 of the
force times the span."""
SCALE_FLOOR = 2.2250738585072014e-308
"""Least error scale of a quadrature (1/s; the smallest normal double): with subnormal
forces (a 1e-313 N load, no spin, no stiffness) the scale RTOL * force * step underflowed
to 0 and the error ratio divided by it (fuzzing). Far below any resolvable integral, it
changes no scale that does not underflow."""
GBS_STEP_WORK = 8
"""Work units charged per extrapolated step of the sliding integrator on top of its
right-hand-side evaluations: the extrapolation tableau, error norm, event test and step
control cost about as much as 8 evaluations (measured; docs/model.md 7)."""
MAX_ROOT_ITERS = 200
"""Cap on conservative-advancement iterations for one rolling exit search."""


class ContactWorkExceeded(RuntimeError):
    """A contact segment hit its work cap; ``work`` is what it had used."""

    def __init__(self, message: str, work: int = 0) -> None:
        super().__init__(message)
        self.work = work


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
        Q = self.q0 + self.eu * E
        co, sn = math.cos(theta), math.sin(theta)  # P = Q e^{-i theta}, as real parts:
        return ((Q.real * co + Q.imag * sn) - self.kappa + dtheta * dtheta,
                (Q.imag * co - Q.real * sn) - self.beta * dtheta)

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
        return 64.0 * 2.220446049250313e-16 * self.force_scale(dtheta) + self.gn_floor

    def force_scale(self, dtheta: float) -> float:
        """|q0| + |eu| + kappa + theta'^2 (1/s^2): the size of the terms of Gn and Gt."""
        return abs(self.q0) + abs(self.eu) + self.kappa + dtheta * dtheta

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
    """Where a contact segment stopped: after ``duration`` seconds, state, and the event.

    Every contact segment (Sliding, Rolling, LinearRub, QuadraticRub, LockedRub) returns
    one from ``run(rem, limit)``: advance at most ``rem`` seconds, at most ``limit`` work
    units, and stop at the first event."""

    duration: float
    """Length of the segment (s), from its start to its end or event."""
    theta: float
    dtheta: float
    event: str | None  # None (end), "lift_off", "slip_zero", "slip_stuck", "cone"
    tally: ContactTally = field(default_factory=ContactTally)
    next_step: float = math.inf
    """Sliding only: the integrator's step size (s) for the next sliding segment."""


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
        step0: float = math.inf,
    ) -> None:
        self.wf = wf
        self.step0 = step0  # first integrator step (s); inf: 0.05/w
        self.gn_slack = gn_slack  # lift-off only once Gn < -gn_slack (1/s^2)
        self.s = s
        self.mus = wf.mu * s
        self.theta0 = theta0
        self.dtheta0 = dtheta0
        self.E0 = E0
        self.w = w = wf.omega_ref(dtheta0)
        self.h_max = 0.5 / w
        self.scale = [RTOL * (1.0 + abs(theta0)), RTOL * w]
        """Per-step tolerances of theta and theta'; ``run`` adds the quadratures' (RTOL times
        the scale of their integrands, per second of step). Before the quadratures were
        controlled, steps near a steady rub (theta'' ~ 0) were accepted whose contact force,
        which turns with theta, was off by 2.5e-8 at 1 ms steps (found against the locked rub)."""
        self.force_tol = RTOL * wf.force_scale(dtheta0) * (1.0 + wf.mu)
        """RTOL times the scale of the contact force per m c_r (1/s^2)."""
        self.nu = 0.0
        """Rate (rad/s) of the integration by parts of the contact force; 0: plain (run)."""

    def rhs(self, u: float, y: list[float]) -> list[float]:
        """d/du of (theta, theta', I_n, J_x, J_y, I_e) at local time u (s).

        With nu = 0, J = I_c, the integral of the contact force F = -(gn + i ft) e^{i theta}.
        Otherwise J integrates D = F' - i nu F = -(1 + i mu s)(gn' + i (theta' - nu) gn)
        e^{i theta}, and I_c = (F(u) - F(0) - J)/(i nu) (``contact_impulse``). Near a steady
        whirl at the rate nu, D is small where F turns fast, so J needs far fewer
        extrapolation columns than I_c for the same accuracy.
        """
        wf = self.wf
        th, dth = y[0], y[1]
        euE = wf.eu * (self.E0 * cmath.exp(1j * wf.Omega * u))
        Q = wf.q0 + euE
        co, sn = math.cos(th), math.sin(th)  # P = Q e^{-i theta}, as real parts
        gn = (Q.real * co + Q.imag * sn) - wf.kappa + dth * dth
        ft = self.mus * gn
        ddth = (Q.imag * co - Q.real * sn) - wf.beta * dth - ft
        if self.nu == 0.0:
            jx, jy = ft * sn - gn * co, -(gn * sn) - ft * co
        else:
            V = wf.Omega * euE - dth * Q  # gn' = Re(i V e^{-i theta}) + 2 theta' theta''
            ar, ai = (V.real * sn - V.imag * co) + 2.0 * dth * ddth, (dth - self.nu) * gn
            br, bi = ar - self.mus * ai, ai + self.mus * ar
            jx, jy = bi * sn - br * co, -(br * sn) - bi * co
        return [dth, ddth, gn, jx, jy, ft * (wf.wr + dth)]

    def midpoint_sweep(self, u0: float, y0: list[float], f0: list[float], H: float,
                       n: int) -> list[float]:
        """gbs.midpoint(self.rhs, u0, y0, f0, H, n), fused: the same floating-point
        operations (bit-identical, checked by a test) on scalars instead of lists, which
        halves the cost of the sliding integrator. u0, H in s; y as in ``rhs``."""
        wf = self.wf
        q0, eu, E0, iW, W, kappa, beta, wr, mus, nu = (
            wf.q0, wf.eu, self.E0, 1j * wf.Omega, wf.Omega, wf.kappa, wf.beta, wf.wr,
            self.mus, self.nu,
        )
        exp, cos, sin = cmath.exp, math.cos, math.sin
        try:  # an overflowing trial step (cos(inf)) is rejected by its NaN error ratio
            h = H / n
            h2 = 2.0 * h
            m0, m1, m2, m3, m4, m5 = y0  # the previous midpoint iterate, then the current one
            c0, c1, c2 = m0 + h * f0[0], m1 + h * f0[1], m2 + h * f0[2]
            c3, c4, c5 = m3 + h * f0[3], m4 + h * f0[4], m5 + h * f0[5]
            for i in range(1, n + 1):
                euE = eu * (E0 * exp(iW * (u0 + i * h if i < n else u0 + H)))
                Q = q0 + euE
                Qr, Qi = Q.real, Q.imag
                co, sn = cos(c0), sin(c0)
                gn = (Qr * co + Qi * sn) - kappa + c1 * c1
                ft = mus * gn
                f1 = (Qi * co - Qr * sn) - beta * c1 - ft
                if nu == 0.0:
                    f3, f4 = ft * sn - gn * co, -(gn * sn) - ft * co
                else:
                    V = W * euE - c1 * Q
                    ar, ai = (V.real * sn - V.imag * co) + 2.0 * c1 * f1, (c1 - nu) * gn
                    br, bi = ar - mus * ai, ai + mus * ar
                    f3, f4 = bi * sn - br * co, -(br * sn) - bi * co
                f5 = ft * (wr + c1)
                if i == n:
                    break
                m0, c0 = c0, m0 + h2 * c1
                m1, c1 = c1, m1 + h2 * f1
                m2, c2 = c2, m2 + h2 * gn
                m3, c3 = c3, m3 + h2 * f3
                m4, c4 = c4, m4 + h2 * f4
                m5, c5 = c5, m5 + h2 * f5
            return [
                0.5 * (c0 + m0 + h * c1),
                0.5 * (c1 + m1 + h * f1),
                0.5 * (c2 + m2 + h * gn),
                0.5 * (c3 + m3 + h * f3),
                0.5 * (c4 + m4 + h * f4),
                0.5 * (c5 + m5 + h * f5),
            ]
        except (ValueError, OverflowError):
            return [math.nan] * 6

    def force(self, u: float, theta: float, dtheta: float) -> complex:
        """Contact force per m c_r (1/s^2, inertial) at local time u in state (theta, theta')."""
        gn, _ = self.wf.gn_gt(theta, dtheta, self.E0 * cmath.exp(1j * self.wf.Omega * u))
        return -complex(gn, self.mus * gn) * cmath.exp(1j * theta)

    def events(self, y: list[float], u: float) -> tuple[float, float]:
        """(Gn, s v_rel/c_r) at state y and local time u: contact ends when either is <= 0."""
        E = self.E0 * cmath.exp(1j * self.wf.Omega * u)
        gn, _ = self.wf.gn_gt(y[0], y[1], E)
        gn += self.gn_slack
        if self.wf.mu == 0.0:  # frictionless: the slip direction carries no physics
            return gn, 1.0
        return gn, self.s * (self.wf.wr + y[1])

    def run(self, rem: float, limit: int = WORK_MAX) -> SegmentEnd:
        """Integrate up to ``rem`` seconds or the first event; the end carries the next
        step size (``SegmentEnd.next_step``).

        Raises ContactWorkExceeded, saying where it stopped, before an integrator step
        once the segment has used more than ``limit`` work units (right-hand sides)."""
        y = [self.theta0, self.dtheta0, 0.0, 0.0, 0.0, 0.0]
        u = 0.0
        H0 = self.step0
        H = min(H0 if math.isfinite(H0) else 0.05 / self.w, self.h_max)
        self.nu = self.dtheta0 if abs(self.dtheta0) * rem >= NU_MIN else 0.0
        tol_j = self.force_tol * (abs(self.nu) if self.nu else 1.0)  # I_c's error = J's / nu
        rates = (self.force_tol, tol_j, tol_j, self.force_tol * (abs(self.wf.wr) + self.w))
        tally = ContactTally()
        tally.peak = max(0.0, self.events(y, 0.0)[0])
        n_steps = 0
        while u < rem:
            if tally.work > limit:
                raise ContactWorkExceeded(
                    f"sliding stopped at {u!r} s of its {rem!r} s segment after {n_steps} "
                    f"integrator steps (step size {H!r} s, theta = {y[0]!r} rad, "
                    f"theta' = {y[1]!r} rad/s)", tally.work)
            n_steps += 1
            step = min(H, rem - u)
            cut = step < H  # cut short by the segment's end: accept from any column
            f0 = self.rhs(u, y)
            scale = self._step_scale(rates, step, y)
            y_new, err, k, nfev = gbs.extrapolated_step(
                self.midpoint_sweep, u, y, f0, step, scale, k_min=2 if cut else K_MIN
            )
            tally.work += nfev + GBS_STEP_WORK
            if not err <= 1.0:  # also rejects NaN (an overflowing trial step)
                H = gbs.next_step_size(step, err, k) if err == err else 0.1 * step
                continue
            gn, sv = self.events(y_new, u + step)
            if gn <= 0.0 or sv <= 0.0:
                x, y_ev, kind = self._locate(u, y, f0, step, k, tally)
                self._tally(tally, y_ev, u + x)
                return SegmentEnd(u + x, y_ev[0], y_ev[1], kind, tally, H)
            tally.peak = max(tally.peak, gn)
            u_next = u + step if step < rem - u else rem
            u, y = u_next, y_new
            if not cut:  # a cut step says nothing about the step the motion allows
                H = min(gbs.next_step_size(step, err, k), self.h_max)
        self._tally(tally, y, rem)
        return SegmentEnd(rem, y[0], y[1], None, tally, H)

    def _step_scale(self, rates: tuple[float, ...], step: float, y: list[float]) -> list[float]:
        """Error scales of one step: theta and theta' as in __init__; each quadrature
        ``rates[i] * step`` plus RTOL of its accumulated value (without that relative part
        the rounding of a long segment's growing integrals outruns the tolerance), and at
        least SCALE_FLOOR."""
        j = RTOL * abs(complex(y[3], y[4])) + SCALE_FLOOR
        return [
            *self.scale,
            rates[0] * step + RTOL * abs(y[2]) + SCALE_FLOOR,
            rates[1] * step + j,
            rates[2] * step + j,
            rates[3] * step + RTOL * abs(y[5]) + SCALE_FLOOR,
        ]

    def _tally(self, tally: ContactTally, y: list[float], u: float) -> None:
        tally.I_n = y[2]
        tally.I_c = self.contact_impulse(y, u)
        tally.I_t = self.mus * y[2]
        tally.I_e = y[5]

    def contact_impulse(self, y: list[float], u: float) -> complex:
        """I_c (1/s, inertial): the integral of the contact force per m c_r over [0, u],
        from the integrated state y at local time u (``rhs``)."""
        J = complex(y[3], y[4])
        if self.nu == 0.0:
            return J
        F0 = self.force(0.0, self.theta0, self.dtheta0)
        return -1j * (self.force(u, y[0], y[1]) - F0 - J) / self.nu

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
                self.midpoint_sweep, u, y, f0, x, self.scale, k_fixed=max(k, 4)
            )
            tally.work += nfev + GBS_STEP_WORK
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

    def __init__(self, wf: WallForces, theta0: float, E0: complex,
                 cone_slack: float = 0.0) -> None:
        self.wf = wf
        self.cone_slack = cone_slack
        """(1/s^2) > 0 ignores cone violations smaller than it: used after a sliding attempt
        proved unable to leave zero slip (a violation below resolution)."""
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

    def run(self, rem: float, limit: int = WORK_MAX) -> SegmentEnd:
        """Roll up to ``rem`` seconds or until the first exit (lift-off or friction cone);
        its work is bounded by MAX_ROOT_ITERS per exit, whatever ``limit``."""
        cone_slack = self.cone_slack
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
        tal.I_c = -complex(1.0, mus) * cmath.exp(1j * (self.theta0 - x0)) * ring
        tal.I_e = mus * ((wf.wr + W) * tal.I_n + eq.Gn * int_y)
        tal.peak = eq.Gn + max(gx * x0 + gy * y0, gx * x1 + gy * y1)
        tal.work = 1
        return SegmentEnd(rem, self.theta0 + W * rem + dx, W + y1, None, tal)


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
        tal.I_c = -complex(1.0, mus) * cmath.exp(1j * (self.theta0 - x0)) * ring
        tal.I_e = mus * ((wf.wr + W) * tal.I_n + Gn * int_y + (gx * S2 + gy * S3).real)
        tal.peak = Gn + max(gx * x0 + gy * y0 + gxx * q0[0] + q0[2],
                            gx * x + gy * y + gxx * q[0] + q[2])
        tal.work = 1
        return SegmentEnd(rem, self.theta0 + W * rem + (x - x0), W + y, None, tal)


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
        tal.I_c = -complex(gn, ft) * cmath.exp(1j * theta) * phase_integral(wf.Omega, rem)
        tal.I_e = ft * (wf.wr + dtheta) * rem
        tal.peak = gn
        tal.work = 1
        return SegmentEnd(rem, theta + wf.Omega * rem, dtheta, None, tal)


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
