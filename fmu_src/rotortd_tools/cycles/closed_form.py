"""Period-one impacting cycles in closed form (no event location), scaled co-rotating.

The period condition Re H(T) = -d, the impact speed from |1 - rdot G| = |U*|, the grazing
margin (largest interior |U| in flight), and the cycles labelled short/long, small/large.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.optimize
from rotortd import ScaledParams
from rotortd.scaled import regular_equilibrium

from rotortd_tools.cycles.flow import ScaledFlow, system_matrix
from rotortd_tools.cycles.impact_map import section_point


def _resolvent(sp: ScaledParams, T: float) -> np.ndarray:
    """(e^{A T} - I)^{-1} (complex 2x2); regular for T > 0 since Re(eig A) = -gamma/2 < 0."""
    return np.linalg.inv(scipy.linalg.expm(system_matrix(sp) * T) - np.eye(2))


def _q(sp: ScaledParams) -> complex:
    """q = (1 + d)(1 + i mu s) with forward slip s = +1 (the stick cap not firing)."""
    return (1.0 + sp.d) * complex(1.0, sp.mu)


def period_condition(sp: ScaledParams, T: float) -> float:
    """Re H(T) + d, H = q [(e^{AT} - I)^{-1}]_{22}; zero at the period of every cycle.

    Derivation (scaled co-rotating): a period-one cycle has w(T-) - w_eq = e^{AT}(w0 - w_eq)
    with w(T-) = (U0, V-) and w0 = (U0, V- - q rdot U0), so (e^{AT} - I)(w0 - w_eq) =
    (0, q rdot U0): w0 - w_eq = rdot U0 q (R12, R22), R = (e^{AT} - I)^{-1}. The radial part of
    V+ = rdot U0 H must be -d rdot, i.e. Re H(T) = -d, whatever the amplitude rdot.
    """
    return float((_q(sp) * _resolvent(sp, T)[1, 1]).real + sp.d)


def _period_condition_many(sp: ScaledParams, ts: np.ndarray) -> np.ndarray:
    """period_condition at many T at once (eigen-decomposition of A; A is diagonalisable)."""
    lam, V = np.linalg.eig(system_matrix(sp))
    Vi = np.linalg.inv(V)
    out = np.empty(len(ts))
    for i, t in enumerate(ts):
        E = (V * np.exp(lam * t)) @ Vi - np.eye(2)
        R22 = E[0, 0] / (E[0, 0] * E[1, 1] - E[0, 1] * E[1, 0])
        out[i] = (_q(sp) * R22).real + sp.d
    return out


def period_roots(sp: ScaledParams, t_max: float = 60.0, n: int = 6000) -> list[float]:
    """All roots T in (0, t_max] of ``period_condition`` (scaled time), by sampling + Brent."""
    ts = np.linspace(t_max / n, t_max, n)
    f = _period_condition_many(sp, ts)
    roots = []
    for i in np.nonzero(np.sign(f[:-1]) != np.sign(f[1:]))[0]:
        roots.append(
            scipy.optimize.brentq(lambda t: period_condition(sp, t), ts[i], ts[i + 1], xtol=1e-15)
        )
    return roots


@dataclass(frozen=True)
class AnalyticCycle:
    """A period-one cycle from the closed form (scaled co-rotating), admissible or not.

    T: period; rdot: impact normal speed rdot-; U0: impact point; dU0: post-impact velocity.
    """

    T: float
    rdot: float
    U0: complex
    dU0: complex

    @property
    def x(self) -> np.ndarray:
        """Post-impact section point (alpha, rdot+, thetadot+)."""
        return section_point(self.U0, self.dU0)


def analytic_cycles(sp: ScaledParams, t_max: float = 60.0) -> list[AnalyticCycle]:
    """All period-one cycles with period <= t_max by the closed form (no event location).

    For each period root T, U0 (1 - rdot G) = U* with G = q R12, so |1 - rdot G| = |U*|:
    a quadratic in rdot (roots > 0 kept). Admissibility (no earlier contact in (0, T)) and
    the stick cap are *not* checked here; see ``max_radius_in_flight``.
    """
    Us = regular_equilibrium(sp)
    q = _q(sp)
    out = []
    for T in period_roots(sp, t_max):
        R = _resolvent(sp, T)
        G, H = q * R[0, 1], q * R[1, 1]
        a, b, c = abs(G) ** 2, -2.0 * G.real, 1.0 - abs(Us) ** 2
        disc = b * b - 4.0 * a * c
        if disc < 0.0:
            continue
        sq = math.sqrt(disc)
        for rd in sorted({(-b - sq) / (2 * a), (-b + sq) / (2 * a)}):
            if rd <= 0.0:
                continue
            U0 = Us / (1.0 - rd * G)
            out.append(AnalyticCycle(T, rd, U0, rd * U0 * H))
    return out


def radius_profile(
    sp: ScaledParams, U0: complex, dU0: complex, T: float, n: int = 2000
) -> tuple[np.ndarray, np.ndarray]:
    """(t, |U(t)|) on [0, T] (scaled) along the free flight from (U0, dU0)."""
    ts = np.linspace(0.0, T, n + 1)
    w = ScaledFlow(sp).states(np.array([U0, dU0]), ts)
    return ts, np.abs(w[:, 0])


def max_radius_in_flight(sp: ScaledParams, U0: complex, dU0: complex, T: float) -> float:
    """Largest interior local maximum of |U(t)| on (0, T) (scaled), or 0 when there is none.

    1 - this is the grazing margin of a cycle: it reaches 0 when the flight touches the
    clearance circle tangentially in mid-flight (grazing).
    """
    flow = ScaledFlow(sp)
    w0 = np.array([U0, dU0])
    n = max(400, int(60 * T))
    ts, r = radius_profile(sp, U0, dU0, T, n)
    best = 0.0
    for i in range(1, n):
        if r[i] >= r[i - 1] and r[i] >= r[i + 1]:
            res = scipy.optimize.minimize_scalar(
                lambda t: -abs(flow.state(w0, t)[0]),
                bounds=(ts[i - 1], ts[i + 1]),
                method="bounded",
                options={"xatol": 1e-13},
            )
            best = max(best, -float(res.fun))
    return best


def labelled_cycles(sp: ScaledParams) -> dict[str, AnalyticCycle]:
    """Closed-form cycles keyed "<short|long>-<small|large>".

    short/long: the first/second root of ``period_condition`` (shorter/longer period);
    small/large: the smaller/larger impact speed of that period (below gamma_BEB only the
    large one exists, the small one has passed through rdot = 0 at the BEB).
    """
    out: dict[str, AnalyticCycle] = {}
    by_T: dict[float, list[AnalyticCycle]] = {}
    for c in analytic_cycles(sp):
        by_T.setdefault(c.T, []).append(c)
    for k, T in enumerate(sorted(by_T)[:2]):
        cs = sorted(by_T[T], key=lambda c: c.rdot)
        name = ("short", "long")[k]
        out[f"{name}-large"] = cs[-1]
        if len(cs) > 1:
            out[f"{name}-small"] = cs[0]
    return out
