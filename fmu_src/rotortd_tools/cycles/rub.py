"""Synchronous forward-rub pseudo-equilibria (sliding, U' = 0), scaled co-rotating.

From the core (``rotortd.forward_rub_equilibria``, converted to scaled units) and from an
independent scaled derivation (a cross-check); alpha in rad, N in m c_r Omega^2.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass

from rotortd import ScaledParams, WallForces, forward_rub_equilibria
from rotortd.scaled import CHAPTER_OMEGA as OMEGA
from rotortd.scaled import si_params, wrap_angle


@dataclass(frozen=True)
class RubPoint:
    """A synchronous forward-rub pseudo-equilibrium (sliding, U' = 0), scaled co-rotating.

    alpha: co-rotating contact angle (rad); N: normal force / (m c_r Omega^2) (>= 0);
    stable: both eigenvalues of the linearised sliding motion have Re < 0;
    eig: those eigenvalues (per unit scaled time).
    """

    gamma: float
    alpha: float
    N: float
    stable: bool
    eig: tuple[complex, complex]


def rub_equilibria(sp: ScaledParams) -> list[RubPoint]:
    """Forward-rub equilibria from the core's ``forward_rub_equilibria``, converted to scaled."""
    wf = WallForces.build(si_params(sp), OMEGA, 0j, 1.0)
    out = []
    for eq in forward_rub_equilibria(wf):
        eig = (eq.eig[0] / OMEGA, eq.eig[1] / OMEGA)
        out.append(RubPoint(sp.gamma, eq.alpha, eq.Gn / OMEGA**2, eq.stable, eig))
    return sorted(out, key=lambda e: not e.stable)


def rub_equilibria_scaled(sp: ScaledParams) -> list[RubPoint]:
    """Independent scaled derivation of the forward-rub equilibria (cross-check of the core).

    At U = e^{i alpha}, U' = 0 the contact force is -N (1 + i mu s) U, s = +1 (slip
    R/c_r + 1 > 0), so rho e^{i(phi - alpha)} = omega^2 - 1 + i gamma + N (1 + i mu): all
    roots alpha of gamma + mu N(alpha) = rho sin(phi - alpha) with N = rho cos(phi - alpha)
    + 1 - omega^2 >= 0. Linearising theta'' = -(gamma + 2 mu) theta' - a1 theta with
    a1 = rho (cos x + mu sin x), x = phi - alpha, gives the eigenvalues.
    """
    mu = sp.mu
    amp = sp.rho * math.hypot(1.0, mu)
    S = (sp.gamma + mu * (1.0 - sp.omega**2)) / amp
    if abs(S) > 1.0:
        return []
    delta = math.atan(mu)
    out = []
    for x in (delta + math.asin(S), delta + math.pi - math.asin(S)):
        N = sp.rho * math.cos(x) + 1.0 - sp.omega**2
        if N < 0.0:
            continue
        a1 = sp.rho * (math.cos(x) + mu * math.sin(x))
        b1 = sp.gamma + 2.0 * mu
        root = cmath.sqrt(b1 * b1 / 4.0 - a1)
        eig = (-b1 / 2.0 + root, -b1 / 2.0 - root)
        alpha = wrap_angle(sp.phi - x)
        out.append(RubPoint(sp.gamma, alpha, N, max(e.real for e in eig) < 0.0, eig))
    return sorted(out, key=lambda e: not e.stable)


def rub_fold_gamma(sp: ScaledParams) -> float:
    """Largest gamma with a forward-rub equilibrium: the smooth fold of the two rub branches.

    gamma_fold = rho sqrt(1 + mu^2) - mu (1 - omega^2) (S = 1 in rub_equilibria_scaled).
    """
    return sp.rho * math.hypot(1.0, sp.mu) - sp.mu * (1.0 - sp.omega**2)
