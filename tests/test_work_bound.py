"""The per-step work bound (docs/model.md 7): every step ends within WORK_MAX work units
(plus at most one sliding event location, WORK_OVERSHOOT) for any finite input, and stops
with STATUS_WORK_CAP and a message saying where when the bound is reached; with the spin as
a state (SpinCore, integrate_spin) its segments count into the same bound. Extremes that
are slow but correct (a 1e12 N force) finish within it, and a tiny spin speed behaves like
Omega = 0."""

from __future__ import annotations

import math

import pytest
from rotortd import STATUS_OK, STATUS_WORK_CAP, WORK_MAX, RotorParams, SpinCore, TouchdownCore
from rotortd.contact.search import WORK_OVERSHOOT

BASE = RotorParams()  # the FMU's defaults: m = 50 kg, c_r = 0.7 mm, Omega = 184.2 rad/s
W0 = 184.2


def _assert_capped(rep: object, core: TouchdownCore, t0: float, h: float, cap: int) -> None:
    assert rep.status == STATUS_WORK_CAP
    assert "work bound reached" in rep.message and "t = " in rep.message
    assert cap < rep.work <= cap + WORK_OVERSHOOT
    assert t0 <= core.t < t0 + h
    assert all(math.isfinite(x) for x in (core.z.real, core.z.imag)) or "free" in rep.message


def test_long_step_with_fast_impacts_stops_at_the_bound() -> None:
    """A 10 s step of a rotor thrown around by a large imbalance with d = 1 (tens of
    thousands of impacts per ms): the cap fires at the real bound; the state is the one
    at the time reported, and the next step goes on from there."""
    p = BASE.replace(e_c=0.1, c=0.0, k=0.0, d=1.0, mu=0.0, c_r=1e-6, m=1e-3)
    core = TouchdownCore(p, z0=0j, v0=1.0 + 0j)
    rep = core.step(10.0, 1e5)
    _assert_capped(rep, core, 0.0, 10.0, WORK_MAX)
    assert "free flight" in rep.message and "impacts in the step" in rep.message
    assert rep.work_cap == WORK_MAX and len(rep.impacts) > 1000
    assert abs(core.z) <= p.c_r * (1.0 + 1e-12)
    t1 = core.t
    rep2 = core.step(1e-9, 1e5)
    assert rep2.status == STATUS_OK and core.t == pytest.approx(t1 + 1e-9, abs=1e-15)


def test_sliding_segment_stops_inside_at_its_budget() -> None:
    """The 1e12 N scene with a small budget: the sliding integrator stops inside its
    segment and says where (the budget argument of TouchdownCore.step)."""
    core = TouchdownCore(BASE)
    F = 1e12 + 0j
    assert core.step(1e-4, W0, F).status == STATUS_OK  # impacts, then sliding
    t0 = core.t
    rep = core.step(1e-4, W0, F, budget=2000)
    _assert_capped(rep, core, t0, 1e-4, 2000)
    assert "in sliding" in rep.message and "sliding stopped at" in rep.message


@pytest.mark.parametrize("case", ["vx0 = 1e308", "F_x = -1.7e308 mid-run"])
def test_overflowing_extremes_stop_at_the_bound(case: str) -> None:
    """Finite inputs beyond the FMU's ranges whose flight overflows (NaN states): the
    search cannot make progress, and the step stops at its budget instead of hanging."""
    if case == "vx0 = 1e308":
        core, F = TouchdownCore(BASE, z0=0j, v0=1e308 + 0j), 0j
    else:
        core, F = TouchdownCore(BASE), -1.7e308 + 0j
        assert core.step(1e-3, W0).status == STATUS_OK
    t0 = core.t
    rep = core.step(1e-3, W0, F, budget=50_000)
    _assert_capped(rep, core, t0, 1e-3, 50_000)


def _assert_spin_capped(rep: object, core: SpinCore, t0: float, h: float, cap: int) -> None:
    """A SpinCore step stopped at its budget: the status, a message saying where (work,
    time, segment kind, the spin as a state), the work within the bound and a consistent
    state at the time reached."""
    assert rep.status == STATUS_WORK_CAP
    assert "work bound reached" in rep.message and "t = " in rep.message
    assert "with the spin as a state" in rep.message
    assert cap < rep.work <= cap + WORK_OVERSHOOT
    assert t0 <= core.t < t0 + h
    assert abs(core.z) <= core.params.c_r * (1.0 + 1e-12)
    assert all(math.isfinite(x) for x in (core.z.real, core.z.imag, core.v.real,
                                          core.v.imag, core.Omega))


def test_spin_core_step_with_fast_impacts_stops_at_its_budget() -> None:
    """SpinCore, a 10 s step of a light rotor thrown around by a large imbalance with
    d = 1 (hundreds of impacts per 0.1 ms): the step stops at its budget in free flight,
    says where, and the next step goes on from the state reached."""
    p = BASE.replace(e_c=0.1, c=0.0, k=0.0, d=1.0, mu=0.0, c_r=1e-6, m=1e-3)
    core = SpinCore(p, 1e-3, z0=0j, v0=1.0 + 0j, Omega0=1e5)
    rep = core.step(10.0, F_ext=0j, amb_on=1.0, T_drive=0.0, budget=50_000)
    _assert_spin_capped(rep, core, 0.0, 10.0, 50_000)
    assert "free flight" in rep.message and "impacts in the step" in rep.message
    assert rep.work_cap == 50_000 and len(rep.impacts) > 100
    t1 = core.t
    rep2 = core.step(1e-9, F_ext=0j, amb_on=1.0, T_drive=0.0)
    assert rep2.status == STATUS_OK and core.t == pytest.approx(t1 + 1e-9, abs=1e-15)


def test_spin_core_step_pressed_into_the_wall_stops_at_its_budget() -> None:
    """SpinCore pressed into the bearing by 1e9 N with a drive torque: impacts and contact
    work; a step with a small budget stops inside, says where, and the state it leaves
    continues with an OK step."""
    core = SpinCore(BASE, 0.04, z0=0j, v0=0j, Omega0=W0)
    F = 1e9 + 0j
    for _ in range(3):
        assert core.step(1e-4, F_ext=F, amb_on=1.0, T_drive=1.0).status == STATUS_OK
    t0 = core.t
    rep = core.step(1e-4, F_ext=F, amb_on=1.0, T_drive=1.0, budget=2000)
    _assert_spin_capped(rep, core, t0, 1e-4, 2000)
    assert "s into the step of" in rep.message
    assert core.step(1e-6, F_ext=F, amb_on=1.0, T_drive=1.0).status == STATUS_OK


def test_spin_core_default_budget_is_the_core_bound() -> None:
    """Without a budget a SpinCore step gets WORK_MAX, and a budget above it is cut to it."""
    core = SpinCore(BASE, 0.04, z0=0j, v0=0j, Omega0=W0)
    assert core.step(1e-4).work_cap == WORK_MAX
    assert core.step(1e-4, budget=10 * WORK_MAX).work_cap == WORK_MAX


def test_spin_core_leaves_the_wall_inward() -> None:
    """On the wall with a tangential velocity, the AMB pulling inward: the rotor must
    leave the wall (TouchdownCore does, in one OK step)."""
    held = TouchdownCore(BASE, z0=BASE.c_r + 0j, v0=0.05j)
    assert held.step(1e-3, W0).status == STATUS_OK
    core = SpinCore(BASE, 0.04, z0=BASE.c_r + 0j, v0=0.05j, Omega0=W0)
    rep = core.step(1e-3, budget=20_000)
    assert rep.status == STATUS_OK and core.t == pytest.approx(1e-3)


def test_force_of_1e12_newton_stays_within_the_bound() -> None:
    """F_x = 1e12 N presses the rotor into the bearing (default parameters, 1e-4 s steps):
    a stiff, lightly damped friction pendulum at sqrt(F/(m c_r)) = 5.3e6 rad/s that the
    sliding integrator follows at about 0.5 rad per step, some 107,000 units per step.
    Every step ends OK, well within the bound (the full 200 steps: the slow group)."""
    core = TouchdownCore(BASE)
    for _ in range(10):
        rep = core.step(1e-4, W0, 1e12 + 0j)
        assert rep.status == STATUS_OK and rep.work <= WORK_MAX // 10
        assert abs(core.z) <= BASE.c_r * (1.0 + 1e-12)


@pytest.mark.slow
def test_force_of_1e12_newton_for_200_steps() -> None:
    core = TouchdownCore(BASE)
    works = []
    for _ in range(200):
        rep = core.step(1e-4, W0, 1e12 + 0j)
        assert rep.status == STATUS_OK
        works.append(rep.work)
    assert max(works) <= WORK_MAX // 10
    assert core.t == pytest.approx(0.02, abs=1e-15)


@pytest.mark.parametrize("W", [5e-324, -5e-324, 1e-310, 1e-300])
def test_tiny_spin_speed_behaves_like_zero(W: float) -> None:
    """A subnormal or tiny Omega: steps in free flight, impacts and contact end OK, and the
    kinematics are finite; the scaled dU/dt, where it would overflow (or divide by
    c_r Omega = 0), is 0 as at Omega = 0."""
    for z0, v0 in ((0j, 0j), (0.5e-3 + 0j, 0.1 + 0.2j), (BASE.c_r + 0j, 0.05j)):
        core = TouchdownCore(BASE.replace(k=0.0, c=0.0) if z0 == 0 else BASE, z0=z0, v0=v0)
        for i in range(20):
            rep = core.step(1e-3 if i % 2 else 3.7e-3, W, 1e3 + 0j if i > 10 else 0j)
            assert rep.status == STATUS_OK
            kin = core.kinematics(W, 1.0)
            assert all(math.isfinite(x) for x in kin)
        if BASE.c_r * abs(W) < abs(core.v) / 1.7e308:  # dU/dt = ~v/(c_r Omega) overflows
            assert kin.du_re == 0.0 and kin.du_im == 0.0
    zero = TouchdownCore(BASE, z0=0.5e-3 + 0j, v0=0.1 + 0.2j).kinematics(0.0, 1.0)
    assert zero.du_re == 0.0 and zero.du_im == 0.0
    spin = SpinCore(BASE, 0.04, z0=0.5e-3 + 0j, v0=0.1 + 0.2j, Omega0=W)  # the spin a state
    for i in range(10):
        rep = spin.step(1e-3 if i % 2 else 3.7e-3, F_ext=0j, amb_on=1.0, T_drive=0.0)
        assert rep.status == STATUS_OK and math.isfinite(spin.Omega)
    assert spin.n_impacts > 0


def test_a_stop_below_the_bound_does_not_claim_it() -> None:
    """A segment that stops for another reason than the work bound (the spin-state flight
    without an a-priori bound of its motion raises ContactWorkExceeded with work = 0) gets
    a message that says how much of the bound was used, never "work bound reached: 208 >
    1600000" (the rolling exit search once stopped a step so)."""
    from rotortd.contact.wall import ContactWorkExceeded
    from rotortd.step.report import StepContext, StepReport, stop_at_work_bound

    for used, claim in ((200, False), (WORK_MAX + 1, True)):
        rep, st = StepReport(), StepContext(WORK_MAX)
        st.work.iters = used
        stop_at_work_bound(rep, st, ContactWorkExceeded("no a-priori bound", 0), 0.5, 0.1,
                           0.2, "free flight")
        assert rep.status == STATUS_WORK_CAP
        assert rep.message.startswith("work bound reached") == claim, rep.message
        assert f"{used}" in rep.message and "no a-priori bound" in rep.message, rep.message


def test_the_overshoot_covers_one_sliding_event_location() -> None:
    """WORK_OVERSHOOT is at least the largest piece between two checks of the bound: a
    step of the held sliding integrator and its event location (segments.sliding), each
    extrapolation at most 9 columns of right-hand sides and its step work."""
    from rotortd.segments import gbs
    from rotortd.segments.roots import ROOT_ITERS

    extrapolation = gbs.RHS_WORK * sum(gbs.SEQUENCE) + gbs.STEP_WORK
    assert (1 + 41 + ROOT_ITERS) * extrapolation <= WORK_OVERSHOOT
