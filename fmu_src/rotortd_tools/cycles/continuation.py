"""Pseudo-arclength continuation of period-one cycles in gamma, and its events.

Folds, period doublings, torus bifurcations, grazing and the BEB birth, located on the core
map (scaled co-rotating; gamma dimensionless).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, replace

import numpy as np
import scipy.linalg
import scipy.optimize
from rotortd.scaled import chapter_params, wrap_angle

from rotortd_tools.cycles.closed_form import labelled_cycles, max_radius_in_flight, period_condition
from rotortd_tools.cycles.fixed_points import (
    NewtonFailed,
    cycle_at,
    map_residual,
    multipliers_of,
    newton_fixed_point,
)
from rotortd_tools.cycles.impact_map import Flight, ImpactMap, NoImpact, post_impact_state

MARGIN_STOP = 1e-3
"""Continuation stops when the grazing margin falls below this (grazing located after)."""


@dataclass(frozen=True)
class BranchPoint:
    """One point of a continued cycle branch (scaled co-rotating), or a located event.

    branch: id of the branch; gamma; x = (alpha, rdot+, thetadot+); T period; rdot impact
    speed rdot-; multipliers; stable; margin = 1 - max interior |U| in flight;
    dgamma_ds: gamma component of the unit tangent (its sign change marks a fold);
    pd: det(DP + I) (its sign change marks a period doubling, a real multiplier at -1);
    event: None, or "fold", "period_doubling", "grazing", "beb_birth", "torus" (a complex
    pair crossing the unit circle).
    """

    branch: str
    gamma: float
    x: tuple[float, float, float]
    T: float
    rdot: float
    multipliers: tuple[complex, ...]
    stable: bool
    margin: float
    dgamma_ds: float
    pd: float
    event: str | None = None


def _fixed_point_system(
    y: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, Flight, np.ndarray]:
    """F(y) = P(x; gamma) - x and its 3x4 Jacobian for y = (x, gamma) (core map, analytic J)."""
    sp = chapter_params(gamma=float(y[3]))
    P = ImpactMap(sp)
    F, fl = map_residual(P, y[:3])
    Jx, Jg = P.jacobian(fl)
    return F, np.column_stack([Jx - np.eye(3), Jg]), fl, Jx


def _tangent(DF: np.ndarray, prev: np.ndarray | None) -> np.ndarray:
    """Unit null vector of the 3x4 DF, oriented along ``prev`` (or towards larger gamma)."""
    _, _, Vt = np.linalg.svd(DF)
    t = Vt[-1]
    ref = prev if prev is not None else np.array([0.0, 0.0, 0.0, 1.0])
    return t if float(t @ ref) >= 0.0 else -t


def _correct(
    y_pred: np.ndarray, t: np.ndarray, tol: float = 1e-11, max_iter: int = 8
) -> tuple[np.ndarray, Flight, np.ndarray, np.ndarray]:
    """Newton on (F(y) = 0, t.(y - y_pred) = 0); returns (y, flight, DF, DP)."""
    y = y_pred.copy()
    for _ in range(max_iter):
        if y[1] >= 0.0 or y[3] <= 0.0:
            raise NewtonFailed("left the physical domain (rdot+ >= 0 or gamma <= 0)")
        F, DF, fl, Jx = _fixed_point_system(y)
        if fl.kind != "impact":
            raise NewtonFailed("grazing touch")
        g = np.append(F, t @ (y - y_pred))
        if np.max(np.abs(g)) < tol:
            return y, fl, DF, Jx
        y = y - np.linalg.solve(np.vstack([DF, t]), g)
        y[0] = wrap_angle(y[0])
    raise NewtonFailed("corrector did not converge")


def _branch_point(branch: str, y: np.ndarray, fl: Flight, Jx: np.ndarray, t: np.ndarray):
    sp = chapter_params(gamma=float(y[3]))
    lam = multipliers_of(Jx)
    U0, dU0 = post_impact_state(y[:3])
    margin = 1.0 - max_radius_in_flight(sp, U0, dU0, fl.T)
    return BranchPoint(
        branch=branch,
        gamma=float(y[3]),
        x=(float(y[0]), float(y[1]), float(y[2])),
        T=fl.T,
        rdot=fl.rdot,
        multipliers=tuple(complex(v) for v in lam),
        stable=bool(np.max(np.abs(lam)) < 1.0),
        margin=margin,
        dgamma_ds=float(t[3]),
        pd=float(np.real(np.prod(1.0 + lam))),
    )


def continue_branch(
    branch: str,
    x0: np.ndarray,
    gamma0: float,
    direction: float,
    gamma_range: tuple[float, float],
    ds: float = 0.01,
    ds_max: float = 0.04,
    max_points: int = 400,
    rdot_min: float = 1e-7,
) -> list[BranchPoint]:
    """Pseudo-arclength continuation of a cycle of the core map in (x, gamma).

    Stops when gamma leaves ``gamma_range``, at grazing (margin <= 0: beyond it the flight
    would hit the wall earlier, the cycle is virtual), when rdot- < rdot_min (the branch
    reaches the BEB) or when the step size collapses.
    """
    sp = chapter_params(gamma=gamma0)
    xs, fl, _ = newton_fixed_point(ImpactMap(sp), x0)
    y = np.append(xs, gamma0)
    _, DF, fl, Jx = _fixed_point_system(y)
    t = _tangent(DF, np.array([0.0, 0.0, 0.0, direction]))
    pts = [_branch_point(branch, y, fl, Jx, t)]
    while len(pts) < max_points and ds > 1e-6:
        y_pred = y + ds * t
        try:
            y_new, fl, DF, Jx = _correct(y_pred, t)
        except (NewtonFailed, NoImpact, np.linalg.LinAlgError):
            ds *= 0.5
            continue
        if np.linalg.norm(y_new - y) > 3.0 * ds:  # jumped to another branch
            ds *= 0.5
            continue
        t = _tangent(DF, t)
        p = _branch_point(branch, y_new, fl, Jx, t)
        pts.append(p)
        y = y_new
        ds = min(ds * 1.3, ds_max)
        if not gamma_range[0] <= p.gamma <= gamma_range[1]:
            break
        if p.margin <= MARGIN_STOP or p.rdot < rdot_min:
            break
    return pts


def _refine(branch: str, a: BranchPoint, b: BranchPoint, key, event: str) -> BranchPoint:
    """Locate key(point) = 0 between a and b by secant in gamma with Newton at fixed gamma."""
    pa, pb = a, b
    fa, fb = key(a), key(b)
    best = a if abs(fa) < abs(fb) else b
    for _ in range(30):
        w = fa / (fa - fb)
        g = pa.gamma + w * (pb.gamma - pa.gamma)
        x = np.array(pa.x) + w * (np.array(pb.x) - np.array(pa.x))
        try:
            cyc = cycle_at(chapter_params(gamma=g), x, branch)
        except (NewtonFailed, NoImpact):
            break
        lam = cyc.multipliers
        p = BranchPoint(
            branch,
            g,
            tuple(cyc.x),
            cyc.T,
            cyc.rdot,
            tuple(lam),
            cyc.stable,
            cyc.grazing_margin,
            0.0,
            float(np.real(np.prod(1.0 + lam))),
        )
        fp = key(p)
        best = p
        if abs(fp) < 1e-11 or abs(pb.gamma - pa.gamma) < 1e-13:
            break
        if np.sign(fp) == np.sign(fa):
            pa, fa = p, fp
        else:
            pb, fb = p, fp
    return replace(best, event=event)


def _torus_key(p: BranchPoint) -> float:
    """|complex pair| - 1 (0 when there is no complex pair)."""
    cm = [abs(v) for v in p.multipliers if abs(v.imag) > 1e-9]
    return max(cm) - 1.0 if cm else -1.0


def _events(branch: str, pts: list[BranchPoint]) -> list[BranchPoint]:
    """Folds, period doublings and torus bifurcations between consecutive points."""
    ev: list[BranchPoint] = []
    for a, b in itertools.pairwise(pts):
        if a.dgamma_ds * b.dgamma_ds < 0.0:
            w = a.dgamma_ds / (a.dgamma_ds - b.dgamma_ds)
            ev.append(_refine_fold(branch, a, b, w))
        if a.pd * b.pd < 0.0:
            ev.append(_refine(branch, a, b, lambda p: p.pd, "period_doubling"))
        ta, tb = _torus_key(a), _torus_key(b)
        if ta * tb < 0.0 and ta > -1.0 and tb > -1.0:
            ev.append(_refine(branch, a, b, _torus_key, "torus"))
    return ev


def fold_point(gamma0: float, T0: float) -> tuple[float, float]:
    """(gamma, T) of a fold of cycles: a double root in T of ``period_condition``.

    Both cycles of a period root (small and large) fold there, since the period condition
    does not involve the amplitude. Solved by Newton (fsolve) from (gamma0, T0).
    """

    def eqs(v: np.ndarray) -> list[float]:
        sp = chapter_params(gamma=float(v[0]))
        h = 1e-5
        f = period_condition(sp, float(v[1]))
        df = (period_condition(sp, v[1] + h) - period_condition(sp, v[1] - h)) / (2 * h)
        return [f, df]

    sol, _, _ier, _ = scipy.optimize.fsolve(eqs, [gamma0, T0], xtol=1e-13, full_output=True)
    return float(sol[0]), float(sol[1])


def _refine_fold(branch: str, a: BranchPoint, b: BranchPoint, w: float) -> BranchPoint:
    """Fold point near the continuation's turning point between a and b (closed form)."""
    g, T = fold_point(a.gamma + w * (b.gamma - a.gamma), a.T + w * (b.T - a.T))
    near = a if abs(a.dgamma_ds) < abs(b.dgamma_ds) else b
    return replace(near, gamma=g, T=T, dgamma_ds=0.0, event="fold")


def grazing_gamma(branch: str, g_in: float, g_out: float) -> float:
    """gamma where the closed-form ``branch`` cycle grazes (max interior |U| = 1).

    ``g_in``: a gamma with positive margin, ``g_out``: one with negative margin.
    """

    def margin(g: float) -> float:
        sp = chapter_params(gamma=g)
        c = labelled_cycles(sp)[branch]
        return 1.0 - max_radius_in_flight(sp, c.U0, c.dU0, c.T)

    return float(scipy.optimize.brentq(margin, g_in, g_out, xtol=1e-14))


def continue_cycles(
    gamma_values: np.ndarray | list[float], seed_gamma: float = 0.1
) -> list[BranchPoint]:
    """Continue the period-one cycle branches over [min, max] of ``gamma_values``.

    Two branches are seeded from the closed form at ``seed_gamma`` and continued both ways
    by pseudo-arclength on the core map: "large" (through the long-large cycle) and "small"
    (through the long-small cycle, born at the BEB). The step is limited to the spacing of
    ``gamma_values``. Returns the points in branch order plus located events (``event`` set):
    folds, period doublings, torus bifurcations, grazing (end of an admissible branch) and
    the BEB birth (rdot -> 0).
    """
    gv = np.asarray(gamma_values, float)
    rng = (float(gv.min()), float(gv.max()))
    ds_max = max(0.01, float(np.max(np.diff(np.sort(gv)))) if len(gv) > 1 else 0.04)
    seeds = labelled_cycles(chapter_params(gamma=seed_gamma))
    out: list[BranchPoint] = []
    for name, key in (("large", "long-large"), ("small", "long-small")):
        if key not in seeds:
            continue
        x0 = seeds[key].x
        back = continue_branch(name, x0, seed_gamma, -1.0, rng, ds_max=ds_max)
        fwd = continue_branch(name, x0, seed_gamma, +1.0, rng, ds_max=ds_max)
        back = [replace(p, dgamma_ds=-p.dgamma_ds) for p in back]  # orient along fwd
        pts = back[::-1] + fwd[1:]
        out.extend(pts)
        out.extend(_events(name, pts))
        for end in (pts[0], pts[-1]):
            if end.margin <= MARGIN_STOP:
                g = _grazing_from_end(end, pts)
                out.append(replace(end, gamma=g, margin=0.0, event="grazing"))
            elif end.rdot < 1e-6:
                out.append(replace(end, gamma=_birth_gamma(end, pts), event="beb_birth"))
    return out


def _grazing_from_end(end: BranchPoint, pts: list[BranchPoint]) -> float:
    """Grazing gamma past a branch end with a vanishing margin (closed form, bisection)."""
    cands = [
        k
        for k, c in labelled_cycles(chapter_params(gamma=end.gamma)).items()
        if abs(c.T - end.T) < 1e-6
    ]
    key = cands[0]
    inner = next(p for p in (pts if end is pts[-1] else pts[::-1]) if p.margin > 0.05)
    step = end.gamma - inner.gamma
    g_out = end.gamma + 0.1 * step
    for _ in range(20):
        sp = chapter_params(gamma=g_out)
        c = labelled_cycles(sp).get(key)
        if c is not None and max_radius_in_flight(sp, c.U0, c.dU0, c.T) > 1.0:
            break
        g_out += 0.1 * step
    return grazing_gamma(key, end.gamma - 0.5 * step, g_out)


def _birth_gamma(end: BranchPoint, pts: list[BranchPoint]) -> float:
    """gamma where rdot- -> 0, extrapolated linearly from the branch end (rdot ~ gamma - g*)."""
    nxt = pts[1] if end is pts[0] else pts[-2]
    slope = (nxt.rdot - end.rdot) / (nxt.gamma - end.gamma)
    return end.gamma - end.rdot / slope
