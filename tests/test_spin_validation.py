"""SpinCore against the independent spin reference (tests/reference/spin_reference.py).

The reference shares no code with the core (scipy DOP853 at rtol 1e-12, its own impact law,
contact equations and event handling). Tolerances come from the measured sensitivity of the
scene: the amplification A of a 1e-12 c_r perturbation of the start position into Omega,
measured in the test itself (about 1600 at J = m R^2/2, 800 at 5 m R^2: the impacts and the
entry into rolling amplify); the reference, at rtol 1e-12, is expected within a few A 1e-12.
"""

from __future__ import annotations

import functools
import math
import random

import numpy as np
import pytest
from rotortd import MODE_ROLLING, RotorParams, SpinCore, TouchdownCore
from rotortd.rigid import Delassus, spin_impact

from tests.reference.spin_reference import impact_law, simulate, steady_whirl_start
from tests.reference.spin_scenes import CHAPTER_G, OMEGA0

P = RotorParams(g=9.81)
T_END, H = 0.3, 1e-4


def test_impact_law_agrees_with_the_reference_law() -> None:
    """Two codings of the law (rigid.spin_impact, reference.impact_law) on 5000 random
    impacts, caps included: impulses and restitution to 1e-12."""
    rng = random.Random(11)
    capped = 0
    for _ in range(5000):
        m, R = 50.0, 0.04
        e = rng.choice([0.0, 3e-4, 5e-3, 2e-2])
        J = m * R * R * rng.choice([0.05, 0.5, 5.0])
        mu = min(rng.uniform(0, 1.5), 0.9 * J / (m * e * (R + e)) if e else 9.0)
        d = rng.choice([0.0, 0.5, 0.95, 0.99, 1.0])
        beta, rd = rng.uniform(-math.pi, math.pi), 10 ** rng.uniform(-4, 1)
        s = rng.uniform(-2, 2) * rng.choice([1.0, 1e-3])
        ours = spin_impact(Delassus.at(m, J, e, R, beta), mu, d, rd, s)
        ref = impact_law(m, J, e, R, mu, d, beta, rd, s)
        scale = m * (rd + abs(s))
        assert abs(ours.P_n - ref.P_n) <= 1e-12 * scale
        assert abs(ours.P_t - ref.P_t) <= 1e-12 * scale
        assert abs(ours.d_eff - ref.d_eff) <= 1e-12 and ours.stick == ref.stick
        capped += ref.capped
    assert capped > 5


@functools.cache
def _reference(J: float) -> object:
    z0, v0 = steady_whirl_start(CHAPTER_G, OMEGA0, a=1.0)
    grid = np.arange(round(T_END / H) + 1) * H
    return simulate(CHAPTER_G, J, OMEGA0, z0, v0, 0.0, T_END, grid, a=0.0)


def _drop(J: float, h: float, dz: float = 0.0) -> tuple[np.ndarray, np.ndarray, list]:
    """Omega and mode at every communication point of the drop (the bearing off from
    t = 0, from the held-speed levitated whirl, its position moved by dz c_r)."""
    held = TouchdownCore.on_steady_whirl(P, OMEGA0)
    core = SpinCore(P, J, held.z + dz * P.c_r, held.v, 0.0, OMEGA0)
    om, modes, trans = [core.Omega], [core.mode], []
    for _ in range(round(T_END / h)):
        rep = core.step(h, amb_on=0.0)
        om.append(core.Omega)
        modes.append(core.mode)
        trans += rep.transitions
    return np.array(om), np.array(modes), trans


@pytest.mark.parametrize("J_over_mR2", [0.5, 5.0])
def test_drop_into_dry_whip_matches_the_reference(J_over_mR2: float) -> None:
    """The drop at 184.2 rad/s into dry whip: Omega at every communication point, the
    times of entering contact and rolling, the mean whip speed over the last 0.1 s, mode 2
    kept; steps of 1e-4 and 1e-3 s agree within 100 A 1e-12."""
    J = J_over_mR2 * P.m * P.R ** 2
    ref = _reference(J)
    om, modes, trans = _drop(J, H)
    amp = np.max(np.abs(_drop(J, H, 1e-12)[0] - om)) / OMEGA0 / 1e-12
    assert 100 < amp < 1e5  # the scene amplifies (impacts, the entry into rolling)
    tol = 3.0 * amp * 1e-12 * OMEGA0  # rad/s
    assert np.max(np.abs(om - ref.samples["Omega"])) <= tol
    for name in ("sliding", "rolling"):
        ours = next(t for t, m in trans if m == name)
        assert abs(ours - ref.first_time(name)) <= 1e-9
    last = np.arange(len(om)) * H >= T_END - 0.1 - 1e-12
    assert abs(om[last].mean() - ref.samples["Omega"][last].mean()) <= tol
    first = int(np.argmax(modes == MODE_ROLLING))
    assert first > 0 and np.all(modes[first:] == MODE_ROLLING)
    coarse = _drop(J, 1e-3)[0]
    assert np.max(np.abs(coarse - om[::10])) <= 100.0 * amp * 1e-12 * OMEGA0
