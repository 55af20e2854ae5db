"""Exact free flight of the core against closed forms and the mpmath reference.

Errors are measured normwise in scaled units: positions in c_r, velocities in c_r w
(w the fastest rate of the scene), against the bound 10 eps max(1, |s| h) of the issue.
"""

from __future__ import annotations

import cmath
import math

import mpmath
import pytest
from rotortd import RotorParams, TouchdownCore
from rotortd.segments.flight import FlightModel

from tests.reference.mp_reference import mp_flight

EPS = 2.220446049250313e-16
W0 = 184.2
BASE = RotorParams()


def _par(p: RotorParams) -> dict:
    return {f: getattr(p, f) for f in p.__dataclass_fields__}


def _rate(p: RotorParams, W: float, a: float) -> float:
    return max(abs(W), math.sqrt(a * p.k / p.m), a * p.c / p.m, 1.0)


SCENES = {
    "chapter": (BASE, W0, 1.0, 0j),
    "k=0": (BASE.replace(k=0.0), W0, 1.0, 3 + 1j),
    "c=0": (BASE.replace(c=0.0), W0, 1.0, 0j),
    "k=c=0": (BASE.replace(k=0.0, c=0.0), W0, 1.0, 2j),
    "resonance": (BASE.replace(c=0.0), math.sqrt(9.8e5 / 50), 1.0, 0j),
    "near-resonance": (BASE.replace(c=0.0), math.sqrt(9.8e5 / 50) * (1 + 1e-9), 1.0, 0j),
    "critical": (BASE.replace(c=2 * math.sqrt(9.8e5 * 50)), W0, 1.0, 0j),
    "critical+": (BASE.replace(c=2 * math.sqrt(9.8e5 * 50) * (1 + 1e-10)), W0, 1.0, 0j),
    "critical-": (BASE.replace(c=2 * math.sqrt(9.8e5 * 50) * (1 - 1e-10)), W0, 1.0, 0j),
    "bearing off, gravity": (BASE.replace(g=9.81), W0, 0.0, 0j),
    "Omega=0": (BASE, 0.0, 1.0, 5j),
    "negative Omega": (BASE, -W0, 1.0, 0j),
    "overdamped": (BASE.replace(c=1e6), W0, 1.0, 0j),
}
STEPS = (1e-9, 1e-6, 1e-4, 1e-3, 1e-2, 0.1, 1.0, 10.0)


@pytest.mark.parametrize("name", list(SCENES))
def test_flight_matches_mpmath_within_bound(name: str) -> None:
    p, W, a, F = SCENES[name]
    fm = FlightModel(p, W, F, a)
    w = _rate(p, W, a)
    z0, v0, psi0 = complex(1e-4, -2e-4), complex(0.05, 0.02), 0.3
    worst = 0.0
    for h in STEPS:
        z, v = fm.propagate(z0, v0, cmath.exp(1j * psi0), h)
        zr, vr = mp_flight(_par(p), z0, v0, psi0, W, F, a, h, dps=40)
        zs = max(abs(complex(zr)), abs(z0) + abs(v0) / w, p.c_r)
        vs = max(abs(complex(vr)), abs(v0) + abs(z0) * w, p.c_r * w)
        err = max(abs(z - complex(zr)) / zs, abs(v - complex(vr)) / vs)
        worst = max(worst, err / (10 * EPS * max(1.0, w * h)))
    assert worst <= 1.0, f"{name}: error is {worst:.3g} x the bound 10 eps max(1, |s|h)"


def test_undamped_oscillator_closed_form() -> None:
    p = BASE.replace(c=0.0, e_c=0.0)
    wn = math.sqrt(p.k / p.m)
    fm = FlightModel(p, W0, 0j, 1.0)
    z0, v0 = complex(3e-4, 1e-4), complex(-0.02, 0.05)
    for t in (1e-5, 0.37, 3.3):
        z, v = fm.propagate(z0, v0, 1.0, t)
        ze = z0 * math.cos(wn * t) + v0 / wn * math.sin(wn * t)
        ve = -z0 * wn * math.sin(wn * t) + v0 * math.cos(wn * t)
        assert abs(z - ze) <= 20 * EPS * max(1, wn * t) * 5e-4
        assert abs(v - ve) <= 20 * EPS * max(1, wn * t) * 5e-4 * wn


def test_undamped_resonance_grows_secularly() -> None:
    """c = 0, Omega^2 = k/m: z = (F1 t/(2 i W)) e^{i W t} + homogeneous, from rest at 0."""
    p = BASE.replace(c=0.0)
    W = math.sqrt(p.k / p.m)
    fm = FlightModel(p, W, 0j, 1.0)
    F1 = p.e_c * W * W * cmath.exp(1j * p.phi)
    for t in (1e-3, 0.1, 2.0):
        z, _ = fm.propagate(0j, 0j, 1.0, t)
        # particular t e^{iWt} F1/(2iW) plus the homogeneous part cancelling its initial value
        exact = F1 / (2j * W) * (t * cmath.exp(1j * W * t) - math.sin(W * t) / W)
        assert abs(z - exact) <= 1e-14 * max(abs(exact), p.e_c * W * t)


def test_free_fall_with_bearing_off() -> None:
    p = BASE.replace(g=9.81, e_c=0.0)
    fm = FlightModel(p, W0, 0j, 0.0)
    for t in (1e-4, 5e-3, 1.0):
        z, v = fm.propagate(0j, 0j, 1.0, t)
        assert z == pytest.approx(-0.5j * 9.81 * t * t, rel=4 * EPS)
        assert v == pytest.approx(-9.81j * t, rel=4 * EPS)


def test_constant_force_without_stiffness() -> None:
    """k = 0: z'' = -beta z' + F/m gives z = F/(m beta) (t - (1 - e^{-beta t})/beta)."""
    p = BASE.replace(k=0.0, e_c=0.0)
    F = complex(30.0, -7.0)
    fm = FlightModel(p, W0, F, 1.0)
    b = mpmath.mpf(p.c) / p.m
    mpmath.mp.dps = 40
    for t in (1e-6, 0.01, 1.0, 10.0):
        z, v = fm.propagate(0j, 0j, 1.0, t)
        ze = complex(F / (p.m * b) * (t - (-mpmath.expm1(-b * t)) / b))
        ve = complex(F / (p.m * b) * (-mpmath.expm1(-b * t)))
        assert abs(z - ze) <= 8 * EPS * abs(ze)
        assert abs(v - ve) <= 8 * EPS * abs(ve)


@pytest.mark.parametrize("side", [-1.0, 1.0])
def test_critical_damping_limit_is_continuous(side: float) -> None:
    c_crit = 2 * math.sqrt(BASE.k * BASE.m)
    z0, v0 = complex(2e-4, 0), complex(0, 0.03)
    crit = FlightModel(BASE.replace(c=c_crit), W0, 0j, 1.0).propagate(z0, v0, 1.0, 0.01)
    for rel in (1e-4, 1e-7, 1e-10, 1e-13):
        near = FlightModel(BASE.replace(c=c_crit * (1 + side * rel)), W0, 0j, 1.0)
        z, v = near.propagate(z0, v0, 1.0, 0.01)
        # d(state)/dc is O(t z / m) and O(z/m): the difference must shrink linearly in rel
        assert abs(z - crit[0]) <= 10 * rel * abs(z0) + 1e-18
        assert abs(v - crit[1]) <= 10 * rel * abs(v0) * 1e3 + 1e-15


def test_scaled_corotating_form_reproduced() -> None:
    """Equation (4) in (U, U') from the inertial flight: residual of the ODE at ~1e-14."""
    gamma = 0.152009
    p = BASE
    core = TouchdownCore.from_scaled(p, W0, U0=0.3 + 0.1j, dU0=-0.05 + 0.2j)
    sp = p.scaled(W0)
    fm = FlightModel(p, W0, 0j, 1.0)
    A = [[0, 1], [1 - sp.omega**2 - 1j * sp.gamma, -sp.gamma - 2j]]
    b = sp.rho * cmath.exp(1j * sp.phi)
    mpmath.mp.dps = 40
    for t_s in (0.1, 1.0, 7.5):
        z, v = fm.propagate(core.z, core.v, 1.0, t_s / W0)
        rot = cmath.exp(-1j * t_s)
        U = z * rot / p.c_r
        dU = (v - 1j * W0 * z) * rot / (p.c_r * W0)
        M = mpmath.matrix([[A[0][0], A[0][1], 0], [A[1][0], A[1][1], b], [0, 0, 0]])
        X = mpmath.expm(M * t_s) * mpmath.matrix([0.3 + 0.1j, -0.05 + 0.2j, 1])
        assert abs(U - complex(X[0])) <= 1e-14 * max(1, t_s)
        assert abs(dU - complex(X[1])) <= 1e-14 * max(1, t_s)
    assert abs(sp.gamma - gamma) < 1e-6


def test_regular_equilibrium_matches_Ustar() -> None:
    p = BASE.replace(c=0.3 * BASE.m * W0)
    core = TouchdownCore.on_steady_whirl(p, W0)
    sp = p.scaled(W0)
    Ustar = sp.rho * cmath.exp(1j * sp.phi) / (sp.omega**2 - 1 + 1j * sp.gamma)
    k = core.kinematics(W0)
    assert complex(k.u_re, k.u_im) == pytest.approx(Ustar, abs=1e-15)
    assert abs(complex(k.du_re, k.du_im)) <= 1e-15
    for _ in range(100):
        core.step(1.3e-3, W0)
    k = core.kinematics(W0)
    assert abs(complex(k.u_re, k.u_im) - Ustar) <= 1e-13
    assert core.n_impacts == 0
