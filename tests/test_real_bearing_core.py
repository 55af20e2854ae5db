"""The core's real touchdown bearing (docs/model.md §10) against the independent reference
(tests/reference/real_bearing.py, which shares no code with fmu_src) and the closed forms
of §10: the drop of issue 24 impact by impact, a single compliant impact, a rigid impact on
a sprung race, the balances, the state round trip and the refusals.

Tolerances come from measured sensitivity: on the drop's first 20 ms the reference at
rtol 1e-12 and at 1e-13 differ by 2e-13 c_r in z, 8e-13 rad/s in Omega and 1.6e-10 rad/s in
omega_b (the race's small inertia amplifies); the core differs from the 1e-12 reference by
3.4e-13 c_r, 3.4e-12 rad/s and 1.5e-10 rad/s."""

from __future__ import annotations

import cmath
import math
from typing import Any

import pytest
from rotortd import restore_core
from rotortd.bodies.race import BearingParams
from rotortd.limits import CrossParameterError, ParameterError
from rotortd.params import RotorParams
from rotortd.step.simulator import TouchdownCore

from tests.reference import real_bearing as rb

W0 = 184.2
ALL_ON = {"race_turns": True, "support_compliant": True, "contact_compliant": True}


def _drop_core(**opts: float) -> TouchdownCore:
    """The issue's drop: the chapter's rotor with gravity, mu 0.15, d 0.9, J = m R^2/2, from
    the levitated whirl at 184.2 rad/s with the bearing failed at t = 0."""
    p = RotorParams(g=9.81, d=0.9, mu=0.15)
    Z1 = p.m * p.e_c * W0**2 * cmath.exp(1j * p.phi) / (p.k - p.m * W0**2 + 1j * p.c * W0)
    return TouchdownCore(p, J=0.04, z0=Z1, v0=1j * W0 * Z1, Omega0=W0,
                         bearing=BearingParams(**{**ALL_ON, **opts}))


def _contact_changes(transitions: list[tuple[float, str]]) -> list[tuple[float, str]]:
    """The reference's mode changes of the contact (its race changes dropped), named as the
    core's: free -> lift_off, slide -> sliding, stick -> rolling."""
    names = {"free": "lift_off", "slide+": "sliding", "slide-": "sliding", "stick": "rolling"}
    out: list[tuple[float, str]] = []
    for t, m in transitions:
        kind = names.get(m.split("/")[0], m)
        if t > 0.0 and (not out or out[-1][1] != kind):
            out.append((t, kind))
    return out


def test_drop_agrees_with_the_reference_impact_by_impact() -> None:
    T, h = 0.02, 1e-4
    ref = rb.drop_scene(t_end=T, n_grid=round(T / h) + 1)
    core = _drop_core()
    ez = eW = ewb = ezb = 0.0
    peak, trans = 0.0, []
    c_r = core.params.c_r
    for i in range(1, round(T / h) + 1):
        rep = core.step(h, None, 0j, 0.0, T_drive=0.0)
        assert rep.status == 0
        peak = max(peak, rep.F_n_peak)
        trans += rep.transitions
        y = ref.y[i]
        race = core.race
        assert race is not None
        ez = max(ez, abs(core.z - complex(y[0], y[1])) / c_r)
        eW = max(eW, abs(core.Omega - y[5]))
        ewb = max(ewb, abs(race.omega_b - y[10]))
        ezb = max(ezb, abs(race.z_b - complex(y[6], y[7])) / c_r)
    assert ez <= 3e-12 and ezb <= 3e-12, (ez, ezb)
    assert eW <= 4e-11, eW
    assert ewb <= 2e-9, ewb
    expected = _contact_changes(ref.transitions)
    assert [m for _, m in trans] == [m for _, m in expected]
    assert max(abs(t - te) for (t, _), (te, _) in zip(trans, expected)) <= 1e-12
    assert peak == pytest.approx(ref.N_peak, rel=1e-9)
    assert 4.4e-3 < next(t for t, m in trans if m == "rolling") < 4.5e-3  # the race caught up


def _single_impact_core(p_c: float, d: float, v_in: float) -> tuple[TouchdownCore, float]:
    """A normal compliant impact on a fixed rigid race: no friction, imbalance, gravity or
    AMB; the rotor starts 0.1 c_r inside the circle moving outward at v_in."""
    p = RotorParams(e_c=0.0, g=0.0, mu=0.0, d=d, levitate=False)
    bp = BearingParams(contact_compliant=True, p_c=p_c, k_c=1e9)
    x0 = 0.9 * p.c_r
    core = TouchdownCore(p, J=0.04, z0=x0, v0=v_in, bearing=bp)
    return core, (p.c_r - x0) / v_in


@pytest.mark.parametrize(("p_c", "d"), [(1.0, 0.9), (1.5, 0.9), (1.0, 1.0), (1.5, 0.5)])
def test_single_compliant_impact_matches_its_closed_form(p_c: float, d: float) -> None:
    v_in = 0.1
    core, t_close = _single_impact_core(p_c, d, v_in)
    exact = rb.single_impact(core.params.m, v_in, 1e9, p_c, d)
    rep = core.step(t_close + 2.0 * exact.T, None, 0j, 0.0, T_drive=0.0)
    (t1, m1), (t2, m2) = rep.transitions
    assert (m1, m2) == ("sliding", "lift_off")
    assert t1 == pytest.approx(t_close, rel=1e-14)
    assert t2 - t1 == pytest.approx(exact.T, rel=2e-11)
    assert rep.F_n_peak == pytest.approx(exact.N_max, rel=2e-11)
    v_out = -core.v.real
    tol = 5e-14 if p_c == 1.0 else 1e-11  # delta^{3/2} is not smooth at the contact's ends
    assert v_out == pytest.approx(d * v_in, rel=tol)
    assert rep.impacts == []  # a compliant contact has no impulse


def test_the_compliant_damping_follows_a_tunable_d() -> None:
    """d is tunable: changed before a compliant impact (0.9 -> 0.5), the impact rebounds
    at the new d v_in (the damping c_d of (10.7) follows it); d = 0 is refused mid-run as
    at the start, and the core keeps its parameters."""
    v_in = 0.1
    core, t_close = _single_impact_core(1.0, 0.9, v_in)
    core.set_params(core.params.replace(d=0.5))
    exact = rb.single_impact(core.params.m, v_in, 1e9, 1.0, 0.5)
    core.step(t_close + 2.0 * exact.T, None, 0j, 0.0, T_drive=0.0)
    assert -core.v.real == pytest.approx(0.5 * v_in, rel=5e-14)
    with pytest.raises(CrossParameterError, match=r"d = 0\.0 is refused"):
        core.set_params(core.params.replace(d=0.0))
    assert core.params.d == 0.5


def test_a_slow_closure_gets_the_floor_damping() -> None:
    """docs/model.md §10: chi = c_d/max(v_in, v_floor), v_floor = 1e-3 m/s: a contact that
    closes at 1e-4 m/s is damped as one closing at v_floor, so it rebounds faster than
    d v_in. Against an independent integration of m x'' = -K x (1 + chi x') (scipy DOP853,
    rtol 1e-12) from x = 0, x' = v_in to the exit."""
    from scipy.integrate import solve_ivp

    v_in, d = 1e-4, 0.9
    core, t_close = _single_impact_core(1.0, d, v_in)
    m, k_c = core.params.m, 1e9
    chi = rb.c_d(d) / 1e-3

    def rhs(_t: float, y: list[float]) -> list[float]:
        return [y[1], -k_c * y[0] * (1.0 + chi * y[1]) / m]

    def out(_t: float, y: list[float]) -> float:
        return y[0]

    out.terminal, out.direction = True, -1.0  # type: ignore[attr-defined]
    sol = solve_ivp(rhs, (0.0, 1.0), [0.0, v_in], method="DOP853", rtol=1e-12, atol=1e-20,
                    events=out)
    v_exit = -float(sol.y_events[0][0][1])
    assert v_exit > 1.05 * d * v_in  # less damping than an impact at v_in would get
    core.step(t_close + 2.0 * float(sol.t_events[0][0]), None, 0j, 0.0, T_drive=0.0)
    assert -core.v.real == pytest.approx(v_exit, rel=1e-9)


def test_rigid_impact_on_a_sprung_race_matches_its_closed_form() -> None:
    p = RotorParams(e_c=0.0, g=0.0, mu=0.0, d=0.95, levitate=False)
    bp = BearingParams(support_compliant=True, m_b=2.0, k_b=5e7, c_b=2e3)
    v_in = 0.1
    core = TouchdownCore(p, J=0.04, z0=0.5 * p.c_r, v0=v_in, bearing=bp)
    rep = core.step(0.5 * p.c_r / v_in * (1.0 + 1e-9), None, 0j, 0.0, T_drive=0.0)
    (imp,) = rep.impacts
    rotor, race = rb.rigid_impact_sprung(p.m, bp.m_b, p.d, v_in)
    assert imp.v_plus.real == pytest.approx(rotor, rel=1e-14)
    assert imp.P_n == pytest.approx(p.m * (v_in - rotor), rel=1e-14)
    assert imp.P_n / bp.m_b == pytest.approx(race, rel=1e-14)  # the race's kick


def test_a_dip_of_an_event_function_inside_one_step_is_found() -> None:
    """segments/bearing_contact.py: the event functions are checked at each accepted step's
    end and at its midpoint (the state's cubic Hermite interpolant), so a function that dips
    below 0 and returns inside one step, around its midpoint, is found, and located to 4 ulp
    of the time. A synthetic event function of the spin angle, (psi - psi_c)^2 - eps^2, with
    the dip centred on the midpoint of a step of a compliant sliding contact and narrower
    than a quarter of it: the segment ends where psi = psi_c - eps."""
    from rotortd.contact.events import LIFT_OFF
    from rotortd.segments import gbs
    from rotortd.segments.bearing_contact import BearingContact, BearingModel
    from rotortd.segments.spin_contact import HeldInputs

    core = _drop_core()
    while core.mode == 0:
        core.step(1e-5, None, 0j, 0.0, T_drive=0.0)
    held = HeldInputs(core.params, core.J, 0.0, 0j, 0.0)
    y0 = core._bearing_state()
    seg = BearingContact(held, core._law, core._cstate, y0)
    grid: list[tuple[float, float, float]] = []  # accepted steps: (u, H, psi at u)
    real_step = gbs.extrapolated_step

    def spy(sweep: Any, u: float, y: list[float], f0: list[float], H: float,
            scale: list[float], **kw: Any) -> Any:
        out = real_step(sweep, u, y, f0, H, scale, **kw)
        if out[1] <= 1.0 and "k_fixed" not in kw:
            grid.append((u, H, y[4]))
        return out

    gbs.extrapolated_step = spy
    try:
        seg.run(2e-4)
    finally:
        gbs.extrapolated_step = real_step
    u, H, _ = grid[len(grid) // 2]
    W = y0[5]  # psi advances at about Omega: the dip placed by time
    psi_c, eps = y0[4] + W * (u + 0.5 * H), 0.1 * W * H

    class Dip(BearingModel):
        def events(self, y: list[float]) -> list[tuple[Any, float]]:
            return [*super().events(y), (LIFT_OFF, (y[4] - psi_c) ** 2 - eps**2)]

    dip = BearingContact(held, core._law, core._cstate, y0)
    dip.model = Dip(held, core._law, core._cstate)
    end = dip.run(2e-4)
    assert end.event == LIFT_OFF
    assert end.y[4] == pytest.approx(psi_c - eps, rel=1e-13, abs=1e-12 * W * H)
    assert u < end.duration < u + H


def _energy(core: TouchdownCore) -> float:
    """Mechanical energy (J) of rotor and race with the AMB off (docs/model.md §10)."""
    p, race = core.params, core.race
    assert race is not None
    bp = race.bp
    E = cmath.exp(1j * (core.psi + p.phi))
    vG = core.v + 1j * core.Omega * p.e_c * E
    zG = core.z + p.e_c * E
    delta = abs(core.z - race.z_b) - p.c_r
    V_c = 0.0
    if bp.contact_compliant and delta > 0.0:
        K = bp.k_c * 1e-5 ** (1.0 - bp.p_c)
        V_c = K * delta ** (bp.p_c + 1.0) / (bp.p_c + 1.0)
    return (0.5 * p.m * abs(vG) ** 2 + 0.5 * core.J * core.Omega**2
            + 0.5 * bp.m_b * abs(race.v_b) ** 2 * bp.support_compliant
            + 0.5 * bp.J_b * race.omega_b**2 * bp.race_turns
            + p.m * p.g * zG.imag + 0.5 * bp.k_b * abs(race.z_b) ** 2 * bp.support_compliant
            + V_c)


@pytest.mark.parametrize("opts", [{}, {"contact_compliant": False, "support_compliant": False}])
def test_energy_balance_closes_over_the_drop(opts: dict[str, bool]) -> None:
    """E(0) - E(t) = contact heat (impacts, damping, friction) + race drag + support damper,
    to 1e-9 of the sum of the magnitudes of the terms."""
    core = _drop_core(**opts)
    E0, heat = _energy(core), 0.0
    for _ in range(150):
        rep = core.step(1e-4, None, 0j, 0.0, T_drive=0.0)
        assert rep.status == 0
        heat += rep.E_diss
    race = core.race
    assert race is not None
    terms = [E0, _energy(core), heat, race.E_drag, race.E_support]
    resid = E0 - _energy(core) - heat - race.E_drag - race.E_support
    assert abs(resid) <= 1e-9 * sum(abs(x) for x in terms), (resid, terms)
    assert heat > 0.0


@pytest.mark.parametrize("T_b0", [0.02, 0.0])
def test_state_round_trip_mid_contact_continues_bit_for_bit(T_b0: float) -> None:
    """Restored mid-contact (the race turning; with T_b0 = 0 a race at rest is not held by
    static friction), the two cores continue bit for bit."""
    a = _drop_core(T_b0=T_b0)
    for _ in range(30):  # into the second contact (sliding, the race turning)
        a.step(1e-4, None, 0j, 0.0, T_drive=0.0)
    assert a.mode != 0
    b = restore_core(a.get_state())
    for _ in range(30):
        ra = a.step(1e-4, None, 0j, 0.0, T_drive=0.0)
        rb_ = b.step(1e-4, None, 0j, 0.0, T_drive=0.0)
        assert ra.F_n_peak == rb_.F_n_peak
    assert a.output_values() == b.output_values()
    assert a.race is not None and b.race is not None
    assert a.race.record() == b.race.record()


def test_options_need_the_spin_as_a_state() -> None:
    with pytest.raises(CrossParameterError, match="spin as a state"):
        TouchdownCore(RotorParams(), bearing=BearingParams(race_turns=True))
    held = TouchdownCore(RotorParams(), bearing=BearingParams())  # all off: the chapter's
    assert held.race is None


def test_bad_bearing_parameters_are_refused_with_their_range() -> None:
    p = RotorParams()
    with pytest.raises(CrossParameterError, match=r"d = 0.0 is refused under the compliant"):
        TouchdownCore(RotorParams(d=0.0), J=0.04,
                      bearing=BearingParams(contact_compliant=True))
    with pytest.raises(ParameterError,
                       match=r"k_b = 10000000000000.0 N/m is out of range.*1e\+11\] N/m"):
        TouchdownCore(p, J=0.04, bearing=BearingParams(support_compliant=True, k_b=1e13))
    with pytest.raises(ParameterError, match=r"p_c = 1\.6 is out of range.*\[1, 1\.5\]"):
        TouchdownCore(p, J=0.04, bearing=BearingParams(contact_compliant=True, p_c=1.6))
    with pytest.raises(ParameterError, match="J_b = nan"):
        TouchdownCore(p, J=0.04, bearing=BearingParams(race_turns=True, J_b=math.nan))
