"""A sweep run's signature: run to the attractor, then summarise the record window as a row.

Scaled units (t = Omega tau): times and rates per unit scaled time, positions in c_r,
impact normal speeds in c_r Omega, angles in rad, co-rotating (U = z e^{-i psi}/c_r).
With the spin as a state (a SpinCore driven by T_drive, N m) Omega is the initial spin:
it sets the step and the scaled times; the final co-rotating velocity uses the final spin.
The drop (``simulate_drop``) is in SI: seconds, rad/s, m/s.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from rotortd import TouchdownCore
from rotortd.scaled import to_scaled

from rotortd_tools.attractor import (
    Recorder,
    classify,
    detect_period,
    run_drop,
    run_to_attractor,
)
from rotortd_tools.sweep.spec import Settings


def simulate(core: TouchdownCore, Omega: float, settings: Settings,
             T_drive: float | None = None) -> dict[str, Any]:
    """Run transient then record from the core's state; return the signature columns.
    ``T_drive`` (N m) drives a SpinCore; None for the held spin Omega (rad/s)."""
    h = 2.0 * math.pi / (Omega * settings.steps_per_rev)
    n_tr = round(settings.transient * settings.steps_per_rev / (2.0 * math.pi))
    n_rec = max(1, round(settings.record * settings.steps_per_rev / (2.0 * math.pi)))
    rec, message = run_to_attractor(core, Omega, h, n_tr, n_rec, T_drive)
    if rec is None:
        return {"status": "work-cap", "message": message}
    t_rec = n_rec * 2.0 * math.pi / settings.steps_per_rev
    return signature(rec, core, Omega, t_rec, settings)


def simulate_drop(core: TouchdownCore, Omega: float, settings: Settings,
                  T_drive: float | None = None) -> dict[str, Any]:
    """The drop from the core's state: drop_time seconds with the bearing off, the last
    drop_window seconds classified (``classify_drop``); return the signature columns.
    ``T_drive`` (N m) drives a SpinCore; None for the held spin Omega (rad/s)."""
    h = settings.drop_step
    n = max(1, round(settings.drop_time / h))
    n_win = max(1, min(n, round(settings.drop_window / h)))
    rec, message = run_drop(core, Omega, h, n, n_win, T_drive)
    if rec is None:
        return {"status": "work-cap", "message": message}
    p = core.params
    W = _spin(core, Omega)
    U, dU = to_scaled(core.z, core.v, W, p.c_r, core.psi)
    return {
        "status": "ok",
        "message": "",
        **rec.summary(p.R, p.c_r),
        "r_max": rec.r_max,
        "r_min": rec.r_min,
        "final_mode": core.mode,
        "U_re": U.real,
        "U_im": U.imag,
        "dU_re": dU.real,
        "dU_im": dU.imag,
        "Omega_end": W,
    }


def _spin(core: TouchdownCore, Omega: float) -> float:
    """The core's spin (rad/s): its state for a SpinCore, else the held Omega."""
    return float(core.Omega) if core.spin_is_state else Omega  # type: ignore[attr-defined]


def signature(rec: Recorder, core: TouchdownCore, Omega: float, t_rec: float,
              settings: Settings) -> dict[str, Any]:
    """The signature columns from a finished record window of scaled length t_rec."""
    n = len(rec.speeds)
    sp = np.asarray(rec.speeds, float)
    period = detect_period(rec.angles, rec.speeds, settings.period_tol, settings.max_period)
    slide, roll = rec.t_slide / t_rec, rec.t_roll / t_rec
    W = _spin(core, Omega)
    U, dU = to_scaled(core.z, core.v, W, core.params.c_r, core.psi)
    k = settings.section
    return {
        "status": "ok",
        "message": "",
        "regime": classify(n, slide, roll, period),
        "period": period,
        "period_time": _period_time(rec.times, period),
        "r_max": rec.r_max,
        "r_min": rec.r_min,
        "n_impacts": n,
        "impact_rate": n / t_rec,
        "impacts_per_rev": n * 2.0 * math.pi / t_rec,
        "v_mean": float(sp.mean()) if n else math.nan,
        "v_std": float(sp.std()) if n else math.nan,
        "v_min": float(sp.min()) if n else math.nan,
        "v_max": float(sp.max()) if n else math.nan,
        "contact_frac": slide + roll,
        "slide_frac": slide,
        "roll_frac": roll,
        "final_mode": core.mode,
        "U_re": U.real,
        "U_im": U.imag,
        "dU_re": dU.real,
        "dU_im": dU.imag,
        "sec_angle": list(rec.angles[-k:]) if k else [],
        "sec_speed": list(rec.speeds[-k:]) if k else [],
        "Omega_end": W,
    }


def _period_time(times: Sequence[float], period: int) -> float:
    """Mean scaled time over which the impact sequence repeats (NaN when not periodic)."""
    if period <= 0 or len(times) <= period:
        return math.nan
    t = np.asarray(times, float)
    return float(np.mean(t[period:] - t[:-period]))


