"""The core's real touchdown bearing (docs/model.md §10) validated against the independent
reference (tests/reference/real_bearing.py, which shares no code with fmu_src) and the closed
forms of §10: the race catching up under a steady load, the angular momentum balance over a
drop, the compliant law converging to the rigid one, and Black's steady whirls.

Every figure quoted in a docstring was measured on this code (pure Python floats: the same
on every machine of this kind); each tolerance is set from it."""

from __future__ import annotations

import cmath
import itertools
import math
import statistics

import pytest
from rotortd import restore_core
from rotortd.bodies.race import BearingParams
from rotortd.params import RotorParams
from rotortd.step.simulator import TouchdownCore

from tests.reference import real_bearing as rb

W0 = 184.2
N_LOAD = 500.0  # N, the catch-up scene's normal load
N_DIR = -1j  # the load presses the rotor onto the bottom of the race


# ------------------------------------------------------------------ 1. the race catching up


def _catch_up_par() -> rb.Par:
    """The reference's parameters of the catch-up scene (rigid support, e_c = c_bw = g = 0,
    AMB off, the load at the friction angle)."""
    return rb.Par(e_c=0.0, g=0.0, a=0.0, c_bw=0.0, support_compliant=False, p_c=1.0, mu=0.15,
                  J=0.04, J_b=2e-4, T_b0=0.02, d=0.9, levitate=False,
                  F_ext=N_LOAD * complex(1.0, 0.15) * N_DIR)


def _catch_up_core(compliant: bool) -> TouchdownCore:
    """The rotor at rest on the circle at the bottom, spinning at 184.2 rad/s, the race at
    rest; F_ext (held, N) = N_LOAD (1 + i mu) n presses it on."""
    p = RotorParams(e_c=0.0, g=0.0, mu=0.15, d=0.9, levitate=False)
    bp = BearingParams(race_turns=True, J_b=2e-4, T_b0=0.02, c_bw=0.0,
                       contact_compliant=compliant, k_c=1e9)
    return TouchdownCore(p, J=0.04, z0=p.c_r * N_DIR, Omega0=W0, bearing=bp)


def test_race_catches_up_under_the_rigid_law_at_the_closed_form_time() -> None:
    """Rigid law: the rotor sits on the circle (delta = 0 from the first instant), so N is
    the load's normal part exactly and the friction mu N cancels the load's tangential part:
    the centre does not move, Omega and omega_b are linear in time and t*, the common surface
    speed and the static friction after t* are exact (docs/model.md §10 "Closed forms").

    Measured: t* to 1.5e-15 relative (core 0.011881691060712634 s, closed form
    0.011881691060712652 s); R Omega and R_b omega_b at t* (1 + 1e-12) to 4e-16 and 2e-15 of
    the common speed 7.3324 m/s; the centre stays put to 0 m before t*. The static friction
    after t* (-T_f/R over a step of tau wholly after t*) differs from
    ``stick_force_after_catch_up`` (0.66767 N, below mu N = 75 N) by 6.4e-6, 6.4e-8, 6.4e-10,
    6.4e-12 relative at tau = 1e-4 ... 1e-7 s: quadratic in tau (the rotor starts rolling down
    the race), so the force at t*+ agrees to rounding."""
    par = _catch_up_par()
    ts, v_common = rb.catch_up(par, N_LOAD, W0)
    F_t = rb.stick_force_after_catch_up(par, N_LOAD)
    assert 0.0 < F_t < par.mu * N_LOAD
    F = par.F_ext
    core = _catch_up_core(compliant=False)
    rep = core.step(0.999 * ts, None, F, 0.0, T_drive=0.0)
    assert [m for _, m in rep.transitions] == ["sliding"]
    assert core.z == core.params.c_r * N_DIR  # the centre does not move while sliding
    rep = core.step(ts * (1.0 + 1e-12) - core.t, None, F, 0.0, T_drive=0.0)
    ((t_stick, kind),) = rep.transitions
    assert kind == "rolling"
    assert t_stick == pytest.approx(ts, rel=1e-14)
    race = core.race
    assert race is not None
    R, R_b = core.params.R, par.R_b
    assert R * core.Omega == pytest.approx(v_common, rel=1e-14)
    assert R_b * race.omega_b == pytest.approx(v_common, rel=1e-11)  # the 1e-12 overshoot
    rep = core.step(1e-7, None, F, 0.0, T_drive=0.0)
    assert rep.transitions == [] and core.mode == 2  # it sticks: rolls down the race
    assert -rep.T_f / R == pytest.approx(F_t, rel=1e-10)


def test_race_catches_up_under_the_compliant_law_as_the_reference() -> None:
    """Compliant law (k_c = 1e9, p = 1), the rotor starting on the circle: the start is a
    transient, not the closed form's scene. N rises from 0 (the race is held by T_b0 until
    R_b mu N reaches T_b0, for 25.09 us), and while N lags the load the friction lags its
    tangential part, so the centre is set swinging along the race (about 1e-4 rad) and the
    load leaves the friction angle. The closed form's t* is then off by -2.090e-5 relative
    (-2.48e-7 s) on both the core and the reference, which agree on the same scene: t* to
    7.5e-16 s (6.3e-14 relative), z to 7e-14 c_r, Omega to 1.7e-12 rad/s, omega_b to
    3.5e-10 rad/s on a 13-point grid (omega_b: the race's small inertia amplifies)."""
    par = _catch_up_par()
    ts, _ = rb.catch_up(par, N_LOAD, W0)
    T = 1.2 * ts
    grid = [T * i / 12 for i in range(13)]
    ref = rb.Simulator(par).run(rb.state(z=par.c_r * N_DIR, Omega=W0), 0.0, T, grid=grid)
    t_ref = ref.first("stick")
    assert t_ref is not None
    core = _catch_up_core(compliant=True)
    race = core.race
    assert race is not None
    trans, c_r = [], par.c_r
    for i in range(1, 13):
        rep = core.step(T / 12, None, par.F_ext, 0.0, T_drive=0.0)
        trans += rep.transitions
        y = ref.y[i]
        assert abs(core.z - complex(y[0], y[1])) <= 1e-12 * c_r
        assert core.Omega == pytest.approx(y[5], abs=1e-11)
        assert race.omega_b == pytest.approx(y[10], abs=3e-9)
    t_core = next(t for t, m in trans if m == "rolling")
    assert t_core == pytest.approx(t_ref, rel=1e-12)
    assert -2.2e-5 < (t_core - ts) / ts < -2.0e-5  # the start transient, as the reference's


# ------------------------------------------------------------------ 2. angular momentum


def _momentum(core: TouchdownCore) -> tuple[float, list[float]]:
    """L (N m s) about the support's anchor and its four terms (docs/model.md §10):
    m Im(conj(z_G) z_G') + J Omega + m_b Im(conj(z_b) z_b') + J_b omega_b."""
    p, race = core.params, core.race
    assert race is not None
    bp = race.bp
    E = cmath.exp(1j * (core.psi + p.phi))
    zG, vG = core.z + p.e_c * E, core.v + 1j * core.Omega * p.e_c * E
    terms = [p.m * (zG.conjugate() * vG).imag, core.J * core.Omega,
             bp.m_b * (race.z_b.conjugate() * race.v_b).imag if bp.support_compliant else 0.0,
             bp.J_b * race.omega_b if bp.race_turns else 0.0]
    return sum(terms), terms


def _free_drop(compliant: bool) -> TouchdownCore:
    """The drop's start without gravity: the levitated whirl at 184.2 rad/s, AMB off at
    t = 0; a turning, sprung race with c_b = T_b0 = c_bw = 0 (no external torque)."""
    p = RotorParams(g=0.0, d=0.9, mu=0.15)
    Z1 = p.m * p.e_c * W0**2 * cmath.exp(1j * p.phi) / (p.k - p.m * W0**2 + 1j * p.c * W0)
    bp = BearingParams(race_turns=True, support_compliant=True, contact_compliant=compliant,
                       c_b=0.0, T_b0=0.0, c_bw=0.0)
    return TouchdownCore(p, J=0.04, z0=Z1, v0=1j * W0 * Z1, Omega0=W0, bearing=bp)


def test_angular_momentum_is_conserved_under_the_rigid_law() -> None:
    """30 ms of the free drop under the rigid law: 380 impacts, sliding, sticking (rolling on
    the race from 9.1 ms), lift-offs; the race spun from rest by the first friction (with
    T_b0 = 0 its break-away is immediate). L closes to 4.0e-15 of the sum of the magnitudes
    of its terms (largest over the 6 samples)."""
    core = _free_drop(compliant=False)
    L0, terms0 = _momentum(core)
    kinds, n_imp, worst = set(), 0, 0.0
    for i in range(300):
        rep = core.step(1e-4, None, 0j, 0.0, T_drive=0.0)
        assert rep.status == 0
        kinds.update(m for _, m in rep.transitions)
        n_imp += len(rep.impacts)
        if i % 50 == 49:
            L1, terms1 = _momentum(core)
            worst = max(worst, abs(L1 - L0) / sum(abs(x) for x in terms0 + terms1))
    assert kinds == {"sliding", "rolling", "lift_off"} and n_imp > 100
    assert worst <= 1e-13, worst


def test_angular_momentum_balance_with_the_race_drag_and_break_away() -> None:
    """30 ms of the free drop under the rigid law with the race's static friction and drag
    T_b0 = 0.02 N m (c_bw = 0): the race is held at rest until the first impact, whose
    friction impulse breaks it away (a static torque cannot take an impulse); from then the
    frame's only torque on the system is the drag -T_b0 (the race turns forward throughout),
    so L(t) - L0 = -T_b0 (t - t_1). Impacts, sliding, sticking, lift-offs; the balance
    closes to 1.2e-14 of the sum of the magnitudes of its terms (largest over 6 samples;
    rounding over the impacts; the issue's bound is 1e-9)."""
    p = RotorParams(g=0.0, d=0.9, mu=0.15)
    Z1 = p.m * p.e_c * W0**2 * cmath.exp(1j * p.phi) / (p.k - p.m * W0**2 + 1j * p.c * W0)
    T_b0 = 0.02
    bp = BearingParams(race_turns=True, support_compliant=True, contact_compliant=False,
                       c_b=0.0, T_b0=T_b0, c_bw=0.0)
    core = TouchdownCore(p, J=0.04, z0=Z1, v0=1j * W0 * Z1, Omega0=W0, bearing=bp)
    race = core.race
    assert race is not None and race.held
    L0, terms0 = _momentum(core)
    t1, kinds, n_imp, worst = None, set(), 0, 0.0
    for i in range(300):
        rep = core.step(1e-4, None, 0j, 0.0, T_drive=0.0)
        assert rep.status == 0
        kinds.update(m for _, m in rep.transitions)
        n_imp += len(rep.impacts)
        if t1 is None and rep.impacts:
            t1 = rep.impacts[0].t
        assert (t1 is None) == race.held and race.omega_b >= 0.0
        if i % 50 == 49:
            assert t1 is not None
            t = (i + 1) * 1e-4
            L1, terms1 = _momentum(core)
            drag = -T_b0 * (t - t1)
            scale = sum(abs(x) for x in [*terms0, *terms1, drag])
            worst = max(worst, abs(L1 - L0 - drag) / scale)
    assert kinds == {"sliding", "rolling", "lift_off"} and n_imp > 10
    assert worst <= 1e-13, worst


def test_angular_momentum_balance_with_the_contact_couple() -> None:
    """15 ms of the free drop under the compliant law (k_c = 1e9): contacts, sliding,
    sticking, lift-offs. dL/dt = -delta F_t: L changes by -1.5734e-6 N m s. The core reports
    no delta F_t; integrated here by the trapezoidal rule from the core's states (delta at the
    step ends) and its friction impulse per step (P_t = -T_f h/R) it gives -1.5707e-6,
    -1.57330e-6, -1.57339e-6 N m s at h = 1e-5, 2e-6, 1e-6 s: the balance closes to 1.8e-10,
    7.5e-12, 1.9e-12 of the sum of the magnitudes of its terms, falling as h^2 (the
    quadrature's error). Bound without quadrature: |int delta F_t| <= delta_max mu int N with
    delta_max <= N_peak/k_c (N = k_c delta at the deepest point, delta' = 0 there)."""
    core = _free_drop(compliant=True)
    p = core.params
    race = core.race
    assert race is not None
    L0, terms0 = _momentum(core)
    h = 1e-5

    def depth() -> float:
        return max(abs(core.z - race.z_b) - p.c_r, 0.0)

    d0, couple, P_n, peak, kinds = depth(), 0.0, 0.0, 0.0, set()
    for _ in range(1500):
        rep = core.step(h, None, 0j, 0.0, T_drive=0.0)
        assert rep.status == 0
        kinds.update(m for _, m in rep.transitions)
        d1 = depth()
        couple -= 0.5 * (d0 + d1) * (-rep.T_f * h / p.R)
        d0, P_n, peak = d1, P_n + rep.P_n, max(peak, rep.F_n_peak)
    L1, terms1 = _momentum(core)
    scale = sum(abs(x) for x in terms0 + terms1)
    assert kinds == {"sliding", "rolling", "lift_off"}
    assert abs(L1 - L0 - couple) <= 1e-9 * scale, (L1 - L0, couple)
    assert abs(L1 - L0) <= peak / race.bp.k_c * p.mu * P_n
    assert abs(L1 - L0) > 300.0 * abs(L1 - L0 - couple)  # the couple is 99.8 % of the change


# ------------------------------------------------------------------ 3. k_c -> infinity


def _drop_states(**opts: object) -> tuple[dict[float, tuple[complex, float, float]],
                                           list[tuple[float, str]]]:
    """The issue's drop (gravity, all options on unless ``opts``), stepped at 1e-4 s to
    6 ms: the state (z, Omega, omega_b) at 2 ms and 6 ms and the transitions."""
    p = RotorParams(g=9.81, d=0.9, mu=0.15)
    Z1 = p.m * p.e_c * W0**2 * cmath.exp(1j * p.phi) / (p.k - p.m * W0**2 + 1j * p.c * W0)
    bp = BearingParams(**{"race_turns": True, "support_compliant": True,
                          "contact_compliant": True, **opts})
    core = TouchdownCore(p, J=0.04, z0=Z1, v0=1j * W0 * Z1, Omega0=W0, bearing=bp)
    race = core.race
    assert race is not None
    states, trans = {}, []
    for i in range(1, 61):
        rep = core.step(1e-4, None, 0j, 0.0, T_drive=0.0)
        assert rep.status == 0
        trans += rep.transitions
        if i in (20, 60):
            states[i * 1e-4] = (core.z, core.Omega, race.omega_b)
    return states, trans


def test_compliant_law_converges_to_the_rigid_law() -> None:
    """The drop under the compliant law (p = 1) at k_c = 1e9 ... 1e12 N/m against the rigid
    law, state against state at the same time (stepped at 1e-4 s).

    First impact (at 2 ms, after the first contact, which opens at 1.883 ms for 1e9): the
    differences in Omega are 2.438e-3, 5.817e-4, 1.694e-4, 5.222e-5 rad/s, in omega_b 0.4841,
    0.1155, 0.03365, 0.01037 rad/s, in z 1.914e-4, 5.804e-5, 1.829e-5, 5.784e-6 c_r: falling
    4.19, 3.43, 3.24 per decade in Omega and omega_b (the reference's figures, docs/model.md
    §10: 3.2-4.2), 3.30, 3.17, 3.16 in z, the k_c^(-1/2) = 3.16 of the contact time. At
    k_c = 1e8 the first contact does not open before the catch-up (4.765 ms): not yet the
    impact limit (1.66 per decade from 1e8 to 1e9).

    Entry into sustained contact. The two laws differ here in the limit in how, not where,
    the bouncing ends: the rigid law's impact sequence (123 impacts) ends by the low-speed
    rule (docs/model.md §6) in sliding at 3.0847 ms; the compliant law bounces 2, 6, 13, 22
    times (lift-offs before the catch-up at 1e9 ... 1e12), each bounce shorter, and settles
    later. The race then catches up (first sticking) at 4.43799, 4.40805, 4.40772,
    4.40858 ms against the rigid law's 4.40913 ms (1.08e-6, 1.41e-6, 5.5e-7 s off from 1e10 on, not
    monotone). At 6 ms (rolling on the race under both laws) the differences still fall: in
    Omega 1.516e-4, 5.626e-5, 1.848e-5, 6.070e-6 rad/s (2.69, 3.04, 3.04 per decade), in
    omega_b 1.380e-2, 3.268e-3, 1.676e-3, 6.074e-4 rad/s (4.22, 1.95, 2.76), in z 6.632e-3,
    7.300e-4, 1.957e-4, 6.616e-5 c_r (9.08, 3.73, 2.96): no floor down to 6e-6 rad/s, but
    the rate is no longer the clean k_c^(-1/2) of one impact."""
    rig, rig_trans = _drop_states(contact_compliant=False)
    assert rig_trans[0][1] == "sliding" and 3.08e-3 < rig_trans[0][0] < 3.09e-3
    t_rig = next(t for t, m in rig_trans if m == "rolling")
    diffs: dict[float, list[tuple[float, float, float]]] = {2e-3: [], 6e-3: []}
    for kc in (1e9, 1e10, 1e11, 1e12):
        st, trans = _drop_states(k_c=kc)
        t_roll = next(t for t, m in trans if m == "rolling")
        assert abs(t_roll - t_rig) <= (3e-5 if kc == 1e9 else 1.5e-6)
        for T, out in diffs.items():
            (z, W, wb), (z0, W0_, wb0) = st[T], rig[T]
            out.append((abs(W - W0_), abs(wb - wb0), abs(z - z0) / 0.7e-3))
    rates = {T: [tuple(a / b for a, b in zip(x, y, strict=True))
                 for x, y in itertools.pairwise(d)] for T, d in diffs.items()}
    for W_rate, wb_rate, z_rate in rates[2e-3]:
        assert 3.2 <= W_rate <= 4.2 and 3.2 <= wb_rate <= 4.2
        assert 3.15 <= z_rate <= 3.31
    for W_rate, wb_rate, z_rate in rates[6e-3]:
        assert 2.65 <= W_rate <= 3.05 and 1.9 <= wb_rate <= 4.3 and 2.9 <= z_rate <= 9.1


# ------------------------------------------------------------------ 4. Black's problem


def black_par() -> rb.Par:
    """The reference's parameters of Black's problem: the drop's bearing with the race fixed
    in spin, e_c = g = 0, the AMB failed (a = 0), the spin held by J = 1e9 kg m^2."""
    return rb.drop_par(race_turns=False, e_c=0.0, g=0.0, a=0.0, J=1e9)


def core_on_whirl(w: rb.Whirl, Omega: float, eps: float = 1e-3) -> TouchdownCore:
    """A core (J = 1e9 kg m^2, the race fixed in spin, sprung, compliant contact k_c = 1e9,
    p = 1) started on the reference's steady whirl ``w`` at Omega (rad/s), the rotor's
    amplitude A scaled by (1 + eps): the core has no start in contact with a displaced race,
    so its state record is written (the contact closed at the start, chi = c_d/v_floor as
    the reference's) and restored."""
    p = RotorParams(e_c=0.0, g=0.0, mu=0.15, d=0.9, levitate=False)
    bp = BearingParams(support_compliant=True, contact_compliant=True, k_c=1e9, p_c=1.0)
    st = TouchdownCore(p, J=1e9, Omega0=Omega, bearing=bp).get_state()
    A, v, vb = w.A * (1.0 + eps), 1j * w.nu * w.A, 1j * w.nu * w.B
    st["rotor"]["z"], st["rotor"]["v"] = [A.real, A.imag], [v.real, v.imag]
    b = st["bearing"]
    b["x_b"], b["y_b"], b["vx_b"], b["vy_b"] = w.B.real, w.B.imag, vb.real, vb.imag
    s = 0.0 if w.kind == "rolling" else math.copysign(1.0, w.vrel)  # 0: sticking
    b["contact"] = {"s": s, "clamped": False, "chi": rb.c_d(p.d) / rb.V_FLOOR,
                    "race_held": False, "s_b": 1.0}
    st["contact"]["mode"], st["contact"]["slip"] = (2 if w.kind == "rolling" else 1), s
    return restore_core(st)


def whirl_rate_run(core: TouchdownCore, T: float, T_mean: float, h: float = 1e-4
                   ) -> tuple[float, list[tuple[float, str]]]:
    """Step ``core`` (AMB off, no load) for T seconds; the mean of the whirl_rate output
    (rad/s) over the last T_mean seconds (sampled at the step ends) and the transitions."""
    rates, trans, n = [], [], round(T / h)
    for i in range(n):
        rep = core.step(h, None, 0j, 0.0)
        assert rep.status == 0
        trans += rep.transitions
        if i >= n - round(T_mean / h):
            rates.append(core.outputs().whirl_rate)
    return statistics.fmean(rates), trans


@pytest.fixture(scope="module")
def black_184() -> dict[str, rb.Whirl]:
    """The existing whirls at Omega = 184.2 rad/s: the dry whirl and the two dry whips."""
    ws = [w for w in rb.black_whirls(black_par(), W0) if w.exists]
    rolling = [w for w in ws if w.kind == "rolling"]
    whips = sorted((w for w in ws if w.kind == "sliding"), key=lambda w: w.nu)
    assert len(rolling) == 1 and len(whips) == 2
    return {"whirl": rolling[0], "fast_whip": whips[0], "whip": whips[1]}


def test_black_steady_whirls_at_the_model_figures(black_184: dict[str, rb.Whirl]) -> None:
    """The reference's whirls at 184.2 rad/s are docs/model.md §10's: dry whirl -9275.5 rad/s
    (stable), dry whip -883.4 rad/s (stable), dry whip -9197.8 rad/s (unstable)."""
    w = black_184
    assert w["whirl"].nu == pytest.approx(-9275.5, abs=0.05) and w["whirl"].stable
    assert w["whip"].nu == pytest.approx(-883.4, abs=0.05) and w["whip"].stable
    assert w["fast_whip"].nu == pytest.approx(-9197.8, abs=0.05)
    assert not w["fast_whip"].stable


def test_black_dry_whirl_holds_in_the_core(black_184: dict[str, rb.Whirl]) -> None:
    """From the stable dry whirl with A perturbed by 1e-3, 2 ms (about 3 whirl periods; 6 s
    of core time): the core keeps rolling (no transition after its start) and the mean
    whirl rate over the last 1 ms is -9275.2893 rad/s against the steady -9275.5165:
    2.45e-5 relative (the perturbation's penetration still decaying at -19 /s), well inside
    the issue's 1 %. Over 50 ms (161 s) the core gives -9275.5084 (8.7e-7), the reference's
    own simulation -9275.51."""
    w = black_184["whirl"]
    mean, trans = whirl_rate_run(core_on_whirl(w, W0), 2e-3, 1e-3)
    assert all(t < 1e-9 for t, _ in trans)  # (the start settles the mode at once)
    assert abs(mean / w.nu - 1.0) <= 3e-5
    assert abs(mean / w.nu - 1.0) <= 1e-2


def test_black_dry_whip_holds_in_the_core(black_184: dict[str, rb.Whirl]) -> None:
    """From the stable dry whip (-883.365 rad/s, slip 6.6 m/s) with A perturbed by 1e-3, 3 ms
    (12-25 s of core time, the machine loaded): the core keeps sliding (no transition), the
    whirl rate oscillating by up to 7e-3 relative at first, decaying at -11 /s; its mean over
    the last 2 ms is 7.7e-5 relative off the steady rate (over 50 ms: -883.384, 2.1e-5; the
    reference's simulation -883.38)."""
    w = black_184["whip"]
    core = core_on_whirl(w, W0)
    mean, trans = whirl_rate_run(core, 3e-3, 2e-3)
    assert trans == [] and core.mode == 1
    assert abs(mean / w.nu - 1.0) <= 2e-4
    assert abs(mean / w.nu - 1.0) <= 1e-2


@pytest.mark.slow
def test_black_unstable_dry_whip_lifts_off_in_the_core(black_184: dict[str, rb.Whirl]) -> None:
    """From the unstable dry whip (-9197.77 rad/s, slip 0.085 m/s, the reference's largest
    real part of the eigenvalues +1.8e3 /s) with A perturbed by 1e-3: the core slides on and
    lifts off at 5.7487 ms (ln(1e3)/1.8e3 /s = 3.8 ms to grow the perturbation to order one;
    the reference lifts off within 50 ms). 15-17 s of core time: marked slow to keep this
    file's quick group near 35 s."""
    core = core_on_whirl(black_184["fast_whip"], W0)
    trans: list[tuple[float, str]] = []
    for _ in range(80):
        rep = core.step(1e-4, None, 0j, 0.0)
        assert rep.status == 0
        trans += rep.transitions
        if trans:
            break
    assert [m for _, m in trans] == ["lift_off"]
    assert 4e-3 < trans[0][0] < 7e-3
