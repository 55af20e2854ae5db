"""Tests of the independent direct-integration reference ``tests/reference/direct.py``.

All checks are against closed-form facts (steady whirl, free fall, straight-line flight, the
impact law, the loop-the-loop lift-off angle) or the qualitative outcomes of docs/validation.md §4,
never
against the product core. Errors are measured in scaled units: positions in c_r, velocities in
c_r Omega, times in 1/Omega.
"""

from __future__ import annotations

import ast
import cmath
import math
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tests.reference.direct import (
    MODE_FREE,
    MODE_ROLLING,
    MODE_SLIDING,
    DirectResult,
    direct_simulate,
)

OMEGA = 184.2  # rad/s, chapter speed
CR = 0.7e-3  # m
CHAPTER: dict[str, Any] = {
    "m": 50.0, "c": 1400.0, "k": 9.8e5, "e_c": 0.3e-3, "phi": 0.21, "c_r": CR, "R": 0.04,
    "mu": 0.15, "d": 0.95, "g": 0.0, "levitate": True,
}


def chapter(**kw: Any) -> dict[str, Any]:
    """Chapter parameter set (`rotortd.scaled.CHAPTER`) with overrides."""
    return {**CHAPTER, **kw}


def c_for_gamma(gamma: float, m: float = 50.0, omega: float = OMEGA) -> float:
    """Damping c [N s/m] for the scaled damping gamma = c / (m Omega)."""
    return gamma * m * omega


def polar(z: complex, v: complex) -> tuple[float, float]:
    """(rdot [m/s], r theta' [m/s]) of velocity v at position z."""
    n = z / abs(z)
    w = n.conjugate() * v
    return w.real, w.imag


def test_independent_of_product() -> None:
    """The reference must not import the product (fmu_src / rotortd)."""
    src = Path(__file__).parent / "reference" / "direct.py"
    tree = ast.parse(src.read_text())
    names: list[str] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            names.append(node.module or "")
    assert not [n for n in names if "rotortd" in n or "fmu_src" in n]


@pytest.mark.parametrize(("method", "rtol", "tol"),
                         [("DOP853", 1e-13, 1e-10), ("RK45", 1e-9, 1e-6)])
def test_free_whirl_matches_analytic(method: str, rtol: float, tol: float) -> None:
    """Started on the steady whirl z = c_r U* e^{i psi} (gamma = 0.3, gravity levitated), the
    integration stays on it; also checks psi0/t0 handling and the gravity/bias cancellation."""
    par = chapter(c=c_for_gamma(0.3), g=9.81)
    gamma = par["c"] / (par["m"] * OMEGA)
    w = math.sqrt(par["k"] / par["m"]) / OMEGA
    u_star = (par["e_c"] / CR) * cmath.exp(1j * par["phi"]) / (w * w - 1.0 + 1j * gamma)
    assert abs(u_star) < 1.0
    psi0, t0 = 0.3, 0.1
    t_end = t0 + 20.0 * math.pi / OMEGA  # 10 revolutions
    z0 = CR * u_star * cmath.exp(1j * psi0)
    te = np.linspace(t0, t_end, 41)
    res = direct_simulate(par, z0, 1j * OMEGA * z0, psi0, t0, [(t_end, OMEGA, 0j, 1.0)],
                          method=method, rtol=rtol, t_eval=te)
    assert res.status == "ok" and not res.impacts and res.mode == MODE_FREE
    s = res.samples
    assert s is not None and np.allclose(s["t"], te)
    z_ex = CR * u_star * np.exp(1j * (psi0 + OMEGA * (s["t"] - t0)))
    assert np.max(np.abs(s["z"] - z_ex)) / CR < tol
    assert np.max(np.abs(s["v"] - 1j * OMEGA * z_ex)) / (CR * OMEGA) < tol
    assert res.psi == pytest.approx(psi0 + OMEGA * (t_end - t0), rel=1e-15)


def test_single_impact_reset_law() -> None:
    """First impact from the centre: rdot+ = -d rdot-, c_r theta'+ = c_r theta'- - mu(1+d) rdot- s,
    position on the circle, no stick (v_rel = R Omega dominates)."""
    par = chapter()
    v0 = 2.0 * CR * OMEGA * cmath.exp(0.4j)
    res = direct_simulate(par, 0j, v0, 0.0, 0.0, [(2.0 / OMEGA, OMEGA, 0j, 1.0)], max_impacts=1)
    assert res.status == "max_impacts" and len(res.impacts) == 1
    imp = res.impacts[0]
    assert abs(abs(imp["z"]) - CR) <= 4 * np.finfo(float).eps * CR
    rd_m, vt_m = polar(imp["z"], imp["v_minus"])
    rd_p, vt_p = polar(imp["z"], imp["v_plus"])
    s = math.copysign(1.0, par["R"] * OMEGA + vt_m)
    assert rd_m > 0 and imp["rdot"] == pytest.approx(rd_m, rel=1e-15)
    assert rd_p == pytest.approx(-par["d"] * rd_m, rel=1e-13)
    assert vt_p == pytest.approx(vt_m - par["mu"] * (1 + par["d"]) * rd_m * s, rel=1e-13)
    assert not imp["stick"] and not imp["plastic"]
    assert imp["P_n"] == pytest.approx(par["m"] * (1 + par["d"]) * rd_m, rel=1e-14)
    assert imp["P_t"] == pytest.approx(par["m"] * par["mu"] * (1 + par["d"]) * rd_m * s, rel=1e-13)


def test_straight_flight_impact_time_and_stick_cap() -> None:
    """No forces (a = 0, Omega = 0, g = 0): straight flight, exact impact time; with large mu the
    friction impulse would reverse v_rel, so the cap fires and v_rel+ = 0 exactly (radial v+)."""
    par = chapter(mu=0.5)
    y0, vx = 0.5 * CR, 0.1
    res = direct_simulate(par, 1j * y0, vx + 0j, 0.0, 0.0, [(0.02, 0.0, 0j, 0.0)], max_impacts=1)
    imp = res.impacts[0]
    x_hit = math.sqrt(CR * CR - y0 * y0)
    assert imp["t"] == pytest.approx(x_hit / vx, rel=1e-12)
    assert abs(imp["z"] - complex(x_hit, y0)) / CR < 1e-12
    rd_m, vt_m = polar(imp["z"], imp["v_minus"])
    rd_p, vt_p = polar(imp["z"], imp["v_plus"])
    assert par["mu"] * (1 + par["d"]) * rd_m > abs(vt_m)  # uncapped impulse would reverse v_rel
    assert imp["stick"] and abs(vt_p) < 1e-16
    assert rd_p == pytest.approx(-par["d"] * rd_m, rel=1e-13)
    assert imp["P_t"] == pytest.approx(par["m"] * vt_m, rel=1e-13)  # sign of v_rel-, stops it


def test_grazing_inside_one_step_is_found() -> None:
    """Bearing off, gravity, launched straight up with an apex 1e-8 c_r beyond the wall: the
    solver integrates the parabola exactly in huge steps, both step ends lie inside the disk and
    the event sees no sign change; the dense-output scan must still find the impact."""
    g = 9.81
    par = chapter(g=g)
    v0 = math.sqrt(2.0 * g * CR * (1.0 + 1e-8))
    res = direct_simulate(par, 0j, 1j * v0, 0.0, 0.0, [(0.05, 0.0, 0j, 0.0)], max_impacts=1)
    assert len(res.impacts) == 1
    t_hit = 2.0 * CR / (v0 + math.sqrt(v0 * v0 - 2.0 * g * CR))
    assert res.impacts[0]["t"] == pytest.approx(t_hit, rel=1e-10)
    assert res.impacts[0]["rdot"] == pytest.approx(math.sqrt(2e-8 * g * CR), rel=1e-4)


def test_grazing_found_whatever_the_last_bits() -> None:
    """The grazing launch of the test above with v0 moved by -5..5 ulp: the solver's step sizes
    (set by the rounding of its error estimate, zero in exact arithmetic for a parabola) change,
    and a step may hold the apex and the pass through the centre (r has a maximum and a minimum
    in it); the impact must be found every time (issue 18)."""
    g = 9.81
    par = chapter(g=g)
    base = math.sqrt(2.0 * g * CR * (1.0 + 1e-8))
    for k in range(-5, 6):
        v0 = base + k * math.ulp(base)
        res = direct_simulate(par, 0j, 1j * v0, 0.0, 0.0, [(0.05, 0.0, 0j, 0.0)], max_impacts=1)
        t_hit = 2.0 * CR / (v0 + math.sqrt(v0 * v0 - 2.0 * g * CR))
        assert len(res.impacts) == 1, k
        assert res.impacts[0]["t"] == pytest.approx(t_hit, rel=1e-10), k


def test_bearing_off_drop() -> None:
    """Bearing off (a = 0), gravity, Omega = 0, from rest at the centre: first impact at
    sqrt(2 c_r/g); the impacts accumulate at t_acc = t1 (1 + 2d/(1-d)); the low-speed rule enters
    contact no earlier than 2 d v_zeno / (g (1-d)) before t_acc; the rotor then rolls at rest at
    the bottom (N = m g inside the friction cone)."""
    g, d = 9.81, 0.95
    par = chapter(g=g)
    res = direct_simulate(par, 0j, 0j, 0.0, 0.0, [(0.6, 0.0, 0j, 0.0)])
    t1 = math.sqrt(2.0 * CR / g)
    assert res.impacts[0]["t"] == pytest.approx(t1, rel=1e-10)
    assert res.impacts[0]["rdot"] == pytest.approx(g * t1, rel=1e-10)
    v_zeno = 1e-7 * CR * math.sqrt(par["k"] / par["m"])
    assert res.impacts[-1]["plastic"] and res.impacts[-1]["rdot"] < v_zeno
    assert not any(i["plastic"] for i in res.impacts[:-1])
    t_acc = t1 * (1.0 + 2.0 * d / (1.0 - d))
    t_in = res.contact_events[0][0]
    assert res.contact_events[0][1] == "enter_rolling"
    assert -2.0 * d * v_zeno / (g * (1.0 - d)) - 1e-9 <= t_in - t_acc <= 1e-9
    n_expected = 1 + math.log(v_zeno / (g * t1)) / math.log(d)
    assert abs(len(res.impacts) - n_expected) <= 2
    assert res.mode == MODE_ROLLING and abs(res.z + 1j * CR) / CR < 1e-12 and res.v == 0


def test_loop_lift_off_angle() -> None:
    """Frictionless slide inside the circle under gravity (a = 0, Omega = 0) with V^2 = 3.5 g c_r
    at the bottom: N = m (V^2/c_r - 2 g + 3 g cos alpha) = 0 at cos alpha = -1/2 (alpha from the
    bottom), where v^2 = 0.5 g c_r > 0 still."""
    g = 9.81
    par = chapter(g=g, mu=0.0)
    V = math.sqrt(3.5 * g * CR)
    z0 = -1j * CR * (1.0 - 1e-14)
    res = direct_simulate(par, z0, V + 0j, 0.0, 0.0, [(0.05, 0.0, 0j, 0.0)], max_impacts=200)
    kinds = [k for _, k in res.contact_events]
    assert kinds[:2] == ["enter_sliding", "lift_off"]
    # the state at lift-off = first sample of the free flight that follows: re-run to that time
    t_lo = res.contact_events[1][0]
    lo = direct_simulate(par, z0, V + 0j, 0.0, 0.0, [(t_lo, 0.0, 0j, 0.0)], max_impacts=200)
    assert lo.mode == MODE_FREE
    alpha = cmath.phase(lo.z) + math.pi / 2
    assert math.cos(alpha) == pytest.approx(-0.5, abs=1e-9)


def test_segment_split_and_lift_off_at_boundary() -> None:
    """Splitting a segment does not change free flight; a new segment whose force pulls the
    resting rotor off the wall produces a lift-off at the boundary; psi accumulates per segment."""
    par = chapter(c=c_for_gamma(0.3))
    v0 = 0.2 * CR * OMEGA
    one = direct_simulate(par, 0j, v0, 0.0, 0.0, [(3.0 / OMEGA, OMEGA, 0j, 1.0)])
    two = direct_simulate(par, 0j, v0, 0.0, 0.0,
                          [(1.3 / OMEGA, OMEGA, 0j, 1.0), (3.0 / OMEGA, OMEGA, 0j, 1.0)])
    assert not one.impacts and abs(one.z - two.z) / CR < 1e-12
    g = 9.81
    segs = [(0.6, 0.0, 0j, 0.0), (0.65, 2.0, 2j * par["m"] * g, 0.0)]
    res = direct_simulate(chapter(g=g), 0j, 0j, 0.0, 0.0, segs)
    assert (0.6, "lift_off") in res.contact_events
    assert res.psi == pytest.approx(2.0 * 0.05, rel=1e-12)


def test_max_impacts_caps_work() -> None:
    """Elastic, frictionless, force-free billiard never ends: the cap stops it."""
    par = chapter(d=1.0, mu=0.0)
    res = direct_simulate(par, 0.1j * CR, 0.05 + 0j, 0.0, 0.0, [(10.0, 0.0, 0j, 0.0)],
                          max_impacts=50)
    assert res.status == "max_impacts" and len(res.impacts) == 50
    assert all(i["rdot"] == pytest.approx(res.impacts[0]["rdot"], rel=1e-9) for i in res.impacts)


def _chatter(t_end: float) -> tuple[DirectResult, float]:
    """gamma = 0.3 from rest (docs/model.md §1), samples over the last 20/Omega;
    returns wall time."""
    par = chapter(c=c_for_gamma(0.3))
    te = np.linspace(t_end - 20.0 / OMEGA, t_end, 201)
    t_start = time.perf_counter()
    res = direct_simulate(par, 0j, 0j, 0.0, 0.0, [(t_end, OMEGA, 0j, 1.0)], t_eval=te)
    return res, time.perf_counter() - t_start


def test_chattering_ends_in_forward_rub() -> None:
    """gamma = 0.3 from rest chatters (rdot- shrinking by ~d) into sliding; by t = 400/Omega it
    sits at a constant co-rotating angle, i.e. whirl rate Omega (synchronous forward rub)."""
    res, _ = _chatter(400.0 / OMEGA)
    assert res.status == "ok" and res.mode == MODE_SLIDING
    assert [k for _, k in res.contact_events] == ["enter_sliding"]
    rd = np.array([i["rdot"] for i in res.impacts])
    assert res.impacts[-1]["plastic"] and rd[-1] < 1e-7 * CR * OMEGA
    tail = rd[-120:-20] / rd[-121:-21]  # geometric chatter at ratio d
    assert np.all(np.abs(tail - 0.95) < 2e-3)
    s = res.samples
    assert s is not None and np.all(s["mode"] == MODE_SLIDING)
    u = s["z"] * np.exp(-1j * OMEGA * s["t"]) / CR
    assert np.allclose(np.abs(u), 1.0, rtol=0, atol=1e-13)
    assert np.ptp(np.unwrap(np.angle(u))) < 1e-8
    whirl = np.imag(np.conj(s["z"]) * s["v"]) / np.abs(s["z"]) ** 2
    assert np.allclose(whirl / OMEGA, 1.0, rtol=0, atol=1e-8)


def test_dry_whirl_enters_rolling() -> None:
    """gamma = 0.065 from rest: impacts, sliding, then rolling with theta' = -R Omega / c_r
    exactly and a normal force far above m c_r Omega^2. A later drop of Omega by 10 % at a segment
    boundary breaks rolling (v_rel jumps), the rotor slides and rolls again at the new rate."""
    par = chapter(c=c_for_gamma(0.065))
    t1, t2 = 130.0 / OMEGA, 135.0 / OMEGA
    res = direct_simulate(par, 0j, 0j, 0.0, 0.0, [(t1, OMEGA, 0j, 1.0)])
    kinds = [k for _, k in res.contact_events]
    assert kinds == ["enter_sliding", "enter_rolling"]
    assert res.mode == MODE_ROLLING
    thd = (np.conj(res.z) * res.v).imag / abs(res.z) ** 2
    assert thd == pytest.approx(-par["R"] * OMEGA / CR, rel=1e-14)
    assert abs(res.z) == pytest.approx(CR, rel=1e-15)
    n_force = _normal_force(par, res)
    assert n_force > 1000.0 * par["m"] * CR * OMEGA**2
    res2 = direct_simulate(par, 0j, 0j, 0.0, 0.0,
                           [(t1, OMEGA, 0j, 1.0), (t2, 0.9 * OMEGA, 0j, 1.0)])
    assert res2.contact_events[2] == (t1, "leave_rolling")
    assert res2.contact_events[3][1] == "enter_rolling" and res2.mode == MODE_ROLLING
    thd2 = (np.conj(res2.z) * res2.v).imag / abs(res2.z) ** 2
    assert thd2 == pytest.approx(-par["R"] * 0.9 * OMEGA / CR, rel=1e-14)


def _normal_force(par: dict[str, Any], res: DirectResult) -> float:
    """N = Re(e^{-i theta} F) + m c_r theta'^2 at the final state (a = 1, no F_ext, no gravity)."""
    z, v = res.z, res.v
    f = (-par["c"] * v - par["k"] * z
         + par["m"] * par["e_c"] * OMEGA**2 * cmath.exp(1j * (res.psi + par["phi"])))
    thd = (z.conjugate() * v).imag / abs(z) ** 2
    return (z.conjugate() / abs(z) * f).real + par["m"] * abs(z) * thd**2


def test_zeno_rule_error_is_small() -> None:
    """The state shortly after the accumulation point changes by less than 1e-11 (scaled) when
    the cut-off is lowered from 1e-4 to 1e-7 c_r Omega (quadratic or better in v_zeno)."""
    par = chapter(c=c_for_gamma(0.3))
    seg = [(35.0 / OMEGA, OMEGA, 0j, 1.0)]
    a = direct_simulate(par, 0j, 0j, 0.0, 0.0, seg, v_zeno=1e-4 * CR * OMEGA)
    b = direct_simulate(par, 0j, 0j, 0.0, 0.0, seg)
    assert a.mode == b.mode == MODE_SLIDING and len(a.impacts) < len(b.impacts)
    assert abs(a.z - b.z) / CR < 1e-10 and abs(a.v - b.v) / (CR * OMEGA) < 1e-10
