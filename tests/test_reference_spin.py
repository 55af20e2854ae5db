"""Tests of the independent spin-as-a-state reference (``tests/reference/spin_reference.py``,
``spin_mp.py``): the impact law of docs/model.md §8 over random impacts (never creates energy,
agrees with
mpmath), its stick / slide / slip-reversal outcomes, the DOP853 flight against an mpmath Taylor
flight, exact conservation scenes, the graze search, the steady whirl helper, and the drop into
dry whirl. Nothing here imports the product core ``rotortd``.
"""

from __future__ import annotations

import cmath
import functools
import math
from typing import Any

import mpmath
import numpy as np
import pytest

from tests.reference.spin_mp import mp_flight, mp_impact
from tests.reference.spin_reference import (
    MODE_ROLLING,
    MODE_SLIDING,
    SpinResult,
    apply_impulse,
    delassus,
    impact_law,
    simulate,
    steady_whirl_start,
)
from tests.reference.spin_scenes import CHAPTER_G, OMEGA0, drop_scene

CR = 0.7e-3
R = 0.04
M = 50.0


def _energy(m: float, J: float, e_c: float, phi: float, z: complex, v: complex, psi: float,
            Om: float, g: float = 0.0) -> tuple[float, float, float]:
    """(translational T, spin T, m g Im(z_G)) of the rigid body [J]."""
    E = cmath.exp(1j * (psi + phi))
    vg = v + 1j * Om * e_c * E
    return 0.5 * m * abs(vg) ** 2, 0.5 * J * Om * Om, m * g * (z + e_c * E).imag


def _ang_mom(m: float, J: float, e_c: float, phi: float, z: complex, v: complex, psi: float,
             Om: float) -> tuple[float, float]:
    """(orbital m Im(conj(z_G) z_G'), spin J Omega) about the bearing centre [kg m^2/s]."""
    E = cmath.exp(1j * (psi + phi))
    zg, vg = z + e_c * E, v + 1j * Om * e_c * E
    return m * (zg.conjugate() * vg).imag, J * Om


# -------------------------------------------------------------------------------- impact law
def _random_impacts(n: int, seed: int) -> list[dict[str, Any]]:
    """Random impacts: beta, slips (incl. tiny ones that the normal impulse reverses), speeds,
    d < 1 and d = 1, e_c up to R/2, J from just above the well-posedness bound."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        m = float(10 ** rng.uniform(0, 2.5))
        Rr = float(10 ** rng.uniform(-2.3, -0.7))
        e_c = float(Rr * 0.5 * rng.uniform(0, 1) ** 2)
        mu = float(rng.choice([0.0, rng.uniform(0, 0.3), rng.uniform(0, 1.5)]))
        bound = m * mu * e_c * (Rr + e_c)
        jr = float(10 ** rng.uniform(-4, 1.5))
        J = max(bound * (1.0 + jr), m * Rr * Rr * 10 ** rng.uniform(-3, 1)) if i % 3 else \
            max(bound * (1.0 + jr), 1e-12 * m * Rr * Rr)
        d = 1.0 if i % 4 == 0 else float(rng.choice([rng.uniform(0, 1), rng.uniform(0.9, 1)]))
        rd = float(10 ** rng.uniform(-4, 0.5))
        kind = i % 5
        if kind == 0:
            s = 0.0
        elif kind in (1, 2):
            s = float(rd * rng.normal() * 10 ** rng.uniform(-3, 0.5))
        else:
            s = float(rng.normal() * 10 ** rng.uniform(-3, 1.5))
        out.append({"m": m, "J": J, "e_c": e_c, "R": Rr, "mu": mu, "d": d,
                    "beta": float(rng.uniform(-math.pi, math.pi)), "rd": rd, "s": s,
                    "v": complex(*rng.normal(size=2)), "Om": float(rng.normal() * 300),
                    "theta": float(rng.uniform(-math.pi, math.pi))})
    return out


@functools.lru_cache(maxsize=1)
def _impact_stats() -> dict[str, Any]:
    """Float law over 12,000 random impacts: worst energy gain, cap tightness, outcome counts."""
    cases = _random_impacts(12000, 17)
    worst_rel, worst_direct, worst_cap, worst_spec = -math.inf, -math.inf, 0.0, -math.inf
    counts = {"stick": 0, "slide": 0, "capped": 0, "reversal": 0, "d1": 0}
    for cs in cases:
        o = impact_law(cs["m"], cs["J"], cs["e_c"], cs["R"], cs["mu"], cs["d"], cs["beta"],
                       cs["rd"], cs["s"])
        scale = o.P_n * cs["rd"] + abs(o.P_t) * (abs(cs["s"]) + abs(o.v_rel_plus)) + 1e-300
        worst_rel = max(worst_rel, o.dT / scale)
        # the same from the rigid body's velocities (the state is made consistent with rd, s)
        n = cmath.exp(1j * cs["theta"])
        vt = cs["s"] - cs["R"] * cs["Om"]
        v = n * complex(cs["rd"], vt)
        vp, omp = apply_impulse(cs["m"], cs["J"], cs["e_c"], cs["R"], n, cs["beta"], v,
                                cs["Om"], o.P_n, o.P_t)
        psi = cs["beta"] + cs["theta"]  # with phi = 0
        e0 = _energy(cs["m"], cs["J"], cs["e_c"], 0.0, 0j, v, psi, cs["Om"])
        e1 = _energy(cs["m"], cs["J"], cs["e_c"], 0.0, 0j, vp, psi, omp)
        tot = e0[0] + e0[1] + e1[0] + e1[1]
        worst_direct = max(worst_direct, (e1[0] + e1[1] - e0[0] - e0[1]) / tot)
        # post-impact contact-point velocities agree with the law's
        vnp = n.conjugate() * vp
        assert abs(vnp.real - o.rdot_plus) <= 1e-9 * (cs["rd"] + abs(cs["s"]) + abs(vt))
        counts["stick" if o.stick else "slide"] += 1
        counts["capped"] += o.capped
        counts["d1"] += cs["d"] == 1.0
        if not o.stick and cs["s"] != 0.0 and o.P_t * cs["s"] < 0.0:
            counts["reversal"] += 1
        if o.capped and o.d_eff > 0.0:
            worst_cap = max(worst_cap, abs(o.dT) / scale)
        if o.capped:
            o2 = impact_law(cs["m"], cs["J"], cs["e_c"], cs["R"], cs["mu"], cs["d"], cs["beta"],
                            cs["rd"], cs["s"], cap="spec")
            sc2 = o2.P_n * cs["rd"] + abs(o2.P_t) * (abs(cs["s"]) + abs(o2.v_rel_plus)) + 1e-300
            worst_spec = max(worst_spec, o2.dT / sc2)
    return {"cases": cases, "worst_rel": worst_rel, "worst_direct": worst_direct,
            "worst_cap": worst_cap, "worst_spec": worst_spec, "counts": counts}


def test_impact_law_never_creates_energy() -> None:
    st = _impact_stats()
    assert st["worst_rel"] <= 1e-14, st["worst_rel"]
    assert st["worst_direct"] <= 1e-13, st["worst_direct"]
    c = st["counts"]
    assert sum(v for k, v in c.items() if k in ("stick", "slide")) >= 10000
    # every outcome kind is exercised
    assert c["stick"] > 500 and c["slide"] > 500 and c["reversal"] > 50 and c["d1"] > 2000
    assert c["capped"] > 10, c
    assert st["worst_spec"] <= 1e-14, st["worst_spec"]  # the model's literal cap recipe too


def test_impact_cap_is_tight() -> None:
    """When the cap fires, d_eff is the largest admissible restitution: dT(d_eff) ~ 0."""
    assert _impact_stats()["worst_cap"] <= 1e-12


def test_impact_law_agrees_with_mpmath() -> None:
    cases = _impact_stats()["cases"][:2500]
    worst = 0.0
    n_capped = 0
    for cs in cases:
        n = cmath.exp(1j * cs["theta"])
        v = n * complex(cs["rd"], cs["s"] - cs["R"] * cs["Om"])
        o = impact_law(cs["m"], cs["J"], cs["e_c"], cs["R"], cs["mu"], cs["d"], cs["beta"],
                       cs["rd"], cs["s"])
        vp, omp = apply_impulse(cs["m"], cs["J"], cs["e_c"], cs["R"], n, cs["beta"], v,
                                cs["Om"], o.P_n, o.P_t)
        r = mp_impact(cs["m"], cs["J"], cs["e_c"], cs["R"], cs["mu"], cs["d"], cs["beta"],
                      cs["rd"], cs["s"], n=n, v_minus=v, Omega_minus=cs["Om"], dps=30)
        n_capped += o.capped
        sp = abs(o.P_n) + abs(o.P_t) + 1e-300
        sv = abs(v) + abs(vp) + cs["R"] * (abs(cs["Om"]) + abs(omp))
        se = o.P_n * cs["rd"] + abs(o.P_t) * (abs(cs["s"]) + abs(o.v_rel_plus)) + 1e-300
        errs = [abs(o.P_n - float(r["P_n"])) / sp, abs(o.P_t - float(r["P_t"])) / sp,
                abs(vp - complex(r["v_plus"])) / sv,
                cs["R"] * abs(omp - float(r["Omega_plus"])) / sv,
                abs(-o.dT - float(r["E_diss"])) / se]
        assert o.stick == r["stick"] or max(errs[:2]) < 1e-13
        worst = max(worst, *errs)
    assert n_capped > 0
    assert worst < 1e-13, worst


def test_impact_stick_slide_and_reversal_by_normal_impulse() -> None:
    m, Rr, e_c = 10.0, 0.05, 0.02
    J = 0.5 * m * Rr * Rr
    beta = 1.2  # B, A > 0: W_nt > 0
    wnn, wnt, wtt = delassus(m, J, e_c, Rr, beta)
    assert wnt > 0.0
    # stick: small slip, high friction
    o = impact_law(m, J, e_c, Rr, 1.0, 0.5, beta, 1.0, 0.05)
    assert o.stick and o.v_rel_plus == 0.0 and o.P_n > 0 and abs(o.P_t) <= o.P_n
    # slide on: large slip keeps its sign, friction opposes it
    o = impact_law(m, J, e_c, Rr, 0.1, 0.5, beta, 1.0, 20.0)
    assert not o.stick and o.P_t == pytest.approx(0.1 * o.P_n) and o.v_rel_plus > 0.0
    # reversal: the normal impulse alone (W_nt P_n) exceeds a small positive slip
    mu, rd, s = 0.05, 1.0, 0.05
    assert wnt * (1.5 * rd / wnn) > s
    o = impact_law(m, J, e_c, Rr, mu, 0.5, beta, rd, s)
    assert not o.stick and o.P_t < 0.0 and o.v_rel_plus < 0.0  # friction set by the slip after
    assert o.P_t == pytest.approx(-mu * o.P_n)
    # a law taking the sign before the impact would leave an inconsistent slip
    pn_pre = 1.5 * rd / (wnn + mu * wnt)
    assert s - (wnt + mu * wtt) * pn_pre < 0.0
    # slip exactly zero with W_nt != 0 is not necessarily stick at low friction
    o = impact_law(m, J, e_c, Rr, 0.01, 0.5, beta, rd, 0.0)
    assert not o.stick and o.v_rel_plus < 0.0


# -------------------------------------------------------------------------------- flight
def test_flight_agrees_with_mp_taylor() -> None:
    p = {**CHAPTER_G}
    J = 0.5 * M * R * R
    om0 = 100.0
    z0, v0 = steady_whirl_start(p, om0, a=1.0)
    z0, v0 = 0.6 * z0 + 1e-5, 0.5 * v0 + 0.004j  # off the steady whirl: transient + reaction
    t = 0.03
    kw: dict[str, Any] = {"a": 1.0, "F_ext": 25.0 - 40.0j, "T_drive": 0.0}
    zr, vr, pr, omr = mp_flight(p, J, om0, z0, v0, 0.4, t, dps=40, **kw)
    res = simulate(p, J, om0, z0, v0, 0.4, t, [t], rtol=1e-13, **kw)
    assert res.status == "ok" and not res.impacts and res.t == t
    assert abs(float(omr) - om0) > 1e-4  # Omega really varies (reaction term)
    zc, vc = complex(zr), complex(vr)
    errs = [abs(res.z - zc) / abs(zc), abs(res.v - vc) / abs(vc),
            abs(res.psi - float(pr)) / abs(float(pr)), abs(res.Omega - float(omr)) / float(omr)]
    assert max(errs) < 1e-11, errs
    # the change of Omega itself (the reaction term's work) is resolved
    assert abs((res.Omega - om0) - float(omr - om0)) < 1e-9 * abs(float(omr - om0))
    # the mp flight is converged: another precision, order and step agree to ~30 digits
    z2, _, _, om2 = mp_flight(p, J, om0, z0, v0, 0.4, t, dps=45, order=70, **kw)
    assert abs(z2 - zr) < mpmath.mpf(10) ** -30 * abs(zr)
    assert abs(om2 - omr) < mpmath.mpf(10) ** -30 * abs(omr)


def test_flight_closed_form_bearing_off() -> None:
    """a = 0, F_ext = 0: z_G on a parabola, psi quadratic (closed form)."""
    p = {**CHAPTER_G}
    J, T_drive = 0.02, 3.0
    z0, v0, psi0, om0, t = 1e-4 + 2e-4j, 0.002 - 0.001j, 0.3, 100.0, 0.004
    res = simulate(p, J, om0, z0, v0, psi0, t, [t], a=0.0, T_drive=T_drive)
    assert res.status == "ok" and not res.impacts
    e_c, phi, g = p["e_c"], p["phi"], p["g"]
    E0 = cmath.exp(1j * (psi0 + phi))
    zg0, vg0 = z0 + e_c * E0, v0 + 1j * om0 * e_c * E0
    psi = psi0 + om0 * t + 0.5 * T_drive / J * t * t
    zg = zg0 + vg0 * t - 0.5j * g * t * t
    z = zg - e_c * cmath.exp(1j * (psi + phi))
    assert abs(res.psi - psi) < 1e-12 * psi
    assert abs(res.Omega - (om0 + T_drive / J * t)) < 1e-12 * om0
    assert abs(res.z - z) < 1e-12 * CR


def test_steady_whirl_start_is_steady() -> None:
    p = {**CHAPTER_G}
    om = 184.2
    z0, v0 = steady_whirl_start(p, om, a=1.0, F_ext=5.0 + 2.0j, psi0=0.7)
    t = np.linspace(0.0, 0.05, 11)
    res = simulate(p, 1e12, om, z0, v0, 0.7, 0.05, t, a=1.0, F_ext=5.0 + 2.0j)
    Z0 = (5.0 + 2.0j) / p["k"]
    Z1 = (z0 - Z0) * np.exp(-0.7j)
    want = Z0 + Z1 * np.exp(1j * (0.7 + om * t))
    assert res.samples["t"].size == 11
    assert np.max(np.abs(res.samples["z"] - want)) < 1e-10 * CR
    assert abs(abs(Z1) - 0.3e-3 * M * om**2 / abs(p["k"] - M * om**2 + 1j * p["c"] * om)) < 1e-16


def test_graze_inside_a_step_is_found() -> None:
    """Static mass centre, held spin: |z| = |z_G| + e_c at its maximum exceeds c_r by 1e-9 c_r
    for a window of ~1e-6 s per revolution, far shorter than DOP853's steps on this motion."""
    p = {**CHAPTER_G, "g": 0.0, "levitate": False, "mu": 0.0}
    e_c, om = p["e_c"], 100.0
    x0 = CR * (1.0 + 1e-9) - e_c
    psi0 = -p["phi"]  # E0 = 1: z starts at its minimum radius x0 - e_c
    z0, v0 = x0 - e_c + 0j, -1j * om * e_c + 0j
    res = simulate(p, 1e9, om, z0, v0, psi0, 0.05, a=0.0)
    assert res.impacts, "graze missed"
    t_star = math.pi / om
    assert abs(res.impacts[0]["t"] - t_star) < 2e-6
    assert res.impacts[0]["rdot_minus"] > 0.0


# -------------------------------------------------------------------------------- conservation
def _conservation_run(d: float, J: float, om0: float) -> tuple[SpinResult, dict[str, Any]]:
    p = {**CHAPTER_G, "mu": 0.0, "g": 0.0, "d": d, "levitate": False}
    z0, v0 = 0.2 * CR * cmath.exp(0.4j), 0.15 * cmath.exp(2.0j)
    res = simulate(p, J, om0, z0, v0, 0.3, 0.2, np.linspace(0.0, 0.2, 401), a=0.0)
    return res, p


@pytest.mark.parametrize("d", [0.3, 0.95, 1.0])
def test_conservation_angular_momentum_and_energy(d: float) -> None:
    """mu = a = g = F_ext = T_drive = 0: L about the bearing centre is constant (impacts, and with
    d = 0.3 chattering into frictionless sliding); with d = 1 the kinetic energy too."""
    J, om0 = 0.5 * M * R * R, 60.0
    res, p = _conservation_run(d, J, om0)
    assert res.status == "ok" and len(res.impacts) >= 10
    s = res.samples
    if d == 0.3:
        assert np.count_nonzero(s["mode"] == MODE_SLIDING) > 100
    L = np.array([_ang_mom(M, J, p["e_c"], p["phi"], z, v, ps, om)
                  for z, v, ps, om in zip(s["z"], s["v"], s["psi"], s["Omega"])])
    ltot = L.sum(1)
    # the impacts exchange angular momentum between orbit and spin (imbalance coupling)
    assert np.ptp(L[:, 1]) > 1e-6 * abs(ltot[0])
    drift = np.max(np.abs(ltot - ltot[0])) / np.max(np.abs(L).sum(1))
    assert drift < 1e-11, drift
    if d == 1.0:
        T = np.array([sum(_energy(M, J, p["e_c"], p["phi"], z, v, ps, om)[:2])
                      for z, v, ps, om in zip(s["z"], s["v"], s["psi"], s["Omega"])])
        assert np.max(np.abs(T - T[0])) / T[0] < 1e-11
        assert all(abs(i["E_diss"]) < 1e-12 * T[0] for i in res.impacts)
    else:
        assert res.E_impacts > 0.0


# -------------------------------------------------------------------------------- drop scene
@functools.lru_cache(maxsize=2)
def _drop(factor: float) -> SpinResult:
    return drop_scene(factor * M * R * R, 0.3, n_grid=3001)


@pytest.mark.parametrize("factor", [0.5, 5.0])
def test_drop_into_dry_whirl(factor: float) -> None:
    J = factor * M * R * R
    res = _drop(factor)
    assert res.status == "ok"
    t_roll = res.first_time("rolling")
    assert t_roll is not None and t_roll < 0.3
    assert res.mode == MODE_ROLLING
    assert any(i["plastic"] for i in res.impacts)  # chattering ended by the plastic rule
    s = res.samples
    assert s["t"].size == 3001 and np.all(np.diff(s["t"]) > 0.0)  # every grid point, once
    roll = s["mode"] == MODE_ROLLING
    assert np.all(s["theta_dot"][roll] < 0.0) and np.all(s["Omega"][roll] > 0.0)  # backward
    assert np.max(np.abs(s["v_rel"][roll])) < 1e-9 * R * OMEGA0
    assert np.all(s["N"][roll] > 0.0)
    # energy balance of the whole run (a = 0): T + V + dissipation is constant
    p = CHAPTER_G

    def etot(k: int) -> float:
        return sum(_energy(M, J, p["e_c"], p["phi"], s["z"][k], s["v"][k], s["psi"][k],
                           s["Omega"][k], p["g"]))

    e0, e1 = etot(0), etot(-1)
    assert abs(e1 + res.E_impacts + res.E_friction - e0) < 1e-11 * e0
    # rolling conserves energy (no slip, no bearing): check it over the rolling samples
    er = np.array([etot(k) for k in np.nonzero(roll)[0]])
    assert np.ptp(er) < 1e-12 * e0


# -------------------------------------------------------------------------------- contact events
def test_loop_lift_off_angle() -> None:
    """e_c = 0, mu = 0, a = 0: a point on the inside of a vertical circle, started at the bottom
    with v0^2 = 3.5 g c_r, slides and leaves the wall at height 1.5 c_r (theta = pi/6)."""
    p = {**CHAPTER_G, "levitate": False, "e_c": 0.0, "mu": 0.0}
    g = p["g"]
    v0 = math.sqrt(3.5 * g * CR)
    first = simulate(p, 0.04, 10.0, -1j * CR * (1 - 1e-13), v0 + 0j, 0.0, 0.03, a=0.0)
    t_lift = next(t for t, nm in first.transitions if nm == "free")
    assert first.transitions[0][1] == "sliding"
    res = simulate(p, 0.04, 10.0, -1j * CR * (1 - 1e-13), v0 + 0j, 0.0, 0.03, [t_lift], a=0.0)
    th = cmath.phase(res.samples["z"][0])
    assert abs(th - math.pi / 6) < 1e-9, th - math.pi / 6


def test_rolling_cone_sliding_lift_off_energy_balance() -> None:
    """Chapter rotor, bearing off, started rolling backward at the bottom: rolling until the
    friction cone, sliding, lift-off; T + V + E_impacts + E_friction is constant."""
    p = {**CHAPTER_G, "levitate": False}
    J, V = 0.5 * M * R * R, 0.15
    grid = np.linspace(0.0, 0.05, 501)
    res = simulate(p, J, -V / R, -1j * CR * (1 - 1e-13), V + 0j, 0.0, 0.05, grid, a=0.0)
    names = [nm for _, nm in res.transitions]
    assert names[:3] == ["rolling", "sliding", "free"], names
    s = res.samples

    def etot(k: int) -> float:
        return sum(_energy(M, J, p["e_c"], p["phi"], s["z"][k], s["v"][k], s["psi"][k],
                           s["Omega"][k], p["g"]))

    e0, e1 = etot(0), etot(-1)
    assert res.E_friction > 1e-6 * e0
    assert abs(e1 + res.E_impacts + res.E_friction - e0) < 1e-11 * e0
    # slip reversal in sliding at a lower speed: the slip sign flips, the rotor stays on
    res = simulate(p, J, -0.1 / R, -1j * CR * (1 - 1e-13), 0.1 + 0j, 0.0, 0.05, grid, a=0.0)
    names = [nm for _, nm in res.transitions]
    assert names[:3] == ["rolling", "sliding", "sliding"] and "free" not in names, names
    vr = res.samples["v_rel"][res.samples["mode"] == MODE_SLIDING]
    assert vr.max() > 0.0 > vr.min()
