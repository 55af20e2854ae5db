"""Rolling on the clearance circle (v_rel = 0): closed form.

theta' = -wr is constant and Ft = Gt (static friction); theta, Gn and Gt are sums of two
rotating phasors, so the motion, its exits (lift-off, friction cone) and its integrals are
closed form (frame and units as in ``rotortd.segments``).
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass

from ..contact.events import LIFT_OFF, SLIP_START
from ..contact.search import WORK_MAX
from ..contact.wall import ContactTally, SegmentEnd, WallForces, phase_integral
from ..scaled import wrap_angle

MAX_ROOT_ITERS = 200
"""Most conservative-advancement iterations of one exit function in one rolling segment.
An advance is at most about 2/nu of the fastest phasor's rate nu (a few per whirl turn), so
200 cover some 30 whirl turns; a segment whose search has not reached the end of its span
by then ends there, without event, and the step loop starts the next one (a long step of
steady rolling is taken in segments, each checked against the step's work bound)."""


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

    def first_zero(self, x_max: float, tally: ContactTally) -> tuple[float | None, float]:
        """(u, x_max'): the first u in (0, x_max] where f reaches 0 (f(0) > 0 assumed), or
        None if there is none in (0, x_max'], x_max' <= x_max the span searched: x_max, or
        less when MAX_ROOT_ITERS advances ran out before it (f > 0 proved on [0, x_max']).

        Conservative advancement with f(u + x) >= f + f' x - M x^2/2,
        M = |a1| nu1^2 + |a2| nu2^2 >= |f''|.
        """
        if self.never_zero():
            return None, x_max
        M = abs(self.a1) * self.nu1**2 + abs(self.a2) * self.nu2**2
        tol = 1e-15 * (abs(self.C) + abs(self.a1) + abs(self.a2))
        u = 0.0
        f0, df0 = self.value(0.0)
        if f0 <= tol and df0 > 0.0 and M > 0.0:  # on the boundary, moving inside: step off
            u = min(df0 / M, x_max)
            if self.value(u)[0] <= tol:
                return 0.0, x_max
        for _ in range(MAX_ROOT_ITERS):
            tally.work += 1
            f, df = self.value(u)
            if f <= tol:
                return u, x_max
            if M == 0.0:
                x = -f / df if df < 0.0 else math.inf
            else:
                x = (df + math.sqrt(df * df + 2.0 * M * f)) / M
            if u + x >= x_max:
                return None, x_max
            u += x
        return None, u  # f > 0 on [0, u]: the segment may last that long


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
        """Roll up to ``rem`` seconds or until the first exit (lift-off or friction cone),
        or less, without event, as far as MAX_ROOT_ITERS advances per exit function proved
        none (the step loop goes on with the next segment); its work is bounded by that,
        whatever ``limit``."""
        cone_slack = self.cone_slack
        tally = ContactTally()
        names = (LIFT_OFF, SLIP_START, SLIP_START)
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
            x, searched = fn.first_zero(x_end, tally)
            if x is not None and x < x_end:
                x_end, kind = x, name
            elif searched < x_end:  # no exit up to where the search got: end there
                x_end, kind = searched, None
        self._integrate(tally, x_end)
        theta = wrap_angle(self.theta0 + self.dtheta * x_end)
        return SegmentEnd(x_end, theta, self.dtheta, kind, tally, work=tally.work)

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
        tally.I_z = e0 * phase_integral(self.dtheta - wf.Omega, x)  # theta = theta0 + dtheta u
        samples = (self.gn_gt(x * j / 8.0)[0] for j in range(9))
        tally.peak = max(0.0, *samples)
        tally.work += 1
