"""Where a run starts: the named starts of a sweep point and continuation from a state.

Scaled co-rotating frame (docs/model.md §1, U = z e^{-i psi}/c_r), the point's SI realisation
for the core:

  rest            U = 0, U' = 0
  steady          on the regular equilibrium U* (free whirl); "no-start" when inadmissible
  large           U = 0.9 U*/|U*|, inertial velocity 0 (released near the wall, no whirl)
  cycle[:BRANCH]  right after the impact of the period-one impacting cycle found by Newton
                  on the impact map (``rotortd_tools.cycles.find_period_one_cycle``)
  drop            on the levitated steady whirl (held speed, bearing on) with gravity
                  DROP_G; the run then turns the bearing off (``run_drop``)
  up[:SEED], down[:SEED]
                  continuation along the first swept parameter: each point starts from the
                  previous point's final state (``get_state``/``set_state``, exact); the
                  first point of a pass (and any point after a failed one) starts from SEED
                  (rest by default). One chain per value of the second parameter.

With J (kg m^2) every start is the same state in a ``SpinCore`` of that inertia, spinning
at Omega (rad/s), on the point's real bearing when it has one (docs/model.md §10, the race
centred and at rest unless omega_b0 says otherwise); a continued state takes the point's J.
"""

from __future__ import annotations

from dataclasses import replace

from rotortd import (
    BearingParams,
    ParameterError,
    RotorParams,
    ScaledParams,
    SpinCore,
    TouchdownCore,
)
from rotortd.scaled import regular_equilibrium
from rotortd.step.state import CoreState

from rotortd_tools.sweep.spec import (
    CONTINUATION,
    SCALED_NAMES,
    SweepError,
    cycle_finder,
    drop_params,
)


class NoStart(RuntimeError):
    """A start does not exist at this point (inadmissible whirl, no cycle)."""


def make_start(label: str, p: RotorParams, Omega: float, sp: ScaledParams,
               J: float | None = None, bearing: BearingParams | None = None
               ) -> TouchdownCore:
    """A core at the named simple start (rest, steady, large, cycle[:BRANCH], drop); with
    J (kg m^2) the same state in a SpinCore spinning at Omega (rad/s), on ``bearing`` (the
    real bearing; it needs J) when given."""
    core = _held_start(label, p, Omega, sp)
    if J is None:
        if bearing is not None:
            raise SweepError("the real bearing's parameters need J (the spin as a state)")
        return core
    return SpinCore(core.params, J, z0=core.z, v0=core.v, psi0=core.psi, Omega0=Omega,
                    t0=core.t, bearing=bearing)


def _held_start(label: str, p: RotorParams, Omega: float, sp: ScaledParams
                ) -> TouchdownCore:
    head, _, branch = label.partition(":")
    if head == "drop":
        try:
            return TouchdownCore.on_steady_whirl(drop_params(p), Omega)
        except ParameterError as exc:
            raise NoStart(str(exc)) from None
    if head == "rest":
        return TouchdownCore(p)
    U_star = regular_equilibrium(sp)
    if head == "steady":
        try:
            return TouchdownCore.on_steady_whirl(p, Omega)
        except ParameterError as exc:
            raise NoStart(str(exc)) from None
    if head == "large":
        U0 = 0.9 * U_star / abs(U_star) if abs(U_star) > 0 else 0.9 + 0j
        return TouchdownCore(p, z0=p.c_r * U0, v0=0j)
    if head == "cycle":
        return _cycle_start(p, Omega, sp, branch)
    raise SweepError(f"unknown start {label!r}")


def _cycle_start(p: RotorParams, Omega: float, sp: ScaledParams, branch: str) -> TouchdownCore:
    find = cycle_finder()
    overrides = {k: getattr(sp, k) for k in SCALED_NAMES if k != "gamma"}
    kwargs = {"branch": branch} if branch else {}
    try:
        cyc = find(sp.gamma, **kwargs, **overrides)
    except (KeyError, RuntimeError, ValueError, ArithmeticError) as exc:
        raise NoStart(f"no period-one cycle: {type(exc).__name__}: {exc}") from None
    return TouchdownCore.from_scaled(p, Omega, U0=complex(cyc.U0), dU0=complex(cyc.dU0))



def core_for(start: str, p: RotorParams, Omega: float, sp: ScaledParams,
             state: dict | None, J: float | None = None,
             bearing: BearingParams | None = None) -> TouchdownCore:
    """A core at the start, or continued from ``state`` with the point's parameters (and
    its J, kg m^2, when given: a SpinCore; the real ``bearing`` only at a simple start)."""
    head, _, seed = start.partition(":")
    if head in CONTINUATION:
        if state is None:
            return make_start(seed or "rest", p, Omega, sp, J)
        if J is None:
            core = TouchdownCore(p)
            core.set_state(state)
        else:
            core = SpinCore(p, J)
            core.set_state(replace(CoreState.from_json(state), J=J))
        core.set_params(p)
        return core
    return make_start(start, p, Omega, sp, J, bearing)


