"""The spin state's quiet step, ``segments.spin_quiet.QuietSpinStep`` (a declared
accelerator of ``SpinFlight.short_taylor``): equal to it to rounding at random levitated
states, equal to the 40-digit Taylor reference of tests/test_spin_flight.py, its proof of
clearance sound against the general search, and its declines; and its lane
(``TouchdownCore.quiet_lane`` with the spin a state), equal to ``step`` and
``output_values`` to the bit, in the core and in the FMU under a PI drive."""

from __future__ import annotations

import cmath
import random

import mpmath as mp
import pytest
from rotortd import RotorParams, SpinCore
from rotortd.segments.spin_flight import SpinFlight
from rotortd.segments.spin_quiet import WH_MAX, QuietSpinStep
from rotortd_fmi import touchdown_variables as tv
from RotorTouchdown import RotorTouchdown
from test_spin_flight import MpTaylor, Scene

P = RotorParams(g=9.81)
J0 = 0.5 * P.m * P.R ** 2


def random_flight(rng: random.Random, h: float, r_max: float = 0.9, W_max: float = 900.0
                  ) -> tuple[Scene, SpinFlight, QuietSpinStep] | None:
    """A random levitated flight (inertia, speed, state, AMB level, F_ext, drive torque over
    their ranges), or None when one step of h is longer than the flight's horizon."""
    J = J0 * rng.choice([1.0, 0.1, 10.0])
    W = rng.uniform(-W_max, W_max)
    z = rng.uniform(0.0, r_max) * P.c_r * cmath.exp(1j * rng.uniform(0.0, 7.0))
    v = rng.uniform(0.0, 1.0) * P.c_r * max(abs(W), 140.0) * cmath.exp(1j * rng.uniform(0, 7))
    a = rng.choice([1.0, 0.3])
    F = complex(rng.uniform(-300, 300), rng.uniform(-300, 300)) * rng.choice([0, 1])
    T = rng.choice([0.0, 0.05, -2.0, rng.uniform(-50.0, 50.0)])
    sc = Scene(P, J, a, F, T, z, v, rng.uniform(-100.0, 100.0), W)
    fl = sc.flight()
    if h > fl.horizon:
        return None
    return sc, fl, QuietSpinStep(P, J, a, F, h)


def errors(fl: SpinFlight, sc: Scene, got: tuple[complex, complex, float, float],
           ref: tuple) -> list[float]:
    """z in c_r, v in c_r w, psi relative to max(1, |psi|), Omega in max(|Omega0|, w)."""
    z, v, psi, Om = ref
    w = fl.w
    return [abs(got[0] - z) / P.c_r, abs(got[1] - v) / (P.c_r * w),
            abs(got[2] - psi) / max(1.0, abs(psi)), abs(got[3] - Om) / max(abs(sc.Om), w)]


@pytest.mark.parametrize(("h", "W_max"), [(3e-5, 900.0), (1e-4, 1800.0), (3e-4, 500.0)])
def test_equals_short_taylor_at_random_states(h: float, W_max: float) -> None:
    """Against the one definition at 400 random flights per step length, |Omega0| up to
    W_max: within 2e-15 of the scales (measured: at most 1.0e-15, the rounding of both).
    The step declines where W h > WH_MAX or its truncation estimate is too large (violent
    drive torques and transients of the light rotor, which the ranges include); at least
    100 are compared."""
    rng = random.Random(30)  # (a sample where the estimate at W h instead of 2 W h
    # would let through steps 2.8e-15 off: docs/scripts/mutants.py Q4)
    worst, compared, declined = [0.0] * 4, 0, 0
    for _ in range(400):
        case = random_flight(rng, h, W_max=W_max)
        if case is None:
            continue
        sc, fl, q = case
        got = q.step(sc.z, sc.v, sc.psi, sc.Om, sc.T) if q.usable else None
        ref = fl.short_taylor(h)
        if got is None or ref is None:
            declined += 1
            continue
        z, v, dpsi, Om, _ = ref
        e = errors(fl, sc, got, (z, v, sc.psi + dpsi, Om))
        worst = [max(x, y) for x, y in zip(worst, e)]
        compared += 1
    assert compared >= 100, (compared, declined)
    assert max(worst) <= 2e-15, worst


def test_equals_the_40_digit_reference() -> None:
    """Eight random flights at 1e-4 s, two of them at 300 rad/s with a drive torque of
    2 N m on J/10 (Omega' ~ 500 rad/s^2: the second-order torque takes more than one
    pass): the end state against MpTaylor (40 digits) within 1e-15 of the scales (psi:
    its rounding)."""
    rng = random.Random(11)
    cases = []
    while len(cases) < 8:
        case = random_flight(rng, 1e-4)
        if case is not None and case[2].usable:
            sc, fl, q = case
            if len(cases) < 2:
                sc = Scene(P, J0 / 10, sc.a, sc.F_ext, 2.0 * (-1) ** len(cases), sc.z,
                           sc.v, sc.psi, 300.0)
                fl, q = sc.flight(), QuietSpinStep(P, J0 / 10, sc.a, sc.F_ext, 1e-4)
            cases.append((sc, fl, q))
    for sc, fl, q in cases:
        got = q.step(sc.z, sc.v, sc.psi, sc.Om, sc.T)
        assert got is not None
        zm, vm, psim, Omm = MpTaylor(sc, 1e-4).at(1e-4)
        e = errors(fl, sc, got, (complex(zm), complex(vm), float(psim), float(Omm)))
        assert e[0] <= 1e-15 and e[1] <= 1e-15 and e[3] <= 1e-15, e
        assert abs(mp.mpf(got[2]) - psim) <= 4e-16 * max(1.0, abs(sc.psi)), e


def test_clear_is_sound() -> None:
    """Where ``clear`` proves a step clear, the general search (SpinFlight.run) finds no
    contact in it: 3000 random flights started up to the wall, about a third proved."""
    rng = random.Random(3)
    proved = 0
    for _ in range(3000):
        case = random_flight(rng, 1e-4, r_max=1.0)
        if case is None or not case[2].usable:
            continue
        sc, fl, q = case
        if q.clear(sc.z, sc.v, sc.Om, sc.T):
            proved += 1
            assert fl.run(1e-4).event is None, sc
    assert proved > 500, proved


def test_declines() -> None:
    """Bearing off (no modes to freeze), a step too long for the modes, a spin whose W h
    exceeds WH_MAX, a correction too large for the order (the truncation estimate): the
    step is not usable or returns None."""
    assert not QuietSpinStep(P, J0, 0.0, 0j, 1e-4).usable
    assert not QuietSpinStep(P, J0, 1.0, 0j, 1e-2).usable
    q = QuietSpinStep(P, J0, 1.0, 0j, 1e-4)
    assert q.usable
    W = WH_MAX / 1e-4 + 1.0
    assert q.step(0j, 0j, 0.0, W, 0.0) is None
    assert q.step(0j, 0j, 0.0, 0.5 * W, 0.0) is not None
    # a violent spin-up (Omega' = 1e4 rad/s^2 at 1500 rad/s): the truncation estimate
    # declines it (|delta| at the end, 5e-5 rad, is within DELTA_MAX)
    q = QuietSpinStep(P, J0 / 10, 1.0, 0j, 1e-4)
    assert q.step(1e-4 + 0j, 0j, 0.0, 1500.0, 40.0) is None
    assert q.step(1e-4 + 0j, 0j, 0.0, 500.0, 0.4) is not None


def test_core_takes_it_on_the_levitated_whirl() -> None:
    """SpinCore's quiet step on the chapter's levitated whirl: 100 steps of 1e-4 s with a
    PI-like changing drive torque, each a quiet step (work SEGMENT_WORK + QUIET_WORK), the
    state equal to SpinFlight.short_taylor chained from the same start within 1e-14 c_r."""
    from rotortd.contact.search import SEGMENT_WORK
    from rotortd.segments.spin_quiet import QUIET_WORK

    core = SpinCore.on_steady_whirl(P, 184.2, J=J0)
    z, v, psi, W = core.z, core.v, core.psi, 184.2
    for j in range(100):
        T = 0.05 * (1.0 + 0.5 * (-1) ** j)
        rep = core.step(1e-4, T_drive=T)
        assert rep.work == SEGMENT_WORK + QUIET_WORK and rep.status == 0
        z, v, dpsi, W, _ = SpinFlight(P, J0, 1.0, 0j, T, z, v, psi, W).short_taylor(1e-4)
        psi += dpsi
    assert abs(core.z - z) <= 1e-14 * P.c_r
    assert abs(core.Omega - W) <= 1e-14 * W


# ------------------------------------------------------------------ the spin state's lane

def _twins(W: float, rng: random.Random) -> tuple[SpinCore, SpinCore]:
    """Two cores on the levitated whirl at W, after one quiet step (the lane exists)."""
    cores = []
    for _ in range(2):
        core = SpinCore.on_steady_whirl(P, W, J=J0 * rng.choice([1.0, 0.3]))
        cores.append(core)
    cores[1] = SpinCore(P, cores[0].J, z0=cores[0].z, v0=cores[0].v, psi0=cores[0].psi,
                        Omega0=W)
    for core in cores:
        core.step(1e-4, T_drive=0.05)
    return cores[0], cores[1]


def test_the_lane_is_the_quiet_step_and_output_values_to_the_bit() -> None:
    """The spin state's lane against ``step`` + ``output_values`` at 20 random whirls, 60
    steps each with a drive torque changing every step: state, outputs and T_imb the same
    bits (``repr``), and every step taken in the lane."""
    rng = random.Random(5)
    for _ in range(20):
        a, b = _twins(rng.uniform(180.0, 600.0), rng)
        lane = b.quiet_lane(1e-4, 1e-6)
        assert lane is not None
        for _ in range(60):
            T = rng.uniform(-2.0, 2.0)
            rep = a.step(1e-4, T_drive=T)
            got = lane(b, b.t, 1e-4, T)
            assert got is not None
            assert repr(got[0]) == repr(a.output_values())
            assert repr(got[1]) == repr(rep.T_imb)
        assert a.get_state() == b.get_state()


@pytest.mark.parametrize("leave", ["h", "clock", "inputs", "state"])
def test_the_lane_declines_and_leaves_the_core_untouched(leave: str) -> None:
    """Another step length, a clock off the core's time, other inputs (a step with F_ext),
    or a state set: the lane returns None and the core is as it was."""
    _a, b = _twins(184.2, random.Random(1))
    lane = b.quiet_lane(1e-4, 1e-6)
    assert lane is not None
    h, t = 1e-4, b.t
    if leave == "h":
        h = 2e-4
    elif leave == "clock":
        t = b.t + 1e-5
    elif leave == "inputs":
        b.step(1e-4, F_ext=1.0 + 0j, T_drive=0.05)
    else:
        b.set_state(b.get_state())
    before = b.get_state()
    assert lane(b, t, h, 0.05) is None
    assert b.get_state() == before


def _spin_slave(**values: object) -> RotorTouchdown:
    slave = RotorTouchdown(instance_name="spin-lane")
    for name, value in {"g": 9.81, "integrate_spin": True, "J": J0, "Omega": 184.2,
                        "start_steady": True, **values}.items():
        setattr(slave, name, value)
    slave.setup_experiment(0.0)
    slave.enter_initialization_mode()
    slave.exit_initialization_mode()
    return slave


def test_the_fmu_in_the_spin_lane_publishes_what_the_core_steps_give() -> None:
    """A PI drive sets T_drive before every step (fmi2SetReal): the adapter stays in the
    lane, and its outputs equal those of a core stepped by ``step`` throughout; F_x set
    once takes the general step; T_drive outside its range is refused by it, naming it."""
    slave = _spin_slave()
    core = slave._core
    ref = SpinCore(core.params, core.J, z0=core.z, v0=core.v, psi0=core.psi,
                   Omega0=core.Omega)
    fields = ref.outputs()._fields
    vr = {v.name: v.value_reference for v in slave.vars.values()}
    h, lanes, integral = 1e-4, 0, 0.0
    for j in range(80):
        e = 185.2 - slave.Omega_out if j else 1.0
        integral += e * h
        T = 0.05 * e + 2.0 * integral
        slave.set_real([vr["T_drive"]], [T])
        F = 5.0 if j >= 50 else 0.0
        if j == 50:
            slave.set_real([vr["F_x"]], [F])
        lanes += slave._lane is not None and j != 50
        assert slave.do_step(j * h, h)
        rep = ref.step(h, F_ext=complex(F, 0.0), T_drive=T)
        want = dict(zip(fields, ref.output_values()))
        for var in tv.TABLE:
            if var.shows:
                assert getattr(slave, var.name) == want[var.shows], (j, var.name)
        assert slave.T_imb == rep.T_imb and slave.T_f == rep.T_f, j
    assert lanes >= 70
    slave.set_real([vr["T_drive"]], [2e9])
    assert not slave.do_step(80 * h, h)
