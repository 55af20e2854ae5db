"""Dry whirl with a held drive torque: the orbit's Fourier form with the level as a variable
(docs/notes/dry-whirl-quadrature.md §10).

Frame and units: inertial, SI, as ``dry_whirl_orbit`` (whose grid and sums this module
uses) and ``rolling_spin_fast`` (whose physics, ``DryWhirl``, it uses). With T_drive held
the energy integral of rolling on the fixed race (a c = 0) reads

    I_P(beta) Omega^2 = K - 2 V_p(beta, psi),   K = K_s + 2 T_drive sigma u   (J),

V_p = -c_r Re(conj(G) n) + m g e_c sin(psi + phi) the periodic part of the potential,
K_s = I_P Omega^2 + 2 V_p at the step's start and u >= 0 the spin angle travelled. The level
K moves with u; the integrands are explicit functions of it (x = 2 V_p/K, |x| <= eps):

    F = 1/|Omega| = sqrt(I_P) K^(-1/2) (1 - x)^(-1/2) = sum_k [sqrt(I_P) b_k (2 V_p)^k] K^(-1/2-k),
    1/F = sum_k [b'_k (2 V_p)^k / sqrt(I_P)] K^(1/2-k),
    D = (N + i F_t) F = Q0 F + Q1/F,

(b_k, b'_k the binomial series of (1 - x)^(-1/2) and (1 - x)^(1/2); N + i F_t = Q0 + Q1
Omega^2, the rolling forces being linear in Omega^2). So every harmonic of F and D on the
torus (beta, psi) is c_jl(K) = sum_k a_jlk K^(p0 - k), with a table a_jlk fixed by the rotor
and the held inputs (``LevelTable``: 2-D DFTs on the orbit's grid, once per band of levels).
Within a step K = K_s X, X = 1 + delta s, delta = 2 T sigma/K_s, and

    c_jl(s) = sum_k a_jlk K_s^(p0-k) X^(p0-k),   d^m/ds^m X^a = (a)_m delta^m X^(a-m),

((a)_m the falling factorial), so each term is a power of X times e^{i phi_jl(s)}, integrated
by parts (Levin's form: int_0^u P(s) e^{i omega s} ds = [Y(s) e^{i omega s}]_0^u + R,
Y = sum_(m <= M) (-1)^m P^(m)/(i omega)^(m+1), R the remainder with P^(M+1), omega =
sigma w_jl, |w_jl| >= 1), every derivative in closed form. Summed over the harmonics this
is sum_km w_km(u) S_km with fixed 2-D sums S_km = sum_jl a_jlk/(i omega)^(m+1)
e^{i (j beta + l psi)} (``_Series``, built once per table) and scalar weights
w_km(u) = (-1)^m (p0 - k)_m delta^m K_s^(p0-k) X^(p0-k-m) (``_StepSums``): a step rebuilds
no coefficient, and the level's change within it is exact (no expansion in s). It is
Newton on these sums (as ``dry_whirl_orbit._solve``) and the impulse sums at both ends: its
work follows the number of terms, which falls with the speed (eps = 2 V_b/K). The table
takes a step only where theta's turn over it at the start's speed is above TABLE_TURN:
below it the direct panel of ``rolling_spin_fast`` costs less
(docs/notes/dry-whirl-quadrature.md §10).

Errors (estimated, as ``dry_whirl_orbit``): the check harmonics (+-(K + 1)), the table terms
left out (smallest first, TRIM_SHARE of the tolerance) and the orders k beyond the table's (the
binomial tail, bounded by eps^(k+1)/(1 - eps)), each at its largest over the band, within
LEVEL_SHARE of the step's tolerance; the Levin terms m >= 1 left out and the remainders
beyond N_ORDERS within M_SHARE. Events:
``DryWhirl._no_event`` over the whole torus and every Omega^2 the band allows, once per
table. Where anything fails (the band's eps too large, an event not excluded, the step
leaving the band, the bearing's spring on: a k != 0) ``advance`` declines and the panels of
``rolling_spin_fast`` take the step.

The table is a function of the held inputs and the band of K_s alone (bands of BAND_LOG2 in
log2 K), never of the history: a restored state rebuilds the same table and continues bit for
bit; its build is not charged as work (it is bounded, TABLE_WORK, and taken only where the
step's work limit covers it), so that the work counts are the state's alone.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import replace
from typing import TYPE_CHECKING, Any

from .dry_whirl_orbit import (
    _CB,
    _SB,
    DELTA_MAX,
    K_BETA,
    K_PSI,
    N_BETA,
    N_PSI,
    NEWTON_ITERS,
    RHO_MIN,
    Key,
    Row,
    _dft2,
    _i_min,
    _series,
    _trimmed,
    _v_bound,
    newton_offset,
    segment_end,
)
from .rolling_spin_fast import SAMPLE_WORK, TOL_IMPULSE, TOL_PHASE, DryWhirl

if TYPE_CHECKING:
    from ..contact.wall import SegmentEnd
    from .spin_contact import HeldInputs

TABLE_TURN = 2.0
"""The table takes a step only where theta's turn at the start's speed, rho rem |Omega|, is
above this (rad): below it the direct panel costs less (measured,
docs/notes/dry-whirl-quadrature.md §10). A choice of cost, not of accuracy, so it is made
before any ``DryWhirl`` is built; the panels' own choice (direct up to BETA_DIRECT = 4 rad)
reads the panel's turn, rho ``DryWhirl.panel_length``, which is at least this one."""
FLAT_BELOW = 4
"""A group of ``_Series`` with fewer terms is summed term by term, not by rows."""
BAND_LOG2 = 0.25
"""Width of a band of levels K in log2 K: the table of band b serves K_s in
[2^(b BAND_LOG2), 2^((b + 1) BAND_LOG2)), widened by WIDEN each way for the step's end."""
WIDEN = 1.02
"""The band's table holds from its lower edge / WIDEN to its upper edge * WIDEN."""
EPS_MAX = 0.02
"""Largest 2 V_b/K over the band (V_b = c_r |G| + m g e_c) for which a table is built: the
expansion in x = 2 V_p/K then needs at most K_ORDERS orders."""
K_ORDERS = 12
"""Most orders k of the table (the binomial tail eps^(k+1)/(1 - eps) at most LEVEL_TAIL)."""
LEVEL_TAIL = 1e-17
"""The binomial tail left out of the table, relative to the integrand's mean."""
TRIM_SHARE = 0.3
"""The table's terms left out, smallest first, sum to at most this share of the tolerance
per radian of psi (TOL_PHASE of the mean of F, TOL_IMPULSE of the mean of D)."""
LEVEL_SHARE = 0.9
"""The share of the step's tolerance that the table's left-out parts may take."""
M_SHARE = 0.05
"""The share of the step's tolerance that the Levin terms m >= 1 left out may take
(``_Series``)."""
N_ORDERS = 10
"""Most Levin orders m of a term (``_terms``): beyond, Levin's remainder is bounded (a
table whose remainders exceed their budget is not ``ok``)."""
ORDER_DELTA = 0.01
"""Largest relative change of the level over a step taken here."""
T_PROBE = 2.0 ** 30
"""The drive torque (N m) at which the rolling forces are sampled a second time for their
part linear in T_drive: large, so that the difference is not lost to the rounding of N."""
TABLE_WORK = SAMPLE_WORK * N_BETA * N_PSI * 6
"""The most work (units) a table's build takes (three samples of the forces at each grid
point and the DFTs); it is built only where the step's work limit covers this."""
STEP_WORK = SAMPLE_WORK * (2 * NEWTON_ITERS + 5)
"""The work (units) charged for a step (as ``dry_whirl_orbit``'s)."""

Harmonic = tuple[float, float, list[complex], complex]
"""One harmonic of a table: (j, l, its coefficients a_jlk/(i sigma w_jl) for every order k,
zero where left out, 1/(i sigma w_jl))."""


def _series_b(inverse: bool, k_max: int) -> list[float]:
    """The coefficients of (1 - x)^(-1/2) (inverse False) or (1 - x)^(1/2) (True) to
    x^k_max."""
    p = 0.5 if inverse else -0.5
    out, c = [], 1.0
    for k in range(k_max + 1):
        out.append(c)
        c *= -(p - k) / (k + 1)
    return out


def band_of(K: float) -> int:
    """The band of the level K (J): floor(log2 K / BAND_LOG2)."""
    return math.floor(math.log2(K) / BAND_LOG2)


def torque_cap(T: float) -> float:
    """The bound of |T_drive| (N m) a table serves: the power of 2 at or above |T|, so that a
    drive torque that changes every step (a speed controller's) keeps its table while it
    stays within a factor 2 (the table holds D's part linear in T_drive apart,
    ``LevelTable``); |T| itself beyond 2^1000 (no float is the power of 2 above it)."""
    e = math.ceil(math.log2(abs(T)))
    return 2.0 ** e if e <= 1000 else abs(T)


def level_key(h: HeldInputs, Omega: float) -> Key:
    """What a table depends on besides the band: the rotor, the held inputs (the drive
    torque through ``torque_cap``) and the spin's direction."""
    return (h.p, h.J, h.a, h.F_ext, torque_cap(h.T_drive), Omega >= 0.0)


class LevelTable:
    """The table a_jlk of F and D (module docstring) for ``key`` and the band ``band`` of
    levels; ``ok`` False where it cannot serve (eps too large, an event not excluded, the
    series do not converge within the tolerance). D = D0 + T_drive D_T: the drive torque
    enters the rolling forces additively (N + i F_t gains T m (B + i A)/I_P), so the table
    holds D0 (at T_drive = 0) and cap D_T apart and serves every |T_drive| up to the key's
    cap (``torque_cap``); its bounds (events, the level's rate, Newton's) take the cap."""

    __slots__ = ("D", "F", "K_hi", "K_lo", "band", "cap", "d00_min", "d_scale", "du_min",
                 "err_d", "err_t", "kappa", "key", "n_rising", "n_rows", "ok", "w_max",
                 "w_min")

    def __init__(self, w: DryWhirl, key: Key, band: int) -> None:
        self.key, self.band, self.ok = key, band, False
        self.cap = key[4]
        w = _with_torque(w, self.cap)  # (the bounds at the largest torque served)
        self.K_lo = 2.0 ** (band * BAND_LOG2) / WIDEN
        self.K_hi = 2.0 ** ((band + 1) * BAND_LOG2) * WIDEN
        vb = _v_bound(w)
        eps = 2.0 * vb / self.K_lo
        if not (eps <= EPS_MAX and w.c2 <= DELTA_MAX * w.I0 and w.akcr == 0.0):
            return
        i_max, i_min = w.J + w.m * (w.R + w.e_c) ** 2, _i_min(w)
        lo, hi = (self.K_lo - 2.0 * vb) / i_max, (self.K_hi + 2.0 * vb) / i_min
        if not (lo > 0.0 and w._no_event(lo, hi)):
            return
        self.w_min, self.w_max = math.sqrt(lo), math.sqrt(hi)
        tail, k_max = math.sqrt(i_max * hi / (i_min * lo)) * eps / (1.0 - eps), 0
        while tail > LEVEL_TAIL and k_max < K_ORDERS:
            tail *= eps
            k_max += 1
        if tail > LEVEL_TAIL:
            return
        fs, ds, dts = self._grid(w, k_max)
        self._tables(w, [_dft2(x) for x in fs], [_dft2(x) for x in ds],
                     [_dft2(x) for x in dts], tail)

    def _grid(self, w: DryWhirl, k_max: int
              ) -> tuple[list[list[list[float]]], list[list[list[complex]]],
                         list[list[list[complex]]]]:
        """The table's functions on the orbit's grid, fs[k][a][b] = sqrt(I_P) b_k (2 V_p)^k
        (k <= k_max) and ds[k][a][b] = Q1 b'_k (2 V_p)^k/sqrt(I_P) + Q0 sqrt(I_P) b_(k-1)
        (2 V_p)^(k-1) (D's part of order K^(1/2 - k), k <= k_max + 1, so that both of its
        binomial tails start beyond k_max) with Q0 at T_drive = 0, dts[k][a][b] the same of
        cap G (G = dQ0/dT_drive), at (beta_a, psi_b); the rows of N = alpha0 + T alpha_T +
        gamma K (``peak_on``) and d_scale >= (|Q0| + cap |G|) F + |Q1|/F over the band. Q0,
        Q1 and G from the rolling forces of ``DryWhirl.beta_row`` at two levels (N + i F_t
        is linear in Omega^2) and at a large probe torque (and linear in T_drive)."""
        grid = w.beta_grid(_CB, _SB)
        bF, bR = _series_b(False, k_max + 1), _series_b(True, k_max + 1)
        K_a = 4.0 * _v_bound(w) + 1e-3 * self.K_lo  # (Omega^2 small: Q0 from it is not
        K_b = self.K_hi                              # a difference of large values)
        fs = [[[0.0] * N_PSI for _ in range(N_BETA)] for _ in range(k_max + 1)]
        ds = [[[0j] * N_PSI for _ in range(N_BETA)] for _ in range(k_max + 2)]
        dts = [[[0j] * N_PSI for _ in range(N_BETA)] for _ in range(k_max + 2)]
        self.d_scale = 0.0
        self.n_rows: list[tuple[list[float], list[float], list[float]]] = []
        w0, wp = _with_torque(w, 0.0), _with_torque(w, T_PROBE)
        cap = self.cap
        c_r, Gx, Gy, mge = w.c_r, w.Gx, w.Gy, w.mge
        for b in range(N_PSI):
            ang = 2.0 * math.pi * b / N_PSI + w.phi
            cE, sE = math.cos(ang), math.sin(ang)
            _, d_a, _ = w0.beta_row(grid, cE, sE, K_a - 2.0 * mge * sE)
            _, d_b, _ = w0.beta_row(grid, cE, sE, K_b - 2.0 * mge * sE)
            _, d_p, _ = wp.beta_row(grid, cE, sE, K_a - 2.0 * mge * sE)
            alphas, alphas_t, gammas = [], [], []
            for a, (cb, sb, IP) in enumerate(zip(grid[0], grid[1], grid[2])):
                ct, st = cE * cb + sE * sb, sE * cb - cE * sb
                v2 = 2.0 * (mge * sE - c_r * (Gx * ct + Gy * st))  # 2 V_p
                om_a, om_b = (K_a - v2) / IP, (K_b - v2) / IP
                z_a, z_b = d_a[a] * math.sqrt(om_a), d_b[a] * math.sqrt(om_b)  # N + i F_t
                q1 = (z_b - z_a) / (om_b - om_a)
                q0 = z_a - q1 * om_a
                g = (d_p[a] * math.sqrt(om_a) - z_a) / T_PROBE
                alphas.append(q0.real - q1.real * v2 / IP)
                alphas_t.append(g.real)
                gammas.append(q1.real / IP)
                sq = math.sqrt(IP)
                self.d_scale = max(self.d_scale,
                                   (abs(q0) + cap * abs(g)) * math.sqrt(IP / (self.K_lo - v2))
                                   + abs(q1) * math.sqrt((self.K_hi - v2) / IP))
                x, x_prev = 1.0, 0.0
                for k in range(k_max + 2):
                    if k <= k_max:
                        fs[k][a][b] = sq * bF[k] * x
                    ds[k][a][b] = q1 / sq * bR[k] * x + (q0 * sq * bF[k - 1] * x_prev
                                                         if k else 0j)
                    dts[k][a][b] = cap * g * sq * bF[k - 1] * x_prev if k else 0j
                    x, x_prev = x * v2, x
            self.n_rows.append((alphas, alphas_t, gammas))
        self.n_rising = all(g >= 0.0 for _, _, ga in self.n_rows for g in ga)
        """N grows with K at every point of the grid (the centripetal term): the peak over
        a step's levels is at the larger."""
        return fs, ds, dts

    def _tables(self, w: DryWhirl, cf: list[dict[tuple[int, int], complex]],
                cd: list[dict[tuple[int, int], complex]],
                ct: list[dict[tuple[int, int], complex]], tail: float) -> None:
        """The harmonics kept (``Harmonic``), the series, the means and the error
        bounds."""
        rho1, sig = 1.0 + w.rho, w.sig
        lo_hi = (self.K_lo, self.K_hi)

        def top(c: list[complex], p0: float) -> float:  # the largest over the band
            return sum(abs(v) * max(K ** (p0 - k) for K in lo_hi) for k, v in enumerate(c))

        f00 = [c[(0, 0)].real for c in cf]
        d00 = [c[(0, 0)] for c in cd]
        t00 = [c[(0, 0)] for c in ct]
        f_min = min(sum(v * K ** (-0.5 - k) for k, v in enumerate(f00)) for K in lo_hi)
        self.d00_min = min(abs(sum(v * K ** (0.5 - k) for k, v in enumerate(d00)))
                           - abs(sum(v * K ** (0.5 - k) for k, v in enumerate(t00)))
                           for K in lo_hi)  # (|D0_00 + T D_T,00| for |T| <= cap)

        k1, jp1 = K_BETA + 1, K_PSI + 1
        err_t = [0.0, 0.0, tail * top(f00, -0.5)]  # (the binomial tail: slow)
        err_d = [0.0, 0.0, tail * self.d_scale]
        hf = self._kept(cf, -0.5, True, TRIM_SHARE * TOL_PHASE * f_min, err_t,
                             rho1, sig, top)
        hd = self._kept(cd, 0.5, False, TRIM_SHARE * TOL_IMPULSE * self.d00_min,
                             err_d, rho1, sig, top)
        ht = self._kept(ct, 0.5, False, 0.5 * TRIM_SHARE * TOL_IMPULSE * self.d00_min,
                             err_d, rho1, sig, top)
        delta_max = 2.0 * abs(w.T) / self.K_lo
        self.du_min = 0.5 * TABLE_TURN / w.rho * self.w_min / self.w_max
        tol_t = TOL_PHASE / (w.rho * self.w_max)  # (s: TOL_PHASE rad of theta)
        self.F = _Series((hf, f00,
                          (0.5 * M_SHARE * tol_t / 4.0,  # (t: 2 Re, 2 ends)
                           0.5 * M_SHARE * TOL_PHASE / (2.0 * self.w_max))),
                         -0.5, [max(K ** (-0.5 - k) for K in lo_hi) for k in range(len(f00))],
                         delta_max)
        scale_d = [max(K ** (0.5 - k) for K in lo_hi) for k in range(len(d00))]
        budgets_d = (0.5 * M_SHARE * TOL_IMPULSE * self.d00_min * self.du_min / 2.0,
                     0.5 * M_SHARE * TOL_IMPULSE * self.d00_min)
        self.D = _Series((hd, d00, budgets_d), 0.5, scale_d, delta_max,
                         (ht, t00, (0.5 * budgets_d[0], 0.5 * budgets_d[1])))
        for (j, jp) in ((j, jp) for j in range(-k1, k1 + 1) for jp in range(-jp1, jp1 + 1)):
            if abs(j) == k1 or abs(jp) == jp1:
                _add(err_t, j, jp, 2.0 * top([c[(j, jp)] for c in cf], -0.5), rho1)
                _add(err_d, j, jp, 2.0 * top([c[(j, jp)] for c in cd], 0.5)
                     + 2.0 * top([c[(j, jp)] for c in ct], 0.5), rho1)
        self.err_t, self.err_d = tuple(err_t), tuple(err_d)
        self.kappa = 0.5 * (w.c2 * rho1 / _i_min(w)
                            + 2.0 * (w.c_r * math.hypot(w.Gx, w.Gy) * w.rho + abs(w.mge)
                                     + abs(w.T)) / (self.K_lo - 2.0 * _v_bound(w)))
        self.ok = (all(map(math.isfinite, (*self.err_t, *self.err_d))) and self.d00_min > 0.0
                   and self.F.ok and self.D.ok)

    @staticmethod
    def _kept(cs: list[dict[tuple[int, int], complex]], p0: float, real: bool, budget: float,
              err: list[float], rho1: float, sig: float, top: Any
              ) -> list[Harmonic]:
        """The harmonics kept of a series (for a real one the half j > 0 or j = 0 < l):
        its terms a_jlk, each at its largest over the band, are left out smallest first
        while they sum to at most ``budget`` (doubled for a real series; added to ``err``:
        a left-out term integrates to at most its size times the step's du, the bound
        the tolerance is checked against)."""
        sizes: dict[tuple[int, int], list[float]] = {}
        for j in range(-K_BETA, K_BETA + 1):
            for jp in range(-K_PSI, K_PSI + 1):
                if (j, jp) != (0, 0) and (not real or j > 0 or (j == 0 and jp > 0)):
                    sizes[(j, jp)] = [top([0j] * k + [v[(j, jp)]], p0)
                                      for k, v in enumerate(cs)]
        left, total = set(), 0.0
        for hk in sorted(((jl, k) for jl, row in sizes.items() for k in range(len(row))),
                         key=lambda e: sizes[e[0]][e[1]]):
            size = sizes[hk[0]][hk[1]] * (2.0 if real else 1.0)
            if total + size > budget:
                break
            total += size
            left.add(hk)
            _add(err, hk[0][0], hk[0][1], size, rho1)
        out: list[Harmonic] = []
        for (j, jp), row in sizes.items():
            keep = [k for k in range(len(row)) if ((j, jp), k) not in left]
            if not keep:
                continue
            inv = 1.0 / (1j * sig * (j * rho1 + jp))
            out.append((float(j), float(jp), [v[(j, jp)] * inv if k in keep else 0j
                                              for k, v in enumerate(cs)], inv))
        return out

    def peak_on(self, psi_a: float, psi_b: float, K_a: float, K_b: float, T: float
                ) -> float:
        """The largest |N| (N) on the beta grid of the rows of the grid within [psi_a,
        psi_b] (either order) widened by one row each way, at the levels K_a and K_b (N is
        linear in K at each point) and the drive torque T (N m): as ``Orbit.peak_on``."""
        lo, hi = min(psi_a, psi_b), max(psi_a, psi_b)
        k0 = math.floor(lo * N_PSI / (2.0 * math.pi))
        k1 = min(math.floor(hi * N_PSI / (2.0 * math.pi)) + 1, k0 + N_PSI - 1)
        out = 0.0
        levels = (max(K_a, K_b),) if self.n_rising else (K_a, K_b)
        for k in range(k0, k1 + 1):
            al, at, ga = self.n_rows[k % N_PSI]
            for K in levels:  # (N > 0 over the band, _no_event: |N| = N)
                out = max(out, max([a + T * b + g * K for a, b, g in zip(al, at, ga)]))
        return out


def _with_torque(w: DryWhirl, T: float) -> DryWhirl:
    """A copy of ``w`` with the drive torque T (N m) in place of its own (the forces, the
    event bounds and the rates read ``w.T``)."""
    return DryWhirl(replace(w.h, T_drive=T), w.theta0, w.psi0, w.Omega0)


def _add(err: list[float], j: int, jp: int, size: float, rho1: float) -> None:
    """Add a left-out harmonic of magnitude ``size`` to an error triple (``_dropped``'s:
    sum 2 |c|/|w| and sum |c| over the fast ones, sum |c| over the slow ones)."""
    if j:
        err[0] += 2.0 * size / abs(j * rho1 + jp)
        err[1] += size
    else:
        err[2] += size


def advance(prev: Any, h: HeldInputs, theta: float, psi: float, Omega: float, rem: float,
            limit: int, step0: float) -> tuple[SegmentEnd | None, LevelTable | None]:
    """Roll rem (s) from (theta, psi, Omega) under ``h`` (T_drive held, a c = 0) on the
    table of its level's band: (the segment's end, the table). The end is None where the
    method does not apply (module docstring): the caller advances the segment otherwise;
    the table is returned all the same, so that a refused one is not rebuilt every step.
    ``prev``: the previous step's table (or ``dry_whirl_orbit.Orbit``, or None)."""
    keep = prev if isinstance(prev, LevelTable) else None
    if h.p.R / h.p.c_r * rem * abs(Omega) <= TABLE_TURN:
        return None, keep  # (the direct panel takes it, at less work: §10)
    w = DryWhirl(h, theta, psi, Omega)
    if not (rem > 0.0 and w.K0 > 0.0 and math.isfinite(w.K0)) or w.rho < RHO_MIN:
        return None, keep
    K_s = w.K0 + 2.0 * (w.mge * w.sE0 - w.v0)  # I_P Omega^2 + 2 V_p at the start
    if not K_s > 0.0:
        return None, None
    key, band = level_key(h, Omega), band_of(K_s)
    tab = keep if keep is not None and keep.key == key and keep.band == band else None
    if tab is None:
        if limit < TABLE_WORK:
            return None, None
        tab = LevelTable(w, key, band)
    if not tab.ok or limit < STEP_WORK:
        return None, tab
    du_hi = rem * tab.w_max * (1.0 + 1e-9)
    du_lo = rem * tab.w_min * (1.0 - 1e-9)
    dK = 2.0 * abs(w.T) * du_hi
    if not (tab.K_lo <= K_s - dK and K_s + dK <= tab.K_hi and dK <= ORDER_DELTA * K_s
            and du_lo >= tab.du_min and _within_tolerance(tab, w, du_lo, du_hi)):
        return None, tab
    return _step(tab, w, psi, rem, K_s, step0), tab


def _within_tolerance(tab: LevelTable, w: DryWhirl, du: float, du_err: float) -> bool:
    """The table's left-out parts over a step of du to du_err rad of psi (errors at
    du_err, tolerances at du) within LEVEL_SHARE of TOL_PHASE (1 + its turn of theta) rad
    of theta and of TOL_IMPULSE of its mean impulse (as ``dry_whirl_orbit``'s)."""
    a, b, c = tab.err_t
    e_t = min(a, b * du_err) + c * du_err
    a, b, c = tab.err_d
    e_d = min(a, b * du_err) + c * du_err
    return (e_t * w.rho * tab.w_max <= LEVEL_SHARE * TOL_PHASE * (1.0 + w.rho * du)
            and e_d <= LEVEL_SHARE * TOL_IMPULSE * tab.d00_min * du)


class _Series:
    """One series (F or D) of a table as fixed 2-D sums, one group of ``_series`` rows per
    order k of the level and per Levin order m (docs/notes/dry-whirl-quadrature.md §10):

        S_km(beta, psi) = sum_jl a_jlk/(i sigma w_jl)^(m+1) e^{i (j beta + l psi)},

    so that the periodic part of the integral at a step's level is sum_km w_km(u) S_km with
    scalar weights (``_StepSums``): no coefficient is rebuilt per step. m = 0 holds every
    kept term; m >= 1 the terms whose largest use over the band (m! (|delta| /|w|)^m of
    the m = 0 term, delta at most 2 |T|/K_lo, over 1 - ORDER_DELTA to the power m + 1) is
    above what the part's budgets leave out, smallest first (``Part``): the first for their
    value at either end (an absolute bound B), the second for their change per radian of
    psi (at most 2 |w| B: the sum's change over a step of du is at most that times du, for
    tolerances that grow with du). ``part_t``: D's part linear in T_drive (cap D_T), its
    groups weighted by T/cap per step. Also the means' a_00k (``mean``, and ``mean_t`` of
    D_T) and their p0 - k + 1 (``a``), each group's falling factorial (``facs``), and
    ``ok``: False where Levin's remainders beyond N_ORDERS exceed the per-radian budget.
    ``scale[k]``: the largest K^(p0 - k) over the band."""

    __slots__ = ("a", "facs", "flat", "groups", "m_top", "mean", "mean_t", "ok")

    def __init__(self, part: Part, p0: float, scale: list[float], delta_max: float,
                 part_t: Part | None = None) -> None:
        parts = [part] if part_t is None else [part, part_t]
        self.mean = part[1]
        self.mean_t = None if part_t is None else part_t[1]
        kept = []
        self.ok = True
        for f, (hs, _, budgets) in enumerate(parts):
            terms = _terms(hs, p0, scale, delta_max)
            left = [0.0, sum(2.0 * t[0] / t[6] for t in terms if t[1] < 0)]
            self.ok = self.ok and left[1] <= budgets[1]  # (the remainders beyond N_ORDERS)
            for t in sorted((t for t in terms if t[1] >= 0), key=lambda t: t[0]):
                per_rad = 2.0 * t[0] / t[6]
                if not t[1]:
                    kept.append((f, *t))
                elif left[0] + t[0] <= budgets[0]:
                    left[0] += t[0]
                elif left[1] + per_rad <= budgets[1]:
                    left[1] += per_rad
                else:
                    kept.append((f, *t))
        by_group: dict[tuple[int, int, int], dict[tuple[float, float], complex]] = {}
        for f, _, m, k, j, jp, c, _ in kept:
            by_group.setdefault((k, m, f), {})[(j, jp)] = c
        self.groups, self.flat = [], []
        for (k, m, f), entries in sorted(by_group.items()):
            if len(entries) < FLAT_BELOW:  # (a few terms: cheaper one by one than as rows)
                gi = len(self.groups)
                self.flat += [(j, jp, gi, c) for (j, jp), c in entries.items()]
                self.groups.append((k, m, f, False, []))
            else:
                self.groups.append((k, m, f, *_rows(entries)))
        self.m_top = max(g[1] for g in self.groups)
        self.a = [p0 - k + 1.0 for k in range(len(self.mean))]
        """p0 - k + 1 of each order k of the mean (``_StepSums.excess``)."""
        self.facs = [(-1.0) ** m * math.prod(p0 - k - i for i in range(m))
                     for k, m, *_ in self.groups]
        """(-1)^m (p0 - k)_m of each group (k, m), the falling factorial (``_StepSums``'s
        weights)."""


Part = tuple[list[Harmonic], list[Any], tuple[float, float]]
"""One part of a ``_Series``: its harmonics, the mean's a_00k, and the budgets of its Levin
terms m >= 1 left out (at the ends, per radian)."""


def _terms(hs: list[Harmonic], p0: float, scale: list[float], delta_max: float
           ) -> list[tuple[float, int, int, float, float, complex, float]]:
    """Every term (bound of its use, m, k, j, l, coefficient a_jlk/(i w)^(m+1), 1/|w|) of
    the harmonics hs: m = 0, and m >= 1 while its bound is positive (``_Series``); beyond
    m = N_ORDERS, Levin's remainder int P^(m+1) e^{i w s} ds/(i w)^(m+1) as a term m = -1
    (its bound per radian is |w| times the next term's, at most its per_rad)."""
    terms = []
    for j, jp, a, inv in hs:
        w_inv = abs(inv)
        for k, v in enumerate(a):
            if not v:
                continue
            terms.append((0.0, 0, k, j, jp, v, w_inv))
            use, c, m = abs(v) * scale[k], v, 0
            while use > 0.0 and m < N_ORDERS:
                m += 1  # (m! C(p0 - k, m) from (m - 1)! C(p0 - k, m - 1))
                c *= inv
                use *= abs(p0 - k - m + 1) * delta_max * w_inv / (1.0 - ORDER_DELTA)
                terms.append((use / (1.0 - ORDER_DELTA), m, k, j, jp, c, w_inv))
            if use > 0.0:
                use *= abs(p0 - k - m) * delta_max * w_inv / (1.0 - ORDER_DELTA)
                terms.append((use / (1.0 - ORDER_DELTA), -1, k, j, jp, 0j, w_inv))
    return terms


class _StepSums:
    """A ``_Series`` at a step's start level K_s (J), delta = 2 T sigma/K_s: each group's
    weight in closed form (Levin: int_0^u P(s) e^{i w s} ds = [Y(s) e^{i w s}]_0^u + the
    remainder of ``_Series``, Y = sum_m (-1)^m P^(m)/(i w)^(m+1), with P(s) = K^(p0 - k) =
    K_s^(p0 - k) X^(p0 - k), X = 1 + delta s, exactly: P^(m) = (p0 - k)_m delta^m
    K_s^(p0 - k) X^(p0 - k - m), (a)_m the falling factorial), and the mean's integral in
    closed form. ``gain`` = T/cap weights the series' part linear in T_drive."""

    __slots__ = ("a", "delta", "e_top", "flat", "items", "mean", "mean0", "p0")

    def __init__(self, ser: _Series, p0: float, K_s: float, delta: float,
                 gain: float = 0.0) -> None:
        P = [K_s ** p0]
        r = 1.0 / K_s
        for _ in range(len(ser.mean) - 1):
            P.append(P[-1] * r)
        dm = [1.0]
        for _ in range(ser.m_top):
            dm.append(dm[-1] * delta)
        mean = ser.mean if ser.mean_t is None else [
            c + gain * ct for c, ct in zip(ser.mean, ser.mean_t)]
        self.mean = [c * pk for c, pk in zip(mean, P)]  # (the mean's K^(p0 - k) at K_s)
        self.mean0 = sum(self.mean)
        self.p0, self.delta = p0, delta
        self.a = ser.a
        gains = (1.0, gain)
        self.items = [(gains[f] * fall * P[k] * dm[m], k + m, by_beta, rows)
                      for (k, m, f, by_beta, rows), fall in zip(ser.groups, ser.facs)]
        """Each group's weight at X = 1, the power of 1/X it takes beyond X^p0, its rows'
        orientation and its rows (none: its terms are in ``flat``)."""
        self.e_top = max(e for _, e, _, _ in self.items)
        self.flat = ser.flat

    def at(self, beta: float, psi: float, u: float) -> complex:
        """sum_km w_km(u) S_km(beta, psi): the periodic part's Levin sum at (beta, psi) (rad)
        reached after u (rad)."""
        zs = (cmath.rect(1.0, psi), cmath.rect(1.0, beta))
        X = 1.0 + self.delta * u
        pw = [X ** self.p0]
        r = 1.0 / X
        for _ in range(self.e_top):
            pw.append(pw[-1] * r)
        s = 0j
        ws = []
        for g, e, by_beta, rows in self.items:
            w = g * pw[e]
            ws.append(w)
            if rows:
                s += w * _series(rows, beta, psi, zs[by_beta])
        for j, jp, gi, c in self.flat:
            s += ws[gi] * c * cmath.rect(1.0, j * beta + jp * psi)
        return s

    def excess(self, u: float) -> Any:
        """int_0^u of the mean less mean0 u: sum_k c_k u (E_k - 1), E_k = (X^a_k - 1)/(a_k x),
        x = delta u, a_k = p0 - k + 1, by expm1/log1p and (X^(a-1) - 1) = (X^a - 1 - x)/X
        (no cancellation beyond a factor |a_k/(a_k - 1)| <= 3 per order); below |x| = 1e-8
        by E_k - 1 = (a_k - 1) x/2 + (a_k - 1)(a_k - 2) x^2/6 (the next term is below 1e-24,
        and x may be subnormal)."""
        x = self.delta * u
        a = self.a
        if abs(x) < 1e-8:
            return u * sum(c * ((ak - 1.0) * x * (0.5 + (ak - 2.0) * x / 6.0))
                           for c, ak in zip(self.mean, a))
        y = math.expm1(a[0] * math.log1p(x))
        r = 1.0 / (1.0 + x)
        acc = 0.0 * self.mean0
        for c, ak in zip(self.mean, a):
            acc += c * (y / (ak * x) - 1.0)
            y = (y - x) * r
        return acc * u


def _rows(entries: dict[tuple[float, float], complex]) -> tuple[bool, list[Row]]:
    """``_series``'s rows of the terms c_jl of ``entries`` (``dry_whirl_orbit._trimmed``),
    over psi (one row per j) or over beta (one per l), whichever takes fewer: (over beta,
    the rows)."""
    rows = [_trimmed(lambda j, jp: entries.get((j, jp), 0j), 0, by_beta)
            for by_beta in (False, True)]
    by_beta = len(rows[1]) < len(rows[0])
    return by_beta, rows[by_beta]


def _step(tab: LevelTable, w: DryWhirl, psi: float, rem: float, K_s: float, step0: float
          ) -> SegmentEnd:
    """The end of rem (s) of rolling from ``w``'s start at the level K_s (J): Newton on
    t(u) = rem (t' = F on the path), then the impulse's sums at both ends."""
    sig, rho1 = w.sig, 1.0 + w.rho
    delta = 2.0 * w.T * sig / K_s
    sf = _StepSums(tab.F, -0.5, K_s, delta)
    b_s = psi + w.phi - w.theta0
    s_t0 = sf.at(b_s, psi, 0.0)
    f00 = sf.mean0
    u_lin = rem / f00
    r0 = f00 * u_lin - rem

    def residual(x: float) -> float:  # t(u_lin + x) - rem
        u = u_lin + x
        return r0 + f00 * x + sf.excess(u) + 2.0 * (
            sf.at(b_s + rho1 * sig * u, psi + sig * u, u) - s_t0).real

    u = u_lin + newton_offset(w, rem, u_lin, residual, tab.kappa)
    sd = _StepSums(tab.D, 0.5, K_s, delta, w.T / tab.cap)
    b_e, p_e = b_s + rho1 * sig * u, psi + sig * u
    P = sd.mean0 * u + sd.excess(u) + sd.at(b_e, p_e, u) - sd.at(b_s, psi, 0.0)
    K_e = K_s + 2.0 * w.T * sig * u

    def peak_on(psi_a: float, psi_b: float) -> float:
        return tab.peak_on(psi_a, psi_b, K_s, K_e, w.T)

    return segment_end(w, psi, rem, u, P, 0j, peak_on, STEP_WORK, step0, tab)
