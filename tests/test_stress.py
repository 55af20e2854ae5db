"""Stress tests of numerical stability (slow group, issue 6).

Every step of every case is checked by ``_check_step``: status OK, no NaN/inf, |z| within
c_r (1 + 1e-12), the work counter within its documented cap (``StepReport.work_cap``, equal
to ``work_cap(...)``), and no energy created by contact (E_diss >= 0 per step). Frictionless
cases (mu = 0) also close the rotor's energy balance:

    E(t) + E_diss(t) = E(0) + W_amb_damping(t) + W_imbalance(t) + W_external(t)

with E = m|v|^2/2 + a k|z|^2/2 (+ gravity/bias potential, constant force work). In a
conservative flight (c = 0, e_c = 0, constant force) the works vanish and the balance is
exact up to rounding; otherwise the works are integrated here by the trapezoidal rule on
a fine grid, split at every impact (v_minus / v_plus from the step report), so the check
only carries the quadrature error (O((h w)^2)).

Wall clock is never asserted. docs/benchmarks.md lists the cases and their results.
"""

from __future__ import annotations

import cmath
import math
import random

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from rotortd import (
    STATUS_OK,
    STATUS_WORK_CAP,
    WORK_MAX,
    RotorParams,
    StepReport,
    TouchdownCore,
    work_cap,
)
from rotortd_tools.cycles import (
    C_R,
    OMEGA,
    chapter_params,
    find_period_one_cycle,
    grazing_gamma,
    labelled_cycles,
    si_params,
)

pytestmark = pytest.mark.slow
W = OMEGA
CHAPTER = si_params(chapter_params())


# --------------------------------------------------------------------------- helpers
def _check_step(core: TouchdownCore, rep: StepReport, h: float, Om: float, F: complex,
                amb: float, speed0: float) -> None:
    p = core.params
    assert rep.status == STATUS_OK, rep.message
    assert rep.work_cap == work_cap(p, h, Om, F, amb, speed0)
    assert 0 <= rep.work <= rep.work_cap
    _check_state(core, rep, Om)


def _check_state(core: TouchdownCore, rep: StepReport, Om: float) -> None:
    p = core.params
    vals = (core.z.real, core.z.imag, core.v.real, core.v.imag, core.t, core.psi,
            rep.F_n, rep.F_n_peak, rep.P_n, rep.T_f, rep.E_diss, rep.F_contact.real,
            rep.F_contact.imag, core.E_diss)
    assert all(math.isfinite(x) for x in vals), vals
    assert abs(core.z) <= p.c_r * (1.0 + 1e-12)
    scale = abs(rep.P_n) * (abs(core.v) + p.c_r * abs(Om)) + 1e-300
    assert rep.E_diss >= -1e-12 * scale, (rep.E_diss, scale)
    assert rep.F_n >= 0.0 and rep.P_n >= 0.0 and rep.F_n_peak >= 0.0


def run_checked(core: TouchdownCore, steps: list[tuple[float, float, complex, float]],
                retry_at_bound: bool = False) -> list[StepReport]:
    """Step through (h, Omega, F_ext, amb_on) and check every step.

    retry_at_bound: a step that stops at the work bound (issue 18: a step beyond
    WORK_MAX returns fmi2Discard) must have used the whole bound and left a consistent
    state; the rest of it is then taken in 100 equal steps, as a master would retry, and
    each of those must complete."""
    reps = []
    for h, Om, F, amb in steps:
        speed, t0 = abs(core.v), core.t
        rep = core.step(h, Om, F, amb)
        if retry_at_bound and rep.status == STATUS_WORK_CAP:
            assert rep.work >= WORK_MAX, rep.message
            _check_state(core, rep, Om)
            rest = (t0 + h - core.t) / 100.0
            reps += run_checked(core, [(rest, Om, F, amb)] * 100)
            continue
        _check_step(core, rep, h, Om, F, amb, speed)
        reps.append(rep)
    return reps


def energy(core: TouchdownCore, amb: float, F_ext: complex) -> float:
    """m|v|^2/2 + a k |z|^2/2 - Re(conj(f_const) z): the rotor's mechanical energy with the
    potential of the constant force (bias, gravity, F_ext), J."""
    p = core.params
    f_const = amb * p.bias_force + F_ext - 1j * p.m * p.g
    z, v = core.z, core.v
    return 0.5 * p.m * abs(v) ** 2 + 0.5 * amb * p.k * abs(z) ** 2 - (f_const.conjugate()
                                                                       * z).real


def _power(p: RotorParams, amb: float, Om: float, psi: float, v: complex) -> float:
    """Power of AMB damping and imbalance on the rotor at spin angle psi, velocity v (W)."""
    f_imb = p.m * p.e_c * Om * Om * cmath.exp(1j * (psi + p.phi))
    return -amb * p.c * abs(v) ** 2 + (f_imb.conjugate() * v).real


def energy_balance(core: TouchdownCore, h: float, n: int, Om: float, amb: float = 1.0,
                   F_ext: complex = 0j) -> tuple[float, float]:
    """(residual, scale) of E + E_diss - E0 - W over n steps of h, works by trapezoid split
    at impacts."""
    p = core.params
    E0, D0, work = energy(core, amb, F_ext), core.E_diss, 0.0
    scale = abs(E0)
    for _ in range(n):
        t_a, psi_a, v_a, speed = core.t, core.psi, core.v, abs(core.v)
        rep = core.step(h, Om, F_ext, amb)
        _check_step(core, rep, h, Om, F_ext, amb, speed)
        knots = [(t_a, psi_a, v_a)]
        for imp in rep.impacts:
            psi_i = psi_a + Om * (imp.t - t_a)
            knots += [(imp.t, psi_i, imp.v_minus), (imp.t, psi_i, imp.v_plus)]
        knots.append((core.t, core.psi, core.v))
        for (ta, pa, va), (tb, pb, vb) in zip(knots[::2], knots[1::2]):
            pw_a, pw_b = _power(p, amb, Om, pa, va), _power(p, amb, Om, pb, vb)
            work += 0.5 * (tb - ta) * (pw_a + pw_b)
            scale += 0.5 * (tb - ta) * (abs(pw_a) + abs(pw_b))
        scale = max(scale, abs(energy(core, amb, F_ext)))
    res = energy(core, amb, F_ext) + (core.E_diss - D0) - E0 - work
    return res, scale


def scene_steps(h: float, n: int, Om: float = W) -> list[tuple[float, float, complex, float]]:
    return [(h, Om, 0j, 1.0)] * n


# --------------------------------------------------------------------------- extremes
GAMMAS = [1e-6, 1e-3, 0.065, 0.3, 1.0, 10.0]
RESTITUTIONS = [0.0, 1e-6, 0.5, 0.999999, 1.0]
FRICTIONS = [0.0, 0.15, 0.5, 2.0]
RHOS = [1e-6, 0.1, 3.0 / 7.0, 2.0, 100.0]


def _chapter(**over: float) -> RotorParams:
    return si_params(chapter_params(**over))


@pytest.mark.parametrize("gamma", GAMMAS)
@pytest.mark.parametrize("d", RESTITUTIONS)
def test_extreme_damping_and_restitution(gamma: float, d: float) -> None:
    """gamma 1e-6 ... 10 (overdamped), d in {0, 1e-6, 0.5, 0.999999, 1}: 0.1 s from rest
    in steps of 1e-3 s, then one 0.05 s step. (Beyond ~0.25 s, gamma <= 1e-3 with d >= 0.999999
    rattles at ~2e6 impacts/s, ~180 s CPU per simulated second: see docs/benchmarks.md.)"""
    core = TouchdownCore(_chapter(gamma=gamma, d=d))
    run_checked(core, [*scene_steps(1e-3, 100), (0.05, W, 0j, 1.0)])


@pytest.mark.parametrize("mu", FRICTIONS)
@pytest.mark.parametrize("rho", RHOS)
def test_extreme_friction_and_imbalance(mu: float, rho: float) -> None:
    """mu 0 ... 2, rho 1e-6 ... 100 (gamma = 0.065, whip-prone), 0.2 s from rest."""
    core = TouchdownCore(_chapter(gamma=0.065, mu=mu, rho=rho))
    run_checked(core, scene_steps(1e-3, 200))


@pytest.mark.parametrize("c_r", [1e-9, 1e-6, 1.0])
@pytest.mark.parametrize("gamma", [0.065, 0.3])
def test_extreme_clearances(c_r: float, gamma: float) -> None:
    """Clearance 1 nm and 1 m (eccentricity scaled with it, rho = 3/7), 0.2 s from rest
    and from the wall moving inward."""
    p = RotorParams.from_scaled(chapter_params(gamma=gamma), W, m=50.0, c_r=c_r)
    run_checked(TouchdownCore(p), scene_steps(1e-3, 200))
    core = TouchdownCore(p, z0=complex(0.0, c_r), v0=complex(0.3 * c_r * W, -0.1 * c_r * W))
    run_checked(core, scene_steps(1e-3, 100))


SPEEDS = [184.2, -184.2, 0.0, 1e5, -1e5, 0.0, 1e3, -1e-3, 3e4, -3e4, 184.2]


@pytest.mark.parametrize("h", [1e-6, 1e-4])
@pytest.mark.parametrize("case", ["chapter", "mu=0", "d=1,mu=2"])
def test_spin_speed_extremes_with_sign_changes(h: float, case: str) -> None:
    """|Omega| from 0 to 1e5 rad/s, changing sign between steps (2 steps per speed)."""
    p = {"chapter": CHAPTER, "mu=0": CHAPTER.replace(mu=0.0),
         "d=1,mu=2": CHAPTER.replace(d=1.0, mu=2.0)}[case]
    core = TouchdownCore(p, z0=0.5e-3j, v0=0.05)
    run_checked(core, [(h, s, 0j, 1.0) for s in SPEEDS for _ in range(2)])


def test_spin_speed_extremes_long_sliding_steps() -> None:
    """The same schedule at h = 1e-3 s, mu = 0 (5 steps per speed): long sliding segments
    at 1e5 rad/s (once an expected failure: the extrapolation stayed at order 6)."""
    core = TouchdownCore(CHAPTER.replace(mu=0.0), z0=0.5e-3j, v0=0.05)
    run_checked(core, [(1e-3, s, 0j, 1.0) for s in SPEEDS for _ in range(5)])


@pytest.mark.parametrize("case", ["k=c=0", "critical", "resonance", "overdamped"])
def test_degenerate_dynamics(case: str) -> None:
    """k = c = 0 (free drift into the wall), critical damping c^2 = 4 m k, undamped
    resonance (c = 0, Omega^2 = k/m), strong overdamping: 0.3 s in mixed steps."""
    m, k = 50.0, 9.8e5
    wn = math.sqrt(k / m)
    par = {"k=c=0": dict(k=0.0, c=0.0), "critical": dict(c=2.0 * math.sqrt(m * k)),
           "resonance": dict(c=0.0), "overdamped": dict(c=50.0 * math.sqrt(m * k))}[case]
    p = CHAPTER.replace(**par)
    Om = wn if case == "resonance" else W
    core = TouchdownCore(p, z0=1e-4 + 0j, v0=0.01j)
    steps = [(h, Om, 0j, 1.0) for h in (1e-9, 1e-6, 1e-4, 1e-3) for _ in range(20)]
    run_checked(core, [*steps, *scene_steps(1e-3, 250, Om), (1.0, Om, 0j, 1.0)])


@pytest.mark.parametrize("h", [1e-9, 1e-7, 1e-5, 1e-3, 0.1, 1.0, 10.0])
def test_step_sizes_from_1ns_to_10s(h: float) -> None:
    """One step size per run over the whole range, chattering scene (gamma = 0.3 from rest)
    and dry whirl (0.065): at most 0.5 s of simulated time or one step."""
    for gamma in (0.3, 0.065):
        core = TouchdownCore(_chapter(gamma=gamma))
        n = max(1, min(2000, round(0.5 / h)))
        run_checked(core, scene_steps(h, n))


def test_random_variable_steps_match_fixed_steps() -> None:
    """Random step sizes (log-uniform 1e-7 ... 1e-2 s) end where fixed steps end: free
    whirl (exact) and the stable limit cycle (tight)."""
    rng = random.Random(6)
    cyc = find_period_one_cycle(0.1)
    whirl = _chapter(gamma=0.3)
    for make, tol in ((lambda: TouchdownCore.on_steady_whirl(whirl, W), 1e-12),
                      (cyc.core, 1e-9)):
        ref = make()
        run_checked(ref, scene_steps(1e-3, 300))
        core, t_end = make(), 0.3
        while core.t < t_end - 1e-15:
            h = min(10.0 ** rng.uniform(-7, -2), t_end - core.t)
            run_checked(core, [(h, W, 0j, 1.0)])
        p = core.params
        assert abs(core.t - t_end) <= 1e-15
        assert abs(core.z - ref.z) / p.c_r <= tol
        assert abs(core.v - ref.v) / (p.c_r * W) <= tol
        assert core.n_impacts == ref.n_impacts


# --------------------------------------------------------------------------- soak
def test_soak_million_microsteps_no_drift() -> None:
    """10^6 steps of 1e-6 s on the steady whirl (gamma = 0.3) end where one 1 s step and the
    closed form z = Z0 + Z1 e^{i Omega t} end; the orbit radius never grows."""
    p = _chapter(gamma=0.3)
    core = TouchdownCore.on_steady_whirl(p, W)
    r0 = abs(core.z)
    long = TouchdownCore.on_steady_whirl(p, W)
    long.step(1.0, W)
    r_max, work_max = 0.0, 0
    for j in range(1_000_000):
        rep = core.step(1e-6, W)
        work_max = max(work_max, rep.work)
        if j % 1000 == 0:
            r_max = max(r_max, abs(core.z))
            assert rep.status == STATUS_OK
    assert work_max <= 2        # bound + cached propagation: no contact search on the whirl
    assert core.t == 1.0                     # compensated clock: no drift in time
    Z1 = (p.e_c * W * W * cmath.exp(1j * p.phi)) / (p.k / p.m - W * W + 1j * p.c / p.m * W)
    z_closed = Z1 * cmath.exp(1j * W * 1.0)
    assert abs(core.z - long.z) / p.c_r <= 1e-10    # measured 4e-11 (eps per step, linear)
    assert abs(core.z - z_closed) / p.c_r <= 1e-10
    assert abs(long.z - z_closed) / p.c_r <= 1e-12
    assert r_max <= r0 * (1 + 1e-9)


def test_soak_limit_cycle_microsteps_match_long_steps() -> None:
    """2e5 steps of 5e-6 s through the impacting limit cycle (gamma = 0.1) give the impacts
    and end state of 1000 steps of 1e-3 s (no growth, no lost impacts)."""
    cyc = find_period_one_cycle(0.1)
    fine, coarse = cyc.core(), cyc.core()
    for _ in range(200_000):
        rep = fine.step(5e-6, W)
        assert rep.status == STATUS_OK and abs(fine.z) <= C_R * (1 + 1e-12)
    run_checked(coarse, scene_steps(1e-3, 1000))
    assert fine.n_impacts == coarse.n_impacts == 64
    assert abs(fine.z - coarse.z) / C_R <= 1e-9
    assert abs(fine.t_last_impact - coarse.t_last_impact) * W <= 1e-9


# --------------------------------------------------------------------------- energy
@pytest.mark.parametrize("d", [0.0, 0.5, 0.95, 1.0])
def test_frictionless_conservative_energy_balance_is_exact(d: float) -> None:
    """mu = 0, no damping, no imbalance: E + E_diss is constant through impacts, chattering
    and frictionless sliding (to rounding)."""
    p = CHAPTER.replace(mu=0.0, c=0.0, e_c=0.0, d=d)
    core = TouchdownCore(p, z0=0.3e-3 + 0j, v0=complex(0.2, 0.35))
    E0 = energy(core, 1.0, 0j)
    for h in (1e-4, 1e-3, 0.05):
        reps = run_checked(core, scene_steps(h, 100))
        assert all(r.E_diss >= 0.0 for r in reps)
        balance = energy(core, 1.0, 0j) + core.E_diss - E0
        assert abs(balance) <= 1e-9 * E0, (h, balance / E0)
    assert core.n_impacts > 0
    if d == 1.0:
        assert core.E_diss <= 1e-12 * E0


@pytest.mark.parametrize("gamma", [0.065, 0.1, 0.3])
def test_frictionless_energy_balance_with_amb_and_imbalance(gamma: float) -> None:
    """mu = 0 with AMB damping and imbalance: E + E_diss - E0 equals the work of damping and
    imbalance (trapezoid at 1e-5 s, split at impacts) to quadrature accuracy."""
    p = _chapter(gamma=gamma, mu=0.0)
    core = TouchdownCore(p, z0=0.2e-3 + 0j, v0=0.1j)
    res, scale = energy_balance(core, 1e-5, 20_000, W)
    assert core.n_impacts > 0
    assert abs(res) <= 1e-5 * scale, (res, scale)


def test_energy_balance_with_gravity_drop_and_external_force() -> None:
    """mu = 0, g = 9.81, AMB off, constant external force: the potential of the constant
    force closes the balance through the drop, impacts and frictionless sliding."""
    p = CHAPTER.replace(mu=0.0, g=9.81)
    core = TouchdownCore(p)
    res, scale = energy_balance(core, 1e-5, 20_000, W, amb=0.0, F_ext=complex(300.0, -50.0))
    assert core.n_impacts > 0
    assert abs(res) <= 1e-5 * scale, (res, scale)


# --------------------------------------------------------------------------- grazing
def test_grazing_impact_speed_grows_like_square_root() -> None:
    """Along gamma through the grazing of the large cycle (gamma_g ~ 0.0636): starting from
    the grazing cycle's post-impact state, gamma_g - delta produces a new mid-flight impact
    whose speed grows like delta^(1/2); gamma_g + delta produces none."""
    g_graze = grazing_gamma("long-large", 0.065, 0.063)
    cyc = labelled_cycles(chapter_params(gamma=g_graze))["long-large"]
    h = 0.95 * cyc.T / W
    deltas = np.logspace(-9, -3, 13)
    speeds, times = [], []
    for delta in deltas:
        for sign in (+1.0, -1.0):
            core = TouchdownCore.from_scaled(_chapter(gamma=g_graze + sign * delta), W,
                                             U0=cyc.U0, dU0=cyc.dU0, psi0=0.0)
            reps = run_checked(core, [(h, W, 0j, 1.0)])
            if sign > 0:
                assert not reps[0].impacts
            else:
                imp = reps[0].impacts[0]
                speeds.append(imp.rdot / (C_R * W))
                times.append(imp.t * W)
    slope = np.polyfit(np.log(deltas), np.log(speeds), 1)[0]
    assert abs(slope - 0.5) < 0.01, slope
    assert np.all(np.diff(speeds) > 0)
    assert max(times) - min(times) < 0.1           # the same grazing point, mid-flight
    assert 0.3 * cyc.T < times[0] < 0.7 * cyc.T


# --------------------------------------------------------------------------- fuzzing
@st.composite
def schedules(draw: st.DrawFn) -> tuple:
    """A chapter-like scene with random tunables and a schedule of steps whose Omega,
    amb_on and F_ext change between steps (what tests/test_fuzz_core.py does not vary)."""
    p = CHAPTER.replace(
        c=draw(st.floats(0.0, 3e4)), k=draw(st.sampled_from([0.0, 1e4, 9.8e5, 1e8])),
        mu=draw(st.floats(0.0, 2.0)), d=draw(st.floats(0.0, 1.0)),
        e_c=draw(st.floats(0.0, 1e-3)), g=draw(st.sampled_from([0.0, 9.81])))
    steps = draw(st.lists(st.tuples(
        st.floats(-7.0, -2.0).map(lambda e: 10.0**e),
        st.floats(-2e3, 2e3),
        st.complex_numbers(max_magnitude=2e3, allow_nan=False, allow_infinity=False),
        st.sampled_from([0.0, 0.3, 1.0])), min_size=1, max_size=12))
    r0 = draw(st.floats(0.0, 1.0))
    return p, r0 * p.c_r * cmath.exp(1j * draw(st.floats(-3.2, 3.2))), steps


@settings(max_examples=150, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(schedules())
def test_fuzz_input_schedules(scene: tuple) -> None:
    p, z0, steps = scene
    v0 = -0.01 * z0 / p.c_r
    run_checked(TouchdownCore(p, z0=z0, v0=v0), steps, retry_at_bound=True)


@settings(max_examples=60, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(d=st.floats(0.0, 1.0), k=st.floats(1e4, 1e7), vx=st.floats(-0.5, 0.5),
       vy=st.floats(-0.5, 0.5), h=st.floats(-5.0, -1.0).map(lambda e: 10.0**e))
def test_fuzz_frictionless_conservative_balance(d: float, k: float, vx: float, vy: float,
                                                h: float) -> None:
    p = CHAPTER.replace(mu=0.0, c=0.0, e_c=0.0, d=d, k=k)
    core = TouchdownCore(p, z0=0.35e-3j, v0=complex(vx, vy))
    E0 = energy(core, 1.0, 0j)
    run_checked(core, scene_steps(h, max(1, min(200, round(0.05 / h)))))
    assert abs(energy(core, 1.0, 0j) + core.E_diss - E0) <= 1e-9 * E0 + 1e-300
