"""Dry whirl with the spin as a state, by its energy integral: rolling on the fixed rigid race
at a cost that does not grow with the speed (docs/notes/dry-whirl-quadrature.md).

Frame and units: inertial, SI, as ``spin_contact``. The contact point is z = c_r n,
n = e^{i theta}; E = e^{i(psi + phi)}, beta = psi + phi - theta, rho = R/c_r. Rolling
(v_rel = 0) on the fixed race has c_r theta' = -R Omega, so with sigma = sign(Omega) and
u >= 0 the unsigned spin angle travelled (rad),

    psi = psi0 + sigma u,   theta = theta0 - rho sigma u,   beta = beta0 + (1 + rho) sigma u.

With the bearing's damper off (a c = 0) and gravity, F_ext and T_drive held, the contact
force does no work and the spring force -a k z none on the circle, so

    1/2 I_P(beta) Omega^2 + V(theta, psi) = const,   I_P = J + m (R^2 + e_c^2 - 2 R e_c cos beta),
    V = -c_r Re(conj(G) n) + m g e_c sin(psi + phi) - T_drive psi,   G = a F_bias + F_ext - i m g,

and the time is the quadrature dt = du / |Omega| = F(beta(u), psi(u)) du with
F = sqrt(I_P / (K0 - 2 (V - V0))) (s/rad), K0 = I_P(beta0) Omega0^2, a smooth function on
the torus (beta, psi) for psi in the panel (theta = psi + phi - beta).

Two ways to evaluate t(u) = int_0^u F du on a panel u in [0, L] (L <= L_MAX rad of psi):

- direct (the contact angle turns by at most BETA_DIRECT rad over the panel): Chebyshev
  interpolation of F along the path at P_DIRECT nodes (fewer where theta turns less than
  1.5 rad, P_DIRECT_FEW), integrated exactly;
- Fourier-Levin (any speed): F(beta, psi) = sum_j R_j(psi) e^{i j beta}, the R_j from an
  N_GRID-point DFT in beta at P_CHEB Chebyshev nodes in u (in beta, I_P adds no dependence
  on psi: the R_j vary only with the potential, by eps = 2 c_r |G|/K per radian, which
  vanishes at speed); on the path e^{i j beta(u)} = e^{i j beta0} e^{i j (1 + rho) sigma u},
  and int R_j(u) e^{i w u} du = [y_j(u) e^{i w u}] with y_j the polynomial solution of
  y' + i w y = R_j (backward recurrence on its monomial coefficients, stable when
  |j| (1 + rho) L/2 > P_CHEB). So t(u) = mean part (j = 0, a polynomial) + the periodic
  remainder at the two ends: a fixed amount of work, whatever the number of turns of beta
  in the panel.

The step end is the root of t(u) = rem (Newton with t'(u) = F on the path); the end state
follows from the energy integral. The impulses int N, int F_t and int F_c of the segment are
the same quadrature of (N + i F_t) F, and the momentum balance for int F_c.

Events: none is allowed in a panel. A panel is taken only when bounds over every (beta,
psi) of the panel and every Omega^2 the energy allows there prove N > 0 and |F_t| < mu N
(``_no_event``); otherwise ``advance`` returns None and the extrapolation integrator of
``spin_contact`` (which locates the event) takes the segment. At speed N is dominated by
the centripetal term m c_r rho^2 Omega^2, so the bound holds at any speed when
mu > e_c/(c_r rho^2) + m e_c (R + e_c)/I_min (docs/notes/dry-whirl-quadrature.md §4).

Errors (estimated, not enclosed): the truncated harmonics and the Chebyshev tails are
required below TOL_PHASE (1 + the turn of theta over the panel) rad of theta (converted to
time by 1/(rho |Omega|)), those of the impulses below TOL_IMPULSE of their mean; otherwise
``advance`` declines (None).
"""

from __future__ import annotations

import cmath
import math
from operator import mul
from typing import TYPE_CHECKING, Any

from ..contact.wall import ContactTally, SegmentEnd

if TYPE_CHECKING:
    from .spin_contact import HeldInputs

P_CHEB = 8
"""Chebyshev nodes in u of the Fourier-Levin panel."""
MOD_FINE = 1e-4
"""Above this relative variation of the potential over the panel,
(2 c_r |G| + 2 m g e_c + |T_drive| L_MAX)/K0, P_CHEB_FINE nodes at once (P_CHEB would not
meet the tolerance: at 60 rad/s it is 2e-3 for the chapter's rotor)."""
P_CHEB_FINE = 12
"""The same when P_CHEB nodes do not meet TOL_PHASE (at low speed the potential modulates
the harmonics in psi by eps = 2 c_r |G|/K, 3e-3 at 60 rad/s for the chapter's rotor)."""
N_GRID = 13
"""Points of the DFT in beta (odd: harmonic +-(K_MAX + 1) is not the Nyquist one)."""
K_MAX = 5
"""Harmonics in beta kept (|j| <= K_MAX); +-(K_MAX + 1) are computed as the check."""
P_DIRECT = 20
"""Chebyshev nodes along the path in the direct mode."""
P_DIRECT_FEW = ((0.5, 10), (1.5, 14))
"""Fewer nodes first where theta turns little over the panel (up to 0.5 rad: 10 nodes, then
14; up to 1.5 rad: 14), their Chebyshev tails checked as P_DIRECT's; P_DIRECT where they do
not meet the tolerance (16 nodes do not at 3.4 rad: measured, not kept). A strong drive
torque can take the 10 nodes past the tolerance at 0.5 rad (100 N m at 60 rad/s on the
chapter's rotor: one step in three), the 14 then meet it."""
BETA_DIRECT = 4.0
"""Largest turn of the contact angle theta (rad) over a panel of the direct mode."""
L_MAX = 1.0
"""Largest panel, rad of psi."""
TOL_PHASE = 1e-14
"""Largest estimated truncation error of a panel in theta, relative to 1 + the turn of theta
over the panel (rad); rounding alone is a few eps of that turn."""
TOL_IMPULSE = 1e-14
"""Largest estimated truncation error of the impulses, relative to their mean rate times the
panel."""
MARGIN = 1e-9
"""Relative margin of the event bounds (their rounding is a few eps)."""
NEWTON_ITERS = 12
"""Most Newton iterations of the step end (it converges in 3 to 5)."""
SAMPLE_WORK = 2
"""Work units per sample of the integrand (as gbs.RHS_WORK per right-hand side)."""


def _cheb_tables(p: int) -> tuple[list[float], list[list[float]], list[list[float]]]:
    """Chebyshev points of the first kind x_i, the map from values to Chebyshev coefficients
    (row m: a_m = sum_i CH[m][i] v_i) and the monomial coefficients of T_m (row j: x^j)."""
    xs = [math.cos(math.pi * (i + 0.5) / p) for i in range(p)]
    ch = [[(1.0 if m else 0.5) * 2.0 / p * math.cos(m * math.pi * (i + 0.5) / p)
           for i in range(p)] for m in range(p)]
    t = [[0.0] * p for _ in range(p)]  # t[m][j]: coefficient of x^j in T_m
    t[0][0] = 1.0
    if p > 1:
        t[1][1] = 1.0
    for m in range(2, p):
        for j in range(p):
            t[m][j] = (2.0 * t[m - 1][j - 1] if j else 0.0) - t[m - 2][j]
    tm = [[t[m][j] for m in range(p)] for j in range(p)]  # row j over m
    return xs, ch, tm


_CHEB = {p: _cheb_tables(p) for p in (P_CHEB, P_CHEB_FINE)}
_MX = {p: [[sum(map(mul, row_j, col)) for col in zip(*ch)] for row_j in tm]
       for p, (_, ch, tm) in _CHEB.items()}
"""Values at the nodes -> monomial coefficients in one product (row j: x^j)."""
_DIRECT = {p: _cheb_tables(p)[:2] for p in (P_DIRECT, *(q for _, q in P_DIRECT_FEW))}
"""The direct panel's nodes and map from values to Chebyshev coefficients, by node count."""
_BG = [2.0 * math.pi * j / N_GRID for j in range(N_GRID)]
_CB = [math.cos(a) for a in _BG]
_SB = [math.sin(a) for a in _BG]
_EM = [[cmath.exp(-1j * k * a) / N_GRID for a in _BG] for k in range(-K_MAX - 1, K_MAX + 2)]
"""_EM[k + K_MAX + 1][l] = e^{-i k beta_l}/N: the DFT rows, k = -K_MAX-1 .. K_MAX+1."""


def _row(k: int) -> list[complex]:
    return _EM[k + K_MAX + 1]


def applies(h: HeldInputs) -> bool:
    """The method's physics holds: the bearing's damper does no work (a c = 0)."""
    return h.a * h.p.c == 0.0


class DryWhirl:
    """Rolling from (theta, psi, Omega) under the held inputs ``h`` (a c = 0), advanced by the
    energy integral (module docstring). ``advance`` returns the segment's end, or None when
    the method does not apply to this panel (then the integrator must take it)."""

    def __init__(self, h: HeldInputs, theta: float, psi: float, Omega: float) -> None:
        p = h.p
        self.h = h
        self.m, self.c_r, self.R, self.e_c, self.phi, self.mu = (p.m, p.c_r, p.R, p.e_c,
                                                                 p.phi, p.mu)
        self.J, self.T = h.J, h.T_drive
        F1 = h.a * p.bias_force + h.F_ext  # constant force at the geometric centre (N)
        self.F1x, self.F1y = F1.real, F1.imag
        self.Gx, self.Gy = F1.real, F1.imag - p.m * p.g  # with gravity (G, N)
        self.mge = p.m * p.g * p.e_c
        self.akcr = h.a * p.k * p.c_r
        self.rho = p.R / p.c_r
        self.cen = p.m * p.c_r * self.rho * self.rho  # m c_r rho^2: N = cen Omega^2 + ... (kg m)
        self.sig = 1.0 if Omega >= 0.0 else -1.0
        self.theta0, self.psi0, self.Omega0 = theta, psi, Omega
        self.I0 = self.J + p.m * (p.R * p.R + p.e_c * p.e_c)
        self.c2 = 2.0 * p.m * p.R * p.e_c  # I_P = I0 - c2 cos(beta)
        cb0 = math.cos(psi + p.phi - theta)
        self.K0 = (self.I0 - self.c2 * cb0) * Omega * Omega  # I_P(beta0) Omega0^2 (J)
        self.ct0, self.st0 = math.cos(theta), math.sin(theta)
        self.cE0, self.sE0 = math.cos(psi + p.phi), math.sin(psi + p.phi)
        self.v0 = self.c_r * (self.Gx * self.ct0 + self.Gy * self.st0)  # -(theta part of V0)

    # ------------------------------------------------------------------ the physics

    def _dv_psi(self, u: float) -> tuple[float, float, float]:
        """(the psi part of V - V0 plus the theta part of -V0 (J), cos, sin of psi + phi)."""
        a = self.psi0 + self.sig * u + self.phi
        cE, sE = math.cos(a), math.sin(a)
        return self.v0 + self.mge * (sE - self.sE0) - self.T * self.sig * u, cE, sE

    def _forces(self, ct: float, st: float, cE: float, sE: float, dv: float
                ) -> tuple[float, float, float, float]:
        """(F = 1/|Omega| (s/rad), N (N), F_t (N), Omega^2) at n = ct + i st,
        E = cE + i sE with V - V0 = dv (J), Omega^2 from the energy integral. The forces as
        ``spin_contact.ContactModel.rolling`` with a c = 0."""
        m, e_c = self.m, self.e_c
        cb, sb = cE * ct + sE * st, sE * ct - cE * st
        IP = self.I0 - self.c2 * cb
        g_r = self.Gx * ct + self.Gy * st
        om2 = (self.K0 - 2.0 * (dv - self.c_r * g_r)) / IP
        U = m * e_c * om2
        rn = g_r - self.akcr + U * cb + self.cen * om2
        Fot = self.Gy * ct - self.Gx * st + U * sb
        T = self.T + e_c * (self.F1x * sE - self.F1y * cE) - self.akcr * e_c * sb
        B, A = e_c * sb, self.R - e_c * cb
        dW = (T - B * rn - A * Fot) / IP
        return 1.0 / math.sqrt(om2), rn + m * B * dW, Fot + m * A * dW, om2

    def beta_grid(self, cbs: list[float], sbs: list[float]) -> tuple[list[float], ...]:
        """(cos beta, sin beta, I_P, B = e_c sin beta, A = R - e_c cos beta) on a grid of
        beta, for ``beta_row``."""
        e_c = self.e_c
        return (cbs, sbs, [self.I0 - self.c2 * c for c in cbs], [e_c * s for s in sbs],
                [self.R - e_c * c for c in cbs])

    def beta_row(self, grid: tuple[list[float], ...], cE: float, sE: float, base: float
                 ) -> tuple[list[float], list[complex], list[float]]:
        """F (s/rad), D = (N + i F_t) F (N s/rad) and |N| (N) on the ``beta_grid`` at one
        psi (E = cE + i sE) where 2 (E - V) = base + 2 c_r Re(conj(n) G): the forces of
        ``_forces`` written for a grid (the Fourier-Levin panel's and the orbit's samples;
        tests/test_dry_whirl_orbit.py checks them against ``_forces``)."""
        m, e_c, c_r, akcr, Gx, Gy = self.m, self.e_c, self.c_r, self.akcr, self.Gx, self.Gy
        cen = self.cen
        T = self.T + e_c * (self.F1x * sE - self.F1y * cE)
        fs, ds, ns = [], [], []
        for cb, sb, IP, B, A in zip(*grid):
            ct, st = cE * cb + sE * sb, sE * cb - cE * sb  # theta = psi + phi - beta
            g_r, g_i = Gx * ct + Gy * st, Gy * ct - Gx * st  # conj(n) G
            om2 = (base + 2.0 * c_r * g_r) / IP
            F = 1.0 / math.sqrt(om2)
            U = m * e_c * om2
            rn = g_r - akcr + U * cb + cen * om2
            Fot = g_i + U * sb
            dW = (T - akcr * B - B * rn - A * Fot) / IP
            N = rn + m * B * dW
            fs.append(F)
            ns.append(abs(N))
            ds.append(complex(N * F, (Fot + m * A * dW) * F))
        return fs, ds, ns

    def _speed(self, u: float) -> float:
        """|Omega| (rad/s) on the path at u, from the energy integral."""
        th = self.theta0 - self.rho * self.sig * u
        dv, cE, sE = self._dv_psi(u)
        ct, st = math.cos(th), math.sin(th)
        IP = self.I0 - self.c2 * (cE * ct + sE * st)
        return math.sqrt((self.K0 - 2.0 * (dv - self.c_r * (self.Gx * ct + self.Gy * st))) / IP)

    def _path(self, u: float) -> tuple[float, float, float, float, float]:
        """(F, N, F_t, Omega^2, theta) on the path at u (at u = 0 from the start's cosines and
        sines, the same values)."""
        if u == 0.0:
            return (*self._forces(self.ct0, self.st0, self.cE0, self.sE0, self.v0), self.theta0)
        th = self.theta0 - self.rho * self.sig * u
        dv, cE, sE = self._dv_psi(u)
        return (*self._forces(math.cos(th), math.sin(th), cE, sE, dv), th)

    # ------------------------------------------------------------------ bounds

    def _omega2_bounds(self, L: float) -> tuple[float, float]:
        """Bounds of Omega^2 over every (theta, psi) of the panel [0, L] (rad^2/s^2)."""
        Gm = math.hypot(self.Gx, self.Gy)
        Vb = (self.c_r * Gm * min(2.0, self.rho * L) + self.mge * min(2.0, L)
              + abs(self.T) * L)
        m, R, e_c = self.m, self.R, self.e_c
        Ilo, Ihi = self.J + m * (R - e_c) ** 2, self.J + m * (R + e_c) ** 2
        return (self.K0 - 2.0 * Vb) / Ihi, (self.K0 + 2.0 * Vb) / Ilo

    def _no_event(self, lo: float, hi: float) -> bool:
        """N > 0 and |F_t| < mu N at every (theta, psi) of the panel and every Omega^2 in
        [lo, hi] (docs/notes/dry-whirl-quadrature.md §4)."""
        m, R, e_c = self.m, self.R, self.e_c
        Gm = math.hypot(self.Gx, self.Gy)
        U = m * e_c * hi
        cen = self.cen
        rn_lo = cen * lo - Gm - self.akcr - U
        rn_hi = cen * hi + Gm + U
        Fo = Gm + U
        T = abs(self.T) + e_c * math.hypot(self.F1x, self.F1y) + self.akcr * e_c
        Ilo = self.J + m * (R - e_c) ** 2
        dW = (T + e_c * rn_hi + (R + e_c) * Fo) / Ilo
        N_lo = (rn_lo - m * e_c * dW) * (1.0 - MARGIN)
        Ft_hi = (Fo + m * (R + e_c) * dW) * (1.0 + MARGIN)
        return N_lo > 0.0 and Ft_hi < self.mu * N_lo

    # ------------------------------------------------------------------ the step

    def advance(self, rem: float, limit: int, step0: float = math.inf,
                levin: bool | None = None) -> SegmentEnd | None:
        """Advance at most rem (s): the end of the panel or of rem, whichever comes first
        (no event can occur in a panel taken). None when the method does not apply (energy
        too close to a turning point, an event not excluded, the truncation estimate above
        TOL_PHASE, or a work limit below the panel's cost). ``levin`` forces the mode (None:
        direct when the panel's theta turn is at most BETA_DIRECT, else Fourier-Levin)."""
        if not (rem > 0.0 and self.K0 > 0.0 and math.isfinite(self.K0)):
            return None
        L = self.panel_length(rem)
        if L is None:
            return None
        direct = self.rho * L <= BETA_DIRECT if levin is None else not levin
        if not direct and max(L, 2.0 * (P_CHEB + 1) / (1.0 + self.rho)) > L_MAX:
            return None
        most = P_DIRECT if direct else (P_CHEB + P_CHEB_FINE) * (N_GRID + 1)
        if SAMPLE_WORK * (most + 2 * NEWTON_ITERS) > limit:
            return None
        self.samples = 0
        panel = self._panel(L, direct)
        if panel is None:
            return None
        L = panel.L
        work = SAMPLE_WORK * (self.samples + 2 * NEWTON_ITERS)
        if panel.t(L) <= rem:
            u, dur = L, panel.t(L)
        else:
            u, dur = self._newton(panel, rem, L), rem
        return self._end(panel, u, dur, work, step0)

    def panel_length(self, rem: float) -> float | None:
        """The panel's length (rad of psi) for rem (s): enough to reach rem at the largest
        speed the energy allows over L_MAX, at most L_MAX; None where that speed bound is
        not usable (Omega^2 may fall below half its start's over L_MAX). Its turn of theta,
        rho L, selects the direct panel (at most BETA_DIRECT)."""
        lo, hi = self._omega2_bounds(L_MAX)
        if not lo > 0.5 * self.Omega0 * self.Omega0:
            return None
        return min(L_MAX, rem * math.sqrt(hi) * (1.0 + 1e-9))

    def _panel(self, L: float, direct: bool) -> _DirectPanel | _LevinPanel | None:
        """The panel of at least L (rad of psi) whose events are excluded and whose error
        estimate meets TOL_PHASE: direct, or Fourier-Levin with P_CHEB nodes, then
        P_CHEB_FINE (the Levin panel is at least 2 (p + 1)/(1 + rho) long, so that its
        recurrence does not amplify); None if there is none."""
        mod = (2.0 * self.c_r * math.hypot(self.Gx, self.Gy) + 2.0 * self.mge
               + abs(self.T) * L_MAX) / self.K0
        ps = (P_CHEB_FINE,) if mod > MOD_FINE else (P_CHEB, P_CHEB_FINE)
        if direct:
            turn = self.rho * L
            ps = (*[q for top, q in P_DIRECT_FEW if turn <= top], P_DIRECT)
        for p in ps:
            Lp = L if direct else max(L, 2.0 * (p + 1) / (1.0 + self.rho))
            if Lp > L_MAX:
                return None
            lo, hi = self._omega2_bounds(Lp)
            if not self._no_event(lo, hi):
                return None
            panel = _DirectPanel(self, Lp, p) if direct else _LevinPanel(self, Lp, p)
            self.samples += p if direct else p * (N_GRID + 1)
            if panel.error_estimate() <= TOL_PHASE * (1.0 + self.rho * Lp) / (
                    self.rho * math.sqrt(lo)):
                return panel
        return None

    def _newton(self, panel: _DirectPanel | _LevinPanel, rem: float, L: float) -> float:
        """The root u in [0, L] of t(u) = rem (t increasing, t' = F on the path)."""
        u = min(L, rem * abs(self.Omega0))
        for _ in range(NEWTON_ITERS):
            du = (panel.t(u) - rem) * self._speed(u)
            u = min(L, max(0.0, u - du))
            if abs(du) <= 2.0 * math.ulp(u):
                break
        return u

    def contact_impulse(self, u: float, dur: float, int_n: complex,
                        paths: tuple[tuple[float, ...], tuple[float, ...]] | None = None
                        ) -> complex:
        """int F_c dt (N s) over [0, u] lasting dur (s), from the momentum balance
        m dz_G' = (F1 - i m g - a k z + F_c) dt (a c = 0), z_G' = i Omega (e_c E - R n);
        int_n = int n dt (s), needed only when a k != 0; ``paths``: ``_path`` at 0 and u,
        where the caller has them."""
        p0, pu = paths if paths is not None else (self._path(0.0), self._path(u))
        G = complex(self.Gx, self.Gy)
        return self.m * (self._zg_dot(u, pu) - self._zg_dot(0.0, p0)) - G * dur + self.akcr * int_n

    def _zg_dot(self, u: float, path: tuple[float, ...]) -> complex:
        """The mass centre's velocity z_G' (m/s) at u from ``_path(u)``."""
        om2, th = path[3], path[4]
        E = cmath.rect(1.0, self.psi0 + self.sig * u + self.phi)  # (cmath.exp(i x)'s values)
        return 1j * self.sig * math.sqrt(om2) * (self.e_c * E - self.R * cmath.rect(1.0, th))

    def _end(self, panel: _DirectPanel | _LevinPanel, u: float, dur: float, work: int,
             step0: float) -> SegmentEnd:
        _, N, _, om2, th = self._path(u)
        Om = self.sig * math.sqrt(om2)
        P, Pc = panel.impulses(u, dur)
        mc = self.m * self.c_r  # the tally is per unit m c_r (wall.ContactTally)
        peak = max([abs(N)] + [n for uu, n in zip(panel.us, panel.Ns) if uu <= u])
        tally = ContactTally(I_n=P.real / mc, I_c=Pc / mc, I_t=P.imag / mc, I_e=0.0,
                             peak=peak / mc, work=work)
        return SegmentEnd(dur, th, -self.rho * Om, None, tally, step0,
                          psi=self.psi0 + self.sig * u, Omega=Om, work=work)


def _cheb_int(a: list[Any]) -> list[Any]:
    """Chebyshev coefficients of int_{-1}^{x} sum_m a_m T_m(xi) d xi (a_0 not halved)."""
    p = len(a)
    a = [*a, 0.0, 0.0]
    b = [0.0 * a[0]] * (p + 1)
    b[1] = a[0] - a[2] / 2.0
    for m in range(2, p + 1):
        b[m] = (a[m - 1] - a[m + 1]) / (2 * m)
    b[0] = sum(bm if m % 2 else -bm for m, bm in enumerate(b) if m)  # value 0 at -1
    return b


def _clenshaw(b: list[Any], x: float) -> Any:
    """sum_m b_m T_m(x)."""
    bk1 = bk2 = 0.0 * b[0]
    x2 = 2.0 * x
    for bm in reversed(b[1:]):
        bk1, bk2 = x2 * bk1 - bk2 + bm, bk1
    return x * bk1 - bk2 + b[0]


class _DirectPanel:
    """F, (N + i F_t) F and (N + i F_t) F n along the path at Chebyshev nodes of [0, L]."""

    def __init__(self, w: DryWhirl, L: float, p: int = P_DIRECT) -> None:
        self.L = L
        self.w = w
        fs, ds, ns = [], [], []
        xs, chd = _DIRECT[p]
        self.us = [0.5 * L * (1.0 + x) for x in xs]
        self.Ns = []
        for u in self.us:
            F, N, Ft, _, th = w._path(u)
            fs.append(F)
            ds.append(complex(N * F, Ft * F))
            if w.akcr:
                ns.append(F * cmath.exp(1j * th))
            self.Ns.append(abs(N))
        self.af = [sum(map(mul, fs, row)) for row in chd]
        self.ad = [sum(map(mul, ds, row)) for row in chd]
        self.an = [sum(map(mul, ns, row)) for row in chd] if w.akcr else []
        self.bf = _cheb_int(self.af)
        self.scale_d = max(abs(d) for d in ds)

    def error_estimate(self) -> float:
        """Estimated error (s) of t over the panel: its Chebyshev tail; and of the impulses,
        relative (inf when above TOL_IMPULSE)."""
        af = self.af
        ef = 0.5 * self.L * 2.0 * (abs(af[-1]) + abs(af[-2]))
        ed = abs(self.ad[-1]) + abs(self.ad[-2])
        if self.an:
            ed += self.w.akcr * max(abs(self.an[-1]) + abs(self.an[-2]), 0.0)
        return ef if ed <= TOL_IMPULSE * self.scale_d else math.inf

    def t(self, u: float) -> float:
        return 0.5 * self.L * _clenshaw(self.bf, 2.0 * u / self.L - 1.0)

    def impulses(self, u: float, dur: float) -> tuple[complex, complex]:
        """(int (N + i F_t) dt (N s), int F_c dt (N s)) from 0 to u (dur s); the second
        from the momentum balance (``DryWhirl.contact_impulse``)."""
        x = 2.0 * u / self.L - 1.0
        int_n = 0.5 * self.L * _clenshaw(_cheb_int(self.an), x) if self.an else 0j
        return (0.5 * self.L * _clenshaw(_cheb_int(self.ad), x),
                self.w.contact_impulse(u, dur, int_n))


def _mono(vals: list[complex]) -> tuple[list[complex], float]:
    """Monomial coefficients in x in [-1, 1] of the interpolant of vals at the Chebyshev
    nodes (len(vals) of them) through its Chebyshev coefficients (rounding a few eps of
    max |vals|), and the size of its Chebyshev tail |a_{p-1}| + |a_{p-2}|."""
    _, ch, tm = _CHEB[len(vals)]
    a = [sum(map(mul, vals, row)) for row in ch]
    return [sum(map(mul, a, row)) for row in tm], abs(a[-1]) + abs(a[-2])


def _mono_fast(vals: list[complex]) -> list[complex]:
    """The same in one product (_MX; its rounding is up to ~140 eps of max |vals| at
    P_CHEB = 8, 3500 at 12: used for the harmonics j != 0, whose integrals are small)."""
    return [sum(map(mul, vals, row)) for row in _MX[len(vals)]]


def _levin(c: list[complex], w: float) -> list[complex]:
    """Monomial coefficients of the polynomial y with y' + i w y = c (|w| > len(c): the
    backward recurrence then does not amplify)."""
    p = len(c)
    y = [0j] * p
    iw = 1j * w
    nxt = 0j
    for j in range(p - 1, -1, -1):
        nxt = (c[j] - (j + 1) * nxt) / iw
        y[j] = nxt
    return y


def _horner(c: list[complex], x: float) -> complex:
    r = 0j
    for cj in reversed(c):
        r = r * x + cj
    return r


class _LevinPanel:
    """The Fourier-Levin form of the panel [0, L] (module docstring): the harmonics R_j of F
    and D_j of D = (N + i F_t) F in beta at fixed psi, at P_CHEB Chebyshev nodes in u. (In
    beta rather than theta: I_P depends on beta alone, so the harmonics' dependence on psi
    comes only from the potential, of relative size eps = 2 c_r |G|/K; in theta it would
    come from I_P, of relative size delta = c2/I0.)"""

    def __init__(self, w: DryWhirl, L: float, p: int) -> None:
        self.L, self.w = L, w
        grid = w.beta_grid(_CB, _SB)
        rows_f = [_row(k) for k in range(K_MAX + 2)]
        rows_d = [_row(k) for k in range(-K_MAX - 1, K_MAX + 2)]
        qf: list[list[complex]] = [[] for _ in rows_f]
        qd: list[list[complex]] = [[] for _ in rows_d]
        us = [0.5 * L * (1.0 + x) for x in _CHEB[p][0]]
        Es = []
        for u in us:
            dv, cE, sE = w._dv_psi(u)
            Es.append(complex(cE, sE))
            fs, ds, _ = w.beta_row(grid, cE, sE, w.K0 - 2.0 * dv)
            for q, row in zip(qf, rows_f):
                q.append(sum(map(mul, fs, row)))
            for q, row in zip(qd, rows_d):
                q.append(sum(map(mul, ds, row)))
        self.us, self.Es = us, Es
        self.Ns = [abs(w._path(u)[1]) for u in us]  # N on the path at the nodes
        self.b0 = w.psi0 + w.phi - w.theta0
        self.rs = rs = (1.0 + w.rho) * w.sig * 0.5 * L  # w_j = j rs: harmonic j's frequency in x
        f0, t0 = _mono(qf[0])
        f1 = _mono(qf[1])[1]
        self.f0_int = [cj.real / (j + 1) for j, cj in enumerate(f0)]
        self.f0_m1 = _horner(self.f0_int, -1.0).real
        self.yf = []
        for j in range(1, K_MAX + 1):
            y = _levin(_mono_fast(qf[j]), j * rs)
            self.yf.append((y, _horner(y, -1.0)))
        self.qf = qf
        k1 = K_MAX + 1
        hi = 2.0 * max(abs(q) for q in qf[k1]) * 2.0 / (k1 * abs(rs) * 2.0 / L)
        self.est = 0.5 * L * 2.0 * (t0 + f1) + hi
        d = dict(zip(range(-K_MAX - 1, K_MAX + 2), qd))
        self.d0 = _mono(d[0])[0]
        self.dk = {j: _mono_fast(d[j]) for j in range(-K_MAX, K_MAX + 1) if j}
        scale_d = max(abs(q) for q in d[0]) * L
        hi_d = sum(max(abs(q) for q in d[j]) * 2.0 / (k1 * abs(rs) * 2.0 / L)
                   for j in (-k1, k1))
        self.d_ok = hi_d <= TOL_IMPULSE * scale_d

    def error_estimate(self) -> float:
        """Estimated error of t over the panel (s): the Chebyshev tails of R_0 and R_1 over
        the panel and the dropped harmonics +-(K_MAX + 1) (their oscillatory integrals,
        2 |R_j|/(j (1 + rho)) each); inf when the impulses' first dropped harmonics
        integrate to above TOL_IMPULSE of their mean over the panel."""
        return self.est if self.d_ok else math.inf

    def _beta(self, u: float) -> float:
        return self.b0 + (1.0 + self.w.rho) * self.w.sig * u

    def t(self, u: float) -> float:
        x = 2.0 * u / self.L - 1.0
        mean = x * _horner(self.f0_int, x).real + self.f0_m1
        e1 = cmath.exp(1j * self._beta(u))
        e01 = cmath.exp(1j * self.b0)
        osc = 0j
        ek, ek0 = 1.0 + 0j, 1.0 + 0j
        for y, y_m1 in self.yf:
            ek *= e1
            ek0 *= e01
            osc += ek * _horner(y, x) - ek0 * y_m1
        return 0.5 * self.L * (mean + 2.0 * osc.real)

    def impulses(self, u: float, dur: float) -> tuple[complex, complex]:
        """(int (N + i F_t) dt (N s), int F_c dt (N s)) from 0 to u (dur s); the second from
        the momentum balance (``DryWhirl.contact_impulse``)."""
        x = 2.0 * u / self.L - 1.0
        b0, b = self.b0, self._beta(u)
        P = _osc_between(self.d0, 0, self.rs, b0, b, x)
        for j, c in self.dk.items():
            P += _osc_between(c, j, self.rs, b0, b, x)
        P *= 0.5 * self.L
        return P, self.w.contact_impulse(u, dur, self._int_n(u) if self.w.akcr else 0j)

    def _int_n(self, u: float) -> complex:
        """int n dt from 0 to u (s): n = E e^{-i beta}, so sum_j int R_j E e^{i (j - 1) beta} du
        (R_-j = conj R_j; E slow, taken into the interpolated values)."""
        x = 2.0 * u / self.L - 1.0
        b0, b = self.b0, self._beta(u)
        out = 0j
        for j in range(-K_MAX, K_MAX + 2):
            q = self.qf[j] if j >= 0 else [v.conjugate() for v in self.qf[-j]]
            vals = [v * E for v, E in zip(q, self.Es)]
            c = _mono(vals)[0] if j in (0, 1) else _mono_fast(vals)
            out += _osc_between(c, j - 1, self.rs, b0, b, x)
        return 0.5 * self.L * out


def _osc_between(c: list[complex], k: int, rs: float, b0: float, b: float, x: float
                 ) -> complex:
    """int_{-1}^{x} c(xi) e^{i k beta(xi)} d xi with beta(xi) = b0 + rs (xi + 1) (so
    beta(x) = b): polynomial integral for k = 0, else the Levin form."""
    if k == 0:
        ci = [cj / (j + 1) for j, cj in enumerate(c)]
        return x * _horner(ci, x) + _horner(ci, -1.0)
    y = _levin(c, k * rs)
    return cmath.exp(1j * k * b) * _horner(y, x) - cmath.exp(1j * k * b0) * _horner(y, -1.0)
