"""The quiet lane (``TouchdownCore.quiet_lane``, ``quiet_step``): a declared accelerator of
the proved-free step and ``output_values`` (issue 26 item 3), checked against those
definitions to the bit, and its refusals, which leave the core untouched.

Every scene starts on a random admissible steady whirl (random rotor, speed, gravity,
imbalance phase), sometimes with a transient added, so the envelope proof holds for all
time and every step of the held inputs is proved free; a twin core takes the same steps
through ``step`` and ``output_values``. The lane must give the same state (``get_state``),
outputs and T_imb, bit for bit, and must be taken in most scenes (else the comparison is
empty)."""

from __future__ import annotations

import random
import sys
from pathlib import Path
from typing import Any

import pytest
from rotortd import RotorParams, SpinCore, TouchdownCore

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "fmu_src"))

from rotortd_fmi import touchdown_variables as tv
from RotorTouchdown import RotorTouchdown


def _scene(rng: random.Random) -> tuple[TouchdownCore, float, float] | None:
    """A random core on a steady whirl (perturbed in half the scenes), its speed (rad/s)
    and a step (s); None when the draw has no admissible whirl."""
    p = RotorParams(m=rng.uniform(1.0, 100.0), c=rng.uniform(10.0, 5000.0),
                    k=rng.uniform(1e4, 1e7), e_c=rng.uniform(0.0, 3e-4),
                    phi=rng.uniform(-3.0, 3.0), c_r=7e-4, R=0.04, mu=0.15, d=0.9,
                    g=rng.choice([0.0, 9.81]))
    W = rng.uniform(-400.0, 400.0)
    h = rng.choice([1e-3, 1e-4, 3.3e-4, 0.02, 0.7])
    try:
        core = TouchdownCore.on_steady_whirl(p, W)
    except ValueError:
        return None
    if rng.random() < 0.5:  # a transient on top of the whirl (psi0 = 0 in both)
        core = TouchdownCore(p, z0=0.97 * core.z, v0=core.v, Omega0=W)
    return core, W, h


def _twin(core: TouchdownCore, W: float) -> TouchdownCore:
    twin = TouchdownCore(core.params, Omega0=W)
    twin.set_state(core.get_state())
    return twin


def test_the_lane_is_the_proved_free_step_and_output_values_to_the_bit() -> None:
    rng = random.Random(26)
    scenes = taken = 0
    for _ in range(120):
        drawn = _scene(rng)
        if drawn is None:
            continue
        core, W, h = drawn
        scenes += 1
        for _ in range(3):  # the envelope proof and the cached impulse coefficients
            core.step(h, W)
        twin = _twin(core, W)
        for _ in range(25):
            quiet = core.quiet_step(h)
            rep = twin.step(h, W)
            if quiet is None:
                core.step(h, W)
            else:
                taken += 1
                out, T_imb = quiet
                assert out == twin.output_values()
                assert T_imb == rep.T_imb
            assert core.get_state() == twin.get_state()
    assert scenes >= 60 and taken >= 0.8 * 25 * scenes


def test_a_tiny_speed_gives_the_lane_a_finite_rate_of_u() -> None:
    """W = 1e-310 rad/s held: c_r W underflows against v, so dU = (v - i W z) conj(E)/(c_r W)
    overflows; the lane sets it to 0, as ``output_values`` does, and gives its values."""
    p = RotorParams()
    W, h = 1e-310, 1e-3
    core = TouchdownCore(p, z0=1e-4 + 0j, v0=1e-3j, Omega0=W)
    for _ in range(3):
        core.step(h, W)
    twin = _twin(core, W)
    quiet = core.quiet_step(h)
    assert quiet is not None
    twin.step(h, W)
    assert quiet[0] == twin.output_values()
    assert quiet[0][7:9] == (0.0, 0.0)


def _in_lane() -> tuple[TouchdownCore, float, float]:
    p = RotorParams(m=50.0, c=2763.0, k=9.8e5, e_c=3e-4, phi=0.21, c_r=7e-4, R=0.04,
                    mu=0.15, d=0.95)
    W, h = 184.2, 1e-3
    core = TouchdownCore.on_steady_whirl(p, W)
    for _ in range(3):
        core.step(h, W)
    assert core.quiet_lane(h) is not None
    return core, W, h


@pytest.mark.parametrize("leave", ["inputs", "params", "state", "imbalance_torque", "h",
                                   "clock"])
def test_the_lane_declines_and_leaves_the_core_untouched(leave: str) -> None:
    core, W, h = _in_lane()
    lane = core.quiet_lane(h)
    assert lane is not None
    t = core.t
    if leave == "inputs":
        core.step(h, W, 10.0 + 0j)
        t = core.t
    elif leave == "params":
        core.set_params(core.params.replace(c=2000.0))
    elif leave == "state":
        core.set_state(core.get_state())
    elif leave == "imbalance_torque":
        core.imbalance_torque = False
    before = core.get_state()
    if leave == "h":
        assert lane(core, t, 2 * h) is None
    elif leave == "clock":
        assert lane(core, t + 0.5 * h, h) is None
        assert core.quiet_lane(h, 1e-2 * h)(core, t + 0.5 * h, h) is None  # type: ignore[misc]
        assert core.quiet_lane(h, 1e-2 * h)(core, t + 0.5e-2 * h, h) is not None  # type: ignore[misc]
        return
    else:
        assert lane(core, t, h) is None
    assert core.get_state() == before


def test_no_lane_in_contact_or_with_the_spin_a_state_too_fast() -> None:
    p = RotorParams(m=50.0, c=2763.0, k=9.8e5, e_c=3e-4, phi=0.21, c_r=7e-4, R=0.04,
                    mu=0.15, d=0.95)
    core = TouchdownCore(p, z0=6.9e-4 + 0j, v0=0.05 + 0j, Omega0=184.2)
    n = 0
    for _ in range(200):
        rep = core.step(1e-3, 184.2, 0j, 0.0)  # bearing off: impacts
        n += len(rep.impacts)
        assert core.quiet_lane(1e-3) is None or core.mode == 0
    assert n > 0
    spin = SpinCore.on_steady_whirl(p, 184.2, J=0.04)  # (its own lane: test_spin_quiet.py)
    for _ in range(3):
        spin.step(1e-3)  # W h = 0.32 at 1e-3 s: beyond the spin's quiet step (WH_MAX)
    assert spin.quiet_lane(1e-3) is None and spin.quiet_step(1e-3) is None


def _slave(**values: Any) -> RotorTouchdown:
    slave = RotorTouchdown(instance_name="lane")
    for name, value in {"start_steady": True, "c": 2763.0, "psi0": 0.0, **values}.items():
        setattr(slave, name, value)
    slave.setup_experiment(0.0)
    slave.enter_initialization_mode()
    slave.exit_initialization_mode()
    return slave


def test_the_fmu_in_the_lane_publishes_what_the_core_steps_give() -> None:
    """The adapter takes the lane at held inputs and leaves it when an input is set (FMI's
    fmi2SetReal): its outputs equal those of a core stepped by ``step`` throughout, a
    change of Omega included."""
    slave = _slave()
    ref = TouchdownCore.on_steady_whirl(slave._core.params, 184.2)
    fields = ref.outputs()._fields
    omega_vr = next(v.value_reference for v in slave.vars.values() if v.name == "Omega")
    h, lanes = 1e-3, 0
    for j in range(60):
        if j == 30:
            slave.set_real([omega_vr], [184.0])
        held = slave._lane is not None and j != 30  # (a set: the general step)
        assert held == (j != 30 and ref.quiet_lane(h) is not None), j
        lanes += held
        assert slave.do_step(j * h, h)
        rep = ref.step(h, 184.2 if j < 30 else 184.0)
        want = dict(zip(fields, ref.output_values()))
        for var in tv.TABLE:
            if var.shows:
                assert getattr(slave, var.name) == want[var.shows], (j, var.name)
        assert slave.T_imb == rep.T_imb, j
    assert lanes >= 50  # taken whenever the core offers it (above), which is most steps


def test_a_host_clock_rounding_its_steps_gets_the_steps_of_its_length() -> None:
    """libcosim passes differences of integer-ns times as step sizes, 1e-3 s jittering by a
    few ulps of the time: such a step is the step length taken before (``_host_step``), so
    the run is the one at exact steps, to the bit, and in the lane; a real change of the
    step size is taken as it is."""
    exact, jittery = _slave(), _slave()
    h = 1e-3
    for j in range(400):
        t = j * h
        assert exact.do_step(exact._core.t, h)
        assert jittery.do_step(t, ((j + 1) * 1_000_000) * 1e-9 - (j * 1_000_000) * 1e-9)
    assert jittery._core.get_state() == exact._core.get_state()
    assert jittery._lane is not None
    t = jittery._core.t
    assert jittery.do_step(t, 2e-3) and abs(jittery._core.t - (t + 2e-3)) <= 1e-15


def test_a_restored_state_steps_as_it_did_from_the_lane() -> None:
    """An FMU state saved while the lane is held, restored after more lane steps: the
    steps from it repeat the first ones to the bit (the restore drops the lane; the steps
    after it take the general path, then the lane again)."""
    slave = _slave()
    h = 1e-3
    for _ in range(10):
        assert slave.do_step(slave._core.t, h)
    assert slave._lane is not None
    saved = slave._get_fmu_state()
    first = []
    for _ in range(10):
        assert slave.do_step(slave._core.t, h)
        first.append((slave.x, slave.y, slave.T_imb, slave.psi))
    slave._set_fmu_state(saved)
    again = []
    for _ in range(10):
        assert slave.do_step(slave._core.t, h)
        again.append((slave.x, slave.y, slave.T_imb, slave.psi))
    assert again == first and slave._lane is not None
