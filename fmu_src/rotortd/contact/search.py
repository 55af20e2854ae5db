"""Rigorous location of the first contact of a free flight with the clearance circle.

Frame and units: inertial, SI. The gap function is g(s) = |z(s)|^2 - c_r^2 (m^2); a
contact is its first zero in (0, h].

Method (conservative advancement with a Taylor bound). At a point s with exact state
(z, v) from the closed form, g, g' = 2 Re(conj(z) v), g'' = 2|v|^2 + 2 Re(conj(z) z'') and
g''' = 6 Re(conj(v) z'') + 2 Re(conj(z) z''') are exact to rounding, and on [s, s + tau],
as long as |z| <= c_r,

    |v| <= V = |v(s)| + K tau,   |z''| <= A = beta V + K,   |z'''| <= Jm = beta A + kappa V + J,
    |z''''| <= L = beta Jm + kappa A + |Omega| J,
    |g'''| <= G3 = 6 V A + 2 c_r Jm,   |g''''| <= G4 = 6 A^2 + 8 V Jm + 2 c_r L

(flight.py defines K and J). As u^4/24 <= (tau/4) u^3/6 on [0, tau], the quartic
remainder folds into the cubic term: g(s + u) <= p(u) = g + g' u + g'' u^2/2 + c3 u^3/6,
c3 = g''' + G4 tau/4 + the rounding band of g''' (``g3_slack``). If p < 0 on (0, tau]
there is no contact there; otherwise the first root u* of p is a safe step: a contact
before s + u* would be a first exit at which the bound (valid up to it) is negative, a
contradiction. Advancing by u* converges to a transversal root from below with
fourth-order convergence (p and g differ by O(u^4)), and passes a near-miss in
O(log(1/miss)) steps; a crossing can never be stepped over, whatever its depth, which
is what makes grazing contacts impossible to miss. ``flight_is_clear``, which only needs
a yes over one short step, uses the plain cubic bound G3 u^3/6 instead: there the exact
g''' costs more than it gains (measured).

Resolution: contact is declared when g >= -TOL_G (|z| within 32 ulp of c_r). If the
trajectory is moving outward there and its predicted excursion beyond the wall exceeds
TOL_G, it is an impact, polished by Newton to |g| of a few ulp. Otherwise it is a
*touch* (normal speed zero to resolution): the caller decides between sustained
contact (the free motion curves outward, g'' > 0) and flying on (g'' <= 0).
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass

from ..segments.flight import FlightModel, Modes
from .events import CLEAR, IMPACT, TOUCH, Event

EPS = 2.220446049250313e-16
INF = math.inf
TOL_G_ULPS = 64.0
"""Contact resolution: g >= -TOL_G_ULPS * eps * c_r^2 counts as at the wall."""
TINY = 5e-324
"""Smallest subnormal double: the absolute rounding error of an operation that underflows."""
G2_FLOOR = 1024.0 * TINY
"""Absolute part of the rounding bands of g' and g'' (m^2/s, m^2/s^2): with subnormal
forces or speeds their relative bands vanish, but the products in g' and g'' still carry
an absolute error of a few TINY, enough to flip a sign (fuzzing: a 1e-313 N force)."""
BRACKET_RTOL = 1e-6
"""Relative width at which the bracket of the cubic's first root stops (its left end is
returned). Any point left of the root is a safe step; near a contact the next advance
starts 1e-6 of a step short of the root and closes the rest with the cubic's own accuracy."""
HORIZON = 0.5
"""Longest interval (in units of 1/w, w the flight's fastest rate) one bound covers: the
slack G4 tau/4 grows with the interval, so a longer one only shortens the safe step."""
MAX_ADVANCES = 400
"""Advances in one search call (a grazing pass needs ~40); a flight creeping along the
wall for long may need more, and the caller then resumes from where the search stopped."""
CREEP = 2.0**-20
"""An advance shorter than CREEP times its interval is creeping: the Taylor bound of g'''
(g3 plus the quartic slack) is loose there, by up to 1e9 where the orbit osculates the
circle after a lift-off at N = 0 (flights of 7.5e-16 s until the work bound, found by the
core fuzz), and the modes' bound is tried (ContactLocator._creep_bound)."""
CREEP_RUN = 16
"""Creeping advances of one search, the gap not closing (g' <= 0), before the modes' bound is
tried: a flight that creeps along the wall does so for thousands; the short flights between
the impacts of a chattering sequence take a few creeping advances each, and keep the Taylor
bound (the same bits as before the modes' bound existed)."""
CREEP_WORK = 4
"""Work units of the modes' bound of g''' (16 pairs of modes, about four points' work)."""
WORK_MAX = 1_600_000
"""Work bound of one communication step, in work units (``Work``; docs/model.md 7): a
step that would need more stops with STATUS_WORK_CAP (TouchdownCore and SpinCore alike).
Every loop of the core counts into one counter; it is checked before each segment, at
each advance of the contact search and at each step of the sliding integrator."""
WORK_OVERSHOOT = 20_000
"""Most work units a step can use beyond WORK_MAX: what runs between two checks of the
bound. The largest such piece is a step of the held sliding integrator with its event
location: at most 1 + 41 + ROOT_ITERS = 102 extrapolations (the step, stepping off the
event surface, the root finder) of at most gbs.RHS_WORK * 90 + gbs.STEP_WORK = 196 units
each, 19,992 (segments.sliding.Sliding._locate; tests/test_work_bound.py)."""
SEGMENT_WORK = 8
"""Work units charged for each segment of a step's event loop (a flight to the next event,
an impact, a contact segment, a mode change): its fixed cost besides the loops it runs
(a new search with its modes, the impact law, the contact models, a flight map), so that
no kind of segment costs more time per unit than a search advance (docs/model.md 7)."""
FLIGHT_MAP_WORK = 6
"""Work units of a point of the search from the divided-difference flight map (when the
modes are ill conditioned): it computes the map's coefficients, the time of about 6 search
advances (measured)."""


@dataclass(slots=True)
class Work:
    """Deterministic work counter: closed-form evaluations, root-finder and integrator
    iterations, and the segments of a step's event loop (SEGMENT_WORK each)."""

    evals: int = 0
    iters: int = 0
    segs: int = 0  # SEGMENT_WORK per segment of the step's event loop

    @property
    def total(self) -> int:
        """evals + iters + segs."""
        return self.evals + self.iters + self.segs


@dataclass(slots=True)
class Contact:
    """First contact of a flight: local time ``s`` (s), state z (m), v (m/s), phasor E.
    (Slotted, not frozen: a frozen dataclass's construction cost 590 ns, one per flight.)

    ``kind`` (``Event``) is IMPACT (moving outward, normal speed resolved), TOUCH (normal speed
    zero to resolution, free motion curving outward into the wall) or CLEAR (no contact
    up to ``s``: the search used its MAX_ADVANCES and the caller resumes from there).
    """

    s: float
    z: complex
    v: complex
    E: complex
    kind: Event


def _cubic(g0: float, g1: float, g2: float, g3: float, u: float) -> float:
    return g0 + u * (g1 + u * (0.5 * g2 + u * g3 / 6.0))


def _critical_points(g1: float, g2: float, g3: float, tau: float) -> list[float]:
    """Roots in (0, tau) of p'(u) = g1 + g2 u + g3 u^2/2, sorted."""
    pts: list[float] = []
    a = 0.5 * g3  # may underflow to 0 for a denormal g3: branch on a itself
    if a == 0.0:
        if g2 != 0.0:
            pts.append(-g1 / g2)
    else:
        disc = g2 * g2 - 4.0 * a * g1
        if disc >= 0.0:
            r = disc**0.5
            q = -0.5 * (g2 + (r if g2 >= 0.0 else -r))
            cands = [q / a]
            if q != 0.0:
                cands.append(g1 / q)
            pts.extend(cands)
    return sorted(u for u in pts if 0.0 < u < tau)


_NO_RESCALE = 2.0**-600
"""Cubics with a coefficient at least this large need no rescaling (_unit_scale)."""


def _unit_scale(g0: float, g1: float, g2: float, g3: float) -> tuple[float, ...]:
    """The coefficients times a power of two (exact) that brings the largest near 1, when
    all are below 2^-600: else p(u) of subnormal forces underflows to -0.0, a false root."""
    big = max(abs(g0), abs(g1), abs(g2), abs(g3))
    if big == 0.0 or big >= _NO_RESCALE:
        return g0, g1, g2, g3
    e = -math.frexp(big)[1]
    return math.ldexp(g0, e), math.ldexp(g1, e), math.ldexp(g2, e), math.ldexp(g3, e)


def _negative_throughout(g0: float, g1: float, g2: float, g3: float, tau: float) -> bool:
    """Quick sufficient test that p < 0 on [0, tau]: p(u) <= g0 + its positive terms at tau."""
    p3 = tau * g3 / 6.0 if g3 > 0.0 else 0.0  # conditionals, not max(): the hottest test
    p2 = 0.5 * g2 if g2 > 0.0 else 0.0
    return g0 + tau * ((g1 if g1 > 0.0 else 0.0) + tau * (p2 + p3)) < 0.0


def g3_bound(fm: FlightModel, v: complex, tau: float) -> float:
    """Bound G3 (m^2/s^3) of |g'''| on a free flight of length tau (s) that starts with
    velocity v (m/s, inertial) and stays inside the clearance (module docstring): 6 V A +
    2 c_r Jm with V = |v| + K tau, as the polynomial FlightModel.g3_poly in V."""
    V = abs(v) + fm.K * tau
    s0, s1, s2 = fm.g3_poly
    return s0 + V * (s1 + V * s2) + TINY  # rounded up, never 0 by underflow


def g3_exact(fm: FlightModel, z: complex, v: complex, acc: complex, E: complex) -> float:
    """Third derivative g''' (m^2/s^3) of the free flight at (z, v) with z'' = acc (m, m/s,
    m/s^2, inertial; phasor E = e^{i psi}), exact to rounding."""
    jerk = fm.jerk(v, acc, E)
    return 6.0 * (v.conjugate() * acc).real + 2.0 * (z.conjugate() * jerk).real


def g3_slack(fm: FlightModel, v: complex, tau: float) -> float:
    """Slack S (m^2/s^3) with g(s + u) <= g + g' u + g'' u^2/2 + (g''' + S) u^3/6 for u in
    [0, tau] (s), on a free flight that starts with velocity v (m/s, inertial) and stays
    inside the clearance: the quartic remainder G4 tau/4, plus the rounding band of the
    computed g''' (16 eps of G3 = 6 V A + 2 c_r Jm, which bounds its terms; module
    docstring). G3 and G4 are the polynomials FlightModel.g3_poly and g4_poly in V."""
    V = abs(v) + fm.K * tau
    s0, s1, s2 = fm.g3_poly
    q0, q1, q2 = fm.g4_poly
    return 0.25 * tau * (q0 + V * (q1 + V * q2)) + 16.0 * EPS * (s0 + V * (s1 + V * s2)) + TINY


def flight_is_clear(fm: FlightModel, z: complex, v: complex, E: complex, tau: float) -> bool:
    """True if the cubic bound proves that the free flight from (z, v) (m, m/s, inertial;
    phasor E = e^{i psi}) stays off the wall for tau seconds: the first test of
    ``ContactLocator.find``, for callers that only need a yes. False means 'not proved'.
    Cubics that would need rescaling (|g| < 2^-600, a sub-atomic clearance) are left to
    the search."""
    c2 = fm.c_r * fm.c_r
    g = (z * z.conjugate()).real - c2
    if g >= -TOL_G_ULPS * EPS * c2 or g > -_NO_RESCALE:  # at the wall, or tiny: search
        return False
    acc = fm.accel(z, v, E)
    g1 = 2.0 * (z.conjugate() * v).real
    g2 = 2.0 * (v * v.conjugate()).real + 2.0 * (z.conjugate() * acc).real
    return _negative_throughout(g, g1, g2, g3_bound(fm, v, tau), tau)


def safe_step(g0: float, g1: float, g2: float, g3: float, tau: float, work: Work) -> float | None:
    """Lower bound of the first root in (0, tau] of p(u) = g0 + g1 u + g2 u^2/2 + g3 u^3/6.

    Requires g0 <= 0 (g0 == 0 means 'on the wall'; then p(u)/u is examined). Returns
    None when p < 0 on all of (0, tau]; otherwise a u > 0 with p < 0 on (0, u].
    """
    if g0 > -_NO_RESCALE:  # else the coefficients are not all tiny: nothing to rescale
        g0, g1, g2, g3 = _unit_scale(g0, g1, g2, g3)
    if g0 < 0.0 and _negative_throughout(g0, g1, g2, g3, tau):
        return None  # the common case, quickly
    return _first_root_step(g0, g1, g2, g3, tau, work)


def _first_root_step(g0: float, g1: float, g2: float, g3: float, tau: float, work: Work
                     ) -> float | None:
    """safe_step after its quick test failed (coefficients already rescaled): the left end
    of the bracket of p's first root in (0, tau], or None when p < 0 throughout."""
    if g0 == 0.0:
        return _safe_step_on_wall(g1, g2, g3, tau, work)
    knots = [0.0, *_critical_points(g1, g2, g3, tau), tau]
    lo = 0.0
    for hi in knots[1:]:
        if _cubic(g0, g1, g2, g3, hi) >= 0.0:
            return _bracket_left((g0, g1, g2, g3), lo, hi, work)
        lo = hi
    return None


def _safe_step_on_wall(g1: float, g2: float, g3: float, tau: float, work: Work) -> float | None:
    """First root of q(u) = g1 + g2 u/2 + g3 u^2/6 in (0, tau] (p = u q), q(0) = g1 <= 0."""
    if g1 > 0.0 or (g1 == 0.0 and g2 >= 0.0):
        return 0.0
    knots = [0.0]
    if g3 != 0.0 and 0.0 < -1.5 * g2 / g3 < tau:
        knots.append(-1.5 * g2 / g3)
    knots.append(tau)
    lo = 0.0
    for hi in knots[1:]:
        if g1 + hi * (0.5 * g2 + hi * g3 / 6.0) >= 0.0:
            return _bracket_left((None, g1, g2, g3), lo, hi, work)
        lo = hi
    return None


def _bracket_left(
    coeffs: tuple[float | None, float, float, float], lo: float, hi: float, work: Work
) -> float:
    """Shrink [lo, hi] by Illinois; return the left end. ``coeffs`` = (g0, g1, g2, g3): the
    function is p(u) = g0 + u q(u), q(u) = g1 + u (g2/2 + u g3/6), or q itself when g0 is
    None (on the wall); it is increasing on [lo, hi] with f(lo) < 0 <= f(hi). A declared
    accelerator: the one root finder (``segments.roots.illinois`` on -f) inlined, as this
    loop is the search's innermost one, with p evaluated inline (the same expressions as
    _cubic); tests/test_core_events.py checks that the two give the same bits."""
    g0, g1, g2, g3 = coeffs
    c2 = 0.5 * g2
    flo = g1 + lo * (c2 + lo * g3 / 6.0)
    fhi = g1 + hi * (c2 + hi * g3 / 6.0)
    if g0 is not None:
        flo, fhi = g0 + lo * flo, g0 + hi * fhi
    side = 0
    for _ in range(100):
        work.iters += 1
        if hi - lo <= BRACKET_RTOL * hi:
            break
        x = (lo * fhi - hi * flo) / (fhi - flo) if fhi != flo else 0.5 * (lo + hi)
        if not lo < x < hi:
            x = 0.5 * (lo + hi)
        fx = g1 + x * (c2 + x * g3 / 6.0)
        if g0 is not None:
            fx = g0 + x * fx
        if fx < 0.0:
            lo, flo = x, fx
            if side == -1:
                fhi *= 0.5
            side = -1
        else:
            hi, fhi = x, fx
            if side == 1:
                flo *= 0.5
            side = 1
    return lo


class ContactLocator:
    """Finds the first contact of one flight (fixed FlightModel and initial state)."""

    def __init__(self, fm: FlightModel, z0: complex, v0: complex, E0: complex) -> None:
        self.fm = fm
        self.z0, self.v0, self.E0 = z0, v0, E0
        self.c2 = fm.c_r * fm.c_r
        self.tol_g = TOL_G_ULPS * EPS * self.c2
        w = max(fm.rate, abs(v0) / fm.c_r)
        self.horizon = HORIZON / w if w > 0.0 else math.inf
        self._modes: Modes | None = None  # built on the first state() call
        self._modes_built = False

    def state(self, s: float, work: Work) -> tuple[complex, complex, complex]:
        """Exact (z, v, E) at local time s, from the flight's start (no drift): by modes
        when they are well conditioned, else by the divided-difference flight map."""
        work.evals += 1
        modes = self._get_modes()
        if modes is not None:
            z, v, rot = modes.at(s)
            return z, v, self.E0 * rot
        work.evals += FLIGHT_MAP_WORK - 1
        z, v = self.fm.propagate(self.z0, self.v0, self.E0, s)
        return z, v, self.E0 * cmath.exp(1j * self.fm.Omega * s)

    def _creep_bound(self, s: float, work: Work) -> float:
        """The modes' bound of |g'''| from local time s on (Modes.g3_bound: the amplitudes
        only decay, so it holds for the rest of the search), for a search that creeps (an
        advance shorter than CREEP times its interval); NaN when the modes are ill
        conditioned (no bound, and no second try: NaN compares false)."""
        md = self._get_modes()
        if md is None:
            return math.nan
        work.evals += CREEP_WORK
        return md.g3_bound(s)

    def _get_modes(self) -> Modes | None:
        """The flight's modes (FlightModel.modes), built on first use; None when they are
        ill conditioned (then points come from the divided-difference flight map)."""
        if not self._modes_built:
            self._modes, self._modes_built = self.fm.modes(self.z0, self.v0, self.E0), True
        return self._modes

    def g3(self, z: complex, v: complex, E: complex) -> float:
        """Exact third derivative of g (m^2/s^3) of the free flight at (z, v, E)."""
        return g3_exact(self.fm, z, v, self.fm.accel(z, v, E), E)

    def grace_step(self, z: complex, v: complex, E: complex) -> float:
        """Step (s) off the wall for a tangential departure: g, g', g'' zero to resolution
        and g3 <= 0, so that the cubic term governs.

        The larger of (a) the time the cubic needs to get 8 TOL_G inside,
        (48 TOL_G/|g3|)^(1/3), capped at 4|g3|/(G3 w) (w the flight's fastest rate) so
        that the cubic still dominates the quartic term, and (b) the time the bound G3 of
        |g3| needs to move the rotor TOL_G outward, (6 TOL_G/G3)^(1/3), within which no
        contact can be resolved whatever g3 is (g3 = 0: a rotor at rest on the wall)."""
        g3 = self.g3(z, v, E)
        fm = self.fm
        G3 = g3_bound(fm, v, 0.0)
        w = max(fm.rate, abs(v) / fm.c_r)
        cubic = (48.0 * self.tol_g / max(-g3, 1e-300)) ** (1.0 / 3.0)
        if G3 * w > 0.0:
            cubic = min(cubic, 4.0 * abs(g3) / (G3 * w))
        return max(cubic, (6.0 * self.tol_g / G3) ** (1.0 / 3.0))

    def bands(self, v: complex) -> tuple[float, float]:
        """Rounding bands of g' (m^2/s) and g'' (m^2/s^2) at the wall with velocity v. The
        band of g'' = 2 c_r^2 Gn is four times wider than the contact side's band of Gn
        (WallForces.gn_tol), so a state is never 'pressing' here and 'leaving' there."""
        fm = self.fm
        force = abs(fm.f0) + abs(fm.F1) + fm.kappa * fm.c_r + fm.beta * abs(v)
        tol_g1 = 16.0 * EPS * fm.c_r * abs(v) + G2_FLOOR
        tol_g2 = 256.0 * EPS * (abs(v) ** 2 + fm.c_r * force) + G2_FLOOR
        return tol_g1, tol_g2

    def find(self, h: float, on_wall: bool, work: Work, limit: int = MAX_ADVANCES
             ) -> Contact | None:
        """First contact in (0, h], or None. ``on_wall``: the start lies on the circle.

        At most min(limit, MAX_ADVANCES) advances (at least one), each of which costs at
        least one work unit; then it returns a CLEAR contact where it stopped. The caller
        passes the work left in its step, so a search never runs past the step's bound.

        Each advance bounds g over tau = min(remaining, horizon) by the cubic with the
        exact g''' plus g3_slack, and steps to the bound's first root, or by tau if it
        has none there. (The plain cubic bound needed a second, shorter tau near a root;
        with the slack G4 tau/4 already small beside g''' there, re-bounding cost more than
        it saved.) A search that creeps (CREEP_RUN advances shorter than CREEP of their
        interval, the gap not closing) bounds g''' by the modes from there on, where that is
        smaller (``_creep_bound``; docs/model.md §3, creeping flights).

        The loop is the core's hottest code (about 8 trial points per flight, 11% fewer
        instructions inline), so it evaluates the point, its bound and safe_step's quick
        no-root test inline: the expressions are those of FlightModel.accel and jerk,
        g3_exact, g3_slack, safe_step and Modes.at, in the same order, so the results are
        bit-identical to composing those helpers (tests/test_core_events.py pins it)."""
        s = 0.0
        z, v, E = self.z0, self.v0, self.E0
        wall = on_wall
        fm, c2, tol_g = self.fm, self.c2, self.tol_g
        beta, kappa, f0, F1 = fm.beta, fm.kappa, fm.f0, fm.F1
        iWF1 = 1j * fm.Omega * F1
        K = fm.K
        s0, s1, s2 = fm.g3_poly
        q0, q1, q2 = fm.g4_poly
        horizon = self.horizon
        Kh, qh = K * horizon, 0.25 * horizon  # g3_slack's K tau and tau/4 at tau = horizon
        neg_rescale = -_NO_RESCALE
        exp = cmath.exp
        modal = 0  # 1: points by Modes.at (inline), -1: by self.state, 0: not decided yet
        c3_modes, creep, creeps = INF, CREEP, 0  # the modes' bound of |g'''| once creeping
        for _ in range(MAX_ADVANCES if limit >= MAX_ADVANCES else max(limit, 1)):
            acc = -beta * v - kappa * z + f0 + F1 * E
            zc = z.conjugate()
            g = (z * zc).real - c2
            g1 = 2.0 * (zc * v).real
            g2 = 2.0 * (v * v.conjugate()).real + 2.0 * (zc * acc).real
            if g >= -tol_g or (wall and s == 0.0):
                bands = self.bands(v)
                hit = self._at_wall(s, z, v, E, g, g1, g2, bands, work, first=(s == 0.0))
                if hit is not None:
                    return hit
                g, g1 = 0.0, min(g1, 0.0)
                tol_g1, tol_g2 = bands
                if g1 >= -tol_g1 and g2 >= -tol_g2 and s < h:  # tangential departure
                    s = min(h, s + self.grace_step(z, v, E))
                    z, v, E = self.state(s, work)
                    continue
            remaining = h - s
            if remaining <= 0.0:
                return None
            jerk = -beta * acc - kappa * v + iWF1 * E
            g3 = 6.0 * (v.conjugate() * acc).real + 2.0 * (zc * jerk).real
            if remaining > horizon:  # tau = min(remaining, horizon)
                tau = horizon
                V = abs(v) + Kh
                slack = qh * (q0 + V * (q1 + V * q2))
            else:
                tau = remaining
                V = abs(v) + K * tau
                slack = 0.25 * tau * (q0 + V * (q1 + V * q2))
            c3 = g3 + (slack + 16.0 * EPS * (s0 + V * (s1 + V * s2)) + TINY)
            if c3 > c3_modes:  # (creeping: the modes' bound is the tighter one)
                c3 = c3_modes
            if g <= neg_rescale:  # safe_step's quick test (no rescaling can apply)
                p3 = tau * c3 / 6.0 if c3 > 0.0 else 0.0
                p2 = 0.5 * g2 if g2 > 0.0 else 0.0
                quiet = g + tau * ((g1 if g1 > 0.0 else 0.0) + tau * (p2 + p3)) < 0.0
            else:
                quiet = None  # not tested here: safe_step rescales and tests
            if quiet:  # no contact within tau
                if tau >= remaining:
                    return None
                s = s + tau
            else:
                u = (safe_step(g, g1, g2, c3, tau, work) if quiet is None
                     else _first_root_step(g, g1, g2, c3, tau, work))
                if u is not None and u < creep * tau and g1 <= 0.0:
                    creeps += 1
                    if creeps == CREEP_RUN:
                        c3_modes = self._creep_bound(s, work)
                        if c3 > c3_modes:
                            um = safe_step(g, g1, g2, c3_modes, tau, work)
                            u = um if um is None or um > u else u
                if u is None:
                    if tau >= remaining:
                        return None
                    u = tau
                if u <= 0.0:
                    # at the wall with g1 = g2 = 0 and nothing pushing: treat as touch
                    return Contact(s, z, v, E, TOUCH)
                s = s + u if u < remaining else h
            if modal == 0:
                md = self._get_modes()
                modal = -1 if md is None else 1
                if md is not None:
                    Z0, Z1, a1, a2, iw, l1, l2 = md.Z0, md.Z1, md.a1, md.a2, md.iw, md.l1, md.l2
                    E0 = self.E0
            if modal < 0:
                z, v, E = self.state(s, work)
                continue
            work.evals += 1  # self.state by modes, inline
            rot = exp(iw * s)
            e1 = a1 * exp(l1 * s)
            e2 = a2 * exp(l2 * s)
            zs = Z1 * rot
            z, v, E = Z0 + zs + e1 + e2, iw * zs + l1 * e1 + l2 * e2, E0 * rot
        return Contact(s, z, v, E, CLEAR)  # proved free of contact up to s; resume there

    def _at_wall(
        self,
        s: float,
        z: complex,
        v: complex,
        E: complex,
        g: float,
        g1: float,
        g2: float,
        bands: tuple[float, float],
        work: Work,
        first: bool,
    ) -> Contact | None:
        """Classify a point at the wall: impact, touch, or None (leaving / grazing by).
        ``bands``: the rounding bands of g' and g'' there (``bands(v)``)."""
        tol_g1, tol_g2 = bands
        outward = g1 > tol_g1
        if outward and g2 < 0.0:
            outward = g + g1 * g1 / (-2.0 * g2) > self.tol_g  # resolvable excursion
        if outward:
            if first:
                return Contact(s, z, v, E, IMPACT)
            return self._polish(s, z, v, E, g, g1, work)
        if g1 < -tol_g1:
            return None
        if g2 > tol_g2 or (g2 >= -tol_g2 and self.g3(z, v, E) > 0.0):
            return Contact(s, z, v, E, TOUCH)
        return None

    def _polish(
        self, s: float, z: complex, v: complex, E: complex, g: float, g1: float, work: Work
    ) -> Contact:
        """Newton on g from a point within TOL_G of the wall; keep the best point."""
        best = (abs(g), s, z, v, E)
        for _ in range(3):
            if g1 <= 0.0:
                break
            s_new = s - g / g1
            if s_new == s:
                break
            z, v, E = self.state(s_new, work)
            s = s_new
            g = (z * z.conjugate()).real - self.c2
            g1 = 2.0 * (z.conjugate() * v).real
            if abs(g) < best[0]:
                best = (abs(g), s, z, v, E)
            if abs(g) <= 4.0 * EPS * self.c2:
                break
        _, s, z, v, E = best
        return Contact(s, z, v, E, IMPACT)
