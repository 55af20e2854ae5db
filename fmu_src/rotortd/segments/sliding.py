"""Sliding on the clearance circle (v_rel != 0), integrated by extrapolation (gbs.py).

Frame and units as in ``rotortd.segments``: Ft = mu s Gn, s = sign(v_rel), at 1e-13 relative
tolerance, with the step's contact integrals carried as error-controlled quadratures (the
contact force by parts near a steady whirl, Sliding.rhs), and the integral of the
co-rotating position e^{i(theta - Omega u)} (for the imbalance torque) as an auxiliary
quadrature, error-controlled on its own without changing the others (gbs.extrapolated_step's
aux_scale).
"""

from __future__ import annotations

import cmath
import math

from ..contact.events import LIFT_OFF, SLIP_STUCK, SLIP_ZERO, Event
from ..contact.search import WORK_MAX
from ..contact.wall import ContactTally, ContactWorkExceeded, SegmentEnd, WallForces
from . import gbs
from .roots import ROOT_ITERS, illinois

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


class Sliding:
    """One sliding segment with slip sign ``slip`` from (theta0, dtheta0, E0)."""

    def __init__(
        self,
        wf: WallForces,
        theta0: float,
        dtheta0: float,
        E0: complex,
        slip: float,
        gn_slack: float = 0.0,
        step0: float = math.inf,
        aux: bool = True,
    ) -> None:
        self.wf = wf
        self.aux = aux  # refine the auxiliary quadrature Z (False: Z is not needed)
        self.step0 = step0  # first integrator step (s); inf: 0.05/w
        self.gn_slack = gn_slack  # lift-off only once Gn < -gn_slack (1/s^2)
        self.slip = slip  # the slip sign, sign(v_rel)
        self.mus = wf.mu * slip
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
        W2 = wf.Omega * wf.Omega
        self.aux_rate = max(RTOL, self.force_tol / W2) if W2 > 0.0 else 1.0
        """Error scale (1) per second of step of the auxiliary quadrature Z = int e^{i(theta -
        Omega u)} du, whose term in the imbalance torque is e_c m c_r Omega^2 Z: RTOL of the
        contact force's scale, as the other quadratures (force_tol/Omega^2), and at least
        RTOL of its integrand (modulus 1); loose at Omega = 0, where the term vanishes."""
        self.aux_evals = [0]
        """Right-hand sides spent on refining Z alone (gbs.extrapolated_step's aux_evals),
        counted into the segment's work like every other right-hand side."""

    def rhs(self, u: float, y: list[float]) -> list[float]:
        """d/du of (theta, theta', I_n, J_x, J_y, I_e, Z_x, Z_y) at local time u (s), with
        Z = int e^{i(theta - Omega u)} du (s), the auxiliary quadrature (ContactTally.I_z).

        With nu = 0, J = I_c, the integral of the contact force F = -(gn + i ft) e^{i theta}.
        Otherwise J integrates D = F' - i nu F = -(1 + i mu s)(gn' + i (theta' - nu) gn)
        e^{i theta}, and I_c = (F(u) - F(0) - J)/(i nu) (``contact_impulse``). Near a steady
        whirl at the rate nu, D is small where F turns fast, so J needs far fewer
        extrapolation columns than I_c for the same accuracy.
        """
        wf = self.wf
        th, dth = y[0], y[1]
        rot = cmath.exp(1j * wf.Omega * u)
        euE = wf.eu * (self.E0 * rot)
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
        zx, zy = co * rot.real + sn * rot.imag, sn * rot.real - co * rot.imag
        return [dth, ddth, gn, jx, jy, ft * (wf.wr + dth), zx, zy]

    def midpoint_sweep(self, u0: float, y0: list[float], f0: list[float], H: float,
                       n: int) -> list[float]:
        """gbs.midpoint(self.rhs, u0, y0, f0, H, n), fused: the same floating-point
        operations (bit-identical, checked by a test) on scalars instead of lists, which
        halves the cost of the sliding integrator. u0, H in s; y as in ``rhs``. Without
        ``aux`` the quadrature Z (y[6], y[7]) is not advanced (its right-hand side is not
        evaluated): the other components are the same to the last bit."""
        wf = self.wf
        q0, eu, E0, iW, W, kappa, beta, wr, mus, nu = (
            wf.q0, wf.eu, self.E0, 1j * wf.Omega, wf.Omega, wf.kappa, wf.beta, wf.wr,
            self.mus, self.nu,
        )
        exp, cos, sin = cmath.exp, math.cos, math.sin
        aux, f6, f7 = self.aux, 0.0, 0.0  # without aux, Z (y[6], y[7]) is left as it is
        try:  # an overflowing trial step (cos(inf)) is rejected by its NaN error ratio
            h = H / n
            h2 = 2.0 * h
            m0, m1, m2, m3, m4, m5, m6, m7 = y0  # the previous midpoint iterate, then the
            c0, c1, c2 = m0 + h * f0[0], m1 + h * f0[1], m2 + h * f0[2]  # current one
            c3, c4, c5 = m3 + h * f0[3], m4 + h * f0[4], m5 + h * f0[5]
            c6, c7 = m6 + h * f0[6], m7 + h * f0[7]
            for i in range(1, n + 1):
                rot = exp(iW * (u0 + i * h if i < n else u0 + H))
                euE = eu * (E0 * rot)
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
                if aux:
                    rr, ri = rot.real, rot.imag
                    f6, f7 = co * rr + sn * ri, sn * rr - co * ri
                if i == n:
                    break
                m0, c0 = c0, m0 + h2 * c1
                m1, c1 = c1, m1 + h2 * f1
                m2, c2 = c2, m2 + h2 * gn
                m3, c3 = c3, m3 + h2 * f3
                m4, c4 = c4, m4 + h2 * f4
                m5, c5 = c5, m5 + h2 * f5
                if aux:
                    m6, c6 = c6, m6 + h2 * f6
                    m7, c7 = c7, m7 + h2 * f7
            return [
                0.5 * (c0 + m0 + h * c1),
                0.5 * (c1 + m1 + h * f1),
                0.5 * (c2 + m2 + h * gn),
                0.5 * (c3 + m3 + h * f3),
                0.5 * (c4 + m4 + h * f4),
                0.5 * (c5 + m5 + h * f5),
                0.5 * (c6 + m6 + h * f6),
                0.5 * (c7 + m7 + h * f7),
            ]
        except (ValueError, OverflowError):
            return [math.nan] * 8

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
        return gn, self.slip * (self.wf.wr + y[1])

    def run(self, rem: float, limit: int = WORK_MAX) -> SegmentEnd:
        """Integrate up to ``rem`` seconds or the first event; the end carries the next
        step size (``SegmentEnd.next_step``).

        Raises ContactWorkExceeded, saying where it stopped, before an integrator step
        once the segment has used more than ``limit`` work units (right-hand sides)."""
        y = [self.theta0, self.dtheta0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
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
            aux0 = self.aux_evals[0]
            y_new, err, k, nfev = gbs.extrapolated_step(
                self.midpoint_sweep, u, y, f0, step, scale, k_min=2 if cut else K_MIN,
                aux_scale=self._aux_scale(step, y), aux_evals=self.aux_evals,
            )
            tally.work += gbs.RHS_WORK * (nfev + self.aux_evals[0] - aux0) + gbs.STEP_WORK
            if not err <= 1.0:  # also rejects NaN (an overflowing trial step)
                H = gbs.next_step_size(step, err, k) if err == err else 0.1 * step
                continue
            gn, sv = self.events(y_new, u + step)
            if gn <= 0.0 or sv <= 0.0:
                x, y_ev, kind = self._locate(u, y, f0, step, k, tally)
                self._store_integrals(tally, y_ev, u + x)
                return SegmentEnd(u + x, y_ev[0], y_ev[1], kind, tally, H, work=tally.work)
            tally.peak = max(tally.peak, gn)
            u_next = u + step if step < rem - u else rem
            u, y = u_next, y_new
            if not cut:  # a cut step says nothing about the step the motion allows
                H = min(gbs.next_step_size(step, err, k), self.h_max)
        self._store_integrals(tally, y, rem)
        return SegmentEnd(rem, y[0], y[1], None, tally, H, work=tally.work)

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

    def _aux_scale(self, step: float, y: list[float]) -> tuple[float, ...]:
        """Error scales (s) of the auxiliary quadrature Z = int e^{i(theta - Omega u)} du of
        one step: aux_rate times the step plus RTOL of its accumulated value, at least
        SCALE_FLOOR; none (Z is neither controlled nor refined) when ``aux`` is False."""
        if not self.aux:
            return ()
        z = self.aux_rate * step + RTOL * abs(complex(y[6], y[7])) + SCALE_FLOOR
        return z, z

    def _store_integrals(self, tally: ContactTally, y: list[float], u: float) -> None:
        tally.I_n = y[2]
        tally.I_c = self.contact_impulse(y, u)
        tally.I_t = self.mus * y[2]
        tally.I_e = y[5]
        tally.I_z = complex(y[6], y[7])

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

        seen: dict[float, float] = {}  # the normalised event function at each point

        def at(x: float) -> tuple[list[float], float]:
            aux0 = self.aux_evals[0]
            yx, _, _, nfev = gbs.extrapolated_step(
                self.midpoint_sweep, u, y, f0, x, self.scale, k_fixed=max(k, 4),
                aux_scale=self._aux_scale(x, y), aux_evals=self.aux_evals,
            )
            tally.work += gbs.RHS_WORK * (nfev + self.aux_evals[0] - aux0) + gbs.STEP_WORK
            gn, sv = self.events(yx, u + x)
            seen[x] = f = min(gn / s_n, sv / s_v)
            return yx, f

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
                stuck = kind is SLIP_ZERO and abs(sv0) <= noise * s_v
                return H * 2.0**-40, y_x, SLIP_STUCK if stuck else kind
        # Stop on the event surface: at a point within the rounding band of the event
        # functions, or where the bracket is one or two ulp of the time.
        _, hi, y_best = illinois(
            lambda x: at(x)[::-1], lo, flo, H, fhi, y_hi,
            lambda lo, hi, _: seen[hi] >= -noise or hi - lo <= 2e-16 * (abs(u) + hi) + 1e-300,
            ROOT_ITERS, noise)
        return hi, y_best, self._kind(y_best, u + hi, s_n, s_v)

    def _kind(self, y: list[float], u: float, s_n: float, s_v: float) -> Event:
        gn, sv = self.events(y, u)
        return LIFT_OFF if gn / s_n <= sv / s_v else SLIP_ZERO
