"""SpinCore, the rotor with its spin as a state: balances, state, work (docs/model.md §8).

The balances are computed here from the core's public state (z, v, psi, Omega), not from
its internals: T = 1/2 m |z_G'|^2 + 1/2 J Omega^2 with z_G' = v + i Omega e_c E,
L = m Im(conj(z_G) z_G') + J Omega about the bearing centre, V = m g Im(z_G).
"""

from __future__ import annotations

import cmath
import json
import math

import pytest
from rotortd import (
    MODE_ROLLING,
    MODE_SLIDING,
    STATUS_OK,
    CrossParameterError,
    RotorParams,
    SpinCore,
    restore_core,
)

CHAPTER_G = RotorParams(g=9.81)
J_HALF = 0.5 * CHAPTER_G.m * CHAPTER_G.R ** 2  # 0.04 kg m^2


def _body(core: SpinCore) -> dict[str, float]:
    p = core.params
    E = cmath.exp(1j * (core.psi + p.phi))
    zG = core.z + p.e_c * E
    vG = core.v + 1j * core.Omega * p.e_c * E
    return {
        "T": 0.5 * p.m * abs(vG) ** 2 + 0.5 * core.J * core.Omega ** 2,
        "L": p.m * (zG.conjugate() * vG).imag + core.J * core.Omega,
        "V": p.m * p.g * zG.imag,
        "psi": core.psi,
    }


def _run(core: SpinCore, h: float, n: int, **inputs: float) -> list[int]:
    modes = []
    for _ in range(n):
        rep = core.step(h, **inputs)
        assert rep.status == STATUS_OK, rep.message
        modes.append(core.mode)
    return modes


@pytest.mark.parametrize("d", [1.0, 0.8])
def test_conservation_scene_keeps_momentum_and_energy(d: float) -> None:
    """mu = 0, a = 0, g = 0, F_ext = 0, T_drive = 0: the contact force is normal and passes
    through the bearing centre, so L is conserved through impacts and contact; with d = 1
    the energy too (docs/model.md §8). Over 1 s, to 1e-12 relative."""
    p = RotorParams(mu=0.0, g=0.0, d=d)
    core = SpinCore(p, J_HALF, z0=0.3e-3 + 0.1e-3j, v0=0.08 - 0.05j, psi0=0.4, Omega0=184.2)
    b0 = _body(core)
    _run(core, 1e-3, 1000, amb_on=0.0)
    b1 = _body(core)
    assert core.n_impacts > 50
    assert abs(b1["L"] - b0["L"]) <= 1e-12 * abs(b0["L"])
    if d == 1.0:
        assert core.E_diss == 0.0
        assert abs(b1["T"] - b0["T"]) <= 1e-12 * b0["T"]


@pytest.mark.parametrize("T_drive", [0.0, 5.0])
def test_energy_balance_closes_through_the_drop_into_dry_whirl(T_drive: float) -> None:
    """The drop from the levitated whirl (bearing off from t = 0, gravity, the chapter's
    rotor, J = m R^2/2): the change of T + V equals the drive's work T_drive dpsi minus
    the dissipation, with a residual below 1e-10 of the sum of the terms' magnitudes."""
    core = SpinCore.on_steady_whirl(CHAPTER_G, 184.2, J=J_HALF)
    b0 = _body(core)
    modes = _run(core, 1e-4, 3000, amb_on=0.0, T_drive=T_drive)
    b1 = _body(core)
    terms = [b1["T"] - b0["T"], b1["V"] - b0["V"], -T_drive * (b1["psi"] - b0["psi"]),
             core.E_diss]
    assert core.n_impacts > 10 and MODE_ROLLING in modes
    assert abs(sum(terms)) <= 1e-10 * sum(abs(x) for x in terms)


def test_dry_whirl_rolls_backward_and_stays_rolling() -> None:
    """After the drop the rotor rolls backward round the bearing (whirl = -R Omega/c_r),
    and stays in mode 2 at every communication point once there."""
    core = SpinCore.on_steady_whirl(CHAPTER_G, 184.2, J=J_HALF)
    modes = _run(core, 1e-4, 3000, amb_on=0.0)
    first = modes.index(MODE_ROLLING)
    assert first < 2000 and all(m == MODE_ROLLING for m in modes[first:])
    kin = core.kinematics()
    p = core.params
    assert kin.whirl_rate == pytest.approx(-p.R * core.Omega / p.c_r, rel=1e-12)
    assert abs(kin.v_rel) <= 1e-9 * p.R * abs(core.Omega)


def test_state_round_trip_is_bit_identical() -> None:
    """Save mid-run (in flight and in contact), restore into a fresh core through JSON,
    continue: every later state is identical to the last bit."""
    core = SpinCore.on_steady_whirl(CHAPTER_G, 184.2, J=J_HALF)
    for n_before in (300, 900):
        _run(core, 1e-4, n_before, amb_on=0.0, T_drive=2.0)
        saved = json.loads(json.dumps(core.get_state()))
        copy = restore_core(saved)
        assert isinstance(copy, SpinCore) and copy.J == core.J
        for _ in range(200):
            core.step(1e-4, amb_on=0.0, T_drive=2.0)
            copy.step(1e-4, amb_on=0.0, T_drive=2.0)
        assert copy.get_state() == core.get_state()


def test_held_and_spin_states_do_not_mix() -> None:
    from rotortd import ParameterError, TouchdownCore

    spin = SpinCore(RotorParams(), J_HALF, Omega0=100.0)
    held = TouchdownCore(RotorParams())
    with pytest.raises(ParameterError, match="restore it into a SpinCore"):
        held.set_state(spin.get_state())
    with pytest.raises(ParameterError, match="restore it into a TouchdownCore"):
        spin.set_state(held.get_state())
    assert type(restore_core(held.get_state())) is TouchdownCore
    assert type(restore_core(spin.get_state())) is SpinCore


def test_ill_posed_inertia_is_refused() -> None:
    p = RotorParams(mu=1.0, e_c=0.01)
    with pytest.raises(CrossParameterError, match="J = 1e-05 kg m"):
        SpinCore(p, 1e-5)


def test_infinite_inertia_limit_is_the_held_speed_core() -> None:
    """J -> infinity: the spin barely changes and the motion approaches the held-speed
    core's (the same physics with Omega held), through impacts and sliding."""
    from rotortd import TouchdownCore

    p = RotorParams(g=9.81)
    held = TouchdownCore.on_steady_whirl(p, 184.2)
    spin = SpinCore.on_steady_whirl(p, 184.2, J=1e7)
    for _ in range(300):
        held.step(1e-4, 184.2, amb_on=0.0)
        spin.step(1e-4, amb_on=0.0)
    assert held.n_impacts > 3
    assert abs(spin.z - held.z) <= 1e-5 * p.c_r
    assert spin.Omega == pytest.approx(184.2, rel=1e-6)
    assert math.isfinite(spin.E_diss)


def test_energy_balance_closes_with_the_bearing_on() -> None:
    """The bearing on without its damper (c = 0: the spring k and the bias force store
    energy, V = a k |z|^2/2 - a Re(conj(F_bias) z) + m g Im(z_G)), a drive of 5 N m, from
    rest at the centre: the imbalance drives the rotor into impacts and sliding, the flight
    integrated (Taylor). T + V changes by the drive's work minus the dissipation, to below
    1e-10 of the sum of the terms' magnitudes."""
    p = RotorParams(g=9.81, c=0.0)
    core = SpinCore(p, J_HALF, z0=0j, v0=0j, psi0=0.0, Omega0=184.2)

    def stored() -> float:
        zG = core.z + p.e_c * cmath.exp(1j * (core.psi + p.phi))
        return (0.5 * p.k * abs(core.z) ** 2 - (p.bias_force.conjugate() * core.z).real
                + p.m * p.g * zG.imag)

    b0, V0 = _body(core), stored()
    modes = _run(core, 1e-4, 2000, amb_on=1.0, T_drive=5.0)
    b1 = _body(core)
    terms = [b1["T"] - b0["T"], stored() - V0, -5.0 * (b1["psi"] - b0["psi"]), core.E_diss]
    assert core.n_impacts > 100 and MODE_SLIDING in modes
    assert abs(sum(terms)) <= 1e-10 * sum(abs(x) for x in terms)


def test_energy_balance_closes_with_the_damper() -> None:
    """The bearing on with its damper (c = 1400 N s/m), pressed down by F_ext = -3000j N
    from the bottom of the bearing, a drive of 5 N m: the rotor slides for 0.05 s without
    impacts. The damper's dissipation int c |z'|^2 dt is taken by Simpson's rule from the
    state at every 2e-6 s step (v is smooth without impacts: (w h)^4 ~ 1e-16 relative);
    T + V changes by the drive's and F_ext's work minus friction and damper losses, to below
    1e-10 of the sum of the terms' magnitudes."""
    p, F, T, h, n = RotorParams(g=9.81), -3000j, 5.0, 2e-6, 25000
    core = SpinCore(p, J_HALF, z0=-1j * p.c_r, v0=0j, psi0=0.0, Omega0=184.2)

    def stored() -> float:
        zG = core.z + p.e_c * cmath.exp(1j * (core.psi + p.phi))
        return (0.5 * p.k * abs(core.z) ** 2 - (p.bias_force.conjugate() * core.z).real
                + p.m * p.g * zG.imag - (F.conjugate() * core.z).real)

    b0, V0, f = _body(core), stored(), [p.c * abs(core.v) ** 2]
    for _ in range(n):
        assert core.step(h, F_ext=F, amb_on=1.0, T_drive=T).status == STATUS_OK
        f.append(p.c * abs(core.v) ** 2)
    damper = h / 3 * (f[0] + f[-1] + 4 * sum(f[1:-1:2]) + 2 * sum(f[2:-1:2]))
    b1 = _body(core)
    terms = [b1["T"] - b0["T"], stored() - V0, -T * (b1["psi"] - b0["psi"]), core.E_diss,
             damper]
    assert core.n_impacts == 0 and core.mode == MODE_SLIDING and damper > 0.01
    assert abs(sum(terms)) <= 1e-10 * sum(abs(x) for x in terms)


@pytest.mark.parametrize("W", [0.0, 1e-9, 10.0])
@pytest.mark.parametrize("theta", [0.0, math.pi, 0.3])
def test_at_rest_on_the_wall_under_gravity(W: float, theta: float) -> None:
    """At rest on the wall with gravity along the wall (theta = 0, pi): the normal force is
    zero to rounding, the flight touches at once and the contact may refuse it. The tie is
    broken (contact within N's rounding band) instead of zero-length flights until the work
    bound (theta = pi with Omega = 1e-9 stalled so); elsewhere the rotor leaves the wall."""
    p = RotorParams(g=9.81)
    core = SpinCore(p, J_HALF, z0=p.c_r * cmath.exp(1j * theta), v0=0j, psi0=0.0, Omega0=W)
    rep = core.step(1e-3, amb_on=0.0)
    assert rep.status == STATUS_OK and rep.work < 10_000 and core.t == pytest.approx(1e-3)
    assert abs(core.z) <= p.c_r * (1 + 1e-12)


def test_one_core_for_both_rotors() -> None:
    """The held spin is the J = inf case of the one core (docs/model.md §8): SpinCore adds
    no physics (TouchdownCore with a finite J gives the same bits through a drop with
    impacts and contact), a SpinCore refuses J = inf, and the constructors take every
    argument after params (and J) by keyword."""
    from rotortd import InputError, ParameterError, TouchdownCore

    one = TouchdownCore.on_steady_whirl(CHAPTER_G, 184.2, J=J_HALF)
    two = SpinCore.on_steady_whirl(CHAPTER_G, 184.2, J=J_HALF)
    assert one.spin_is_state and two.spin_is_state
    for _ in range(300):
        one.step(1e-3, amb_on=0.0)
        two.step(1e-3, amb_on=0.0)
    assert one.n_impacts > 100 and one.mode == two.mode == MODE_ROLLING
    assert one.get_state() == two.get_state()
    held = TouchdownCore(CHAPTER_G)
    assert not held.spin_is_state and math.inf == held.J
    with pytest.raises(ParameterError, match="J"):
        SpinCore(CHAPTER_G, math.inf)
    with pytest.raises(TypeError):
        TouchdownCore(CHAPTER_G, 0j)  # type: ignore[misc]
    with pytest.raises(TypeError):
        SpinCore(CHAPTER_G, J_HALF, 0j)  # type: ignore[misc]
    with pytest.raises(InputError, match=r"T_drive = 1\.0 N m: the spin is held"):
        held.step(1e-3, 184.2, T_drive=1.0)
    with pytest.raises(InputError, match="Omega is missing"):
        held.step(1e-3)
    assert held.t == 0.0


def test_wall_forces_follow_the_spin_state() -> None:
    """After a drop with the bearing off, the wall forces are those of the spin speed now
    and the last inputs (at e272741 they kept Omega = 0 and the bearing on)."""
    core = SpinCore.on_steady_whirl(CHAPTER_G, 184.2, J=J_HALF)
    _run(core, 1e-3, 50, amb_on=0.0)
    wf = core.wall_forces
    assert core.Omega != 184.2
    assert wf.Omega == core.Omega and wf.kappa == wf.beta == 0.0  # kappa = a k/m, beta = a c/m


def test_published_amb_force_is_the_one_definition() -> None:
    """The outputs' F_amb (TouchdownCore.output_values inlines it for speed) equals
    RotorParams.amb_force at random states of both rotors, bit for bit."""
    import random

    from rotortd import TouchdownCore

    rng = random.Random(5)
    for _ in range(200):
        p = CHAPTER_G.replace(c=rng.uniform(0.0, 3000.0), k=rng.uniform(0.0, 2e6))
        z = p.c_r * 0.9 * cmath.rect(rng.random(), rng.uniform(-3.0, 3.0))
        v = complex(rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2))
        a = rng.choice((0.0, 1.0, rng.random()))
        for core in (TouchdownCore(p, z0=z, v0=v), SpinCore(p, J_HALF, z0=z, v0=v)):
            out = core.outputs(184.2, a)
            F = p.amb_force(a, z, v)
            assert (out.F_amb_x, out.F_amb_y) == (F.real, F.imag)
