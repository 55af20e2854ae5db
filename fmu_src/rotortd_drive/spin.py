"""Spin integrated inside the bearing FMU (option ``integrate_spin``).

Holding the spin speed ``Omega`` over a communication step is crude when the friction
torque is large (dry whip: kN m against J = 0.04 kg m^2 changes Omega by ~25 rad/s per ms).
:class:`SpinCoupler` sub-steps the touchdown core at ``h_spin`` and after each sub-step
applies the exact angular impulse the core reports for it:

    J (Omega_{i+1} - Omega_i) = T_drive h_i + T_f,i h_i        (T_f,i h_i = -R P_t - R int F_t)

so the angular momentum balance is exact (to round-off) and the coupling error is that of
holding Omega over ``h_spin`` instead of over the communication step. SI units.

Work bound (docs/model.md 7): the sub-steps of one communication step share the core's
per-step bound WORK_MAX. Each sub-step costs its core work plus SUBSTEP_WORK units (the
fixed cost of a core call whose inputs changed); the core gets what is left as its budget.
A step that needs more sub-steps than the bound allows is refused before any is taken, and
one whose sub-steps use up the bound stops after the last one that fit; either way with
STATUS_WORK_CAP and a message saying where.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Protocol

STATUS_OK = 0
STATUS_WORK_CAP = 1  # rotortd.STATUS_WORK_CAP
WORK_MAX = 1_600_000
"""Work bound of one communication step (units), the core's rotortd.WORK_MAX (a test
checks that they agree; this package does not import the core)."""
SUBSTEP_WORK = 20
"""Work units charged per sub-step on top of the core's own count: a core call whose
spin changed rebuilds its flight and wall models (about 20 units of the core's slowest
work per unit, measured; docs/model.md 7)."""


class _Core(Protocol):
    t: float

    def step(self, h: float, Omega: float, F_ext: complex = 0j,
             amb_on: float = 1.0, budget: int | None = None) -> Any: ...


@dataclass
class SpinReport:
    """Aggregate of the core's sub-step reports over one communication step (SI; forces
    and torques averaged over the step, impulses as P/h), plus the spin at its end."""

    status: int = STATUS_OK
    message: str = ""
    impacts: list[Any] = field(default_factory=list)
    F_contact: complex = 0j
    F_n: float = 0.0
    F_n_peak: float = 0.0
    P_n: float = 0.0
    T_f: float = 0.0
    E_diss: float = 0.0
    T_imb: float = 0.0
    """Imbalance reaction torque (N m), the sub-steps' T_imb averaged like T_f. Reported
    only: the spin here integrates J Omega' = T_drive + T_f, as before."""
    mode: int = 0
    transitions: list[Any] = field(default_factory=list)
    Omega_end: float = 0.0     # rad/s
    n_sub: int = 0             # sub-steps taken
    work: int = 0              # work units: the core's plus SUBSTEP_WORK per sub-step
    work_cap: int = WORK_MAX   # the bound on work


class SpinCoupler:
    """Advances a touchdown core and the spin ``J Omega' = T_drive + T_f`` together.

    J [kg m^2] > 0, h_spin [s] > 0 is the largest sub-step; Omega [rad/s] is the state."""

    def __init__(self, J: float, h_spin: float, Omega0: float) -> None:
        if not (math.isfinite(J) and J > 0):
            raise ValueError(f"J={J!r} must be finite and > 0")
        if not (math.isfinite(h_spin) and h_spin > 0):
            raise ValueError(f"h_spin={h_spin!r} must be finite and > 0")
        self.J, self.h_spin, self.Omega = float(J), float(h_spin), float(Omega0)

    def n_sub(self, h: float) -> int:
        """Number of equal sub-steps for a step h [s] (each <= h_spin)."""
        return max(1, math.ceil(h / self.h_spin * (1.0 - 1e-12)))

    def step(self, core: _Core, h: float, T_drive: float, F_ext: complex = 0j,
             amb_on: float = 1.0) -> SpinReport:
        """Advance core and spin by h [s] with T_drive [N m], F_ext [N], amb_on held,
        within the work bound WORK_MAX (module docstring)."""
        out = SpinReport()
        t_start = core.t
        per_sub = SUBSTEP_WORK + 1  # the least a sub-step costs
        if not h / self.h_spin * (1.0 - 1e-12) <= WORK_MAX // per_sub:  # (also NaN, inf)
            out.status, out.message = STATUS_WORK_CAP, (
                f"work bound reached: the step of {h!r} s needs {h / self.h_spin:.6g} "
                f"sub-steps of h_spin = {self.h_spin!r} s, more than the "
                f"{WORK_MAX // per_sub} that the bound of {WORK_MAX} work units allows "
                f"({per_sub} each at least); refused at t = {t_start!r} s, nothing taken")
            out.mode = getattr(core, "mode", 0)
            out.Omega_end = self.Omega
            return out
        n = self.n_sub(h)
        hs = h / n
        for i in range(n):
            left = WORK_MAX - out.work - SUBSTEP_WORK
            if left <= 0:
                out.status, out.message = STATUS_WORK_CAP, (
                    f"work bound reached: {out.work} of {WORK_MAX} work units used by "
                    f"{i} of {n} sub-steps of {hs!r} s; stopped at t = {core.t!r} s")
                break
            rep = core.step(hs, self.Omega, F_ext=F_ext, amb_on=amb_on, budget=left)
            out.work += rep.work + SUBSTEP_WORK
            _accumulate(out, rep, hs)
            self.Omega += (T_drive + rep.T_f) * hs / self.J
            out.n_sub = i + 1
            if rep.status != STATUS_OK:
                out.status, out.message = rep.status, rep.message
                if rep.status == STATUS_WORK_CAP:  # stop where the core stopped
                    out.message = f"sub-step {i + 1} of {n} ({hs!r} s each): {rep.message}"
                    break
        span = max(core.t - t_start, 0.0) or h
        _average(out, span)
        out.Omega_end = self.Omega
        return out


def _accumulate(out: SpinReport, rep: Any, hs: float) -> None:
    """Add one sub-step's impulses (averages times hs) to the running sums."""
    out.impacts.extend(rep.impacts)
    out.F_contact += rep.F_contact * hs
    out.F_n += rep.F_n * hs
    out.F_n_peak = max(out.F_n_peak, rep.F_n_peak)
    out.P_n += rep.P_n
    out.T_f += rep.T_f * hs
    out.T_imb += rep.T_imb * hs
    out.E_diss += rep.E_diss
    out.mode = rep.mode
    out.transitions.extend(rep.transitions)


def _average(out: SpinReport, span: float) -> None:
    """Turn the impulse sums into averages over span [s]."""
    out.F_contact /= span
    out.F_n /= span
    out.T_f /= span
    out.T_imb /= span
