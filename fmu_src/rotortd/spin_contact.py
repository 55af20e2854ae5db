"""Sustained contact with the spin as a state (MODEL.md §6): sliding and rolling.

Frame and units: inertial, SI. On the circle z = c_r n, n = e^{i theta}; with
E = e^{i(psi + phi)}, beta = psi + phi - theta, B = e_c sin(beta), A = R - e_c cos(beta)
(``rigid``), the known forces F_o = F_amb + F_ext - i m g + m e_c Omega^2 E and the torque
T_o = e_c Im(conj(F_amb + F_ext) E) of the bearing and the external force about the mass
centre, the contact force -(N + i F_t) n obeys

    N - m B Omega'               = Re(conj(n) F_o) + m c_r theta'^2        (normal)
    m c_r theta'' + m e_c cos(beta) Omega' = Im(conj(n) F_o) - F_t         (tangential)
    J Omega' + B N + A F_t       = T_drive + T_o                           (spin)

- Sliding (slip s = sign v_rel, v_rel = R Omega + c_r theta'): F_t = mu s N; the 2x2 for
  (N, Omega') has the determinant J + m B (B + mu s A) = m J (W_nn + mu s W_nt) > 0 where
  the problem is well posed (``rigid.check_well_posed``). State (theta, theta', psi, Omega).
- Rolling (v_rel = 0): Omega = -c_r theta'/R; the 3x3 gives
  Omega' = (T_drive + T_o - B rhs_n - A F_ot)/I_P with I_P = J + m (A^2 + B^2), the inertia
  about the contact point. State (theta, psi, Omega).

Both are integrated by Gragg-Bulirsch-Stoer extrapolation (``gbs``) at RTOL = 1e-13 per
step on every component, the contact impulses (int N, int F_t, int F_c) and the friction
dissipation (int mu N |v_rel|) carried as error-controlled quadratures. The step is capped
at H_FRACTION of the fastest rotation (theta', Omega, beta'), so that an event function
(N, v_rel, mu N - |F_t|) that changes sign is seen at a step end; a sign change is located
by re-integrating the step with its column count fixed (regula falsi, to the resolution of
the time). Events: "lift_off" (N reaches 0), "slip_zero" (v_rel reaches 0 in sliding),
"slip_start" (|F_t| reaches mu N in rolling).
"""

from __future__ import annotations

import cmath
import math
from collections.abc import Callable
from dataclasses import dataclass

from . import gbs
from .params import RotorParams
from .wall import ContactWorkExceeded

RTOL = 1e-13
"""Relative tolerance per extrapolated step, every component."""
H_FRACTION = 0.25
"""Largest step, in radians of the fastest rotation of the contact (theta', Omega, beta')."""
STEP_WORK = 8
"""Work units per extrapolated step beyond its right-hand sides (as sliding.GBS_STEP_WORK)."""
ROOT_ITERS = 80
"""Most regula-falsi iterations of an event location."""

Vector = list[float]


@dataclass(frozen=True, slots=True)
class HeldInputs:
    """What a segment holds (SI): parameters, inertia J (kg m^2), amb_on a, the external
    force F_ext (N, at the geometric centre) and the drive torque T_drive (N m)."""

    p: RotorParams
    J: float
    a: float
    F_ext: complex
    T_drive: float


@dataclass(frozen=True, slots=True)
class ContactForces:
    """The contact's forces at one state (SI): N (N), F_t (N), theta'' (rad/s^2),
    Omega' (rad/s^2)."""

    N: float
    F_t: float
    ddtheta: float
    dOmega: float


@dataclass(frozen=True, slots=True)
class SpinSegmentEnd:
    """Where a contact segment stopped (SI): after ``duration`` s, the state, the event
    (None at the end of ``rem``), and its impulses: P_n = int N, P_t = int F_t (N s),
    P_c = int F_c (complex N s), E_diss (J), N_peak (N), work (units)."""

    duration: float
    theta: float
    dtheta: float
    psi: float
    Omega: float
    event: str | None
    P_n: float
    P_t: float
    P_c: complex
    E_diss: float
    N_peak: float
    work: int


def _known(h: HeldInputs, theta: float, dtheta: float, psi: float, Omega: float
           ) -> tuple[complex, float, float, float, float, float, float]:
    """(n, B, A, rhs_n, F_ot, T, cos beta) at a contact state: rhs_n = Re(conj(n) F_o)
    + m c_r theta'^2 (N), F_ot = Im(conj(n) F_o) (N), T = T_drive + T_o (N m)."""
    p = h.p
    n = cmath.exp(1j * theta)
    E = cmath.exp(1j * (psi + p.phi))
    z = p.c_r * n
    v = 1j * p.c_r * dtheta * n
    F = h.a * (p.bias_force - p.c * v - p.k * z) + h.F_ext
    T = h.T_drive + p.e_c * (F.real * E.imag - F.imag * E.real)
    Fo = (F - 1j * p.m * p.g + p.m * p.e_c * Omega * Omega * E) * n.conjugate()
    eb = E * n.conjugate()
    B = p.e_c * eb.imag
    A = p.R - p.e_c * eb.real
    return n, B, A, Fo.real + p.m * p.c_r * dtheta * dtheta, Fo.imag, T, eb.real


def sliding_forces(h: HeldInputs, s: float, theta: float, dtheta: float, psi: float,
                   Omega: float) -> tuple[ContactForces, complex]:
    """The forces of sliding with slip sign s at a state, and the normal n."""
    p = h.p
    n, B, A, rn, Fot, T, cb = _known(h, theta, dtheta, psi, Omega)
    k = B + p.mu * s * A
    dW = (T - k * rn) / (h.J + p.m * B * k)
    N = rn + p.m * B * dW
    Ft = p.mu * s * N
    dd = (Fot - Ft - p.m * p.e_c * cb * dW) / (p.m * p.c_r)
    return ContactForces(N, Ft, dd, dW), n


def rolling_forces(h: HeldInputs, theta: float, psi: float, Omega: float
                   ) -> tuple[ContactForces, complex]:
    """The forces of rolling (v_rel = 0, theta' = -R Omega/c_r) at a state, and n."""
    p = h.p
    dtheta = -p.R * Omega / p.c_r
    n, B, A, rn, Fot, T, _ = _known(h, theta, dtheta, psi, Omega)
    dW = (T - B * rn - A * Fot) / (h.J + p.m * (A * A + B * B))
    return ContactForces(rn + p.m * B * dW, Fot + p.m * A * dW, -p.R * dW / p.c_r, dW), n


class SpinContact:
    """One contact segment, sliding (s = +-1) or rolling (s = 0), from
    (theta, theta', psi, Omega); in rolling theta' = -R Omega/c_r is implied."""

    def __init__(self, h: HeldInputs, s: float, theta: float, dtheta: float, psi: float,
                 Omega: float, step0: float = math.inf) -> None:
        self.h, self.s = h, s
        p = h.p
        self.rolling = s == 0.0
        self.y0: Vector = ([theta, psi, Omega] if self.rolling
                           else [theta, dtheta, psi, Omega])
        self.nq = len(self.y0)
        f, _ = self._forces(self.y0)
        w = max(abs(dtheta), abs(Omega), abs(dtheta - Omega),
                math.sqrt(abs(f.N) / (p.m * p.c_r)), math.sqrt(p.k / p.m), 1.0)
        self.h_max = H_FRACTION / w
        self.step0 = min(step0, 0.1 * self.h_max)
        Fs = max(abs(f.N) * (1.0 + p.mu), p.m * p.c_r * w * w)
        Ws = max(abs(Omega), p.c_r * w / p.R)
        self.tol_state = ([RTOL * (1.0 + abs(theta)), RTOL * (1.0 + abs(psi)), RTOL * Ws]
                          if self.rolling else
                          [RTOL * (1.0 + abs(theta)), RTOL * w, RTOL * (1.0 + abs(psi)),
                           RTOL * Ws])
        self.tol_rate = [RTOL * Fs] * 4 + [RTOL * Fs * (p.R * Ws + p.c_r * w)]
        """Tolerance per second of step of the quadratures int N, int F_t, int F_c, E_diss."""

    def _forces(self, y: Vector) -> tuple[ContactForces, complex]:
        if self.rolling:
            return rolling_forces(self.h, y[0], y[1], y[2])
        return sliding_forces(self.h, self.s, y[0], y[1], y[2], y[3])

    def rhs(self, _u: float, y: Vector) -> Vector:
        """d/du of the state and of (int N, int F_t, Re int F_c, Im int F_c, E_diss)."""
        f, n = self._forces(y)
        Fc = -(f.N + 1j * f.F_t) * n
        if self.rolling:
            p = self.h.p
            return [-p.R * y[2] / p.c_r, y[2], f.dOmega, f.N, f.F_t, Fc.real, Fc.imag, 0.0]
        vrel = self.h.p.R * y[3] + self.h.p.c_r * y[1]
        return [y[1], f.ddtheta, y[3], f.dOmega, f.N, f.F_t, Fc.real, Fc.imag,
                abs(f.F_t * vrel)]

    def events(self, y: Vector) -> list[tuple[str, float]]:
        """The event functions at y, each positive while the segment lasts: N (lift-off),
        and in rolling mu N - |F_t| (slip start), in sliding s v_rel (slip zero)."""
        f, _ = self._forces(y)
        if self.rolling:
            return [("lift_off", f.N), ("slip_start", self.h.p.mu * f.N - abs(f.F_t))]
        vrel = self.h.p.R * y[3] + self.h.p.c_r * y[1]
        return [("lift_off", f.N), ("slip_zero", vrel * self.s)]

    def _margin(self, y: Vector) -> float:
        """The least event function (continuous; its first zero is the first event)."""
        return min(v for _, v in self.events(y))

    def _sweep(self) -> Callable[[float, Vector, Vector, float, int], Vector]:
        rhs = self.rhs
        return lambda u0, y0, f0, H, n: gbs.midpoint(rhs, u0, y0, f0, H, n)

    def run(self, rem: float, limit: int) -> SpinSegmentEnd:
        """Advance at most rem (s) and limit work units; stop at the first event."""
        y = self.y0 + [0.0] * 5
        u, H, work, N_peak = 0.0, self.step0, 0, abs(self._forces(self.y0)[0].N)
        sweep = self._sweep()
        event = None
        while u < rem:
            if work > limit:
                raise ContactWorkExceeded(
                    f"{'rolling' if self.rolling else 'sliding'} with the spin as a state: "
                    f"{work} work units in {u!r} s", work)
            Hs = min(H, self.h_max, rem - u)
            f0 = self.rhs(u, y)
            scale = self.tol_state + [t * Hs + RTOL * abs(q)
                                      for t, q in zip(self.tol_rate, y[self.nq:])]
            y1, err, k, nfev = gbs.extrapolated_step(sweep, u, y, f0, Hs, scale, k_min=4)
            work += nfev + STEP_WORK
            if not err <= 1.0:
                H = 0.25 * Hs if err != err else gbs.next_step_size(Hs, err, k)
                continue
            if self._margin(y1) <= 0.0:
                tau, y1, w2 = self._locate(sweep, u, y, f0, Hs, k, scale)
                work += w2
                u, y = u + tau, y1
                event = min(self.events(y), key=lambda e: e[1])[0]
                N_peak = max(N_peak, abs(self._forces(y)[0].N))
                break
            u = rem if Hs == rem - u else u + Hs
            y = y1
            N_peak = max(N_peak, abs(self._forces(y)[0].N))
            H = gbs.next_step_size(Hs, err, k)
        self.next_step = H
        return self._end(u, y, event, N_peak, work)

    def _locate(self, sweep: Callable[..., Vector], u: float, y: Vector, f0: Vector,
                Hs: float, k: int, scale: Vector) -> tuple[float, Vector, int]:
        """The first zero of the event function in (0, Hs] by regula falsi (Illinois) on
        the step re-integrated with k columns; returns (tau, state there, work)."""
        work = 0

        def at(tau: float) -> tuple[Vector, float]:
            nonlocal work
            yt, _, _, nfev = gbs.extrapolated_step(sweep, u, y, f0, tau, scale, k_fixed=k)
            work += nfev + STEP_WORK
            return yt, self._margin(yt)

        a, fa = 0.0, self._margin(y)
        b = Hs
        yb, fb = at(b)
        side = 0
        for _ in range(ROOT_ITERS):
            if b - a <= 4.0 * math.ulp(u + b) or fb == 0.0:
                break
            c = b - fb * (b - a) / (fb - fa) if fb != fa else 0.5 * (a + b)
            if not a < c < b:
                c = 0.5 * (a + b)
            yc, fc = at(c)
            if fc > 0.0:
                a, fa = c, fc
                if side == 1:
                    fb *= 0.5
                side = 1
            else:
                b, yb, fb = c, yc, fc
                if side == -1:
                    fa *= 0.5
                side = -1
        return b, yb, work

    def _end(self, u: float, y: Vector, event: str | None, N_peak: float,
             work: int) -> SpinSegmentEnd:
        p = self.h.p
        if self.rolling:
            theta, psi, Omega = y[0], y[1], y[2]
            dtheta = -p.R * Omega / p.c_r
        else:
            theta, dtheta, psi, Omega = y[0], y[1], y[2], y[3]
        q = y[self.nq:]
        return SpinSegmentEnd(u, theta, dtheta, psi, Omega, event, q[0], q[1],
                              complex(q[2], q[3]), q[4], N_peak, work)
