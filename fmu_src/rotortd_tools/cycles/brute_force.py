"""Brute force: run the core from standard starts to its attractor and name the regime.

The run and the classification are the sweep's (``rotortd_tools.attractor``); the regime is
reported in the chapter's four coarse words. Scaled co-rotating starts (U0, dU0); times
scaled (t = Omega tau); the chapter's SI realisation at Omega = 184.2 rad/s.
"""

from __future__ import annotations

from dataclasses import dataclass

from rotortd import TouchdownCore
from rotortd.scaled import CHAPTER_OMEGA as OMEGA
from rotortd.scaled import chapter_params, regular_equilibrium, si_params

from rotortd_tools.attractor import CHAPTER_REGIMES, chapter_regime, classify, run_to_attractor
from rotortd_tools.cycles.closed_form import labelled_cycles

REGIMES = CHAPTER_REGIMES
"""The chapter's coarse regimes, in the order of its figure legend."""


@dataclass(frozen=True)
class Attractor:
    """What a TouchdownCore run settles to (statistics over the recording window).

    max_r: max |z|/c_r at the step ends (and 1 when it touches); impacts: count in the
    window; frac_free / frac_sliding / frac_rolling: fractions of the window's time in each
    mode (from the exact transition times); whirl: final inertial whirl rate / Omega
    (1: synchronous forward rub, -R/c_r: rolling); regime: one of REGIMES.
    """

    gamma: float
    start: str
    max_r: float
    impacts: int
    frac_free: float
    frac_sliding: float
    frac_rolling: float
    whirl: float
    regime: str


def run_attractor(
    gamma: float,
    U0: complex,
    dU0: complex,
    start: str = "",
    t_end: float = 300.0,
    t_rec: float = 200.0,
    dt: float = 0.5,
) -> Attractor:
    """Run TouchdownCore from the scaled co-rotating (U0, dU0) for t_end (scaled time).

    Steps of dt (scaled); statistics over the steps that end after t_rec. Chapter set,
    Omega = OMEGA. RuntimeError when a step stops at the core's work cap.
    """
    p = si_params(chapter_params(gamma=gamma))
    core = TouchdownCore.from_scaled(p, OMEGA, U0=U0, dU0=dU0)
    n = round(t_end / dt)
    n_tr = next((k for k in range(n) if (k + 1) * dt > t_rec), n)
    rec, message = run_to_attractor(core, OMEGA, dt / OMEGA, n_tr, n - n_tr)
    if rec is None:
        raise RuntimeError(f"gamma = {gamma}, start {start!r}: {message}")
    window = (n - n_tr) * dt
    slide, roll = rec.t_slide / window, rec.t_roll / window
    n_imp = len(rec.speeds)
    regime = classify(n_imp, slide, roll, 0)
    whirl = core.kinematics().whirl_rate / OMEGA
    free = max(0.0, 1.0 - slide - roll)
    return Attractor(gamma, start, rec.r_max, n_imp, free, slide, roll, whirl,
                     chapter_regime(regime, n_imp))


def standard_starts(gamma: float) -> dict[str, tuple[complex, complex]]:
    """Four starts (scaled co-rotating U0, dU0): rest, near U*, on a cycle, a large orbit."""
    sp = chapter_params(gamma=gamma)
    Us = regular_equilibrium(sp)
    near = Us * 0.98 if abs(Us) < 1.0 else 0.98 * Us / abs(Us)
    starts = {"rest": (0j, 0j), "near U*": (near + 0.01, 0j)}
    cyc = labelled_cycles(sp)
    for key in ("long-large", "short-large"):
        if key in cyc:
            c = cyc[key]
            starts["cycle"] = (c.U0, c.dU0)
            break
    starts["large orbit"] = (0.9 + 0j, -0.9j)
    return starts
