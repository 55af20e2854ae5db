"""The impact law with the spin as a state (rotortd.bodies.rotor): checked on the rigid body itself.

Each random impact is applied to a rigid body (geometric centre velocity v, spin Omega,
imbalance phasor E); the outcome is checked through the body's own kinematics and kinetic
energy T = 1/2 m |v + i Omega e_c E|^2 + 1/2 J Omega^2, not through W.
"""

from __future__ import annotations

import cmath
import math
import random

import pytest
from rotortd.bodies.rotor import Delassus, check_well_posed, spin_impact
from rotortd.contact.impact import reset
from rotortd.params import CrossParameterError, RotorParams

M, R = 50.0, 0.04


def _random_impact(rng: random.Random) -> dict:
    e = rng.choice([0.0, 1e-5, 3e-4, 1e-3, 5e-3, 2e-2, 0.039])
    mu = rng.choice([0.0, rng.uniform(0, 0.3), rng.uniform(0, 2)])
    J = M * R * R * rng.choice([0.01, 0.05, 0.5, 1.0, 5.0])
    if M * mu * e * (R + e) * 1.0001 >= J:
        mu = 0.9 * J / (M * e * (R + e)) if e > 0 else mu
    theta = rng.uniform(-math.pi, math.pi)
    return {
        "e": e, "mu": mu, "J": J, "theta": theta,
        "d": rng.choice([0.0, 0.5, 0.9, 0.95, 0.99, 1.0, rng.random()]),
        "E": cmath.exp(1j * rng.uniform(-math.pi, math.pi)),
        "rdot": 10 ** rng.uniform(-6, 1),
        "vt": rng.uniform(-3, 3) * rng.choice([1.0, 1e-3, 1e-6, 10.0]),
        "Omega": rng.uniform(-300, 300) * rng.choice([1.0, 1e-4, 0.0]),
    }


def _apply(c: dict) -> tuple[dict, object]:
    n = cmath.exp(1j * c["theta"])
    v = complex(c["rdot"], c["vt"]) * n
    beta = cmath.phase(c["E"]) - c["theta"]
    w = Delassus.at(M, c["J"], c["e"], R, beta)
    vrel = R * c["Omega"] + c["vt"]
    r = spin_impact(w, c["mu"], c["d"], c["rdot"], vrel)
    W_plus = c["Omega"] + r.dOmega
    # the impulse acts on the mass centre; the geometric centre moves with the spin too
    vG_plus = v + 1j * c["Omega"] * c["e"] * c["E"] - complex(r.P_n, r.P_t) * n / M
    v_plus = vG_plus - 1j * W_plus * c["e"] * c["E"]

    def T(vv: complex, W: float) -> float:
        return 0.5 * M * abs(vv + 1j * W * c["e"] * c["E"]) ** 2 + 0.5 * c["J"] * W * W

    wp = n.conjugate() * v_plus
    body = {"T0": T(v, c["Omega"]), "T1": T(v_plus, W_plus), "rdot_plus": wp.real,
            "vrel_plus": R * W_plus + wp.imag, "vrel": vrel}
    return body, r


def test_impacts_never_create_energy_on_20000_random_impacts() -> None:
    rng = random.Random(17)
    worst, capped, stuck = -math.inf, 0, 0
    for _ in range(20000):
        c = _random_impact(rng)
        body, r = _apply(c)
        scale = body["T0"] + 0.5 * c["J"] * c["Omega"] ** 2 + 1e-300
        gain = (body["T1"] - body["T0"]) / scale
        worst = max(worst, gain)
        assert gain <= 1e-12, (c, r)
        # the law's own energy bookkeeping agrees with the body's
        assert abs((body["T0"] - body["T1"]) - r.E_diss) <= 1e-10 * scale
        capped += r.d_eff < c["d"]
        stuck += r.stick
    assert capped > 10 and stuck > 1000  # both branches exercised


def test_outcome_is_newton_with_coulomb_after_the_impact() -> None:
    rng = random.Random(5)
    for _ in range(5000):
        c = _random_impact(rng)
        body, r = _apply(c)
        vs = abs(c["rdot"]) + abs(body["vrel"]) + abs(R * r.dOmega)
        assert abs(body["rdot_plus"] + r.d_eff * c["rdot"]) <= 1e-12 * vs
        assert r.P_n >= 0.0
        if r.stick:
            assert abs(body["vrel_plus"]) <= 1e-10 * vs
            assert abs(r.P_t) <= c["mu"] * r.P_n * (1 + 1e-12)
        else:  # full friction against the slip that remains after the impact
            assert abs(abs(r.P_t) - c["mu"] * r.P_n) <= 1e-12 * r.P_n
            assert body["vrel_plus"] * r.P_t >= -1e-10 * vs * abs(r.P_t)


def test_the_normal_impulse_alone_can_reverse_the_slip() -> None:
    """W_nt != 0: a small slip before the impact is reversed by the normal impulse, and
    friction then acts against the slip after the impact, not before."""
    J, e = 0.5 * M * R * R, 0.02
    w = Delassus.at(M, J, e, R, math.pi / 2)  # B = e_c, A = R: W_nt = e R/J
    r = spin_impact(w, 0.05, 0.5, 1.0, 1e-3)
    assert not r.stick and r.vrel_plus < 0.0 < 1e-3 and r.P_t < 0.0


def test_held_spin_limit_is_the_held_law() -> None:
    rng = random.Random(3)
    for _ in range(500):
        c = _random_impact(rng)
        n = cmath.exp(1j * c["theta"])
        v = complex(c["rdot"], c["vt"]) * n
        held = reset(n, v, M, c["d"], c["mu"], R, c["Omega"])
        w = Delassus.at(M, 1e300, c["e"], R, 0.3)
        vt = (n.conjugate() * v).imag  # the held law's own projection of v
        r = spin_impact(w, c["mu"], c["d"], held.rdot, R * c["Omega"] + vt)
        assert r.P_n == pytest.approx(held.P_n, rel=1e-12, abs=1e-300)
        assert r.P_t == pytest.approx(held.P_t, rel=1e-9, abs=1e-12 * held.P_n)
        assert r.stick == held.stick or abs(abs(held.P_t) - c["mu"] * held.P_n) < 1e-9


def test_ill_posed_inertia_is_refused_by_name() -> None:
    p = RotorParams(mu=0.5, e_c=0.01)
    bound = p.m * p.mu * p.e_c * (p.R + p.e_c)
    check_well_posed(p, bound * 1.01)
    with pytest.raises(CrossParameterError, match=r"J = .* kg m\^2 is too small"):
        check_well_posed(p, bound)
