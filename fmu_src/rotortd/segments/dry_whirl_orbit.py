"""Dry whirl on its orbit: rolling on the fixed rigid race with the bearing's damper off
(a c = 0) and no drive torque (T_drive = 0), a step at the same cost at any speed
(docs/notes/dry-whirl-quadrature.md §8).

Frame and units: inertial, SI, as ``rolling_spin_fast`` (whose physics ``DryWhirl`` this
module uses). With T_drive = 0 the potential V(theta, psi) = -c_r Re(conj(G) n)
+ m g e_c sin(psi + phi) is periodic in psi as well as in theta = psi + phi - beta. The
energy E = 1/2 I_P(beta) Omega^2 + V is constant, so the integrands of the time,
F = 1/|Omega| = sqrt(I_P / (2 (E - V))) (s/rad), and of the contact impulse,
D = (N + i F_t) F (N s/rad), are functions on the torus (beta, psi) fixed by E and the held
inputs alone: one orbit. With their 2-D Fourier series F = sum F_jl e^{i (j beta + l psi)}
and on the path beta = beta_s + (1 + rho) sigma u, psi = psi_s + sigma u (u >= 0 the spin
angle travelled from the step's start, sigma = sign Omega),

    t(u) = F_00 u + 2 Re sum_{j > 0 or (j = 0 < l)} F_jl (e^{i phi_jl(u)} - e^{i phi_jl(0)})
                                                          / (i sigma w_jl),
    phi_jl = j beta + l psi,   w_jl = j (1 + rho) + l,

and the same for int D du (all (j, l) != 0) and for int n dt (n F = e^{i phi} sum F_jl
e^{i ((j - 1) beta + (l + 1) psi)}, secular at (j, l) = (1, -1)): closed forms for any u. The
coefficients come from an N_BETA x N_PSI grid on the torus (2-D DFT), once per orbit; a step
is the evaluation of a few such sums (Newton for the step end): its work does not depend on
the speed or on how many turns beta makes in it. No small divisors: w_jl = 0 only at
(0, 0) when 1 + rho > K_PSI + 1 (RHO_MIN).

The orbit is kept from step to step while the held inputs and the energy stay: E is part of
the core's state (``CoreState.orbit_energy``), so that a restored state continues on the
same coefficients bit for bit; the end state's Omega is taken from E (the integral is exact
across steps). A state whose energy differs from the orbit's by more than E_MATCH relative
starts a new orbit.

Errors (estimated, as ``rolling_spin_fast``): the first dropped harmonics, j = +-(K_BETA + 1)
or l = +-(K_PSI + 1), integrated (each at most 2 |F_jl|/|w_jl| over any path; twice that
for the tail beyond and the aliasing): at most TOL_PHASE rad of theta (the time error times
rho |Omega|_max), absolute, for any step; those of D at most TOL_IMPULSE of the step's mean
impulse (otherwise the step declines). Events: ``DryWhirl._no_event`` over every point of the
torus and every Omega^2 the energy allows (bounds over the whole orbit): no lift-off and no
slip start can occur anywhere on an orbit taken, for as long as the inputs hold.
"""

from __future__ import annotations

import cmath
import math
from operator import mul
from typing import TYPE_CHECKING, Any

from ..contact.wall import ContactTally, SegmentEnd
from .rolling_spin_fast import SAMPLE_WORK, TOL_IMPULSE, TOL_PHASE, DryWhirl

if TYPE_CHECKING:
    from ..params import RotorParams
    from .spin_contact import HeldInputs

K_BETA = 6
"""Harmonics in beta kept (|j| <= K_BETA; +-(K_BETA + 1) are the check). (I_P's factor
sqrt(1 - delta cos beta) alone has harmonics of about (delta/2)^j: 2e-14 of F_00 at j = 6
for the chapter's rotor, delta = 0.01; the Levin panel's K_MAX = 5 meets its tolerance
relative to the turn of a panel, this one is absolute.)"""
K_PSI = 6
"""Harmonics in psi kept (|l| <= K_PSI; +-(K_PSI + 1) are the check)."""
N_PSI = 2 * K_PSI + 3
"""Grid points in psi (odd: the check harmonic is not the Nyquist one)."""
N_BETA = 2 * K_BETA + 3
RHO_MIN = 17.0
"""Least R/c_r: the smallest divisor |w_jl| (j != 0) is then 1 + rho - (K_PSI + 1) >= 11."""
E_MATCH = 16.0 * 2.0 ** -52
"""Largest relative difference of a state's energy from the orbit's that continues it (the
rounding of E recomputed from the end state is a few eps)."""
TRIM = 1e-17
"""Kept harmonics at most this relative to the mean (F_00, D_00) are left out of the sums
and counted with the dropped ones in the error estimate (the DFT's rounding is about 1e-17;
at most 168 of them add 1.7e-15 of the mean, within TOL_IMPULSE)."""
EPS_MAX = 0.015
"""Largest c_r |G| + m g e_c relative to E (the potential's modulation of the integrand) for
which an orbit is built; at 0.015 the chapter's rotor's series meet the tolerance (25 rad/s),
at 0.02 they do not."""
DELTA_MAX = 0.05
"""Largest 2 m R e_c / (J + m (R^2 + e_c^2)) (I_P's modulation) for which one is built."""
MAP_SHARE = 0.5
"""The share of the step's tolerance (TOL_PHASE, TOL_IMPULSE) a ``StepMap``'s left-out terms
may take (the orbit's own series take the rest, ``_within_tolerance``)."""
NEWTON_ITERS = 12
"""Most Newton iterations of the step end (it converges in 3 to 5)."""
MAP_WORK = SAMPLE_WORK * N_BETA * N_PSI * (2 * NEWTON_ITERS + 5)
"""The most work (units) a ``StepMap`` build takes: a step's Newton at every grid point; it
is built only where the step's work limit covers this."""

_BG = [2.0 * math.pi * a / N_BETA for a in range(N_BETA)]
_CB = [math.cos(b) for b in _BG]
_SB = [math.sin(b) for b in _BG]
_BETA_ROWS = {j: [cmath.exp(-1j * j * b) / N_BETA for b in _BG]
              for j in range(-K_BETA - 1, K_BETA + 2)}
"""_BETA_ROWS[j][a] = e^{-i j beta_a}/N_BETA: the DFT rows in beta."""
_PSI_ROWS = [[cmath.exp(-1j * jp * 2.0 * math.pi * b / N_PSI) / N_PSI for b in range(N_PSI)]
             for jp in range(-K_PSI - 1, K_PSI + 2)]
"""_PSI_ROWS[l + K_PSI + 1][b] = e^{-i l psi_b}/N_PSI: the DFT rows in psi."""

Key = tuple[Any, ...]
Row = tuple[float, float, complex, list[complex]]
"""One row of a 2-D series (``_trimmed``): the harmonic (j, l) of its lowest term and its
coefficients for Horner's rule (the highest term's, then the rest from the highest down)."""


def orbit_key(p: RotorParams, J: float, a: float, F_ext: complex, Omega: float) -> Key:
    """What an orbit's coefficients depend on besides E: the rotor, the held inputs (bearing
    switch a, F_ext (N); T_drive = 0) and the direction of the spin."""
    return (p, J, a, F_ext, Omega >= 0.0)


class Orbit:
    """The 2-D Fourier coefficients of one orbit (energy ``E`` (J) under ``key``), built
    on first use (``build``; an orbit restored from a state is built at its next step)."""

    __slots__ = ("A", "B", "C", "E", "built", "d00", "err_d", "err_t", "f00", "kappa",
                 "key", "last_rem", "map", "n_rows", "n_sec", "ok", "w_max")

    def __init__(self, E: float, key: Key, last_rem: float = math.nan) -> None:
        self.E, self.key = E, key
        self.built = self.ok = False
        self.map: StepMap | None = None
        self.last_rem = last_rem
        """The length (s) of the last segment taken on the orbit (NaN: none): a segment of
        the same length again builds the orbit's ``StepMap`` (part of the core's state,
        ``CoreState.orbit_step``, so that a restored state makes the same choice)."""

    def build(self, w: DryWhirl) -> None:
        """The coefficients from the grid, with ``w``'s constants (the held inputs of key)."""
        self.built = True
        grid = self._grid(w)
        if grid is None:
            return
        fq, dq = grid
        k1, jp1 = K_BETA + 1, K_PSI + 1
        F = {(j, jp): sum(map(mul, fq[j], _PSI_ROWS[jp + jp1]))
             for j in range(0, k1 + 1) for jp in range(-jp1, jp1 + 1)}
        for (j, jp), v in list(F.items()):
            F[(-j, -jp)] = v.conjugate()
        D = {(j, jp): sum(map(mul, dq[j], _PSI_ROWS[jp + jp1]))
             for j in range(-k1, k1 + 1) for jp in range(-jp1, jp1 + 1)}
        rho1, sig = 1.0 + w.rho, w.sig
        check = [(j, jp) for j in range(-k1, k1 + 1) for jp in range(-jp1, jp1 + 1)
                 if abs(j) == k1 or abs(jp) == jp1]
        self.f00, self.d00 = F[(0, 0)].real, D[(0, 0)]
        small_f = _small(F, abs(self.f00))
        small_d = _small(D, abs(self.d00))
        self.err_t = _dropped(F, check + small_f, rho1)
        self.err_d = _dropped(D, check + small_d, rho1)
        self.w_max = math.sqrt(max(_omega2_bounds(w, self.E)[1], 0.0))  # |Omega| on it
        self.ok = all(map(math.isfinite, (*self.err_t, *self.err_d)))
        self.n_sec = F[(1, -1)] * cmath.exp(1j * w.phi)
        skip_f, skip_d = set(small_f), set(small_d)
        self.A = _trimmed(lambda j, jp: (
            F[(j, jp)] / (1j * sig * (j * rho1 + jp))
            if (j > 0 or (j == 0 and jp > 0)) and (j, jp) not in skip_f else 0j), 0)
        # (t's sum runs over j > 0, and j = 0 < l: the rest is its conjugate)
        self.B = _trimmed(lambda j, jp: (D[(j, jp)] / (1j * sig * (j * rho1 + jp))
                                         if (j, jp) != (0, 0) and (j, jp) not in skip_d
                                         else 0j), 0)
        eph = cmath.exp(1j * w.phi)
        self.C = _trimmed(lambda j, jp: (
            eph * F[(j + 1, jp - 1)] / (1j * sig * (j * rho1 + jp))
            if (j, jp) != (0, 0) and abs(j + 1) <= K_BETA and abs(jp - 1) <= K_PSI else 0j), 1)
        self.kappa = 0.5 * (w.c2 * rho1 / _i_min(w)
                            + 2.0 * (w.c_r * math.hypot(w.Gx, w.Gy) * w.rho + abs(w.mge))
                            / (2.0 * self.E - 2.0 * _v_bound(w)))

    def peak_on(self, psi_a: float, psi_b: float) -> float:
        """The largest |N| (N) on the beta grid of the rows psi_b of the grid that lie
        within [psi_a, psi_b] (either order) widened by one row each way: the peak of a step
        in which beta turns through every phase, to the grid's resolution in beta (N's
        modulation over beta is a few harmonics: the grid's maximum is within about
        (pi/N_BETA)^2/2 = 2 % of that modulation of the cycle's)."""
        lo, hi = min(psi_a, psi_b), max(psi_a, psi_b)
        k0 = math.floor(lo * N_PSI / (2.0 * math.pi))
        k1 = min(math.floor(hi * N_PSI / (2.0 * math.pi)) + 1, k0 + N_PSI - 1)
        rows = self.n_rows
        return max(rows[k % N_PSI] for k in range(k0, k1 + 1))

    def _grid(self, w: DryWhirl
              ) -> tuple[list[list[complex]], dict[int, list[complex]]] | None:
        """The DFT in beta of F and D on each psi row of the grid: fq[j][b] for j >= 0 and
        dq[j][b] for every j (|j| <= K_BETA + 1); None if Omega^2 is not positive
        everywhere or an event is not excluded on the orbit."""
        lo, hi = _omega2_bounds(w, self.E)
        if not (lo > 0.0 and w._no_event(lo, hi)):
            return None
        grid = w.beta_grid(_CB, _SB)
        k1 = K_BETA + 1
        rows_f = [_BETA_ROWS[k] for k in range(k1 + 1)]
        rows_d = [_BETA_ROWS[k] for k in range(-k1, k1 + 1)]
        fq: list[list[complex]] = [[] for _ in rows_f]
        dq: dict[int, list[complex]] = {k: [] for k in range(-k1, k1 + 1)}
        self.n_rows: list[float] = []
        for b in range(N_PSI):
            a = 2.0 * math.pi * b / N_PSI + w.phi
            cE, sE = math.cos(a), math.sin(a)
            fs, ds, ns = w.beta_row(grid, cE, sE, 2.0 * self.E - 2.0 * w.mge * sE)
            self.n_rows.append(max(ns))
            for q, row in zip(fq, rows_f):
                q.append(sum(map(mul, fs, row)))
            for k, row in zip(range(-k1, k1 + 1), rows_d):
                dq[k].append(sum(map(mul, ds, row)))
        return fq, dq


class StepMap:
    """A step of fixed length h (s) on an orbit as functions of its start (beta_s, psi_s) on
    the torus (docs/notes/dry-whirl-quadrature.md §9): the spin angle travelled,
    u = h/F_00 + x(beta_s, psi_s) (rad), and the periodic parts of the impulses,
    P - d00 u (N s) and, when a k != 0, int n dt - n_sec u (s), P = int (N + i F_t) dt.
    Each is a smooth periodic function of the start (the orbit's integrands are), sampled
    on the orbit's grid by ``_solve`` (Newton on the orbit's series to the ulp of u, in x
    and so rounded relative to x) and kept as its 2-D Fourier series: a step of h is then
    one evaluation of these sums in place of Newton's. Terms are left out, smallest first,
    while their sum with the check harmonics' (+-(K + 1), twice for the tail and the
    aliasing) stays within MAP_SHARE of the step's tolerance at the shortest u of the grid:
    for x the smaller of TOL_PHASE in theta and TOL_IMPULSE of u (u carries the mean
    impulse d00 u), for the impulses TOL_IMPULSE of the mean impulse |d00| u. ``ok`` is
    False where the check harmonics alone exceed it, or the orbit's own series exceed the
    rest of the tolerance (Newton then takes the steps)."""

    __slots__ = ("P", "Q", "U", "check_x", "every_step", "h", "ok", "x00")

    def __init__(self, orb: Orbit, w: DryWhirl, h: float) -> None:
        self.h = h
        xs: list[list[float]] = []
        ps: list[list[complex]] = []
        qs: list[list[complex]] = []
        for a in range(N_BETA):  # (rows over psi at one beta)
            rx, rp, rq = [], [], []
            for b in range(N_PSI):
                psi = 2.0 * math.pi * b / N_PSI
                g = on_orbit(orb, w, _BG[a], psi)
                x, P, q = _solve(orb, g, g.theta0, psi, h)
                rx.append(x)
                rp.append(P)
                rq.append(q)
            xs.append(rx)
            ps.append(rp)
            qs.append(rq)
        cx, cp = _dft2(xs), _dft2(ps)
        u_min, u_max = (h / orb.f00 + f(map(f, xs)) for f in (min, max))
        self.x00 = cx[(0, 0)].real
        tol_u = MAP_SHARE * min(TOL_PHASE * (1.0 + w.rho * u_min) / w.rho,
                                TOL_IMPULSE * u_min)  # (u carries the mean impulse d00 u)
        tol_p = MAP_SHARE * TOL_IMPULSE * abs(orb.d00) * u_min
        self.U, self.check_x = _map_rows(cx, tol_u, True)
        self.P, check_p = _map_rows(cp, tol_p, False)
        self.Q, check_q = (_map_rows(_dft2(qs), tol_p / w.akcr, False) if w.akcr
                           else (([], False), 0.0))
        self.ok = (self.check_x <= tol_u and check_p <= tol_p and check_q * w.akcr <= tol_p
                   and _within_tolerance(orb, w, u_min, 1.0 - MAP_SHARE, u_max))
        lo2 = _omega2_bounds(w, orb.E)[0]
        self.every_step = lo2 > 0.0 and _within_tolerance(
            orb, w, h * math.sqrt(lo2) * (1.0 - 1e-9), 1.0, h * orb.w_max * (1.0 + 1e-9))
        """``advance``'s check of the orbit's error holds for every step of h on the orbit
        (its du = h |Omega| lies between h times the bounds of |Omega| on it): not made."""

    def at(self, beta: float, psi: float) -> tuple[float, complex, complex]:
        """``_solve``'s (x = u - h/F_00 (rad), P - d00 u (N s), int n dt - n_sec u (s)) of
        the step of h from (beta, psi) (rad)."""
        zs = (cmath.rect(1.0, psi), cmath.rect(1.0, beta))  # (the bases of Horner's rule)
        x = self.x00 + 2.0 * _map_series(self.U, beta, psi, zs).real
        return (x, _map_series(self.P, beta, psi, zs),
                _map_series(self.Q, beta, psi, zs) if self.Q[0] else 0j)


def on_orbit(orb: Orbit, w: DryWhirl, beta: float, psi: float) -> DryWhirl:
    """The physics (``w``'s held inputs) of the state at (beta, psi) (rad) on ``orb``: theta
    = psi + phi - beta, Omega (in w's direction) and K0 from the orbit's energy."""
    g = DryWhirl(w.h, psi + w.phi - beta, psi, w.sig)
    g.K0 = _k0_on(orb, g)
    g.Omega0 = w.sig * math.sqrt(g.K0 / (w.I0 - w.c2 * math.cos(beta)))
    return g


MapRows = tuple[list[Row], bool]
"""A map's series: its rows (``_trimmed``) and whether they run over psi."""


def _map_series(rows: MapRows, beta: float, psi: float, zs: tuple[complex, complex]
                ) -> complex:
    """``_series`` of a map's rows (``_map_rows``: over psi, or over beta when flagged) at
    (beta, psi) (rad), zs = (e^{i psi}, e^{i beta})."""
    return _series(rows[0], beta, psi, zs[rows[1]])


def _dft2(x: list[list[Any]]) -> dict[tuple[int, int], complex]:
    """The 2-D DFT of values x[a][b] on the orbit's grid (beta_a, psi_b): the coefficients
    c_jl, |j| <= K_BETA + 1, |l| <= K_PSI + 1, of x = sum c_jl e^{i (j beta + l psi)}."""
    k1, jp1 = K_BETA + 1, K_PSI + 1
    cols = [[sum(map(mul, col, _BETA_ROWS[j])) for col in zip(*x)]
            for j in range(-k1, k1 + 1)]  # cols[j + k1][b]: the DFT in beta at psi_b
    return {(j, jp): sum(map(mul, cols[j + k1], _PSI_ROWS[jp + jp1]))
            for j in range(-k1, k1 + 1) for jp in range(-jp1, jp1 + 1)}


def _map_rows(c: dict[tuple[int, int], complex], tol: float, real: bool
              ) -> tuple[MapRows, float]:
    """The rows of ``_series`` for the kept part of a map's series c (for a real function
    the half j > 0 or j = 0 < l, to be doubled and added to c_00), over beta or over psi,
    whichever takes fewer (``_map_series``), smallest terms left out
    while the check harmonics' bound (2 sum |c|) plus theirs stays within tol; and that
    bound of the check harmonics alone."""
    k1, jp1 = K_BETA + 1, K_PSI + 1
    err = check = 2.0 * sum(abs(v) for (j, jp), v in c.items()
                            if abs(j) == k1 or abs(jp) == jp1)
    kept = {k for k in c if abs(k[0]) < k1 and abs(k[1]) < jp1
            and (k[0] > 0 or (k[0] == 0 and k[1] > 0) if real else True)}
    left = set()
    for k in sorted(kept - {(0, 0)}, key=lambda k: abs(c[k])):
        cost = abs(c[k]) * (2.0 if real else 1.0)
        if err + cost > tol:
            break
        err += cost
        left.add(k)
    rows = [_trimmed(lambda j, jp: c[(j, jp)] if (j, jp) in kept and (j, jp) not in left
                     else 0j, 0, by_psi) for by_psi in (False, True)]
    return (rows[0], False) if len(rows[0]) <= len(rows[1]) else (rows[1], True), check


def _small(c: dict[tuple[int, int], complex], scale: float) -> list[tuple[int, int]]:
    """The kept harmonics (|j| <= K_BETA, |l| <= K_PSI, not (0, 0)) of a series c at most
    TRIM scale: left out of the sums (at the rounding level of the grid's DFT, 1e-17 of the
    mean) and counted with the dropped ones."""
    return [(j, jp) for j in range(-K_BETA, K_BETA + 1) for jp in range(-K_PSI, K_PSI + 1)
            if (j, jp) != (0, 0) and abs(c[(j, jp)]) <= TRIM * scale]


def _dropped(c: dict[tuple[int, int], complex], left: list[tuple[int, int]], rho1: float
             ) -> tuple[float, float, float]:
    """The harmonics of a series c left out of its sum: (sum 2 |c_jl|/|w_jl| and sum |c_jl|
    over the fast ones, j != 0; sum |c_0l| over the slow ones), so that their integral over
    du rad of psi is at most min(first, second du) + third du."""
    fast = [k for k in left if k[0]]
    return (sum(2.0 * abs(c[k]) / abs(k[0] * rho1 + k[1]) for k in fast),
            sum(abs(c[k]) for k in fast), sum(abs(c[k]) for k in left if not k[0]))


def _trimmed(coef: Any, wide: int, by_psi: bool = False) -> list[Row]:
    """The rows j = -K_BETA-wide .. K_BETA+wide over l = -K_PSI-wide .. K_PSI+wide of
    coef(j, l) (the coefficients of a sum ``_series`` evaluates: the kept harmonics,
    wide = 0; one more each way for int n dt, wide = 1), each cut to the span of its nonzero
    entries (``Row``: the harmonic of its lowest term, its coefficients for Horner's rule);
    rows without any left out. ``by_psi``: the rows over l instead, each over j."""
    outer = range(-K_PSI - wide, K_PSI + wide + 1) if by_psi else range(
        -K_BETA - wide, K_BETA + wide + 1)
    inner = range(-K_BETA - wide, K_BETA + wide + 1) if by_psi else range(
        -K_PSI - wide, K_PSI + wide + 1)
    out = []
    for k in outer:
        row = [coef(i, k) if by_psi else coef(k, i) for i in inner]
        nz = [i for i, x in enumerate(row) if x]
        if nz:
            lo, top, rest = float(inner[nz[0]]), row[nz[-1]], row[nz[0]:nz[-1]][::-1]
            out.append((lo, float(k), top, rest) if by_psi else (float(k), lo, top, rest))
    return out


def _v_bound(w: DryWhirl) -> float:
    """|V| on the orbit is at most this (J): c_r |G| + m g e_c (T_drive = 0)."""
    return w.c_r * math.hypot(w.Gx, w.Gy) + abs(w.mge)


def _i_min(w: DryWhirl) -> float:
    return w.J + w.m * (w.R - w.e_c) ** 2


def _omega2_bounds(w: DryWhirl, E: float) -> tuple[float, float]:
    """Bounds of Omega^2 over the whole orbit of energy E (rad^2/s^2)."""
    vb = _v_bound(w)
    i_max = w.J + w.m * (w.R + w.e_c) ** 2
    return (2.0 * E - 2.0 * vb) / i_max, (2.0 * E + 2.0 * vb) / _i_min(w)


def energy(w: DryWhirl) -> float:
    """E = 1/2 I_P(beta) Omega^2 + V(theta, psi) (J) at ``w``'s start (T_drive = 0)."""
    return 0.5 * w.K0 - w.v0 + w.mge * w.sE0


def _k0_on(orb: Orbit, w: DryWhirl) -> float:
    """I_P Omega^2 = 2 (E - V) (J) at ``w``'s start on the orbit of energy E (the
    integral's K0 of ``w``, from the orbit's energy rather than the state's speed)."""
    return 2.0 * (orb.E - (-w.v0 + w.mge * w.sE0))


def _series(rows: list[Row], beta: float, psi: float, z: complex) -> complex:
    """sum_jl c_jl e^{i (j beta + l psi)} at (beta, psi) (rad) over the rows of ``_trimmed``,
    z = e^{i psi} for rows over psi (e^{i beta} for rows over beta): each row by Horner's
    rule in z, times e^{i (j beta + l psi)} of its lowest term (cmath.rect, cmath.exp's
    values without building i x). Two thirds of the instructions of the sum of products
    over power lists, whose complex operations allocate twice a term
    (docs/notes/dry-whirl-quadrature.md §9)."""
    s = 0j
    for j, jp, acc, rest in rows:
        for c in rest:
            acc = acc * z + c
        s += cmath.rect(1.0, j * beta + jp * psi) * acc
    return s


def advance(prev: Orbit | None, h: HeldInputs, theta: float, psi: float, Omega: float,
            rem: float, limit: int, step0: float) -> tuple[SegmentEnd | None, Orbit | None]:
    """Roll rem (s) on the orbit of the state (theta, psi, Omega) under ``h`` (T_drive = 0,
    a c = 0): (the segment's end, the orbit). The end is None where the method does not
    apply (the orbit's series do not converge, an event is not excluded, the step is too
    short for the impulses' tolerance, or the work limit is below its cost): the caller then
    advances the segment otherwise; the orbit is returned all the same, so that a refused
    orbit is not rebuilt every step."""
    w = DryWhirl(h, theta, psi, Omega)
    if not (rem > 0.0 and w.K0 > 0.0 and math.isfinite(w.K0)) or w.rho < RHO_MIN:
        return None, prev
    E = energy(w)
    key = orbit_key(h.p, h.J, h.a, h.F_ext, Omega)
    orb, build_work = prev, 0
    if orb is None or orb.key != key or not (
            abs(E - orb.E) <= E_MATCH * (0.5 * w.K0 + _v_bound(w))):
        if _v_bound(w) > EPS_MAX * E or w.c2 > DELTA_MAX * w.I0:
            return None, None  # (the series would not converge: not worth the grid)
        orb = Orbit(E, key)
        build_work = SAMPLE_WORK * N_PSI * N_BETA
    if not orb.built:
        orb.build(w)  # (a restored orbit's build is not charged: the run it continues
        # did not build it either, and the work counts must replay bit for bit)
    if not orb.ok:
        return None, None
    cost = build_work + SAMPLE_WORK * (2 * NEWTON_ITERS + 5)
    if cost > limit:
        return None, orb
    w.K0 = _k0_on(orb, w)  # Omega^2 on the path from the orbit's E
    m = orb.map
    if not (m is not None and m.h == rem and m.every_step) and not _within_tolerance(
            orb, w, rem * abs(Omega)):
        return None, orb
    return _step(orb, w, theta, psi, rem, cost, step0, _mapped(orb, w, theta, psi, rem, limit)
                 or _solve(orb, w, theta, psi, rem)), orb


def _mapped(orb: Orbit, w: DryWhirl, theta: float, psi: float, rem: float, limit: int
            ) -> tuple[float, complex, complex] | None:
    """The step of rem from the orbit's ``StepMap`` of rem: built when the orbit's last
    segment had the same length (and the work limit covers MAP_WORK; like a restored
    orbit's build it is not charged, so that the work counts are the state's alone), kept
    while the segments keep that length; None where there is none (``_solve`` then)."""
    m, last = orb.map, orb.last_rem
    orb.last_rem = rem
    if m is None or m.h != rem:
        if last != rem or limit < MAP_WORK:
            return None
        m = orb.map = StepMap(orb, w, rem)
    return m.at(psi + w.phi - theta, psi) if m.ok else None


def _within_tolerance(orb: Orbit, w: DryWhirl, du: float, share: float = 1.0,
                      du_err: float | None = None) -> bool:
    """The dropped harmonics' error over a step of du rad of psi within ``share`` of
    TOL_PHASE (1 + its turn of theta) rad of theta and of TOL_IMPULSE of its mean impulse.
    Each dropped term integrates to at most |c_jl| min(du, 2/|w_jl|) (``_dropped``).
    ``du_err`` >= du: the errors taken at du_err, the tolerances at du, so that the check
    holds for every step from du to du_err rad (both grow with the step)."""
    de = du if du_err is None else du_err
    a, b, c = orb.err_t
    e_t = min(a, b * de) + c * de
    a, b, c = orb.err_d
    e_d = min(a, b * de) + c * de + w.akcr * e_t
    return (e_t * w.rho * orb.w_max <= share * TOL_PHASE * (1.0 + w.rho * du)
            and e_d <= share * TOL_IMPULSE * abs(orb.d00) * du)


def _solve(orb: Orbit, w: DryWhirl, theta: float, psi: float, rem: float
           ) -> tuple[float, complex, complex]:
    """(x = u - rem/F_00 (rad of psi), P - d00 u (N s), int n dt - n_sec u (s)) of rem (s) of
    rolling on ``orb`` from (theta, psi), u the spin angle travelled and
    P = int (N + i F_t) dt: Newton on the orbit's series of t(u), then the periodic parts of
    the impulses, their series at both ends (int n dt only when a k != 0; else 0). Newton
    runs on x, with t(u) - rem = (F_00 u_lin - rem) + F_00 x + its periodic part: what
    varies from start to start is rounded relative to x, not to u (``StepMap`` samples x)."""
    sig, rho1 = w.sig, 1.0 + w.rho
    b_s = psi + w.phi - theta
    z0 = cmath.rect(1.0, psi)
    s_t0 = _series(orb.A, b_s, psi, z0)
    f00 = orb.f00
    u_lin = rem / f00
    r0 = f00 * u_lin - rem

    def residual(x: float) -> float:  # t(u_lin + x) - rem
        u = u_lin + x
        p = psi + sig * u
        s_t = _series(orb.A, b_s + rho1 * sig * u, p, cmath.rect(1.0, p))
        return r0 + f00 * x + 2.0 * (s_t - s_t0).real

    x = newton_offset(w, rem, u_lin, residual, orb.kappa)
    u = u_lin + x
    b, p = b_s + rho1 * sig * u, psi + sig * u
    z = cmath.rect(1.0, p)
    P = _series(orb.B, b, p, z) - _series(orb.B, b_s, psi, z0)
    int_n = _series(orb.C, b, p, z) - _series(orb.C, b_s, psi, z0) if w.akcr else 0j
    return x, P, int_n


def newton_offset(w: DryWhirl, rem: float, u_lin: float, residual: Any, kappa: float
                  ) -> float:
    """x = u - u_lin (rad of psi) with t(u) = rem (s), by Newton on ``residual(x)`` =
    t(u_lin + x) - rem: started at the mean rate where beta turns at least once in rem,
    else at the speed at the middle; t' = F = 1/|Omega| from ``w``'s energy integral, and
    stopped once the update du left kappa du^2 <= ulp(u) (kappa >= |F'/F|: the error after
    an update of du is at most kappa/2 du^2)."""
    u = rem * abs(w.Omega0)
    x = 0.0 if u * (1.0 + w.rho) > 2.0 * math.pi else rem * w._speed(0.5 * u) - u_lin
    for _ in range(NEWTON_ITERS):
        du = residual(x) * w._speed(u_lin + x)
        x = max(-u_lin, x - du)
        if kappa * du * du <= math.ulp(u_lin + x):
            break
    return x


def _step(orb: Orbit, w: DryWhirl, theta: float, psi: float, rem: float, work: int,
          step0: float, solved: tuple[float, complex, complex]) -> SegmentEnd:
    """The end of rem (s) of rolling on ``orb`` from (theta, psi) (``w``: its physics, with
    K0 from the orbit's energy) that travels u rad of psi with the periodic parts of the
    impulses of ``solved`` (``_solve`` or the orbit's ``StepMap``)."""
    x, P, int_n = solved
    u = rem / orb.f00 + x
    P += orb.d00 * u
    int_n = orb.n_sec * u + int_n if w.akcr else 0j
    return segment_end(w, psi, rem, u, P, int_n, orb.peak_on, work, step0, orb)


def segment_end(w: DryWhirl, psi: float, rem: float, u: float, P: complex, int_n: complex,
                peak_on: Any, work: int, step0: float, orb: Any) -> SegmentEnd:
    """The end of rem (s) of rolling from ``w``'s start (psi (rad)) that travels u rad of
    psi with the impulses P = int (N + i F_t) dt (N s) and int n dt (s): the path at both
    ends, the contact impulse from the momentum balance, the peak N (at the ends and, where
    beta turns through every phase, ``peak_on(psi_a, psi_b)`` over the rows of a grid, else
    at the middle), the tally; ``orb`` is kept for the next step (``Orbit`` or
    ``dry_whirl_driven.LevelTable``)."""
    sig, rho1 = w.sig, 1.0 + w.rho
    start, end = w._path(0.0), w._path(u)
    Pc = w.contact_impulse(u, rem, int_n, (start, end))
    _, N, _, om2, th = end
    peak = max(abs(N), abs(start[1]))
    if u * rho1 >= 2.0 * math.pi:  # beta has turned through every phase
        peak = max(peak, peak_on(psi, psi + sig * u))
    else:
        peak = max(peak, abs(w._path(0.5 * u)[1]))
    Om = sig * math.sqrt(om2)
    mc = w.m * w.c_r  # the tally is per unit m c_r (wall.ContactTally)
    tally = ContactTally(P.real / mc, Pc / mc, P.imag / mc, 0.0, peak / mc, work)
    # (I_n, I_c, I_t, I_e, peak, work; then SegmentEnd's fields in order, z = v = 0j:
    # positional, a step's end every step on the orbit)
    return SegmentEnd(rem, th, -w.rho * Om, None, tally, step0, 0j, 0j, psi + sig * u, Om,
                      work, orb)
