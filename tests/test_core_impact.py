"""The reset law (docs/model.md §4) with the Coulomb stick cap."""

from __future__ import annotations

import cmath

import pytest
from rotortd.contact.impact import reset

M, R, W = 50.0, 0.04, 184.2


def _polar(n: complex, v: complex) -> tuple[float, float]:
    w = n.conjugate() * v
    return w.real, w.imag


def test_elastic_frictionless_flips_normal_keeps_speed() -> None:
    n = cmath.exp(0.7j)
    v = complex(0.03, -0.01) + 0.05 * n
    r = reset(n, v, M, 1.0, 0.0, R, W)
    rd, vt = _polar(n, v)
    rd2, vt2 = _polar(n, r.v_plus)
    assert abs(r.v_plus) == pytest.approx(abs(v), rel=1e-15)
    assert rd2 == pytest.approx(-rd, rel=1e-15)
    assert vt2 == pytest.approx(vt, rel=1e-14, abs=1e-18)
    assert r.E_diss == pytest.approx(0.0, abs=1e-18)


@pytest.mark.parametrize("vt", [0.05, -0.05, -R * W - 1.0])
def test_polar_form_both_slip_signs(vt: float) -> None:
    """rdot+ = -d rdot-, c_r theta'+ = c_r theta'- - mu (1+d) rdot- s."""
    d, mu = 0.95, 0.15
    n = cmath.exp(-1.2j)
    rd = 0.02
    v = complex(rd, vt) * n
    s = 1.0 if R * W + vt > 0 else -1.0
    r = reset(n, v, M, d, mu, R, W)
    rd2, vt2 = _polar(n, r.v_plus)
    assert rd2 == pytest.approx(-d * rd, rel=1e-14)
    assert vt2 == pytest.approx(vt - mu * (1 + d) * rd * s, rel=1e-14)
    assert not r.stick
    assert r.P_n == pytest.approx(M * (1 + d) * rd, rel=1e-15)
    assert r.P_t == pytest.approx(M * mu * (1 + d) * rd * s, rel=1e-15)
    vrel_m, vrel_p = R * W + vt, R * W + vt2
    e = 0.5 * M * (1 - d * d) * rd**2 + r.P_t * (vrel_m + vrel_p) / 2
    assert r.E_diss == pytest.approx(e, rel=1e-14)
    assert r.E_diss > 0


def test_stick_cap_stops_at_zero_slip() -> None:
    d, mu = 0.5, 1.0
    n = 1j
    vt = -R * W + 1e-3  # slip 1e-3 m/s, friction impulse would reverse it
    v = complex(0.2, vt) * n
    r = reset(n, v, M, d, mu, R, W)
    _, vt2 = _polar(n, r.v_plus)
    assert r.stick
    assert R * W + vt2 == pytest.approx(0.0, abs=1e-15)
    assert r.P_t == pytest.approx(M * 1e-3, rel=1e-9)
    assert r.E_diss >= 0


def test_zero_slip_has_no_tangential_impulse() -> None:
    n = -1.0 + 0j
    v = complex(0.1, -R * W) * n
    r = reset(n, v, M, 0.9, 0.3, R, W)
    assert r.P_t == 0.0
    assert _polar(n, r.v_plus)[1] == pytest.approx(-R * W)
