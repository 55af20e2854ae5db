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
from rotortd.bodies.rotor import Delassus, spin_impact

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
    core = SpinCore(P, J, z0=held.z + dz * P.c_r, v0=held.v, psi0=0.0, Omega0=OMEGA0)
    om, modes, trans = [core.Omega], [core.mode], []
    for _ in range(round(T_END / h)):
        rep = core.step(h, amb_on=0.0)
        om.append(core.Omega)
        modes.append(core.mode)
        trans += rep.transitions
    return np.array(om), np.array(modes), trans


@pytest.mark.parametrize("J_over_mR2", [0.5, 5.0])
def test_drop_into_dry_whirl_matches_the_reference(J_over_mR2: float) -> None:
    """The drop at 184.2 rad/s into dry whirl: Omega at every communication point, the
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


def _reference_pair(params: dict, J: float, W0: float, t_end: float, h: float, **ins: float
                    ) -> tuple[object, np.ndarray]:
    """The reference at rtol 1e-12 and the spread |ref(1e-11) - ref(1e-12)| of its Omega
    at every communication point: the measured error scale of the reference itself."""
    z0, v0 = steady_whirl_start(params, W0, a=ins.get("a", 1.0))
    grid = np.arange(round(t_end / h) + 1) * h
    fine = simulate(params, J, W0, z0, v0, 0.0, t_end, grid, rtol=1e-12, **ins)
    coarse = simulate(params, J, W0, z0, v0, 0.0, t_end, grid, rtol=1e-11, **ins)
    assert fine.status == coarse.status == "ok"
    return fine, np.abs(coarse.samples["Omega"] - fine.samples["Omega"])


def _run(core: SpinCore, h: float, n: int, **ins: float) -> tuple[np.ndarray, list]:
    om, trans = [core.Omega], []
    for _ in range(n):
        rep = core.step(h, **ins)
        assert rep.status == 0, rep.message
        om.append(core.Omega)
        trans += rep.transitions
    return np.array(om), trans


def test_run_down_with_the_drive_through_impacts_and_forward_rub() -> None:
    """Braked by the drive (T_drive = -4 N m) from 220 rad/s with the bearing on and
    gravity: the whirl grows through the critical speed into impacts (254), then a forward
    rub (sliding with the whirl forward) that lifts off near 120 rad/s. Omega at every 1 ms
    communication point, the impacts and the times of entering and leaving the rub, against
    the reference within 3x its own rtol spread."""
    J, W0, h, n = 0.04, 220.0, 1e-3, 900
    ref, spread = _reference_pair(CHAPTER_G, J, W0, n * h, h, a=1.0, T_drive=-4.0)
    held = TouchdownCore.on_steady_whirl(P, W0)
    core = SpinCore(P, J, z0=held.z, v0=held.v, psi0=0.0, Omega0=W0)
    om, trans = _run(core, h, n, amb_on=1.0, T_drive=-4.0)
    assert core.n_impacts == len(ref.impacts) > 100
    assert np.max(np.abs(om - ref.samples["Omega"]) - 3.0 * spread) <= 1e-12 * W0
    (t_rub, name), (t_off, name_off) = trans[0], trans[1]
    assert name == "sliding" and name_off == "lift_off"
    assert abs(t_rub - ref.first_time("sliding")) <= 1e-8
    assert abs(t_off - ref.first_time("free")) <= 1e-8
    k = np.searchsorted(np.arange(n + 1) * h, 0.5 * (t_rub + t_off))
    assert ref.samples["theta_dot"][k] > 0.0 and ref.samples["mode"][k] == 1  # forward


@pytest.mark.slow
@pytest.mark.parametrize(("T_drive", "t_end"), [(1.0, 5.0), (0.1, 60.0)])
def test_run_up_through_the_critical_speed(T_drive: float, t_end: float) -> None:
    """Run-up with the bearing on and no contact (g = 0, c = 5000 N s/m, the chapter's rotor
    otherwise, J = 0.04 kg m^2) from 60 rad/s at a constant drive torque: 1 N m passes the
    critical speed sqrt(k/m) = 140 rad/s; 0.1 N m is held below it by the imbalance drag,
    which rises with speed here, so the speed settles just below it without a jump, towards
    the speed where the steady whirl's damper dissipation c Omega^2 |Z1|^2 equals the drive's
    power T Omega. Omega at every 1 ms point against the reference within 3x its own rtol
    spread."""
    params = dict(CHAPTER_G, g=0.0, c=5000.0)
    p = RotorParams(g=0.0, c=5000.0)
    h, W0, J = 1e-3, 60.0, 0.04
    ref, spread = _reference_pair(params, J, W0, t_end, h, a=1.0, T_drive=T_drive)
    core = SpinCore.on_steady_whirl(p, W0, J=J)
    om, _ = _run(core, h, round(t_end / h), amb_on=1.0, T_drive=T_drive)
    assert core.n_impacts == 0 and len(ref.impacts) == 0
    assert np.max(np.abs(om - ref.samples["Omega"]) - 3.0 * spread) <= 1e-12 * W0
    w_crit = math.sqrt(p.k / p.m)
    if T_drive == 1.0:
        assert om[-1] > 1.2 * w_crit
    else:
        def drag(W: float) -> float:  # N m: c Omega |Z1|^2 of the steady whirl at W
            Z1 = p.m * p.e_c * W * W / abs(p.k - p.m * W * W + 1j * p.c * W)
            return p.c * W * Z1 * Z1

        lo, hi = W0, w_crit  # the speed where drag = T_drive (drag rises with speed)
        for _ in range(60):
            lo, hi = ((lo + hi) / 2, hi) if drag((lo + hi) / 2) < T_drive else (lo, (lo + hi) / 2)
        assert np.all(np.diff(om) > 0.0) and 0.9 * w_crit < om[-1] < lo < w_crit
        assert (om[-1] - om[-1001]) < 0.35 * (om[31000] - om[30000])  # settling
