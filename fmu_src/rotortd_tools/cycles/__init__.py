"""Synchronous solutions of the chapter's model: equilibria, rub, impacting cycles.

Frame and units: unless a name says otherwise everything here is in the chapter's
*scaled co-rotating* frame (docs/model.md §1): time t = Omega tau (dimensionless), position
U = z e^{-i psi}/c_r (in units of c_r), velocity U' = dU/dt (in units of c_r Omega). The
free flight is

    U'' + (gamma + 2i) U' + (omega^2 - 1 + i gamma) U = rho e^{i phi},   |U| < 1,

autonomous in this frame, so a synchronous impacting limit cycle (one impact per period
T, T found, not fixed) is a fixed point of the impact map

    P: x = (alpha, rdot+, thetadot+) -> x' (next impact, after the reset),

x being the state right after an impact: U = e^{i alpha}, U' = (rdot+ + i thetadot+) U
(rdot+ < 0 is the radial speed, thetadot+ the co-rotating whirl rate). P is evaluated
with the core (SI, inertial): the exact flight ``FlightModel.propagate``, the rigorous
first-contact search ``ContactLocator.find`` and the reset law ``impact.reset`` (with the
Coulomb stick cap), converting with ``RotorParams.from_scaled(sp, Omega, m, c_r)`` and the
``TouchdownCore.from_scaled`` convention z = c_r U e^{i psi}, psi = psi0 + t, psi0 = 0 at
the start of each flight. The Jacobian of P comes from an independent closed form of the
scaled flow (matrix exponential, variational equations, implicit impact time), or from
finite differences of the core map.

The modules, by job:

  flow          the scaled free flow: system matrix, closed-form flight, d/dgamma
  rub           forward-rub pseudo-equilibria (core and independent scaled derivation)
  impact_map    the impact map P on the core, and its Jacobian
  closed_form   period-one cycles in closed form: period condition, grazing margin, labels
  fixed_points  Newton on P: ``Cycle``, ``cycle_at``, ``find_period_one_cycle``
  continuation  pseudo-arclength continuation in gamma and its events
  brute_force   runs from standard starts to the attractor (``rotortd_tools.attractor``)

The chapter's parameters, U* and gamma_BEB come from ``rotortd.scaled``. The names below are
the package's interface (tests, docs/scripts, the sweep's ``cycle`` start).
"""

from rotortd.scaled import CHAPTER_C_R as C_R
from rotortd.scaled import CHAPTER_MASS as MASS
from rotortd.scaled import CHAPTER_OMEGA as OMEGA
from rotortd.scaled import chapter_params, gamma_beb, regular_equilibrium, si_params

from rotortd_tools.cycles.brute_force import REGIMES, Attractor, run_attractor, standard_starts
from rotortd_tools.cycles.closed_form import (
    AnalyticCycle,
    analytic_cycles,
    labelled_cycles,
    max_radius_in_flight,
    period_condition,
    period_roots,
    radius_profile,
)
from rotortd_tools.cycles.continuation import (
    MARGIN_STOP,
    BranchPoint,
    continue_branch,
    continue_cycles,
    fold_point,
    grazing_gamma,
)
from rotortd_tools.cycles.fixed_points import (
    Cycle,
    NewtonFailed,
    cycle_at,
    find_period_one_cycle,
    map_residual,
    multipliers_of,
    newton_fixed_point,
)
from rotortd_tools.cycles.flow import ScaledFlow, real_jac, system_matrix, to_real
from rotortd_tools.cycles.impact_map import (
    T_MAX,
    WINDOW,
    Flight,
    ImpactMap,
    NoImpact,
    post_impact_state,
    section_point,
)
from rotortd_tools.cycles.rub import (
    RubPoint,
    rub_equilibria,
    rub_equilibria_scaled,
    rub_fold_gamma,
)

__all__ = [
    "C_R", "MARGIN_STOP", "MASS", "OMEGA", "REGIMES", "T_MAX", "WINDOW", "AnalyticCycle",
    "Attractor", "BranchPoint", "Cycle", "Flight", "ImpactMap", "NewtonFailed", "NoImpact",
    "RubPoint", "ScaledFlow", "analytic_cycles", "chapter_params", "continue_branch",
    "continue_cycles", "cycle_at", "find_period_one_cycle", "fold_point", "gamma_beb",
    "grazing_gamma", "labelled_cycles", "map_residual", "max_radius_in_flight",
    "multipliers_of", "newton_fixed_point", "period_condition", "period_roots",
    "post_impact_state", "radius_profile", "real_jac", "regular_equilibrium",
    "rub_equilibria", "rub_equilibria_scaled", "rub_fold_gamma", "run_attractor",
    "section_point", "si_params", "standard_starts", "system_matrix", "to_real",
]
