"""Sustained contact: chattering into rub, dry whirl into rolling, lift-off, low-speed rule."""

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
    RubEquilibrium,
    TouchdownCore,
    WallForces,
    forward_rub_equilibria,
    work_cap,
)
from rotortd.segments import gbs
from rotortd.segments.rub import LinearRub, QuadraticRub, _monomial_integrals
from rotortd.segments.sliding import Sliding
from rotortd.step.contact_step import closed_form_rub

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
    core = TouchdownCore.from_scaled(p, W0, U0=0j, dU0=0j)
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


def test_dry_whirl_from_rest_rolls_with_closed_form_normal_force() -> None:
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
    n0 = cmath.exp(1j * th0)
    core = TouchdownCore(p, z0=p.c_r * n0, v0=1j * p.c_r * w0 * n0)
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
    core = TouchdownCore(p, z0=p.c_r, v0=1j * p.c_r * 100.0)  # on the wall, whirling at 100 rad/s
    core.step(1e-4, W0)
    assert core.mode == MODE_SLIDING
    w_before = core.kinematics(W0).whirl_rate
    rep = core.step(1e-5, -W0)  # slip reverses: friction now accelerates the whirl
    w_after = core.kinematics(-W0).whirl_rate
    assert rep.E_diss >= 0.0
    assert abs(w_after - w_before) <= p.mu * (w_before**2) * 1e-5 * 1.01
    assert w_after > w_before


@pytest.mark.parametrize("q0, mu, slip", [(0j, 0.1, 1.0), (3.0e4 - 2.0e5j, 0.3, -1.0),
                                          (-5.0e5j, 0.0, 1.0)])
def test_fused_sliding_sweep_is_the_generic_midpoint_rule(q0: complex, mu: float,
                                                          slip: float) -> None:
    """Sliding.midpoint_sweep is a fused copy of gbs.midpoint on Sliding.rhs: bit-identical, so the
    sliding integrator is the documented modified-midpoint extrapolation, only faster."""
    wf = WallForces(q0=q0, eu=2.1e5 * cmath.exp(0.7j), beta=36.8, kappa=3.4e4,
                    Omega=W0, wr=1.2e3, mu=mu)
    sl = Sliding(wf, theta0=0.83, dtheta0=171.0, E0=cmath.exp(2.2j), slip=slip)
    y0 = [0.83, 171.0, 0.4, -0.1, 0.2, 3.0, 0.5, -0.25]  # (theta, theta', I_n, J, I_e, Z)
    for nu in (0.0, 171.0, -30.0):  # the plain quadrature of the force, and by parts
        sl.nu = nu
        f0 = sl.rhs(0.37, y0)
        for n in gbs.SEQUENCE:
            for H in (1e-6, 3e-4, 2e-3):
                fused = sl.midpoint_sweep(0.37, y0, f0, H, n)
                assert fused == gbs.midpoint(sl.rhs, 0.37, y0, f0, H, n)


def test_extrapolation_error_ratio_is_nan_when_any_component_is() -> None:
    """A NaN in any controlled component rejects the step (err <= 1 is then False)."""
    assert gbs._error_ratio([1.0, math.nan], [1.0, 2.0], [1.0, 1.0]) != 0.0
    assert not gbs._error_ratio([math.nan, 1.0], [1.0, 1.5], [1.0, 1.0]) <= 1.0
    assert not gbs._error_ratio([1.0, math.nan], [1.0, 1.5], [1.0, 1.0]) <= 1.0
    assert gbs._error_ratio([1.0, 2.0, math.nan], [1.5, 2.0, 0.0], [1.0, 1.0]) == 0.5


class _IntegratingCore(TouchdownCore):
    """A core that takes no rub in closed form (nor the lock): it integrates the sliding."""

    RUB_CLOSED_FORM = False


def _integrating_twin(core: TouchdownCore) -> TouchdownCore:
    """A copy of core that integrates the sliding near and on the rub."""
    twin = _IntegratingCore(core.params)
    twin.set_state(core.get_state())
    return twin


@pytest.mark.parametrize("t_start, locked", [(0.3, False), (0.45, False), (400.0 / W0, True)])
def test_closed_form_rub_steps_agree_with_integrating_the_sliding(t_start: float,
                                                                  locked: bool) -> None:
    """Near the forward rub (0.3 s from rest: within the second-order budget; 0.45 s:
    within the linearisation's) and on it (locked: a rigid rotation), a step is one
    closed-form evaluation (work 1).
    Integrating the same steps by extrapolation instead gives the same state and step
    outputs to the sliding integrator's tolerance."""
    core = TouchdownCore.from_scaled(_gamma(0.3), W0, U0=0j, dU0=0j)
    _run(core, t_start, 1e-3)
    twin = _integrating_twin(core)
    for _ in range(200):
        a, b = core.step(1e-3, W0), twin.step(1e-3, W0)
        assert a.work == 1 and b.work > 1
        for fa, fb in ((a.F_n, b.F_n), (a.T_f, b.T_f), (a.E_diss, b.E_diss)):
            assert abs(fa - fb) <= 1e-13 * abs(fb)
        assert abs(a.F_contact - b.F_contact) <= 1e-13 * abs(b.F_contact)
        assert abs(core.z - twin.z) <= 1e-13 * core.params.c_r
        assert abs(core.v - twin.v) <= 1e-13 * abs(twin.v)
    assert core.state.locked == locked


def test_linearised_rub_is_refused_outside_its_error_budget() -> None:
    """LinearRub.near admits the state at 0.45 s from rest but not the one at 0.3 s
    (deviation ~2e-6, beyond LINEAR_TOL and its error budget), which QuadraticRub.near
    admits; at 0.2 s (deviation ~3e-4) both refuse. Neither admits a saddle or the wrong
    slip sign."""
    core = TouchdownCore.from_scaled(_gamma(0.3), W0, U0=0j, dU0=0j)

    def closed_form() -> object:
        st, wf = core.state, core.wall_forces
        return closed_form_rub(wf, forward_rub_equilibria(wf), st.theta, st.dtheta,
                               cmath.exp(1j * st.psi), st.slip)

    _run(core, 0.2, 1e-3)
    assert closed_form() is None
    _run(core, 0.3, 1e-3)
    st, E = core.state, cmath.exp(1j * core.state.psi)
    stable = next(e for e in forward_rub_equilibria(core.wall_forces) if e.stable)
    assert LinearRub.near(core.wall_forces, stable, st.theta, st.dtheta, E, st.slip) is None
    assert isinstance(closed_form(), QuadraticRub)
    _run(core, 0.45, 1e-3)
    st, E = core.state, cmath.exp(1j * core.state.psi)
    assert closed_form() is not None
    wf = core.wall_forces
    stable, saddle = sorted(forward_rub_equilibria(wf), key=lambda e: not e.stable)
    assert LinearRub.near(wf, saddle, st.theta, st.dtheta, E, st.slip) is None
    assert LinearRub.near(wf, stable, st.theta, st.dtheta, E, -st.slip) is None
    for eq, slip in ((saddle, st.slip), (stable, -st.slip)):
        assert QuadraticRub.near(wf, eq, st.theta, st.dtheta, E, slip) is None


def _sliding_impulse_case(case: str) -> tuple[TouchdownCore, complex, float]:
    """(core sliding on the wall, F_ext in N, amb_on): on the approach to the forward rub
    (chattering scene, 0.2 s, 0.4 s and 0.45 s from rest: integrated, then linearised),
    or with the bearings off, pressed by gravity and a constant force (q0 != 0)."""
    if case == "gravity":
        p = BASE.replace(mu=0.3, g=9.81)
        th0, w0 = 0.5, 300.0
        e = cmath.exp(1j * th0)
        return TouchdownCore(p, z0=p.c_r * e, v0=1j * p.c_r * w0 * e), 200.0 + 100.0j, 0.0
    core = TouchdownCore.from_scaled(_gamma(0.3), W0, U0=0j, dU0=0j)
    t_start = {"approach": 0.2, "near_rub": 0.4, "linearised": 0.45}[case]
    while core.t < t_start - 1e-9:
        core.step(1e-3, W0)
    assert core.mode == MODE_SLIDING
    return core, 0j, 1.0


@pytest.mark.parametrize("case", ["approach", "near_rub", "linearised", "gravity"])
@pytest.mark.parametrize("h", [1e-3, 1e-4])
def test_sliding_impulses_match_high_precision(case: str, h: float) -> None:
    """The step outputs F_contact and F_n, summed over 10 ms of sliding, against the
    contact impulses of the Taylor-series reference (mp_sliding, 30 digits). Before the
    quadratures were error-controlled this was off by 2.5e-8 near the rub at h = 1e-3."""
    core, F, amb = _sliding_impulse_case(case)
    k = core.kinematics(W0)
    th0, w0, psi0 = cmath.phase(core.z), k.whirl_rate, k.psi_wrapped
    I_c, I_n, T = 0j, 0.0, 0.01
    for _ in range(round(T / h)):
        rep = core.step(h, W0, F, amb)
        assert rep.status == 0 and core.mode == MODE_SLIDING
        I_c += rep.F_contact * h
        I_n += rep.F_n * h
    ref = mp_sliding(_par(core.params), th0, w0, psi0, W0, F, amb, T, dps=30)
    assert ref["event"] == "t_end"
    assert abs(I_c - complex(ref["I_c"])) <= 1e-13 * abs(complex(ref["I_c"]))
    assert abs(I_n - float(ref["I_n"])) <= 1e-13 * float(ref["I_n"])


@pytest.mark.parametrize("a1, b1", [(9.0e3, 110.5), (3052.5625, 110.5), (900.0, 110.5),
                                    (9.0e3, 1e-3)])
def test_linearised_rub_flow_and_integrals_against_quadrature(a1: float, b1: float) -> None:
    """LinearRub's closed forms (propagator and the deviation's part of the contact
    integrals) against scipy: x'' + b1 x' + a1 x = 0 integrated by DOP853, its integrands
    by quad. Under-, critically (a1 = b1^2/4 exactly), over- and barely damped."""
    from scipy.integrate import quad, solve_ivp

    W, wr, mus, Gn, gx, th0 = W0, 1.2e3, 0.15, 2.0e4, 1.9e5, 0.7
    wf = WallForces(q0=0j, eu=2.1e5 + 0j, beta=36.8, kappa=3.4e4, Omega=W, wr=wr, mu=mus)
    eq = RubEquilibrium(0.3, Gn, True, (0j, 0j), a1, b1, gx)
    x0, y0, h = 3e-3, -0.4, 2e-3  # (the closed forms are linear: the size is immaterial)
    lin = LinearRub(wf, eq, th0, x0, y0, mus, 1.0, 1.0, gx)
    sol = solve_ivp(lambda _t, u: [u[1], -a1 * u[0] - b1 * u[1]], (0.0, h), [x0, y0],
                    method="DOP853", rtol=1e-13, atol=1e-18, dense_output=True)
    for u in (0.3 * h, h):
        x, y = lin.flow(u)
        xr, yr = sol.sol(u)
        assert abs(x - xr) <= 1e-11 * abs(x0) and abs(y - yr) <= 1e-11 * abs(y0)
    end = lin.run(h)
    x1, y1 = sol.sol(h)
    assert end.dtheta == pytest.approx(W + y1, abs=1e-11 * abs(y0))
    assert end.theta == pytest.approx(th0 + W * h + (x1 - x0), abs=1e-11 * abs(x0))

    def quad_parts(f: object) -> complex:
        def part(k: int) -> float:
            return quad(lambda u: complex(f(u)).real if k == 0 else complex(f(u)).imag,  # type: ignore[operator]
                        0.0, h, epsabs=0.0, epsrel=1e-12, limit=200)[0]
        return complex(part(0), part(1))

    def dgn(u: float) -> float:  # the deviation's part of Gn
        x, y = sol.sol(u)
        return gx * x + 2.0 * W * y

    def dfc(u: float) -> complex:  # and of the contact force's integrand
        x, _ = sol.sol(u)
        return -complex(1.0, mus) * (dgn(u) + 1j * Gn * x) * cmath.exp(1j * (th0 - x0 + W * u))

    rotation = (cmath.exp(1j * W * h) - 1) / (1j * W)
    rigid_c = -complex(1.0, mus) * Gn * cmath.exp(1j * (th0 - x0)) * rotation
    dI_n, dI_c = quad_parts(dgn).real, quad_parts(dfc)
    assert end.tally.I_n - Gn * h == pytest.approx(dI_n, rel=1e-9)
    assert abs(end.tally.I_c - rigid_c - dI_c) <= 1e-9 * abs(dI_c)
    assert end.tally.I_e == pytest.approx(mus * ((wr + W) * end.tally.I_n + Gn * (x1 - x0)),
                                          rel=1e-12)


@pytest.mark.parametrize("a1, b1, u", [(100.0, 200.0, 10.0), (100.0, 200.0, 1e3),
                                       (9.0e3, 110.5, 10.0), (3052.5625, 110.5, 10.0),
                                       (100.0, 200.0, 5e-3)])
def test_linearised_rub_flow_over_long_steps(a1: float, b1: float, u: float) -> None:
    """The propagator over steps of many decay times (where cosh(q u) alone overflows in
    the overdamped case, q u up to 1e5) against scipy's expm, and the step's integrals
    stay finite."""
    from scipy.linalg import expm

    wf = WallForces(q0=0j, eu=2.1e5 + 0j, beta=36.8, kappa=3.4e4, Omega=W0, wr=1.2e3, mu=0.15)
    eq = RubEquilibrium(0.3, 2.0e4, True, (0j, 0j), a1, b1, 1.9e5)
    x0, y0 = 3e-9, -4e-7
    lin = LinearRub(wf, eq, 0.7, x0, y0, 0.15, 1.0, 1.0, 1.9e5)
    ref = expm([[0.0, u], [-a1 * u, -b1 * u]]) @ [x0, y0]
    x, y = lin.flow(u)
    scale = abs(ref[0]) + abs(ref[1]) / math.sqrt(a1)
    assert abs(x - ref[0]) + abs(y - ref[1]) / math.sqrt(a1) <= 1e-10 * scale + 1e-300
    end = lin.run(u)
    assert all(math.isfinite(v) for v in (end.theta, end.dtheta, end.tally.I_n,
                                          end.tally.I_c.real, end.tally.I_c.imag,
                                          end.tally.I_e))


def test_long_step_hands_the_rub_approach_to_the_closed_form() -> None:
    """Chattering into rub (gamma = 0.3, from rest) in one 1 s step costs about what 1000
    steps of 1 ms cost, and ends in the same state: a sliding segment is integrated for at
    most RUB_RETRY/w before the linearised rub and the lock are tried again. (Before, the
    long step integrated all of its sliding: 16,888 work units against 9,701.)"""
    from rotortd_tools.cycles import OMEGA, chapter_params, si_params

    p = si_params(chapter_params(gamma=0.3))
    one = TouchdownCore(p, z0=0j, v0=0j)
    work_one = one.step(1.0, OMEGA).work
    many = TouchdownCore(p, z0=0j, v0=0j)
    work_many = sum(many.step(1e-3, OMEGA).work for _ in range(1000))
    assert one.mode == many.mode == MODE_SLIDING
    assert work_one <= 1.1 * work_many, (work_one, work_many)
    assert abs(one.z - many.z) <= 1e-12 * p.c_r
    assert one.step(1.0, OMEGA).work == 1  # on the rub: one closed-form segment


@pytest.mark.parametrize("a1, b1", [(8013.6, 110.5), (50.0, 2e-3), (1e4, 200.0), (1e4, 400.0),
                                    (1e4, 900.0), (1e4, 45000.0**0.5)])
def test_quadratic_rub_algebra(a1: float, b1: float) -> None:
    """QuadraticRub's particular solution x2 = p.Q, y2 = r.Q of x2'' + b1 x2' + a1 x2 =
    c1 x1^2 + c3 y1^2 (under-, barely, critically and over-damped rub modes) satisfies
    r = p M and r M = -a1 p - b1 r + c, and _monomial_integrals solves (M + iW) K = d.
    At the resonance 9 a1 = 2 b1^2 (one eigenvalue twice the other) it is refused."""
    from rotortd.segments.rub import RubEquilibrium

    eig = tuple(cmath.sqrt(b1 * b1 / 4 - a1) * sg - b1 / 2 for sg in (1, -1))
    eq = RubEquilibrium(0.3, 5e4, True, eig, a1, b1, 2.3e3)
    wf = WallForces(q0=0j, eu=6e4 * cmath.exp(0.4j), beta=b1 / 2, kappa=1e4, Omega=W0,
                    wr=1.2e3, mu=0.3)
    dev = (3e-7, -2e-6, W0, 4e-7, 2e-6, 1e-15, 1e-13)
    q = QuadraticRub.admit(wf, eq, 0.7, W0 - 2e-6, 1.0, dev)
    if abs(9 * a1 - 2 * b1 * b1) <= 1e-6 * (9 * a1 + 2 * b1 * b1):
        assert q is None
        return
    assert q is not None
    p1, p2, p3, r1, r2, r3 = q.pr
    M = [[0.0, 2.0, 0.0], [-a1, -b1, 1.0], [0.0, -2.0 * a1, -2.0 * b1]]
    c = (-0.5 * q.k2, 0.0, -q.mus)

    def times_m(v: tuple) -> list:
        return [sum(v[i] * M[i][j] for i in range(3)) for j in range(3)]

    scale = max(map(abs, q.pr)) * (a1 + b1 * b1)
    for got, want in zip(times_m((p1, p2, p3)), (r1, r2, r3)):
        assert abs(got - want) <= 1e-13 * scale
    for j, got in enumerate(times_m((r1, r2, r3))):
        want = -a1 * q.pr[j] - b1 * q.pr[3 + j] + c[j]
        assert abs(got - want) <= 1e-12 * scale
    d = [0.3 - 1j, 2.0 + 0.5j, -1.5 + 0.2j]
    for W in (0.0, W0, -W0):
        K = _monomial_integrals(a1, b1, W, d)
        for i in range(3):
            res = sum(M[i][j] * K[j] for j in range(3)) + 1j * W * K[i] - d[i]
            assert abs(res) <= 1e-12 * max(abs(x) for x in d)
