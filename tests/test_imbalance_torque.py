"""The imbalance reaction torque T_imb (StepReport.T_imb, the FMU output T_imb).

T_imb = e_c Im(conj(F_amb + F_ext + F_c) e^{i(psi + phi)}), averaged over a held-Omega step
with impacts counted as P/h, is checked against references that share no code with the
core: scipy's DOP853 (rtol 1e-12) integrates the model's equations, written out here from
docs/model.md §1 and §8, carrying the torque's integrand as an extra component and computing the
contact force from its own state:

- free flight (proved clear, or searched): the translational equation (1);
- a step with impacts: (1) between the impact times of the core's impact list, each
  impact adding e_c Im(conj(P_c) E) with the listed impulse P_c = -(P_n + i P_t) n and
  v += P_c/m (the reference's own state elsewhere);
- sliding, the rub (linearised, second order, locked) and rolling: the contact equations
  (3) on the circle from the core's (theta, theta') at the step's start, with N and F_t
  from the reference's own state (sliding: F_t = mu s N; rolling: F_t = Im(e^{-i theta} F)).

Agreement is measured relative to the torque scale e_c (max |F_amb| + m e_c Omega^2 +
max |F_c|) along the reference (impulses as |P|/h) and required within TOL = 1e-9.
"""

from __future__ import annotations

import cmath
import math

import numpy as np
import pytest
from rotortd import (
    MODE_FREE,
    MODE_ROLLING,
    MODE_SLIDING,
    RotorParams,
    SpinCore,
    TouchdownCore,
)
from rotortd.segments.rub import LinearRub, LockedRub, QuadraticRub
from rotortd.segments.sliding import Sliding
from scipy.integrate import solve_ivp

TOL = 1e-9
W0 = 184.2
BASE = RotorParams()
ODE = {"method": "DOP853", "rtol": 1e-12, "atol": 1e-22}
MEASURED: list[float] = []
"""|T_imb - reference| / torque scale of every check (read by a report, not asserted)."""


def _gamma(gamma: float, **kw: float) -> RotorParams:
    return BASE.replace(c=gamma * BASE.m * W0, **kw)


def _bias(p: RotorParams) -> complex:
    return 1j * p.m * p.g if p.levitate else 0j


# ------------------------------------------------------------------ free flight (+ impacts)

def _flight_reference(p: RotorParams, z0: complex, v0: complex, psi0: float, h: float,
                      W: float, F: complex, a: float, impacts: list, t0: float
                      ) -> tuple[float, float, complex, complex]:
    """(P_imb (N m s), torque scale (N m), z(h), v(h)) of a held-Omega flight of h seconds
    with the impulses of ``impacts`` (the core's list: t, z, P_n, P_t) applied."""
    m, c, k, ec, g = p.m, p.c, p.k, p.e_c, p.g
    Fb = _bias(p)
    f_max = [m * ec * W * W]

    def rhs(t: float, y: np.ndarray) -> list[float]:
        z, v = complex(y[0], y[1]), complex(y[2], y[3])
        E = cmath.exp(1j * (psi0 + p.phi + W * t))
        Famb = a * (Fb - c * v - k * z)
        acc = (Famb + F - 1j * m * g + m * ec * W * W * E) / m
        return [v.real, v.imag, acc.real, acc.imag, ec * ((Famb + F).conjugate() * E).imag]

    y = np.array([z0.real, z0.imag, v0.real, v0.imag, 0.0])
    t = 0.0
    stops = [(imp.t - t0, imp) for imp in impacts] + [(h, None)]
    for t_stop, imp in stops:
        if t_stop > t:
            sol = solve_ivp(rhs, (t, t_stop), y, dense_output=True, **ODE)
            assert sol.success
            for tt in np.linspace(t, t_stop, 65):
                yy = sol.sol(tt)
                z, v = complex(yy[0], yy[1]), complex(yy[2], yy[3])
                f_max.append(abs(a * (Fb - c * v - k * z)) + abs(F))
            y, t = sol.y[:, -1].copy(), t_stop
        if imp is not None:
            n = imp.z / abs(imp.z)
            Pc = -complex(imp.P_n, imp.P_t) * n
            E = cmath.exp(1j * (psi0 + p.phi + W * t))
            y[4] += ec * (Pc.conjugate() * E).imag
            y[2] += Pc.real / m
            y[3] += Pc.imag / m
            f_max.append(abs(Pc) / h)
    return y[4], ec * sum(sorted(f_max)[-2:]) * 2.0, complex(y[0], y[1]), complex(y[2], y[3])


def _check_flight_step(core: TouchdownCore, h: float, W: float, F: complex = 0j,
                       a: float = 1.0) -> object:
    p, z0, v0, psi0, t0 = core.params, core.z, core.v, core.psi, core.t
    rep = core.step(h, W, F, a)
    assert rep.status == 0
    P, scale, z1, v1 = _flight_reference(p, z0, v0, psi0, h, W, F, a, rep.impacts, t0)
    assert abs(z1 - core.z) <= 1e-8 * p.c_r  # the reference followed the same flight
    assert abs(v1 - core.v) <= 1e-7 * (abs(v1) + p.c_r * abs(W))
    assert abs(rep.P_imb - P) <= TOL * scale * h, (rep.P_imb, P, scale * h)
    assert abs(rep.T_imb - P / h) <= TOL * scale, (rep.T_imb, P / h, scale)
    MEASURED.append(abs(rep.T_imb - P / h) / scale)
    return rep


FLIGHTS = {
    # name: (params, z0 / c_r, v0 (m/s), psi0, h, Omega, F_ext, amb_on)
    "whirl": (_gamma(0.3), 0.3 + 0.2j, 0.01 - 0.02j, 0.4, 1e-3, W0, 0j, 1.0),
    "whirl_long": (_gamma(0.3), 0.3 + 0.2j, 0.01 - 0.02j, 0.4, 0.05, W0, 0j, 1.0),
    "whirl_short": (_gamma(0.3), -0.1 + 0.4j, 0.02j, -2.0, 1e-6, W0, 0j, 1.0),
    # searched (not proved clear over 5 ms), no contact: the whole step as one flight
    "searched": (_gamma(0.3), 0.7, 0.02j, 0.3, 5e-3, W0, 0j, 1.0),
    "gravity_force": (_gamma(0.3, g=9.81), 0.1j, 0.01, 1.0, 2e-3, -120.0, 300 - 200j, 0.6),
    "no_spin": (_gamma(0.3, g=9.81, levitate=False), 0.2, 0.0, 0.3, 1e-3, 0.0, 50j, 1.0),
    "critical": (BASE.replace(c=2.0 * math.sqrt(BASE.m * BASE.k)), 0.2j, -0.01, 0.0, 1e-3,
                 W0, 0j, 1.0),
    "resonance": (BASE.replace(c=0.0, k=BASE.m * 140.0**2), 0.1, 0.0, 0.0, 2e-3, 140.0,
                  0j, 1.0),
    "bearing_off": (BASE.replace(g=9.81), 0.1, 0.01j, 0.2, 2e-3, W0, 40.0 + 0j, 0.0),
}


@pytest.mark.parametrize("name", sorted(FLIGHTS))
def test_free_flight_step_against_dop853(name: str) -> None:
    """A free flight: proved clear or searched and finding nothing (the closed form:
    FlightModel.imb_impulse_ends at a step length's first flight, imb_impulse's
    coefficients from its second on), or searched with events (the identity with the
    integral of the co-rotating position; whirl_long hits the wall)."""
    p, zr, v0, psi0, h, W, F, a = FLIGHTS[name]
    core = TouchdownCore(p, z0=zr * p.c_r, v0=v0, psi0=psi0)
    # the first flight of a length from its ends, the next ones by the coefficients
    for k in range(3 if name != "whirl_long" else 1):
        rep = _check_flight_step(core, h, W, F, a)
        assert bool(rep.impacts) == (name == "whirl_long") and core.mode == MODE_FREE, k


def test_proved_free_and_searched_paths_both_checked() -> None:
    """The cases above take both flight paths: the quiet closed form (work <= 3, no
    averaging) and the segment loop (a search, here finding nothing)."""
    works = {}
    for name, (p, zr, v0, psi0, h, W, F, a) in FLIGHTS.items():
        works[name] = TouchdownCore(p, z0=zr * p.c_r, v0=v0, psi0=psi0).step(h, W, F, a).work
    assert works["whirl"] <= 3 and works["searched"] > 3


IMPACTING = {
    # name: (params, z0 / c_r, v0 (m/s), psi0, h, Omega, F_ext, amb_on, least impacts)
    "fast_2ms": (_gamma(0.3, g=9.81), 0.2j, 0.4 - 0.25j, 0.7, 2e-3, W0, 20.0, 1.0, 1),
    "fast_10ms": (_gamma(0.3, g=9.81), 0.2j, 0.4 - 0.25j, 0.7, 1e-2, W0, 20.0, 1.0, 2),
    # undamped resonance: the flight's integral from its closed form (dd4), not its ends
    "resonance": (BASE.replace(c=0.0, k=BASE.m * 140.0**2), 0.9, 0.05j, 0.3, 2e-2, 140.0,
                  0j, 1.0, 1),
    # no spin, bearing off: a drop onto the wall (kappa = Omega = 0, also closed form)
    "drop_no_spin": (BASE.replace(g=9.81), 0.3, 0.02, 0.5, 2e-2, 0.0, 5.0, 0.0, 1),
}


@pytest.mark.parametrize("name", sorted(IMPACTING))
def test_step_with_impacts_against_dop853(name: str) -> None:
    """Impacts within the step (d = 0.95): impulses counted as P/h through the identity's
    boundary terms; the flights between them searched."""
    p, zr, v0, psi0, h, W, F, a, least = IMPACTING[name]
    core = TouchdownCore(p, z0=zr * p.c_r, v0=v0, psi0=psi0)
    rep = _check_flight_step(core, h, W, F, a)
    assert len(rep.impacts) >= least and not rep.transitions


# ------------------------------------------------------------------ contact

def _contact_reference(p: RotorParams, theta0: float, dtheta0: float, psi0: float, h: float,
                       W: float, F: complex, a: float, rolling: bool
                       ) -> tuple[float, float, float]:
    """(P_imb (N m s), torque scale (N m), theta(h)) of h seconds of sustained contact on
    the circle: sliding (F_t = mu s N) or rolling (theta' constant, F_t = Im(e^{-i theta} F))."""
    m, c, k, ec, g, cr = p.m, p.c, p.k, p.e_c, p.g, p.c_r
    Fb = _bias(p)
    s = math.copysign(1.0, p.R * W + cr * dtheta0)

    def forces(t: float, th: float, w: float) -> tuple[complex, complex, complex, float]:
        n = cmath.exp(1j * th)
        z, v = cr * n, 1j * cr * w * n
        E = cmath.exp(1j * (psi0 + p.phi + W * t))
        Famb = a * (Fb - c * v - k * z)
        Fo = Famb + F - 1j * m * g + m * ec * W * W * E
        N = m * cr * w * w + (n.conjugate() * Fo).real
        Ft = (n.conjugate() * Fo).imag if rolling else p.mu * s * N
        Fc = -complex(N, Ft) * n
        ddth = 0.0 if rolling else ((n.conjugate() * Fo).imag - Ft) / (m * cr)
        return Famb, Fc, E, ddth

    def rhs(t: float, y: np.ndarray) -> list[float]:
        Famb, Fc, E, ddth = forces(t, y[0], y[1])
        return [y[1], ddth, ec * ((Famb + F + Fc).conjugate() * E).imag]

    sol = solve_ivp(rhs, (0.0, h), [theta0, dtheta0, 0.0], dense_output=True, **ODE)
    assert sol.success
    f_max = 0.0
    for tt in np.linspace(0.0, h, 257):
        th, w, _ = sol.sol(tt)
        Famb, Fc, _, _ = forces(tt, th, w)
        assert (Fc * cmath.exp(-1j * th)).real <= 0.0  # N >= 0 all along: no lift-off
        f_max = max(f_max, abs(Famb + F) + abs(Fc))
    scale = ec * (f_max + m * ec * W * W)
    return sol.y[2, -1], scale, sol.y[0, -1]


def _check_contact_step(core: TouchdownCore, h: float, W: float, F: complex = 0j,
                        a: float = 1.0) -> object:
    st = core.state
    p, mode = core.params, core.mode
    assert mode in (MODE_SLIDING, MODE_ROLLING)
    rep = core.step(h, W, F, a)
    assert rep.status == 0 and not rep.transitions and core.mode == mode
    P, scale, th1 = _contact_reference(p, st.theta, st.dtheta, core.psi - W * h, h, W, F, a,
                                       mode == MODE_ROLLING)
    assert abs(cmath.exp(1j * th1) - core.z / p.c_r) <= 1e-8  # the same contact motion
    assert abs(rep.T_imb - P / h) <= TOL * scale, (rep.T_imb, P / h, scale)
    MEASURED.append(abs(rep.T_imb - P / h) / scale)
    return rep


def _chattering(t_start: float) -> TouchdownCore:
    core = TouchdownCore.from_scaled(_gamma(0.3), W0, U0=0j, dU0=0j)
    while core.t < t_start - 1e-9:
        core.step(1e-3, W0)
    return core


def _count_runs(monkeypatch: pytest.MonkeyPatch) -> dict[str, int]:
    """Count the runs of each contact segment class (which closed form or integrator)."""
    counts: dict[str, int] = {}
    for cls in (Sliding, LinearRub, QuadraticRub, LockedRub):
        orig = cls.run

        def run(self: object, *args: object, _orig: object = orig, _n: str = cls.__name__,
                **kw: object) -> object:
            counts[_n] = counts.get(_n, 0) + 1
            return _orig(self, *args, **kw)  # type: ignore[operator]

        monkeypatch.setattr(cls, "run", run)
    return counts


@pytest.mark.parametrize("t_start, h, segment", [
    (0.2, 1e-3, "Sliding"),        # approaching the forward rub: integrated
    (0.2, 1e-5, "Sliding"),
    (0.3, 1e-3, "QuadraticRub"),   # within the second-order budget
    (0.45, 1e-3, "LinearRub"),     # within the linearisation's
    (400.0 / W0, 1e-3, "LockedRub"),  # on the rub: the rigid rotation
    (400.0 / W0, 0.05, "LockedRub"),
])
def test_sliding_and_rub_steps_against_dop853(t_start: float, h: float, segment: str,
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    """Chattering from rest into the forward rub (gamma = 0.3): a sliding step taken by the
    integrator (auxiliary quadrature) or by a rub closed form."""
    core = _chattering(t_start)
    counts = _count_runs(monkeypatch)
    _check_contact_step(core, h, W0)
    assert set(counts) == {segment}, counts


def test_sliding_with_gravity_and_force_against_dop853() -> None:
    """Sliding pressed by gravity and a constant force with the bearing off (q0 != 0: no
    rub equilibrium, the integrator all the way), over a long step."""
    p = BASE.replace(mu=0.3, g=9.81)
    e = cmath.exp(1j * 0.5)
    core = TouchdownCore(p, z0=p.c_r * e, v0=1j * p.c_r * 300.0 * e)
    core.step(1e-6, W0, 200.0 + 100.0j, 0.0)  # enter contact
    assert core.mode == MODE_SLIDING
    _check_contact_step(core, 5e-3, W0, 200.0 + 100.0j, 0.0)


@pytest.mark.parametrize("h", [1e-3, 1e-5])
def test_rolling_step_against_dop853(h: float) -> None:
    """Dry whirl from rest (gamma = 0.065): rolling at theta' = -R Omega/c_r, where the
    contact force is thousands of m c_r Omega^2."""
    core = TouchdownCore(_gamma(0.065))
    while core.t < 1.0 - 1e-9:
        core.step(1e-3, W0)
    assert core.mode == MODE_ROLLING
    _check_contact_step(core, h, W0)


# ------------------------------------------------------------------ consistency

def test_step_split_and_zero_imbalance() -> None:
    """Over chattering into contact the impulse of one 20 ms step equals the sum over its
    200 steps of 0.1 ms (both exact up to the integrators' tolerance), and e_c = 0 gives
    exactly 0 on every path."""
    long_, short = _chattering(0.05), _chattering(0.05)
    P1 = long_.step(0.02, W0).P_imb
    P2 = sum(short.step(1e-4, W0).P_imb for _ in range(200))
    scale = BASE.e_c * BASE.m * BASE.c_r * W0 * W0 * 60.0 * 0.02  # |F_c| ~ 60 m c_r W^2
    assert abs(P1 - P2) <= TOL * scale
    core = TouchdownCore.from_scaled(_gamma(0.3, e_c=0.0), W0, U0=0.9j, dU0=0j)
    for _ in range(50):
        assert core.step(1e-3, W0, 30.0).T_imb == 0.0


def test_spin_state_reports_the_same_torque_from_its_balance() -> None:
    """SpinCore (the spin a state) reports T_imb from the spin's balance over the step. On a
    short flight with the bearing on it agrees with the held-speed core's closed form from
    the same state, to the spin's change over the step (1e-6 relative at 1e-5 s)."""
    p = RotorParams(g=9.81)
    held = TouchdownCore.on_steady_whirl(p, W0)
    for _ in range(37):
        held.step(1e-4, W0, 200.0 + 100j)
    spin = SpinCore(p, 0.04, z0=held.z, v0=held.v, psi0=held.psi, Omega0=W0, t0=held.t)
    a = held.step(1e-5, W0, 200.0 + 100j)
    b = spin.step(1e-5, F_ext=200.0 + 100j, T_drive=3.0)
    assert not a.impacts and not b.impacts and abs(a.T_imb) > 1e-3
    assert abs(b.T_imb - a.T_imb) <= 1e-6 * abs(a.T_imb)
    assert b.T_f == 0.0
    assert 0.04 * (spin.Omega - W0) == pytest.approx((3.0 + b.T_imb) * 1e-5, rel=1e-12)


def test_state_round_trip_keeps_the_torque_bit_for_bit() -> None:
    """The proved-free closed form of T_imb has two roundings (from a flight's ends, or from
    coefficients once a step length recurs); which one the next flight takes is part of the
    state, so a restored core reports the same bits (FMU fuzz case 256 found it)."""
    import json

    from rotortd import restore_core

    core = TouchdownCore.on_steady_whirl(RotorParams(), W0)
    for _ in range(40):
        core.step(1e-3, W0)
        saved = json.loads(json.dumps(core.get_state()))
        a, b = core.step(1e-3, W0), restore_core(saved).step(1e-3, W0)
        assert (a.T_imb, a.P_imb) == (b.T_imb, b.P_imb)


@pytest.mark.parametrize("gamma", [0.3, 0.065])
def test_switched_off_the_motion_is_the_same_to_the_bit(gamma: float) -> None:
    """``imbalance_torque = False`` skips the torque's work (T_imb and P_imb are NaN) and
    moves the rotor exactly as with it on: impacts, chattering, sliding (its auxiliary
    quadrature no longer refined) and rolling, over 1 s at 1e-3 s steps."""
    W0 = 184.2
    p = RotorParams().replace(c=gamma * 50 * W0)
    on = TouchdownCore(p, z0=0.2 * p.c_r, v0=0.5j * p.c_r * W0)
    off = TouchdownCore(p, z0=0.2 * p.c_r, v0=0.5j * p.c_r * W0)
    off.imbalance_torque = False
    modes = set()
    for _ in range(1000):
        a, b = on.step(1e-3, W0), off.step(1e-3, W0)
        assert (a.F_contact, a.F_n, a.T_f, a.impacts) == (b.F_contact, b.F_n, b.T_f, b.impacts)
        assert math.isfinite(a.T_imb) and math.isnan(b.T_imb) and math.isnan(b.P_imb)
        modes.add(on.mode)
    assert on.n_impacts > 100 and modes >= {0, 1}
    s_on, s_off = on.get_state(), off.get_state()
    assert s_on["step"].pop("imb_h") != s_off["step"].pop("imb_h") and s_on == s_off


def test_a_subnormal_speed_keeps_the_torque_finite() -> None:
    """FMU fuzz case 1867 (seed 1, docs/fuzz.md): Omega = -5e-324 rad/s held, F_ext about
    1e12 N, the bearing almost off. The flight's ends formula divides by kappa - Omega^2 +
    i beta Omega, which is subnormal here, and its K overflowed (then Omega^2 K = 0 * inf
    = NaN and the FMU refused the step); the closed form takes over where the quotient
    overflows, and the torque is finite."""
    p = RotorParams(m=0.6685011154856798, c=80945902.32553299, k=5e-324, e_c=0.0003,
                    phi=-3.2938560455687836e-05, c_r=0.06132191918747797,
                    R=0.001000009999, mu=9.999999999999998, d=0.0,
                    g=1.0327499996655205e-05)
    core = TouchdownCore(p, z0=complex(0.045605198883090683, -0.022700955271032445),
                         v0=complex(0.0, -8846.628975671192), psi0=-0.0008119083639846557)
    rep = core.step(1e-4, -5e-324, complex(-174080569547.08862, 999999999999.9999),
                    3.137189166289206e-05)
    assert rep.status == 0 and len(rep.impacts) == 1
    assert math.isfinite(rep.P_imb) and math.isfinite(rep.T_imb), rep.P_imb
