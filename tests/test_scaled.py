"""rotortd.scaled: the scaled co-rotating frame, U*, gamma_BEB, angle wrapping, chapter set.

The conversions must give the same bits as the core's own expressions (RotorParams.scaled,
RotorParams.from_scaled, contact.wrap_angle, TouchdownCore.from_scaled, kinematics), so that
the core can switch to them without any change in its results; U* and gamma_BEB are checked
against the core's steady whirl and against their definitions.
"""

from __future__ import annotations

import math
import random

import pytest
from rotortd import ParameterError, RotorParams, TouchdownCore
from rotortd import scaled as S


def _bits(x: float) -> str:
    return float(x).hex()


def _random_params(rng: random.Random) -> RotorParams:
    return RotorParams(m=rng.uniform(1, 100), c=rng.uniform(0, 5e3), k=rng.uniform(0, 2e6),
                       e_c=rng.uniform(0, 1e-3), phi=rng.uniform(-7, 7),
                       c_r=rng.uniform(1e-4, 2e-3), R=rng.uniform(0.01, 0.1),
                       mu=rng.uniform(0, 0.5), d=rng.uniform(0, 1))


def test_parameter_conversions_are_the_cores_bit_for_bit() -> None:
    rng = random.Random(16)
    for _ in range(300):
        p = _random_params(rng)
        W = rng.choice((-1.0, 1.0)) * 10 ** rng.uniform(-2, 4)
        assert S.scaled_params(p, W) == p.scaled(W)
        sp = p.scaled(W)
        m, c_r = rng.uniform(1, 100), rng.uniform(1e-4, 2e-3)
        assert S.si_params(sp, W, m=m, c_r=c_r) == RotorParams.from_scaled(sp, W, m=m, c_r=c_r)
    assert S.si_params(S.chapter_params()) == RotorParams.from_scaled(S.chapter_params(), 184.2)
    for bad in (0.0, math.nan):
        with pytest.raises(ParameterError) as mine:
            S.scaled_params(RotorParams(), bad)
        with pytest.raises(ParameterError) as core:
            RotorParams().scaled(bad)
        assert str(mine.value) == str(core.value)
        with pytest.raises(ParameterError) as mine:
            S.si_params(sp, bad)
        with pytest.raises(ParameterError) as core:
            RotorParams.from_scaled(sp, bad)
        assert str(mine.value) == str(core.value)


def test_chapter_set_is_model_md_section_3() -> None:
    sp = S.chapter_params()
    assert sp.gamma == pytest.approx(0.152009, abs=1e-6)
    assert sp.omega == pytest.approx(0.760043, abs=1e-6)
    assert sp.rho == pytest.approx(3 / 7, abs=1e-15)
    assert (sp.phi, sp.mu, sp.d) == (0.21, 0.15, 0.95)
    assert sp.R_over_cr == pytest.approx(57.142857, abs=1e-6)
    assert S.chapter_params(gamma=0.1).gamma == 0.1
    assert S.chapter_params(2 * S.CHAPTER_OMEGA).gamma == pytest.approx(sp.gamma / 2, rel=1e-15)


def test_wrap_angle_reduces_into_minus_pi_pi() -> None:
    rng = random.Random(7)
    xs = [math.pi, -math.pi, math.nextafter(math.pi, 0), math.nextafter(-math.pi, -4), 0.0,
          -0.0, 2 * math.pi, -2 * math.pi, 3 * math.pi, 1e6, -1e9 + 0.3]
    xs += [rng.uniform(-1e4, 1e4) for _ in range(2000)] + [rng.uniform(-7, 7) for _ in range(2000)]
    for x in xs:
        w = S.wrap_angle(x)
        slack = 4.5e-16 + 4.0 * math.ulp(x)  # the true -pi is one rounding below the double
        assert -math.pi - slack <= w < math.pi + slack
        if -math.pi <= x < math.pi - 1e-15:
            assert _bits(w) == _bits(x)


def test_state_conversions_are_the_cores_bit_for_bit() -> None:
    rng = random.Random(3)
    p = RotorParams()
    for _ in range(300):
        W = rng.uniform(1.0, 500.0)
        psi = rng.uniform(-3.1, 3.1)
        U = complex(rng.uniform(-0.6, 0.6), rng.uniform(-0.6, 0.6))
        dU = complex(rng.uniform(-2, 2), rng.uniform(-2, 2))
        core = TouchdownCore.from_scaled(p, W, U0=U, dU0=dU, psi0=psi)
        z, v = S.to_inertial(U, dU, W, p.c_r, psi)
        assert (z, v) == (core.z, core.v)
        k = core.kinematics(W)
        U2, dU2 = S.to_scaled(core.z, core.v, W, p.c_r, psi)
        assert (U2.real, U2.imag, dU2.real, dU2.imag) == (k.u_re, k.u_im, k.du_re, k.du_im)
        assert abs(U2 - U) < 1e-14 and abs(dU2 - dU) < 1e-12
    assert S.to_scaled(1e-4 + 0j, 1j, 0.0, p.c_r, 0.0)[1] == 0j
    slow = TouchdownCore(p, z0=1e-4 + 0j, v0=1j)  # c_r Omega underflows: the Omega = 0 convention
    k = slow.kinematics(1e-320)
    assert S.to_scaled(slow.z, slow.v, 1e-320, p.c_r, 0.0)[1] == complex(k.du_re, k.du_im) == 0


def test_regular_equilibrium_is_the_cores_steady_whirl_and_gamma_beb_its_wall() -> None:
    for g in (0.08, 0.152009, 0.3):
        sp = S.chapter_params(gamma=g)
        p = S.si_params(sp)
        core = TouchdownCore.on_steady_whirl(p, S.CHAPTER_OMEGA)
        k = core.kinematics(S.CHAPTER_OMEGA)
        Us = S.regular_equilibrium(sp)
        assert abs(complex(k.u_re, k.u_im) - Us) < 1e-13
        assert abs(complex(k.du_re, k.du_im)) < 1e-13
    sp = S.chapter_params()
    g_beb = S.gamma_beb(sp)
    assert g_beb == pytest.approx(0.07285242799456, abs=1e-13)
    assert abs(S.regular_equilibrium(S.chapter_params(gamma=g_beb))) == pytest.approx(1.0,
                                                                                      abs=1e-14)
    assert math.isnan(S.gamma_beb(S.chapter_params(rho=0.1)))
