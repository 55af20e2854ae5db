"""Tests of the independent high-precision reference ``tests/reference/mp_reference.py``.

Every check compares against a hand-derived closed form, a conserved quantity or an
independent evaluation path (eigen-decomposition, golden/Newton search on the expm
flight), never against numbers produced by the product code.
"""

from __future__ import annotations

from typing import Any

import mpmath
import numpy as np
import pytest
from mpmath import mp
from scipy.integrate import solve_ivp

from tests.reference import mp_reference
from tests.reference.mp_reference import (
    mp_first_impact,
    mp_flight,
    mp_impact_sequence,
    mp_reset,
    mp_rolling_normal_force,
    mp_sliding,
)

CHAPTER: dict[str, Any] = {
    "m": 50.0,
    "c": 1400.0,
    "k": 9.8e5,
    "e_c": 0.3e-3,
    "phi": 0.21,
    "c_r": 0.7e-3,
    "R": 0.04,
    "mu": 0.15,
    "d": 0.95,
    "g": 9.81,
    "levitate": True,
}
OMEGA = 184.2
C_R = CHAPTER["c_r"]


@pytest.fixture(autouse=True)
def _high_precision() -> Any:
    """Run each test's own mpmath arithmetic at 70 digits (restored afterwards).

    Float inputs are exact binary numbers; the tests convert them with ``mpf`` before
    doing arithmetic, so that no float rounding enters the expected values.
    """
    with mp.workdps(70):
        yield


def par(**kw: Any) -> dict[str, Any]:
    """Chapter parameter set with overrides."""
    return {**CHAPTER, **kw}


def err(x: Any, y: Any, unit: float) -> float:
    """|x - y| in units of ``unit``."""
    return float(abs(x - y) / unit)


# --------------------------------------------------------------------------------------
# flight: analytic special cases
# --------------------------------------------------------------------------------------


def test_flight_undamped_oscillator() -> None:
    p = par(c=0.0, e_c=0.0, g=0.0)
    z0, v0, t = 1e-4 + 2e-4j, 0.01 - 0.02j, 0.37
    z, v = mp_flight(p, z0, v0, 0.3, OMEGA, 0, 1.0, t)
    with mp.workdps(70):
        w = mp.sqrt(mp.mpf(p["k"]) / p["m"])
        zx = mp.mpc(z0) * mp.cos(w * t) + mp.mpc(v0) / w * mp.sin(w * t)
        vx = -mp.mpc(z0) * w * mp.sin(w * t) + mp.mpc(v0) * mp.cos(w * t)
    assert err(z, zx, C_R) < 1e-45
    assert err(v, vx, C_R * w) < 1e-45


def test_flight_free_fall_bearing_off() -> None:
    """a = 0: gravity only (the levitation bias is scaled by a), e_c = 0."""
    p = par(e_c=0.0)
    z0, v0, t = 1e-4j, 0.02 + 0.01j, 0.0123
    z, v = mp_flight(p, z0, v0, 0.0, OMEGA, 0, 0.0, t)
    with mp.workdps(70):
        tt, g = mp.mpf(t), mp.mpf(p["g"])
        zx = mp.mpc(z0) + mp.mpc(v0) * tt - 0.5j * g * tt**2
        vx = mp.mpc(v0) - 1j * g * tt
    assert err(z, zx, C_R) < 1e-45
    assert err(v, vx, 1.0) < 1e-45


def test_flight_resonance_secular_growth() -> None:
    """c = 0, Ω² = k/m: z = A (t e^{iΩt} - sin(Ωt)/Ω), A = -i e_c Ω e^{i(ψ0+φ)}/2."""
    p = par(c=0.0, g=0.0)
    with mp.workdps(70):
        Om = mp.sqrt(mp.mpf(p["k"]) / p["m"])
    psi0, t = 0.4, 2.5  # ~56 periods
    z, v = mp_flight(p, 0, 0, psi0, Om, 0, 1.0, t)
    with mp.workdps(70):
        A = -0.5j * p["e_c"] * Om * mp.expj(psi0 + mp.mpf(p["phi"]))
        tt = mp.mpf(t)
        zx = A * (tt * mp.expj(Om * tt) - mp.sin(Om * tt) / Om)
        vx = A * (mp.expj(Om * tt) * (1 + 1j * Om * tt) - mp.cos(Om * tt))
    assert abs(zx) > 50 * p["e_c"]  # secular growth actually happened
    assert err(z, zx, C_R) < 1e-40
    assert err(v, vx, C_R * Om) < 1e-40


def test_flight_near_resonance() -> None:
    """c = 0, Ω = ω (1 + 1e-9): classical formula evaluated at 100 digits."""
    p = par(c=0.0, g=0.0)
    with mp.workdps(100):
        w = mp.sqrt(mp.mpf(p["k"]) / p["m"])
        Om = w * (1 + mp.mpf("1e-9"))
    psi0, t = -1.1, 0.8
    z, _ = mp_flight(p, 0, 0, psi0, Om, 0, 1.0, t)
    with mp.workdps(100):
        f = p["e_c"] * Om**2 * mp.expj(psi0 + mp.mpf(p["phi"]))
        Zp = f / (w**2 - Om**2)
        tt = mp.mpf(t)
        # z = Zp (e^{iΩt} - cos ωt - i Ω/ω sin ωt)
        zx = Zp * (mp.expj(Om * tt) - mp.cos(w * tt) - 1j * Om / w * mp.sin(w * tt))
    assert err(z, zx, C_R) < 1e-40


def test_flight_critical_damping_with_constant_force() -> None:
    """c² = 4 m k: z - z_e = (z0' + (v0 + β z0') t) e^{-βt}, z_e = F/k, β = c/2m."""
    m, k = 50.0, 9.8e5
    with mp.workdps(70):
        c = 2 * mp.sqrt(mp.mpf(m) * k)
    p = par(c=float(c), e_c=0.0, g=0.0)
    p["c"] = c  # exact critical damping (mpf accepted)
    F = 30.0 - 12.0j
    z0, v0, t = 2e-4 - 1e-4j, -0.03 + 0.05j, 0.011
    z, v = mp_flight(p, z0, v0, 0.0, 0.0, F, 1.0, t)
    with mp.workdps(70):
        beta = c / (2 * m)
        ze = mp.mpc(F) / k
        y0 = mp.mpc(z0) - ze
        B = mp.mpc(v0) + beta * y0
        zx = ze + (y0 + B * t) * mp.exp(-beta * t)
        vx = (B - beta * (y0 + B * t)) * mp.exp(-beta * t)
    assert err(z, zx, C_R) < 1e-45
    assert err(v, vx, C_R * beta) < 1e-45


def test_flight_no_spring_constant_force() -> None:
    """k = 0, c > 0 (also Ω = 0): drift F t/c plus exponential transient."""
    p = par(k=0.0, g=0.0)
    F, z0, v0, t = 5.0 + 7.0j, 1e-4 + 0j, 0.01j, 0.2
    z, v = mp_flight(p, z0, v0, 0.0, 0.0, F, 1.0, t)
    with mp.workdps(70):
        c, m = mp.mpf(p["c"]), mp.mpf(p["m"])
        Fc = mp.mpc(F)
        vx = Fc / c + (mp.mpc(v0) - Fc / c) * mp.exp(-c * t / m)
        zx = mp.mpc(z0) + Fc * t / c + (mp.mpc(v0) - Fc / c) * m / c * (1 - mp.exp(-c * t / m))
    assert err(z, zx, C_R) < 1e-45
    assert err(v, vx, 1.0) < 1e-45


def _eigen_flight(p: dict[str, Any], z0: complex, v0: complex, psi0: float, t: float) -> Any:
    """Non-degenerate closed form (distinct roots, off resonance) at 80 digits."""
    with mp.workdps(80):
        m, c, k = (mp.mpf(p[key]) for key in ("m", "c", "k"))
        Om = mp.mpf(OMEGA)
        F = mp.mpc(0, 1) * m * p["g"] - mp.mpc(0, 1) * m * p["g"] + mp.mpc(3.0, -4.0)
        f = m * p["e_c"] * Om**2 * mp.expj(psi0 + mp.mpf(p["phi"]))
        ze = F / k
        Zp = f / (k - m * Om**2 + 1j * c * Om)
        disc = mp.sqrt(mp.mpc(c**2 - 4 * m * k))
        l1, l2 = (-c + disc) / (2 * m), (-c - disc) / (2 * m)
        y0 = mp.mpc(z0) - ze - Zp
        y1 = mp.mpc(v0) - 1j * Om * Zp
        A1 = (y1 - l2 * y0) / (l1 - l2)
        A2 = y0 - A1
        tt = mp.mpf(t)
        return ze + Zp * mp.expj(Om * tt) + A1 * mp.exp(l1 * tt) + A2 * mp.exp(l2 * tt)


def test_flight_generic_matches_eigen_closed_form() -> None:
    z0, v0, psi0, t = 3e-4 - 2e-4j, 0.05 + 0.02j, 0.7, 0.123
    z, _ = mp_flight(CHAPTER, z0, v0, psi0, OMEGA, 3.0 - 4.0j, 1.0, t)
    assert err(z, _eigen_flight(CHAPTER, z0, v0, psi0, t), C_R) < 1e-45


def test_flight_semigroup_and_omega_zero() -> None:
    z0, v0 = 1e-4 + 3e-4j, -0.02 + 0.01j
    with mp.workdps(70):
        t1, t2 = mp.mpf("0.05"), mp.mpf("0.07")
        t3 = t1 + t2
    for Om in (OMEGA, 0.0):
        psi1 = mp.mpf(0.2) + Om * t1
        z1, v1 = mp_flight(CHAPTER, z0, v0, 0.2, Om, 1.0j, 1.0, t1)
        z2, v2 = mp_flight(CHAPTER, z1, v1, psi1, Om, 1.0j, 1.0, t2)
        z3, v3 = mp_flight(CHAPTER, z0, v0, 0.2, Om, 1.0j, 1.0, t3)
        assert err(z2, z3, C_R) < 1e-45
        assert err(v2, v3, C_R * OMEGA) < 1e-45


# --------------------------------------------------------------------------------------
# reset law
# --------------------------------------------------------------------------------------


def _polar(z: Any, v: Any) -> tuple[Any, Any]:
    """(ṙ, c_r θ') of a velocity v at position z on the wall."""
    n = z / abs(z)
    return (mp.conj(n) * v).real, (mp.conj(n) * v).imag * C_R / abs(z)


@pytest.mark.parametrize("Om,s", [(OMEGA, 1), (-OMEGA, -1)])
def test_reset_polar_form(Om: float, s: int) -> None:
    p = par()
    with mp.workdps(60):
        z = C_R * mp.expj(mp.mpf("0.9"))
        n = z / abs(z)
        vm = n * (0.03 + 0.2j)  # ṙ⁻ = 0.03, c_r θ'⁻ = 0.2; |R Ω| = 7.4 dominates v_rel
    res = mp_reset(p, z, vm, Om)
    rd_m, vt_m = _polar(z, vm)
    rd_p, vt_p = _polar(z, res["v_plus"])
    mu, d = mp.mpf(p["mu"]), mp.mpf(p["d"])
    assert err(rd_p, -d * rd_m, 1.0) < 1e-45
    assert err(vt_p, vt_m - mu * (1 + d) * rd_m * s, 1.0) < 1e-45
    assert err(res["rdot"], rd_m, 1.0) < 1e-45
    assert err(res["P_n"], p["m"] * (1 + d) * rd_m, 1.0) < 1e-45
    assert err(res["P_t"], mu * s * res["P_n"], 1.0) < 1e-45
    assert res["stick"] is False


@pytest.mark.parametrize("sign", [1, -1])
def test_reset_stick_cap(sign: int) -> None:
    """Slip smaller than the friction kick: capped so v_rel⁺ = 0, |P_t| < μ P_n."""
    p = par()
    Om = sign * 10.0
    with mp.workdps(60):
        z = C_R * mp.expj(mp.mpf("-2.0"))
        n = z / abs(z)
        vt = -mp.mpf(p["R"]) * Om + sign * mp.mpf(0.001)  # v_rel⁻ = ±0.001 m/s
        vm = n * (0.05 + 1j * vt)
    res = mp_reset(p, z, vm, Om)
    _, vt_p = _polar(z, res["v_plus"])
    rd_p, _ = _polar(z, res["v_plus"])
    assert res["stick"] is True
    assert err(mp.mpf(p["R"]) * Om + vt_p, 0, 1.0) < 1e-45
    assert res["v_rel_plus"] == 0
    assert err(rd_p, -mp.mpf(p["d"]) * 0.05, 1.0) < 1e-45
    assert err(res["P_t"], mp.mpf(p["m"]) * sign * mp.mpf(0.001), 1.0) < 1e-45
    assert abs(res["P_t"]) < p["mu"] * res["P_n"]


def test_reset_zero_slip_no_tangential_impulse() -> None:
    p = par()
    z = 1j * C_R
    # at z = i c_r: n = i, tangential unit i n = -1; v_t = -R Ω -> v_rel = 0 exactly
    # (R Ω of two doubles is exact at this precision), ṙ = 0.04
    RO = mp.mpf(p["R"]) * OMEGA
    vm = mp.mpc(RO, 0.04)
    res = mp_reset(p, z, vm, OMEGA)
    assert res["v_rel_minus"] == 0
    assert res["P_t"] == 0
    assert res["stick"] is True
    assert err(res["v_plus"], mp.mpc(RO, -mp.mpf(0.04) * p["d"]), 1.0) < 1e-45


# --------------------------------------------------------------------------------------
# event location, grazing
# --------------------------------------------------------------------------------------


def _ellipse_case(A_over_cr: str) -> tuple[dict[str, Any], Any, Any, Any]:
    """Isotropic undamped oscillator z = A sin ωt + i B cos ωt, B = c_r/2, max |z| = A."""
    p = par(c=0.0, e_c=0.0, g=0.0)
    with mp.workdps(70):
        w = mp.sqrt(mp.mpf(p["k"]) / p["m"])
        A = C_R * mp.mpf(A_over_cr)
        B = C_R / mp.mpf(2)
    return p, w, A, B


def test_grazing_found_by_1e10() -> None:
    p, w, A, B = _ellipse_case("1.0000000001")
    hit = mp_first_impact(p, 1j * B, A * w, 0.0, 0.0, 0, 1.0, 0.05)
    assert hit is not None
    t, z, vm = hit
    with mp.workdps(70):
        cr = mp.mpf(C_R)
        tx = mp.asin(mp.sqrt((cr**2 - B**2) / (A**2 - B**2))) / w
    # conditioning near grazing: δt ~ ε c_r / ṙ; ṙ ~ 1e-5 c_r ω here
    assert err(t, tx, 1 / w) < 1e-35
    assert err(abs(z), C_R, C_R) < 1e-48
    assert (mp.conj(z) * vm).real > 0


def test_grazing_missed_by_1e10() -> None:
    p, w, A, B = _ellipse_case("0.9999999999")
    assert mp_first_impact(p, 1j * B, A * w, 0.0, 0.0, 0, 1.0, 0.05) is None


def _local_max_radius(p: dict[str, Any], t_guess: float) -> Any:
    """Max of |z(t)| near t_guess from mp_flight (Newton on d|z|²/dt via expm path)."""
    f0 = {"z0": 0.0, "v0": 0.0, "psi0": 0.0}

    def drdt(t: Any) -> Any:
        z, v = mp_flight(p, f0["z0"], f0["v0"], f0["psi0"], OMEGA, 0, 1.0, t, dps=60)
        return (mp.conj(z) * v).real

    with mp.workdps(60):
        tm = mpmath.findroot(drdt, (t_guess - 1e-3, t_guess + 1e-3), solver="anderson")
        z, _ = mp_flight(p, f0["z0"], f0["v0"], f0["psi0"], OMEGA, 0, 1.0, tm, dps=60)
        return abs(z), tm


@pytest.mark.parametrize("rel,found", [("1e-10", True), ("-1e-10", False)])
def test_grazing_chapter_parameters(rel: str, found: bool) -> None:
    """Chapter set (damped, imbalance, levitated gravity): c_r set just below/above
    the first local maximum of |z| (c_r does not enter the flight dynamics)."""
    big = par(c_r=1.0)  # wall far away: same dynamics
    # from rest: coarse scan for the first local max of |z| (near t = 19 ms, r = 0.59 mm)
    ts = [i * 1e-3 for i in range(1, 40)]
    rs = [abs(mp_flight(big, 0, 0, 0, OMEGA, 0, 1.0, t, dps=20)[0]) for t in ts]
    i_max = next(i for i in range(1, 38) if rs[i] > rs[i - 1] and rs[i] >= rs[i + 1])
    r_max, t_max = _local_max_radius(big, ts[i_max])
    with mp.workdps(60):
        cr = r_max / (1 + mp.mpf(rel))
    p = par(c_r=cr)
    # horizon: past the maximum but before |z| regrows beyond it (after ~23 ms)
    hit = mp_first_impact(p, 0, 0, 0, OMEGA, 0, 1.0, t_max + 3e-3)
    if found:
        assert hit is not None
        # the excursion above c_r is ~2e-7 s wide, far below the sample interval ~1e-4 s
        assert 0 < t_max - hit[0] < 1e-6
        assert err(abs(hit[1]), cr, cr) < 1e-48
    else:
        assert hit is None


def test_first_impact_consistent_with_flight_and_precision() -> None:
    hit50 = mp_first_impact(CHAPTER, 0, 0, 0, OMEGA, 0, 1.0, 0.1)
    hit70 = mp_first_impact(CHAPTER, 0, 0, 0, OMEGA, 0, 1.0, 0.1, dps=70)
    assert hit50 is not None and hit70 is not None
    t, z, vm = hit50
    assert err(t, hit70[0], 1 / OMEGA) < 1e-45
    zf, vf = mp_flight(CHAPTER, 0, 0, 0, OMEGA, 0, 1.0, t)
    assert err(z, zf, C_R) < 1e-45
    assert err(vm, vf, C_R * OMEGA) < 1e-45
    assert err(abs(z), C_R, C_R) < 1e-50
    # nothing earlier: dense check of |z| < c_r before t
    for i in range(1, 60):
        zi, _ = mp_flight(CHAPTER, 0, 0, 0, OMEGA, 0, 1.0, t * i / 60, dps=20)
        assert abs(zi) < C_R


@pytest.mark.parametrize(
    "z0,v0,psi0",
    [(0j, 0j, 0.0), (3e-4 - 1e-4j, 0.02 + 0.05j, 1.3), (-5e-4j, -0.04 + 0.0j, -2.0)],
)
def test_first_impact_independent_of_sampling_density(
    monkeypatch: pytest.MonkeyPatch, z0: complex, v0: complex, psi0: float
) -> None:
    """The located impact does not change when the sampling is made 10x denser
    (a check of the one-extremum-per-interval assumption on typical trajectories)."""
    p = par(c=0.1 * 50 * OMEGA)
    coarse = mp_first_impact(p, z0, v0, psi0, OMEGA, 0, 1.0, 0.2)
    monkeypatch.setattr(mp_reference, "SAMPLES_PER_RAD", 400)
    fine = mp_first_impact(p, z0, v0, psi0, OMEGA, 0, 1.0, 0.2)
    assert coarse is not None and fine is not None
    assert err(coarse[0], fine[0], 1 / OMEGA) < 1e-45


def test_start_outside_rejected() -> None:
    with pytest.raises(ValueError):
        mp_first_impact(CHAPTER, 1.01 * C_R, 0, 0, OMEGA, 0, 1.0, 0.1)


# --------------------------------------------------------------------------------------
# impact sequences
# --------------------------------------------------------------------------------------


def test_sequence_vertical_bouncing_ball() -> None:
    """a = 0, Ω = 0 (s = 0: no friction), fall from the centre: ṙ_k = d^k sqrt(2 g c_r),
    impact times t_1 = sqrt(2 c_r/g), t_{k+1} = t_k + 2 ṙ_k d / g."""
    p = par(e_c=0.0, d=0.8)
    v_stop = 0.3 * (2 * 9.81 * C_R) ** 0.5
    out = mp_impact_sequence(p, 0, 0, 0, 0.0, 0, 0.0, 1.0, v_stop=v_stop)
    assert out["stopped"] == "v_stop"
    imps = out["impacts"]
    assert len(imps) == 7  # 0.8^6 = 0.26 < 0.3 < 0.8^5
    with mp.workdps(70):
        g = mp.mpf(p["g"])
        rd = mp.sqrt(2 * g * C_R)
        t = mp.sqrt(2 * C_R / g)
        for imp in imps:
            assert err(imp["t"], t, 1e-3) < 1e-40
            assert err(imp["rdot"], rd, rd) < 1e-40
            assert err(imp["z"], -1j * C_R, C_R) < 1e-40
            t += 2 * rd * p["d"] / g
            rd *= p["d"]
    assert out["v"] == imps[-1]["v_minus"]


def test_sequence_plastic_stops_in_contact() -> None:
    p = par(e_c=0.0, d=0.0)
    out = mp_impact_sequence(p, 0, 0, 0, 0.0, 0, 0.0, 1.0)
    assert out["stopped"] == "contact"
    assert len(out["impacts"]) == 1


def test_sequence_chapter_from_rest() -> None:
    """γ = 0.3 from rest: impacts on the circle, ordered, reset law applied, each
    impact equal to a fresh mp_first_impact from the previous post-impact state."""
    p = par(c=0.3 * 50 * OMEGA)
    out = mp_impact_sequence(p, 0, 0, 0, OMEGA, 0, 1.0, 1.0, max_impacts=6)
    assert out["stopped"] == "max_impacts"
    imps = out["impacts"]
    assert len(imps) == 6
    t_prev, z_prev, v_prev = mp.zero, 0, 0
    for imp in imps:
        assert err(abs(imp["z"]), C_R, C_R) < 1e-48
        assert imp["rdot"] > 0
        rd_p, _ = _polar(imp["z"], imp["v_plus"])
        assert err(rd_p, -p["d"] * imp["rdot"], OMEGA * C_R) < 1e-45
        hit = mp_first_impact(p, z_prev, v_prev, OMEGA * t_prev, OMEGA, 0, 1.0, 1.0, dps=50)
        assert hit is not None
        assert err(t_prev + hit[0], imp["t"], 1 / OMEGA) < 1e-40
        t_prev, z_prev, v_prev = imp["t"], imp["z"], imp["v_plus"]


# --------------------------------------------------------------------------------------
# sustained contact
# --------------------------------------------------------------------------------------


def test_sliding_frictionless_energy_conserved() -> None:
    """μ = 0, c = 0, AMB spring (constant on the circle) + unbalanced gravity + F_ext:
    E = ½ m c_r² θ'² - Re(conj(P) c_r e^{iθ}), P = F_ext - i m g, is conserved."""
    p = par(c=0.0, e_c=0.0, mu=0.0, levitate=False)
    F = 200.0 + 100.0j
    th0, w0 = 0.5, 300.0
    out = mp_sliding(p, th0, w0, 0.0, OMEGA, F, 1.0, 0.02)
    assert out["event"] == "t_end"

    def energy(th: Any, w: Any) -> Any:
        P = mp.mpc(F) - 1j * mp.mpf(p["m"]) * p["g"]
        cr = mp.mpf(C_R)
        return p["m"] * cr**2 * w**2 / 2 - (mp.conj(P) * cr * mp.expj(th)).real

    with mp.workdps(55):
        e0 = energy(mp.mpf(th0), mp.mpf(w0))
        assert abs(energy(out["theta"], out["dtheta"]) / e0 - 1) < 1e-35


def test_sliding_impulse_balances_momentum() -> None:
    """AMB off, no imbalance: the only forces are the constant P = F_ext - i m g and the
    contact, so the reference's contact impulse must equal m (v(t) - v(0)) - P t."""
    p = par(e_c=0.0, mu=0.3)
    F = 200.0 + 100.0j
    th0, w0, t = 0.5, 300.0, 0.02
    out = mp_sliding(p, th0, w0, 0.0, OMEGA, F, 0.0, t)
    assert out["event"] == "t_end"
    with mp.workdps(55):
        cr, m = mp.mpf(C_R), mp.mpf(p["m"])
        P = mp.mpc(F) - 1j * m * p["g"]
        dv = 1j * cr * (out["dtheta"] * mp.expj(out["theta"]) - w0 * mp.expj(mp.mpf(th0)))
        expect = m * dv - P * t
        assert abs(out["I_c"] - expect) < 1e-30 * abs(expect)
        assert out["I_n"] > 0


def test_sliding_frictionless_imbalance_pendulum() -> None:
    """μ = 0, no constant force, c = 0: α = θ - Ωt - ψ0 - φ obeys α'' = -(e_c Ω²/c_r) sin α,
    so ½ α'² - (e_c Ω²/c_r) cos α is conserved."""
    p = par(c=0.0, mu=0.0, g=0.0)
    psi0, th0, w0, t = 0.3, 1.0, 100.0, 0.01
    out = mp_sliding(p, th0, w0, psi0, OMEGA, 0, 1.0, t)
    with mp.workdps(55):
        K = mp.mpf(p["e_c"]) * mp.mpf(OMEGA) ** 2 / C_R
        phase = psi0 + mp.mpf(p["phi"])
        a0 = th0 - phase
        a1 = out["theta"] - OMEGA * mp.mpf(t) - phase
        j0 = (mp.mpf(w0) - OMEGA) ** 2 / 2 - K * mp.cos(a0)
        j1 = (out["dtheta"] - OMEGA) ** 2 / 2 - K * mp.cos(a1)
        assert abs(j1 / j0 - 1) < 1e-35


def test_sliding_friction_closed_form() -> None:
    """a = 0, no forces, Ω = 0, θ' > 0: θ'' = -μ θ'², θ' = w0/(1 + μ w0 t)."""
    p = par(e_c=0.0, g=0.0)
    out = mp_sliding(p, 0.3, 200.0, 0.0, 0.0, 0, 0.0, 0.05)
    with mp.workdps(55):
        mu, w0, t = mp.mpf(p["mu"]), mp.mpf(200), mp.mpf(0.05)
        assert err(out["dtheta"], w0 / (1 + mu * w0 * t), w0) < 1e-38
        assert err(out["theta"], mp.mpf(0.3) + mp.log(1 + mu * w0 * t) / mu, 1) < 1e-38
        mcr = mp.mpf(p["m"]) * C_R
        assert err(out["N_end"], mcr * out["dtheta"] ** 2, mcr * w0**2) < 1e-38


def test_sliding_backward_whirl_reaches_rolling() -> None:
    """Dry-whirl onset: s = +1, θ' < 0 grows as w0/(1 + μ w0 t) until θ' = -R Ω/c_r."""
    p = par(e_c=0.0, g=0.0)
    out = mp_sliding(p, 0.0, -2000.0, 0.0, OMEGA, 0, 0.0, 1.0)
    assert out["event"] == "v_rel_zero"
    with mp.workdps(55):
        mu, w0 = mp.mpf(p["mu"]), mp.mpf(-2000)
        wr = -mp.mpf(p["R"]) * OMEGA / C_R
        tr = (w0 / wr - 1) / (mu * w0)
        assert err(out["t"], tr, 1 / OMEGA) < 1e-35
        assert err(out["dtheta"], wr, abs(wr)) < 1e-35


def test_sliding_lift_off_angle() -> None:
    """Bead inside a circle under gravity (a = 0, μ = 0): N = 2E/c_r - 3 m g sin θ
    (per unit mass E = ½ c_r² θ'² + g c_r sin θ) vanishes at sin θ_L = 2E/(3 g c_r)."""
    p = par(e_c=0.0, mu=0.0, levitate=False)
    w0 = 200.0
    out = mp_sliding(p, -float(mp.pi) / 2, w0, 0.0, 0.0, 0, 0.0, 1.0)
    assert out["event"] == "lift_off" and out["lift_off"] is True
    with mp.workdps(55):
        g = mp.mpf(p["g"])
        th0 = mp.mpf(-float(mp.pi) / 2)
        cr = mp.mpf(C_R)
        E = cr**2 * mp.mpf(w0) ** 2 / 2 + g * cr * mp.sin(th0)
        assert abs(mp.sin(out["theta"]) - 2 * E / (3 * g * C_R)) < 1e-35
        assert abs(out["N_end"]) < 1e-35 * p["m"] * g
        assert out["dtheta"] > 0


def test_rolling_closed_form() -> None:
    """Rolling under gravity only (a = 0): N = m c_r θ'² - m g sin θ, F_t = -m g cos θ."""
    p = par(e_c=0.0, levitate=False)
    out = mp_rolling_normal_force(p, 0.4, 0.0, OMEGA, 0, 0.0, 0.003)
    with mp.workdps(55):
        wr = -mp.mpf(p["R"]) * OMEGA / C_R
        th = mp.mpf(0.4) + wr * mp.mpf(0.003)
        m, g = mp.mpf(p["m"]), mp.mpf(p["g"])
        assert err(out["theta"], th, 1) < 1e-45
        assert err(out["N"], m * C_R * wr**2 - m * g * mp.sin(th), m * g) < 1e-40
        assert err(out["F_t"], -m * g * mp.cos(th), m * g) < 1e-40


def test_sliding_equals_rolling_limit_consistency() -> None:
    """Sliding from a state with tiny positive slip and μ = 0, bearing off, no forces:
    θ' constant, N = m c_r θ'² as for rolling at the same rate."""
    p = par(e_c=0.0, g=0.0, mu=0.0)
    wr = -p["R"] * OMEGA / C_R
    out = mp_sliding(p, 0.1, wr * (1 - 1e-9), 0.0, OMEGA, 0, 0.0, 1e-3)
    roll = mp_rolling_normal_force(p, 0.1, 0.0, OMEGA, 0, 0.0, 1e-3)
    assert err(out["N_end"], roll["N"], roll["N"]) < 1e-8
    assert err(out["dtheta"], wr * (1 - 1e-9), abs(wr)) < 1e-38


def test_sliding_matches_scipy_dop853() -> None:
    """Generic sliding (chapter set, AMB on, levitated gravity, imbalance, friction)
    against an independent float64 DOP853 integration at rtol 1e-13."""
    p = CHAPTER
    m, c, k, e_c, phi, c_r, mu = (p[key] for key in ("m", "c", "k", "e_c", "phi", "c_r", "mu"))
    psi0, th0, w0, T = 0.3, 1.0, 150.0, 0.02

    def rhs(t: float, y: np.ndarray) -> list[float]:
        e = np.exp(1j * y[0])
        F = (
            -c * 1j * c_r * y[1] * e
            - k * c_r * e
            + m * e_c * OMEGA**2 * np.exp(1j * (psi0 + OMEGA * t + phi))
        )
        G = F / e
        N = G.real + m * c_r * y[1] ** 2
        return [y[1], (G.imag - mu * N) / (m * c_r)]  # s = +1 (R Ω dominates)

    out = mp_sliding(p, th0, w0, psi0, OMEGA, 0, 1.0, T)
    sol = solve_ivp(rhs, (0, T), [th0, w0], method="DOP853", rtol=1e-13, atol=[1e-14, 1e-11])
    assert out["event"] == "t_end"
    assert abs(float(out["theta"]) - sol.y[0, -1]) < 1e-10
    assert abs(float(out["dtheta"]) - sol.y[1, -1]) < 1e-10 * OMEGA


def test_sliding_precision_converged() -> None:
    """dps = 40 and dps = 55 agree to ~40 digits on a generic sliding case."""
    args = (CHAPTER, 0.5, 184.2, 0.3, OMEGA, 10.0 - 5.0j, 1.0, 0.01)
    lo = mp_sliding(*args, dps=40)
    hi = mp_sliding(*args, dps=55)
    assert err(lo["theta"], hi["theta"], 1.0) < 1e-38
    assert err(lo["dtheta"], hi["dtheta"], OMEGA) < 1e-38
