"""Run a core to its attractor and classify it: shared by sweeps and the chapter's brute force.

Scaled units (t = Omega tau; one revolution is 2 pi): the record window's times, dwell times
and rates are scaled, impact normal speeds in c_r Omega, angles in rad, co-rotating
(the impact angle is arg z - psi). ``run_to_attractor`` steps a ``TouchdownCore`` through a
transient and then a record window with a ``Recorder``, which takes the impacts and the
exact contact transition times from the core's step reports (the step length only sets
the sampling of r). ``classify`` names the regime from the window (docs/sweeps.md):
"at least half the window" is ``>= 0.5``.
"""

from __future__ import annotations

import cmath
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from rotortd import MODE_FREE, MODE_ROLLING, MODE_SLIDING, STATUS_OK, TouchdownCore
from rotortd.scaled import wrap_angle

CHAPTER_REGIMES = ("free whirl", "impacting", "rub/sliding", "dry whip/rolling")
"""The chapter's coarse regimes (``chapter_regime``)."""


@dataclass
class Recorder:
    """Accumulates the attractor signature over the record window (scaled units)."""

    c_r: float
    Omega: float
    r_max: float = -math.inf
    r_min: float = math.inf
    t_slide: float = 0.0
    t_roll: float = 0.0
    times: list[float] = field(default_factory=list)
    angles: list[float] = field(default_factory=list)
    speeds: list[float] = field(default_factory=list)

    def step(self, core: TouchdownCore, h: float, Omega: float, t_rec0: float) -> int:
        """Advance the core by h (s) and record; return the step status."""
        t0, psi0, mode = core.t, wrap_angle(core.psi), core.mode
        rep = core.step(h, Omega)
        for imp in rep.impacts:
            ang = cmath.phase(imp.z) - (psi0 + Omega * (imp.t - t0))
            self.times.append((imp.t - t_rec0) * Omega)
            self.angles.append(wrap_angle(ang))
            self.speeds.append(imp.rdot / (self.c_r * Omega))
            self.r_max = max(self.r_max, 1.0)
        t_prev = t0
        for t_tr, kind in rep.transitions:
            self._dwell(mode, t_tr - t_prev)
            mode, t_prev = _MODE_OF[kind], t_tr
        self._dwell(mode, core.t - t_prev)
        r = abs(core.z) / self.c_r
        self.r_max, self.r_min = max(self.r_max, r), min(self.r_min, r)
        return rep.status

    def _dwell(self, mode: int, dt: float) -> None:
        if mode == MODE_SLIDING:
            self.t_slide += dt * self.Omega
        elif mode == MODE_ROLLING:
            self.t_roll += dt * self.Omega


_MODE_OF = {"sliding": MODE_SLIDING, "rolling": MODE_ROLLING, "lift_off": MODE_FREE}


def run_to_attractor(core: TouchdownCore, Omega: float, h: float, n_transient: int,
                     n_record: int) -> tuple[Recorder | None, str]:
    """Step ``core`` n_transient times by h (s) at Omega (rad/s), then n_record times with a
    Recorder; return (recorder, "") or, when a step stops at the work cap, (None, message).
    The record window starts at the core's time after the transient."""
    for _ in range(n_transient):
        rep = core.step(h, Omega)
        if rep.status != STATUS_OK:
            return None, f"transient: {rep.message}"
    rec = Recorder(core.params.c_r, Omega)
    t_rec0 = core.t
    for _ in range(n_record):
        if rec.step(core, h, Omega, t_rec0) != STATUS_OK:
            return None, "record window: step stopped at work cap"
    return rec, ""


def detect_period(angles: Sequence[float], speeds: Sequence[float], tol: float,
                  max_period: int) -> int:
    """Smallest n <= max_period with the impact sequence n-periodic to ``tol``, else 0.

    The impact points (co-rotating angle, normal speed) are compared with those n impacts
    later over the last 4 max_period impacts; at least max(2, n) comparisons are needed.
    """
    a = np.asarray(angles[-4 * max_period - max_period:], float)
    v = np.asarray(speeds[-4 * max_period - max_period:], float)
    for n in range(1, max_period + 1):
        m = len(a) - n
        if m < max(2, n):
            break
        da = np.abs([wrap_angle(float(x)) for x in a[n:] - a[:-n]])
        dv = np.abs(v[n:] - v[:-n])
        if float(max(da.max(), dv.max())) < tol:
            return n
    return 0


def classify(n_impacts: int, slide_frac: float, roll_frac: float, period: int) -> str:
    """Regime from the record window's signature.

    whip (rolling at least half the time), rub (in contact at least half the time),
    free (no impact, no contact), period-<n> (impact map n-periodic), else irregular.
    """
    if roll_frac >= 0.5:
        return "whip"
    if slide_frac + roll_frac >= 0.5:
        return "rub"
    if n_impacts == 0 and slide_frac + roll_frac == 0.0:
        return "free"
    if period > 0:
        return f"period-{period}"
    return "irregular"


def regime_group(regime: str) -> str:
    """Colour group of a regime: period-<n> with n >= 3 becomes period-n."""
    if regime.startswith("period-") and regime not in ("period-1", "period-2"):
        return "period-n"
    return regime



def chapter_regime(regime: str, n_impacts: int) -> str:
    """The chapter's coarse regime (CHAPTER_REGIMES) of a ``classify`` regime: whip and rub
    as they are, otherwise impacting when there was an impact, else free whirl."""
    if regime == "whip":
        return CHAPTER_REGIMES[3]
    if regime == "rub":
        return CHAPTER_REGIMES[2]
    return CHAPTER_REGIMES[1] if n_impacts > 0 else CHAPTER_REGIMES[0]
