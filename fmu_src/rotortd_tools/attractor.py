"""Run a core to its attractor and classify it: shared by sweeps and the chapter's brute force.

Scaled units (t = Omega tau; one revolution is 2 pi): the record window's times, dwell times
and rates are scaled, impact normal speeds in c_r Omega, angles in rad, co-rotating
(the impact angle is arg z - psi). ``run_to_attractor`` steps a ``TouchdownCore`` through a
transient and then a record window with a ``Recorder``, which takes the impacts and the
exact contact transition times from the core's step reports (the step length only sets
the sampling of r). ``classify`` names the regime from the window (docs/sweeps.md):
"at least half the window" is ``>= 0.5``. A ``SpinCore`` (the spin as a state) is stepped
with its held drive torque ``T_drive`` (N m); its spin is then the core's own.

The drop (``run_drop``, SI units, seconds): the bearing off (amb_on = 0) for a fixed number
of steps, the last ones recorded by a ``DropRecorder``; ``classify_drop`` names the outcome
(no-contact, impacting, settled, forward-rub, dry-whip, dry-whirl; docs/sweeps.md).
"""

from __future__ import annotations

import cmath
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from rotortd import MODE_FREE, MODE_ROLLING, MODE_SLIDING, STATUS_OK, TouchdownCore
from rotortd.scaled import wrap_angle

CHAPTER_REGIMES = ("free whirl", "impacting", "rub/sliding", "dry whirl/rolling")
"""The chapter's coarse regimes (``chapter_regime``)."""
MOST = 0.5
""""At least half the window" (``>= MOST``): the fraction rule of ``classify``."""
DROP_OUTCOMES = ("no-contact", "impacting", "settled", "forward-rub", "dry-whip",
                 "dry-whirl")
"""The drop outcomes of ``classify_drop``, in the order they are tested."""
SLIP_ROLL = 0.01
"""Largest slip ratio (mean |v_rel| over the larger of R |Omega| and c_r |theta'|) of a
dry whirl (rolling backward whirl); above it the backward whirl slides: dry whip."""
WHIRL_TURNS = 1.0
"""Fewest turns round the bearing (|mean theta'| window / 2 pi) of a whirl; below it the
rotor in contact is ``settled`` (lying or rocking at the bottom)."""


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

    def step(self, core: TouchdownCore, h: float, Omega: float, t_rec0: float,
             T_drive: float | None = None) -> int:
        """Advance the core by h (s) and record; return the step status. With ``T_drive``
        (N m) the core is a SpinCore: the impact angles use its spin at the step start."""
        t0, psi0, mode = core.t, wrap_angle(core.psi), core.mode
        if T_drive is None:
            W = Omega
            rep = core.step(h, Omega)
        else:
            W = core.Omega  # type: ignore[attr-defined]
            rep = core.step(h, T_drive=T_drive)  # type: ignore[call-arg]
        for imp in rep.impacts:
            ang = cmath.phase(imp.z) - (psi0 + W * (imp.t - t0))
            self.times.append((imp.t - t_rec0) * Omega)
            self.angles.append(wrap_angle(ang))
            self.speeds.append(imp.rdot / (self.c_r * Omega))
            self.r_max = max(self.r_max, 1.0)
        for seg_mode, dt in dwell_times(mode, t0, rep.transitions, core.t):
            self._dwell(seg_mode, dt)
        r = abs(core.z) / self.c_r
        self.r_max, self.r_min = max(self.r_max, r), min(self.r_min, r)
        return rep.status

    def _dwell(self, mode: int, dt: float) -> None:
        if mode == MODE_SLIDING:
            self.t_slide += dt * self.Omega
        elif mode == MODE_ROLLING:
            self.t_roll += dt * self.Omega


_MODE_OF = {"sliding": MODE_SLIDING, "rolling": MODE_ROLLING, "lift_off": MODE_FREE}


def dwell_times(mode: int, t0: float, transitions: list[tuple[float, str]], t1: float
                ) -> list[tuple[int, float]]:
    """(mode, time in it (s)) for each stretch of a step from t0 to t1 (s) that began in
    ``mode``, split at the step report's ``transitions``."""
    out, t_prev = [], t0
    for t_tr, kind in transitions:
        out.append((mode, t_tr - t_prev))
        mode, t_prev = _MODE_OF[kind], t_tr
    out.append((mode, t1 - t_prev))
    return out


def run_to_attractor(core: TouchdownCore, Omega: float, h: float, n_transient: int,
                     n_record: int, T_drive: float | None = None
                     ) -> tuple[Recorder | None, str]:
    """Step ``core`` n_transient times by h (s) at Omega (rad/s), then n_record times with a
    Recorder; return (recorder, "") or, when a step stops at the work cap, (None, message).
    The record window starts at the core's time after the transient. With ``T_drive``
    (N m) the core is a SpinCore driven by it (Omega then only scales the record). The
    imbalance torque is not computed (``TouchdownCore.imbalance_torque``): nothing reads it."""
    core.imbalance_torque = False
    for _ in range(n_transient):
        rep = (core.step(h, Omega) if T_drive is None
               else core.step(h, T_drive=T_drive))  # type: ignore[call-arg]
        if rep.status != STATUS_OK:
            return None, f"transient: {rep.message}"
    rec = Recorder(core.params.c_r, Omega)
    t_rec0 = core.t
    for _ in range(n_record):
        if rec.step(core, h, Omega, t_rec0, T_drive) != STATUS_OK:
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

    dry-whirl (rolling at least half the time), rub (in contact at least half the time),
    free (no impact, no contact), period-<n> (impact map n-periodic), else irregular.
    """
    if roll_frac >= MOST:
        return "dry-whirl"
    if slide_frac + roll_frac >= MOST:
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
    """The chapter's coarse regime (CHAPTER_REGIMES) of a ``classify`` regime: dry-whirl and rub
    as they are, otherwise impacting when there was an impact, else free whirl."""
    if regime == "dry-whirl":
        return CHAPTER_REGIMES[3]
    if regime == "rub":
        return CHAPTER_REGIMES[2]
    return CHAPTER_REGIMES[1] if n_impacts > 0 else CHAPTER_REGIMES[0]


# --------------------------------------------------------------------------- the drop


@dataclass
class DropRecorder:
    """The drop's record window (SI): impacts, dwell times and step-end samples.

    ``t_window`` (s) is the window's length; the sums are over the step-end samples of
    the spin Omega (rad/s), the whirl rate theta' (rad/s) and the slip |v_rel| (m/s)."""

    t_window: float
    n_impacts: int = 0
    t_slide: float = 0.0
    t_roll: float = 0.0
    n: int = 0
    sum_Omega: float = 0.0
    sum_whirl: float = 0.0
    sum_slip: float = 0.0
    r_max: float = -math.inf
    r_min: float = math.inf

    def step(self, core: TouchdownCore, h: float, Omega: float,
             T_drive: float | None) -> int:
        """Advance the core by h (s) with the bearing off and record; return the status."""
        t0, mode = core.t, core.mode
        rep = (core.step(h, Omega, amb_on=0.0) if T_drive is None
               else core.step(h, amb_on=0.0, T_drive=T_drive))  # type: ignore[call-arg]
        self.n_impacts += len(rep.impacts)
        if rep.impacts:
            self.r_max = max(self.r_max, 1.0)
        for seg_mode, dt in dwell_times(mode, t0, rep.transitions, core.t):
            self._dwell(seg_mode, dt)
        k = core.kinematics(Omega if T_drive is None else None, 0.0)
        W = Omega if T_drive is None else core.Omega  # type: ignore[attr-defined]
        self.n += 1
        self.sum_Omega += W
        self.sum_whirl += k.whirl_rate
        self.sum_slip += abs(k.v_rel)
        self.r_max, self.r_min = max(self.r_max, k.r_rel), min(self.r_min, k.r_rel)
        return rep.status

    def _dwell(self, mode: int, dt: float) -> None:
        if mode == MODE_SLIDING:
            self.t_slide += dt
        elif mode == MODE_ROLLING:
            self.t_roll += dt

    def summary(self, R: float, c_r: float) -> dict[str, float | int | str]:
        """Fractions of the window, means (rad/s, m/s), slip ratio and the outcome."""
        n = max(self.n, 1)
        W, whirl, slip = self.sum_Omega / n, self.sum_whirl / n, self.sum_slip / n
        slide, roll = self.t_slide / self.t_window, self.t_roll / self.t_window
        scale = max(R * abs(W), c_r * abs(whirl))
        ratio = slip / scale if scale > 0.0 else (0.0 if slip == 0.0 else math.inf)
        return {
            "n_impacts": self.n_impacts, "slide_frac": slide, "roll_frac": roll,
            "contact_frac": slide + roll, "Omega_mean": W, "whirl_mean": whirl,
            "slip_mean": slip, "slip_ratio": ratio,
            "regime": classify_drop(self.n_impacts, slide, roll, W, whirl, ratio,
                                    self.t_window),
        }


def run_drop(core: TouchdownCore, Omega: float, h: float, n_steps: int, n_window: int,
             T_drive: float | None = None) -> tuple[DropRecorder | None, str]:
    """Drop: step ``core`` n_steps times by h (s) with the bearing off (amb_on = 0) and
    gravity as the core's parameters have it, recording the last n_window steps; Omega
    (rad/s) is the held spin, or ignored with ``T_drive`` (N m, a SpinCore). Return
    (recorder, "") or (None, message) when a step stops at the work cap. The imbalance
    torque is not computed, as in run_to_attractor."""
    core.imbalance_torque = False
    n_window = min(n_window, n_steps)
    for i in range(n_steps - n_window):
        rep = (core.step(h, Omega, amb_on=0.0) if T_drive is None
               else core.step(h, amb_on=0.0, T_drive=T_drive))  # type: ignore[call-arg]
        if rep.status != STATUS_OK:
            return None, f"drop, step {i}: {rep.message}"
    rec = DropRecorder(n_window * h)
    for _ in range(n_window):
        if rec.step(core, h, Omega, T_drive) != STATUS_OK:
            return None, "drop record window: step stopped at work cap"
    return rec, ""


def classify_drop(n_impacts: int, slide_frac: float, roll_frac: float, Omega_mean: float,
                  whirl_mean: float, slip_ratio: float, t_window: float) -> str:
    """Outcome of a drop from its record window (docs/sweeps.md, tested in this order).

    n_impacts: impacts in the window; slide_frac, roll_frac: fractions of the window
    sliding and rolling; Omega_mean, whirl_mean: mean spin and whirl rate theta' (rad/s);
    slip_ratio: mean |v_rel| over max(R |Omega_mean|, c_r |whirl_mean|); t_window (s).

      no-contact      no impact and no contact in the window (``classify``'s free)
      impacting       in contact less than half the window (``classify``: not rub/dry-whirl)
      settled         in contact, but less than WHIRL_TURNS turns round the bearing:
                      |whirl_mean| t_window < 2 pi WHIRL_TURNS (lying or rocking)
      forward-rub     whirling with the spin: whirl_mean Omega_mean > 0 (Omega_mean >= 0
                      counts as positive)
      dry-whirl        whirling against the spin, rolling: slip_ratio <= SLIP_ROLL
      dry-whip        whirling against the spin, sliding: slip_ratio > SLIP_ROLL
    """
    regime = classify(n_impacts, slide_frac, roll_frac, 0)
    if regime == "free":
        return "no-contact"
    if regime not in ("rub", "dry-whirl"):
        return "impacting"
    if abs(whirl_mean) * t_window < 2.0 * math.pi * WHIRL_TURNS:
        return "settled"
    sense = 1.0 if Omega_mean >= 0.0 else -1.0
    if sense * whirl_mean > 0.0:
        return "forward-rub"
    return "dry-whirl" if slip_ratio <= SLIP_ROLL else "dry-whip"
