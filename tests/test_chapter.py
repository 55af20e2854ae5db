"""Chapter reproduction (docs/validation.md §4): BEB, forward rub, period-one impacting cycles.

Everything is computed and checked for properties; nothing is pasted from a run.
Scaled co-rotating units (positions c_r, velocities c_r Omega, times 1/Omega).
"""

from __future__ import annotations

import cmath
import itertools
import math

import numpy as np
import pytest
import scipy.optimize
from rotortd_tools import cycles as C


def _Ustar_abs(g: float) -> float:
    return abs(C.regular_equilibrium(C.chapter_params(gamma=g)))


def test_gamma_beb_formula_matches_root_of_unit_Ustar() -> None:
    sp = C.chapter_params()
    g_root = scipy.optimize.brentq(lambda g: _Ustar_abs(g) - 1.0, 0.01, 0.3, xtol=1e-15)
    assert C.gamma_beb(sp) == pytest.approx(g_root, abs=1e-13)
    assert _Ustar_abs(g_root - 1e-3) > 1.0 > _Ustar_abs(g_root + 1e-3)  # admissible above


def test_forward_rub_saddle_born_at_beb_with_vanishing_normal_force() -> None:
    g_beb = C.gamma_beb(C.chapter_params())
    below = C.rub_equilibria(C.chapter_params(gamma=g_beb - 1e-6))
    assert [e.stable for e in below] == [True]  # only the stable rub below the BEB
    Ns = []
    for eps in (1e-4, 1e-6, 1e-8):
        sp = C.chapter_params(gamma=g_beb + eps)
        eqs = C.rub_equilibria(sp)
        assert sorted(e.stable for e in eqs) == [False, True]
        saddle = next(e for e in eqs if not e.stable)
        Ns.append(saddle.N)
        # the saddle sits where U* touches the circle
        Us = C.regular_equilibrium(sp)
        assert abs(cmath.exp(1j * saddle.alpha) - Us) < 10 * math.sqrt(eps)
        # core function and independent scaled derivation agree
        for a, b in zip(eqs, C.rub_equilibria_scaled(sp)):
            assert a.stable == b.stable
            assert a.alpha == pytest.approx(b.alpha, abs=1e-12)
            assert pytest.approx(b.N, abs=1e-12) == a.N
    assert Ns[0] > Ns[1] > Ns[2] > 0.0
    assert Ns[1] / Ns[0] == pytest.approx(1e-2, rel=1e-2)  # N ~ (gamma - gamma_BEB)
    # the two rub branches end in a smooth fold
    g_fold = C.rub_fold_gamma(C.chapter_params())
    assert len(C.rub_equilibria(C.chapter_params(gamma=g_fold - 1e-6))) == 2
    assert C.rub_equilibria(C.chapter_params(gamma=g_fold + 1e-6)) == []


CASES = [(0.1, "long-large"), (0.1, "long-small"), (0.065, "long-large")]


@pytest.fixture(scope="module", params=CASES, ids=lambda c: f"{c[0]}-{c[1]}")
def cycle(request) -> C.Cycle:
    g, br = request.param
    return C.find_period_one_cycle(g, branch=br)


def test_cycle_is_fixed_point_of_core_map(cycle: C.Cycle) -> None:
    assert cycle.residual < 1e-10
    P = C.ImpactMap(cycle.sp)
    F, fl = C.map_residual(P, cycle.x)
    assert np.max(np.abs(F)) < 1e-10
    assert fl.kind == "impact" and not fl.stick
    assert cycle.grazing_margin > 0.0  # admissible: no earlier contact in flight


def test_cycle_matches_closed_form(cycle: C.Cycle) -> None:
    """Independent: the period condition Re H(T) = -d and |1 - rdot G| = |U*| (no events)."""
    ref = C.labelled_cycles(cycle.sp)[cycle.branch]
    assert pytest.approx(ref.T, abs=1e-10) == cycle.T
    assert abs(cycle.U0 - ref.U0) < 1e-10
    assert abs(cycle.dU0 - ref.dU0) < 1e-10


def test_core_run_returns_to_same_impact(cycle: C.Cycle) -> None:
    for core in (cycle.core(), cycle.core_from_scaled()):
        rep = core.step(1.5 * cycle.T_si, C.OMEGA)
        imp = rep.impacts[0]
        E = cmath.exp(1j * C.OMEGA * imp.t)
        U = imp.z / (C.C_R * E)
        dU = (imp.v_plus - 1j * C.OMEGA * imp.z) / (C.C_R * C.OMEGA * E)
        assert abs(imp.t * C.OMEGA - cycle.T) < 1e-9
        assert abs(U - cycle.U0) < 1e-9
        assert abs(dU - cycle.dU0) < 1e-9
        assert len(rep.impacts) in (1, 2)


def test_multipliers_match_finite_differences_of_core(cycle: C.Cycle) -> None:
    Jfd = C.ImpactMap(cycle.sp).jacobian_fd(cycle.x, eps=1e-7)
    assert np.max(np.abs(Jfd - cycle.jacobian)) < 1e-6 * max(1.0, np.max(np.abs(Jfd)))
    lam_fd = np.sort_complex(np.linalg.eigvals(Jfd))
    assert np.max(np.abs(lam_fd - np.sort_complex(cycle.multipliers))) < 1e-5


def test_stability_by_iterating_the_map() -> None:
    """The stable cycle attracts a perturbed start; an unstable one repels it."""
    for br, expect in (("long-large", True), ("long-small", False)):
        c = C.find_period_one_cycle(0.1, branch=br)
        assert c.stable is expect
        P = C.ImpactMap(c.sp)
        x = c.x + np.array([1e-6, -1e-6, 1e-6])
        for _ in range(40):
            x = P(x)
        d = np.abs(x - c.x)
        d[0] = abs(math.remainder(x[0] - c.x[0], 2 * math.pi))
        assert bool(np.max(d) < 1e-7) is expect


def test_cycle_against_mpmath_reference() -> None:
    """One period of the gamma = 0.065 cycle by the independent mpmath reference."""
    ref = pytest.importorskip("tests.reference.mp_reference")
    c = C.find_period_one_cycle(0.065, branch="long-large")
    p = c.params
    par = {f: getattr(p, f) for f in ("m", "c", "k", "e_c", "phi", "c_r", "R", "mu", "d", "g")}
    par["levitate"] = p.levitate
    res = ref.mp_impact_sequence(
        par, c.z0, c.v0, 0.0, C.OMEGA, 0j, 1.0, 1.5 * c.T_si, max_impacts=1, dps=30
    )
    imp = res["impacts"][0]
    t = float(imp["t"])
    z = complex(imp["z"])
    vp = complex(imp["v_plus"])
    E = cmath.exp(1j * C.OMEGA * t)
    U = z / (C.C_R * E)
    dU = (vp - 1j * C.OMEGA * z) / (C.C_R * C.OMEGA * E)
    assert abs(t * C.OMEGA - c.T) < 1e-9
    assert abs(U - c.U0) < 1e-9
    assert abs(dU - c.dU0) < 1e-9


@pytest.mark.slow
def test_continuation_events() -> None:
    pts = C.continue_cycles(np.linspace(0.05, 0.3, 51))
    ev = {}
    for p in pts:
        if p.event:
            ev.setdefault((p.branch, p.event), []).append(p)
    g_beb = C.gamma_beb(C.chapter_params())
    # both ends of the small branch are born at the BEB with rdot -> 0
    births = ev[("small", "beb_birth")]
    assert len(births) == 2
    for b in births:
        assert b.gamma == pytest.approx(g_beb, abs=1e-6)
    # one fold per branch, at the same gamma (the period condition ignores the amplitude)
    (fl,), (fs,) = ev[("large", "fold")], ev[("small", "fold")]
    assert fl.gamma == pytest.approx(fs.gamma, abs=1e-9)
    large = [p for p in pts if p.branch == "large" and p.event is None]
    assert max(p.gamma for p in large) == pytest.approx(fl.gamma, abs=1e-3)
    # period doubling: a real multiplier at -1
    (pd,) = ev[("large", "period_doubling")]
    assert min(abs(m + 1.0) for m in pd.multipliers) < 1e-6
    # grazing: the max radius in flight reaches 1 there
    (gr,) = ev[("large", "grazing")]
    sp = C.chapter_params(gamma=gr.gamma)
    cyc = C.labelled_cycles(sp)["long-large"]
    assert C.max_radius_in_flight(sp, cyc.U0, cyc.dU0, cyc.T) == pytest.approx(1.0, abs=1e-9)
    # stability changes only at the events
    for a, b in itertools.pairwise(large):
        if a.stable != b.stable:
            lo, hi = sorted((a.gamma, b.gamma))
            assert any(lo - 1e-3 <= e.gamma <= hi + 1e-3 for e in (fl, pd))
