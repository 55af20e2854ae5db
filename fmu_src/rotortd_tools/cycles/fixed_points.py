"""Period-one cycles as fixed points of the core's impact map: Newton, multipliers, ``Cycle``.

Scaled co-rotating (docs/model.md §1), with the SI start (Omega = 184.2 rad/s, psi0 = 0) to run
the core on a cycle. ``find_period_one_cycle`` is what the sweep's ``cycle`` start calls.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from rotortd import RotorParams, ScaledParams, TouchdownCore
from rotortd.scaled import CHAPTER_C_R as C_R
from rotortd.scaled import CHAPTER_OMEGA as OMEGA
from rotortd.scaled import chapter_params, si_params, wrap_angle

from rotortd_tools.cycles.closed_form import labelled_cycles, max_radius_in_flight
from rotortd_tools.cycles.impact_map import Flight, ImpactMap, NoImpact, post_impact_state


class NewtonFailed(RuntimeError):
    """Newton on the impact map did not converge."""


def map_residual(P: ImpactMap, x: np.ndarray) -> tuple[np.ndarray, Flight]:
    """F(x) = P(x) - x (angle difference wrapped to (-pi, pi]) and the flight."""
    fl = P.flight(x)
    F = fl.x1 - x
    F[0] = wrap_angle(F[0])
    return F, fl


def newton_fixed_point(
    P: ImpactMap, x0: np.ndarray, tol: float = 1e-12, max_iter: int = 40
) -> tuple[np.ndarray, Flight, float]:
    """Fixed point of P from the guess x0 by damped Newton (variational Jacobian).

    Returns (x*, flight from x*, max-norm residual |P(x*) - x*|).
    """
    x = np.asarray(x0, float).copy()
    if x[1] >= 0.0:
        raise NewtonFailed("the guess must have rdot+ < 0 (moving inward after the impact)")
    F, fl = map_residual(P, x)
    res = float(np.max(np.abs(F)))
    for _ in range(max_iter):
        if res < tol:
            break
        if fl.kind != "impact":
            raise NewtonFailed("the flight ends in a touch (grazing), not an impact")
        J, _ = P.jacobian(fl)
        dx = np.linalg.solve(J - np.eye(3), -F)
        lam = 1.0
        while lam > 1e-4:
            xn = x + lam * dx
            xn[0] = wrap_angle(xn[0])
            if xn[1] >= 0.0:  # post-impact motion must point inward
                lam *= 0.5
                continue
            try:
                Fn, fln = map_residual(P, xn)
            except NoImpact:
                lam *= 0.5
                continue
            resn = float(np.max(np.abs(Fn)))
            if resn < (1.0 - 0.25 * lam) * res or resn < tol:
                break
            lam *= 0.5
        else:
            raise NewtonFailed(f"line search failed at residual {res:.3g}")
        x, F, fl, res = xn, Fn, fln, resn
    if res >= max(tol, 1e-10):
        raise NewtonFailed(f"no convergence: residual {res:.3g}")
    if fl.kind != "impact" or fl.T <= 1e-9:
        raise NewtonFailed("degenerate fixed point (zero-length flight or grazing touch)")
    return x, fl, res


@dataclass(frozen=True)
class Cycle:
    """A period-one synchronous impacting limit cycle (one impact per period T).

    Scaled co-rotating: ``x`` = (alpha, rdot+, thetadot+) right after the impact, ``U0`` =
    e^{i alpha}, ``dU0`` = dU/dt after the reset, ``T`` the period (flight time), ``alpha``
    the impact angle (rad), ``rdot`` the impact normal speed rdot- (c_r Omega), ``max_radius``
    the largest interior maximum of |U| in flight and ``grazing_margin`` = 1 - max_radius.
    SI inertial (Omega = OMEGA, psi0 = 0): ``z0`` (m), ``v0`` (m/s) right after the impact,
    ``T_si`` (s), ``rdot_si`` (m/s); start a core on it with ``core()``.
    ``multipliers``: eigenvalues of the impact-map Jacobian (the non-trivial Floquet
    multipliers); ``stable`` when all lie inside the unit circle; ``residual``: max-norm
    of P(x) - x evaluated with the core.
    """

    gamma: float
    sp: ScaledParams
    branch: str
    x: np.ndarray
    U0: complex
    dU0: complex
    T: float
    alpha: float
    rdot: float
    multipliers: np.ndarray
    stable: bool
    max_radius: float
    grazing_margin: float
    residual: float
    jacobian: np.ndarray = field(repr=False)
    z0: complex = 0j
    v0: complex = 0j
    T_si: float = 0.0
    rdot_si: float = 0.0

    @property
    def params(self) -> RotorParams:
        """SI parameters (Omega = OMEGA, m = MASS, c_r = C_R)."""
        return si_params(self.sp)

    def core(self) -> TouchdownCore:
        """A TouchdownCore started right after the cycle's impact (psi0 = 0, t0 = 0)."""
        return TouchdownCore(self.params, z0=self.z0, v0=self.v0, psi0=0.0)

    def core_from_scaled(self) -> TouchdownCore:
        """The same start through ``TouchdownCore.from_scaled`` (U0, dU0, psi0 = 0)."""
        return TouchdownCore.from_scaled(self.params, OMEGA, U0=self.U0, dU0=self.dU0, psi0=0.0)


def multipliers_of(J: np.ndarray) -> np.ndarray:
    """Eigenvalues of the map Jacobian, sorted by decreasing modulus."""
    lam = np.linalg.eigvals(J)
    return lam[np.argsort(-np.abs(lam))]


def cycle_at(sp: ScaledParams, x: np.ndarray, branch: str = "") -> Cycle:
    """Newton-refine the guess x on the core map at ``sp`` and collect the cycle data."""
    P = ImpactMap(sp)
    xs, fl, res = newton_fixed_point(P, x)
    J, _ = P.jacobian(fl)
    lam = multipliers_of(J)
    U0, dU0 = post_impact_state(xs)
    mr = max_radius_in_flight(sp, U0, dU0, fl.T)
    z0, v0 = P.to_si(U0, dU0)
    return Cycle(
        gamma=sp.gamma,
        sp=sp,
        branch=branch,
        x=xs,
        U0=U0,
        dU0=dU0,
        T=fl.T,
        alpha=float(xs[0]),
        rdot=fl.rdot,
        multipliers=lam,
        stable=bool(np.max(np.abs(lam)) < 1.0),
        max_radius=mr,
        grazing_margin=1.0 - mr,
        residual=res,
        jacobian=J,
        z0=z0,
        v0=v0,
        T_si=fl.T / OMEGA,
        rdot_si=fl.rdot * C_R * OMEGA,
    )


def find_period_one_cycle(
    gamma: float,
    guess: np.ndarray | None = None,
    branch: str = "long-large",
    **scaled_overrides: float,
) -> Cycle:
    """The period-one cycle at ``gamma`` (other scaled parameters from the chapter set).

    ``guess``: a post-impact section point (alpha, rdot+, thetadot+) for Newton; without
    it the closed form (``labelled_cycles``) provides the guess of the named ``branch``
    ("short-small", "short-large", "long-small", "long-large"). Newton then runs on the
    core-based impact map (residual < 1e-12 typically). Raises KeyError when the branch
    does not exist at this gamma, NewtonFailed when Newton does not converge.
    """
    sp = chapter_params(gamma=gamma, **scaled_overrides)
    if guess is None:
        cyc = labelled_cycles(sp)
        if branch not in cyc:
            raise KeyError(f"no {branch!r} cycle at gamma = {gamma}: found {sorted(cyc)}")
        guess = cyc[branch].x
    return cycle_at(sp, np.asarray(guess, float), branch)
