"""Sustained contact: chattering into rub, dry whip into rolling, lift-off, low-speed rule."""

from __future__ import annotations

import cmath
import math

import mpmath
import pytest
from rotortd import (
    MODE_FREE,
    MODE_ROLLING,
    MODE_SLIDING,
    RotorParams,
    TouchdownCore,
    WallForces,
    forward_rub_equilibria,
    work_cap,
)

from tests.reference.direct import direct_simulate
from tests.reference.mp_reference import (
    mp_impact_sequence,
    mp_rolling_normal_force,
    mp_sliding,
)

EPS = 2.220446049250313e-16
W0 = 184.2
BASE = RotorParams()


def _par(p: RotorParams) -> dict:
    return {f: getattr(p, f) for f in p.__dataclass_fields__}


def _gamma(gamma: float, **kw: float) -> RotorParams:
    return BASE.replace(c=gamma * BASE.m * W0, **kw)


def _run(core: TouchdownCore, t_end: float, h: float, W: float = W0) -> list:
    reps = []
    while core.t < t_end - 0.5 * h:
        rep = core.step(h, W)
        assert rep.status == 0, rep.message
        assert abs(core.z) <= core.params.c_r * (1 + 1e-12)
        assert rep.work <= work_cap(core.params, h, W, 0j, 1.0)
        reps.append(rep)
    return reps


def _alpha_from_equilibrium(gamma: float) -> float:
    """alpha* of the stable forward rub, from (3) with theta' = Omega, solved in mpmath."""
    mpmath.mp.dps = 30
    p = _gamma(gamma)
    sp = p.scaled(W0)
    # scaled: rho (sin x - mu cos x) = gamma + mu (1 - omega^2), x = phi - alpha, and
    # stability needs rho (cos x + mu sin x) > 0
    def f(x: mpmath.mpf) -> mpmath.mpf:
        lhs = sp.rho * (mpmath.sin(x) - sp.mu * mpmath.cos(x))
        return lhs - sp.gamma - sp.mu * (1 - sp.omega**2)

    for x0 in (0.5, 1.0, 1.5, 2.0, 2.5):
        x = mpmath.findroot(f, x0)
        if sp.rho * (mpmath.cos(x) + sp.mu * mpmath.sin(x)) > 0:
            return float(mpmath.mpf(sp.phi) - x)
    raise AssertionError("no stable forward rub")


def test_forward_rub_equilibria_match_independent_solution() -> None:
    eqs = forward_rub_equilibria(WallForces.build(_gamma(0.3), W0, 0j, 1.0))
    stable = [e for e in eqs if e.stable]
    assert len(eqs) == 2 and len(stable) == 1
    a_ref = _alpha_from_equilibrium(0.3)
    assert abs(cmath.phase(cmath.exp(1j * (stable[0].alpha - a_ref)))) <= 1e-14


def test_chattering_from_rest_ends_on_the_forward_rub() -> None:
    p = _gamma(0.3)
    core = TouchdownCore.from_scaled(p, W0, 0j, 0j)
    reps = _run(core, 400.0 / W0, 1e-3)
    assert core.mode == MODE_SLIDING
    k = core.kinematics(W0)
    alpha = cmath.phase(complex(k.u_re, k.u_im))
    a_star = _alpha_from_equilibrium(0.3)
    assert abs(cmath.phase(cmath.exp(1j * (alpha - a_star)))) <= 1e-9
    assert abs(k.whirl_rate / W0 - 1.0) <= 1e-9  # alpha' = theta'/Omega - 1, scaled
    assert k.r_rel == pytest.approx(1.0, abs=1e-14)
    # on the fixed point the core stops integrating: one closed-form rotation per step
    assert max(r.work for r in reps[-100:]) <= 2
    assert reps[-1].F_n > 0 and reps[-1].T_f < 0  # rubbing brakes the spin


def _accumulation_estimate(p: RotorParams, v_zeno: float) -> float:
    """Independent estimate: impacts stepped one by one (scipy DOP853) down to v_zeno, plus
    the remaining geometric series 2 d v/((1-d) A) with A the outward acceleration."""
    r = direct_simulate(_par(p), 0j, 0j, 0.0, 0.0, [(0.3, W0, 0j, 1.0)], v_zeno=v_zeno)
    last = next(i for i in r.impacts if i.get("plastic"))
    z, t = last["z"], last["t"]
    n = z / abs(z)
    vt = (n.conjugate() * last["v_plus"]).imag
    F = -p.c * 1j * vt * n - p.k * z + p.m * p.e_c * W0**2 * cmath.exp(1j * (W0 * t + p.phi))
    A = (n.conjugate() * F).real / p.m + vt * vt / p.c_r
    return t + 2 * p.d * last["rdot"] / ((1 - p.d) * A)


def test_contact_entry_time_agrees_with_impact_by_impact_estimate() -> None:
    p = _gamma(0.3)
    core = TouchdownCore(p)
    _run(core, 0.3, 1e-3)
    t_core = core.t_contact_entry
    diffs = [abs(_accumulation_estimate(p, v * p.c_r * W0) - t_core) * W0 for v in (1e-3, 1e-4)]
    # the estimate converges like the square of its threshold ...
    assert diffs[1] <= diffs[0] / 20
    # ... down to the conditioning floor of a low-speed impact time, eps c_r / rdot per
    # impact amplified by 2d/(1-d) in the remainder: 2d eps/((1-d) v) at v ~ 1e-7 c_r Omega
    floor = 2 * p.d * EPS / ((1 - p.d) * 1e-7)
    assert diffs[1] <= 3 * floor + 1e-7


def test_dry_whip_from_rest_rolls_with_closed_form_normal_force() -> None:
    p = _gamma(0.065)
    core = TouchdownCore(p)
    reps = _run(core, 1.0, 1e-3)  # whips at about 0.66 s (scaled time 121)
    assert core.mode == MODE_ROLLING
    k = core.kinematics(W0)
    assert k.whirl_rate == pytest.approx(-p.R * W0 / p.c_r, rel=4 * EPS)
    assert abs(k.v_rel) <= 8 * EPS * p.R * W0
    # step-averaged normal force vs the closed form of rolling, integrated in mpmath
    t1 = core.t
    theta1 = cmath.phase(core.z)
    rep = core.step(1e-3, W0)
    mpmath.mp.dps = 30

    def N(t: float) -> mpmath.mpf:
        return mp_rolling_normal_force(
            _par(p), theta1, core.psi - W0 * 1e-3, W0, 0j, 1.0, t, dps=30
        )["N"]

    N_avg = mpmath.quad(N, [0, 2.5e-4, 5e-4, 7.5e-4, 1e-3]) / 1e-3
    assert rep.F_n == pytest.approx(float(N_avg), rel=1e-12)
    assert rep.F_n > 1000 * p.m * p.c_r * W0**2
    assert reps[-1].T_f != 0.0 and t1 > 0


def test_lift_off_time_matches_high_precision_sliding() -> None:
    """Whirling on the wall without spin: friction slows the whirl until N = 0."""
    p = BASE.replace(e_c=0.0, mu=0.3)
    wn = math.sqrt(p.k / p.m)
    th0, w0 = 0.4, 1.6 * wn
    core = TouchdownCore(p, p.c_r * cmath.exp(1j * th0), 1j * p.c_r * w0 * cmath.exp(1j * th0))
    events = []
    while core.mode != MODE_FREE or core.t == 0.0:
        t = core.t
        rep = core.step(1e-4, 0.0)
        assert rep.status == 0
        events.extend(rep.transitions)
        assert core.t > t
    t_lift = next(t for t, kind in events if kind == "lift_off")
    ref = mp_sliding(_par(p), th0, w0, 0.0, 0.0, 0j, 1.0, 0.1, dps=30)
    assert ref["event"] == "lift_off"
    assert abs(t_lift - float(ref["t"])) * wn <= 1e-12


def test_plastic_enters_contact_at_first_pushing_impact() -> None:
    """d = 0: contact starts at the first impact where the free force pushes outward.

    (At an impact where it pulls inward the rotor leaves the wall tangentially.) The index
    of that impact comes from the mpmath impact sequence, which stops with "contact".
    """
    p = _gamma(0.3, d=0.0)
    core = TouchdownCore(p)
    while core.mode == MODE_FREE:
        rep = core.step(1e-3, W0)
        assert rep.status == 0
    assert rep.transitions and rep.transitions[0][0] == core.t_last_impact
    ref = mp_impact_sequence(_par(p), 0j, 0j, 0.0, W0, 0j, 1.0, 0.5, dps=30)
    assert ref["stopped"] == "contact"
    assert core.n_impacts == len(ref["impacts"])
    assert core.t_last_impact == pytest.approx(float(ref["impacts"][-1]["t"]), abs=1e-12)


@pytest.mark.parametrize("d", [1.0, 0.999999])
def test_restitution_near_one_follows_the_low_speed_rule(d: float) -> None:
    p = _gamma(0.3, d=d)
    core = TouchdownCore(p)
    _run(core, 100.0 / W0, 1e-3)
    assert core.n_impacts > 0
    assert math.isfinite(core.E_diss) and core.E_diss >= 0


def test_step_split_independence_with_sustained_contact() -> None:
    p = _gamma(0.3)
    T = 2.0
    finals = []
    for n in (1, 20, 2000):
        core = TouchdownCore(p)
        for _ in range(n):
            assert core.step(T / n, W0).status == 0
        finals.append((core.z, core.v))
    for z, v in finals[1:]:
        assert abs(z - finals[0][0]) <= 1e-10 * p.c_r
        assert abs(v - finals[0][1]) <= 1e-10 * p.c_r * W0


def test_spin_reversal_while_sliding_keeps_the_whirl() -> None:
    """A host that changes Omega between steps changes the slip direction, not the whirl."""
    p = BASE.replace(k=0.0, c=0.0, e_c=0.0, mu=0.01)
    core = TouchdownCore(p, p.c_r, 1j * p.c_r * 100.0)  # on the wall, whirling at 100 rad/s
    core.step(1e-4, W0)
    assert core.mode == MODE_SLIDING
    w_before = core.kinematics(W0).whirl_rate
    rep = core.step(1e-5, -W0)  # slip reverses: friction now accelerates the whirl
    w_after = core.kinematics(-W0).whirl_rate
    assert rep.E_diss >= 0.0
    assert abs(w_after - w_before) <= p.mu * (w_before**2) * 1e-5 * 1.01
    assert w_after > w_before
