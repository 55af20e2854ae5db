"""The real touchdown bearing's race and contact law (docs/model.md §10) against references
that share no code with them: scipy's integrators and matrix exponential, mpmath at 30+
digits, and the closed forms written out here from the docs.

* ``RealRace``'s free motion: the centre's path (the damped oscillator, every damping regime
  and c_b = 0) against solve_ivp (DOP853, rtol 1e-12), its derivatives against the ODE, its
  bounds against dense samples of scipy.linalg.expm; the spin's drag law and stop time
  against the closed forms and an integration; the heats of ``advance``.
* An impulse changes the race's momentum exactly; the record round-trips; options off keep
  their states at 0.
* ``laws``: c_d of (10.7) against the docs' digits and mpmath; a single compliant impact
  integrated by scipy leaves with d v_in; the force law and its clamp.
* ``BearingParams.check``: its messages, and the refusal of d = 0 under the compliant law.
"""

from __future__ import annotations

import cmath
import json
import math
import random

import mpmath
import numpy as np
import pytest
from rotortd.bodies.race import BearingParams, RealRace
from rotortd.contact.laws import (
    DELTA_REF,
    compliant_normal_force,
    contact_potential,
    restitution_damping,
    stiffness_coefficient,
)
from rotortd.limits import LIMITS, CrossParameterError, ParameterError
from scipy.integrate import solve_ivp
from scipy.linalg import expm

C_R, R = 0.7e-3, 0.04

# (m_b, k_b, c_b): under-damped (the drop's support), critical (exactly: gam = w0 = 100),
# near-critical on both sides, over-damped, heavily over-damped, undamped
SUPPORTS = {
    "under": (2.0, 5e7, 2e3),
    "critical": (1.0, 1e4, 200.0),
    "near-critical-under": (1.0, 1e4, 200.0 * (1.0 - 1e-9)),
    "near-critical-over": (1.0, 1e4, 200.0 * (1.0 + 1e-9)),
    "over": (1.0, 1e4, 2e3),
    "heavily-over": (1.0, 1e4, 2e5),
    "undamped": (2.0, 5e7, 0.0),
}


def _race(m_b: float, k_b: float, c_b: float, z: complex, v: complex,
          **kw: float) -> RealRace:
    bp = BearingParams(support_compliant=True, m_b=m_b, k_b=k_b, c_b=c_b, **kw)
    return RealRace(bp, c_r=C_R, R=R, z_b=z, v_b=v)


def _scales(m_b: float, k_b: float, z: complex, v: complex) -> tuple[float, float]:
    """(amplitude bound sqrt(E/k_b) (m), speed bound sqrt(E/m_b) (m/s))."""
    E = k_b * abs(z) ** 2 + m_b * abs(v) ** 2
    return math.sqrt(E / k_b), math.sqrt(E / m_b)


# ------------------------------------------------------------------ free motion
@pytest.mark.parametrize("case", sorted(SUPPORTS))
def test_path_against_solve_ivp(case: str) -> None:
    """c(s), c'(s) against DOP853 at rtol 1e-12 over several time constants, to 1e-9 of
    the amplitude and speed scales (measured: <= 1e-11; printed)."""
    m_b, k_b, c_b = SUPPORTS[case]
    z0, v0 = complex(3e-5, -1e-5), complex(-0.02, 0.05)
    race = _race(m_b, k_b, c_b, z0, v0)
    w0 = math.sqrt(k_b / m_b)
    slow = min(w0, w0 * w0 / max(c_b / m_b, 1e-300))  # the slowest rate
    T = min(6.0 / slow, 300.0 / (w0 + c_b / m_b))  # (DOP853 is explicit: no stiff spans)

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        x, yy, vx, vy = y
        return np.array([vx, vy, -(k_b * x + c_b * vx) / m_b, -(k_b * yy + c_b * vy) / m_b])

    ts = np.linspace(0.0, T, 41)
    sol = solve_ivp(rhs, (0.0, T), [z0.real, z0.imag, v0.real, v0.imag], method="DOP853",
                    rtol=1e-12, atol=1e-20, t_eval=ts, dense_output=False)
    Z, V = _scales(m_b, k_b, z0, v0)
    worst = 0.0
    for i, t in enumerate(ts):
        c, c1, _, _ = race.path(float(t))
        ez = abs(c - complex(sol.y[0, i], sol.y[1, i])) / Z
        ev = abs(c1 - complex(sol.y[2, i], sol.y[3, i])) / V
        worst = max(worst, ez, ev)
    print(f"{case}: worst path error {worst:.2e} of the amplitude/speed scales")
    assert worst <= 1e-9


@pytest.mark.parametrize("case", sorted(SUPPORTS))
def test_path_derivatives_obey_the_ode(case: str) -> None:
    """m c'' + c_b c' + k c = 0 and m c''' + c_b c'' + k c' = 0 along the path, to 1e-13 of
    the sum of the terms' magnitudes; the path at 0 is the state."""
    m_b, k_b, c_b = SUPPORTS[case]
    z0, v0 = complex(-2e-5, 4e-5), complex(0.03, 0.01)
    race = _race(m_b, k_b, c_b, z0, v0)
    assert race.path(0.0)[:2] == (z0, v0)
    w0 = math.sqrt(k_b / m_b)
    for s in np.linspace(0.0, 20.0 / w0, 57):
        c, c1, c2, c3 = race.path(float(s))
        for x, x1, x2 in ((c, c1, c2), (c1, c2, c3)):
            scale = m_b * abs(x2) + c_b * abs(x1) + k_b * abs(x)
            assert abs(m_b * x2 + c_b * x1 + k_b * x) <= 1e-13 * scale + 1e-300


def _exact_derivs(m_b: float, k_b: float, c_b: float, z: complex, v: complex, s: float,
                  tau: float, n: int) -> np.ndarray:
    """|c^(k)(t)|, k = 0..4 (columns), at n + 1 equidistant t in [s, s + tau] (rows), from
    scipy.linalg.expm of the oscillator's matrix (the state at s, then steps of tau/n)."""
    A = np.array([[0.0, 1.0], [-k_b / m_b, -c_b / m_b]])
    X = expm(A * s) @ np.array([[z.real, z.imag], [v.real, v.imag]])
    P = expm(A * (tau / n))
    A2 = A @ A
    rows = []
    for _ in range(n + 1):
        D = [X, A @ X, A2 @ X, A2 @ (A @ X), A2 @ (A2 @ X)]
        rows.append([math.hypot(Dk[0, 0], Dk[0, 1]) for Dk in D])
        X = P @ X
    return np.array(rows)


def test_path_bounds_hold_on_dense_samples() -> None:
    """For random supports (every damping regime), states and windows [s, s + tau], the
    bounds of |c|, ..., |c''''| hold at 120 samples each against expm; they are also not
    loose at the window's start (within a factor 2 of the undamped amplitude there)."""
    rng = random.Random(24)
    worst = 0.0
    for _ in range(100):
        m_b = 10 ** rng.uniform(-3, 5)
        k_b = 10 ** rng.uniform(3, 11)
        w0 = math.sqrt(k_b / m_b)
        zeta = rng.choice([0.0, 10 ** rng.uniform(-4, 3), 1.0])
        c_b = 2.0 * zeta * math.sqrt(k_b * m_b)
        z = complex(rng.uniform(-1, 1), rng.uniform(-1, 1)) * 1e-4
        v = complex(rng.uniform(-1, 1), rng.uniform(-1, 1)) * 1e-4 * w0 * rng.uniform(0, 3)
        race = _race(m_b, k_b, c_b, z, v)
        s = rng.choice([0.0, rng.uniform(0.0, 5.0 / w0)])
        tau = rng.uniform(0.01, 10.0) / w0
        B = np.array(race.path_bounds(s, tau))
        ex = _exact_derivs(m_b, k_b, c_b, z, v, s, tau, 200)
        worst = max(worst, float((ex / B).max()))
        assert (ex <= B).all(), (ex.max(axis=0), B, m_b, k_b, c_b, s, tau)
    print(f"largest |c^(k)|/bound on the samples: {worst:.6f}")
    assert worst > 0.5  # the bounds are attained to within a factor 2 somewhere


def test_path_bounds_hold_on_the_slow_mode_of_a_heavily_over_damped_support() -> None:
    """States on (within rounding of) the slow mode v = lam1 z, or the fast one, of supports
    with damping ratios 10 to 1e4: there the ODE's recursion for c'', c''', c'''' cancels
    almost completely; the bounds still hold against expm at 40 digits (mpmath)."""
    mpmath.mp.dps = 40
    rng = random.Random(11)
    for _ in range(10):
        m_b, k_b = 10 ** rng.uniform(-1, 2), 10 ** rng.uniform(3, 8)
        c_b = 2.0 * 10 ** rng.uniform(1, 4) * math.sqrt(k_b * m_b)
        gam, w2 = c_b / (2 * m_b), k_b / m_b
        lam = (-w2 / (gam + math.sqrt(gam * gam - w2)), -(gam + math.sqrt(gam * gam - w2)))
        z = complex(rng.uniform(-1, 1), rng.uniform(-1, 1)) * 1e-4
        v = lam[rng.random() < 0.25] * z
        race = _race(m_b, k_b, c_b, z, v)
        s = rng.choice([0.0, rng.uniform(0.0, 3.0 / abs(lam[0]))])
        tau = rng.uniform(0.01, 2.0) / abs(lam[0])
        B = race.path_bounds(s, tau)
        A = mpmath.matrix([[0, 1], [-mpmath.mpf(k_b) / m_b, -mpmath.mpf(c_b) / m_b]])
        X0 = mpmath.matrix([[z.real, z.imag], [v.real, v.imag]])
        for t in np.linspace(s, s + tau, 17):
            X = mpmath.expm(A * mpmath.mpf(float(t))) * X0
            for k in range(5):
                mag = float(mpmath.sqrt(X[0, 0] ** 2 + X[0, 1] ** 2))
                assert mag <= B[k], (k, mag, B[k], m_b, k_b, c_b, s, tau, t)
                X = A * X


def test_heats_and_state_of_advance() -> None:
    """``advance`` moves the centre along ``path``; E_support is the support damper's
    dissipation int c_b |v_b|^2 dt (integrated with the motion by DOP853) to 1e-10."""
    m_b, k_b, c_b = SUPPORTS["under"]
    z0, v0 = complex(3e-5, 1e-5), complex(0.01, -0.02)
    race = _race(m_b, k_b, c_b, z0, v0)
    def rhs(t: float, y: np.ndarray) -> np.ndarray:  # the state and the heat c_b |v|^2
        x, yy, vx, vy, _ = y
        return np.array([vx, vy, -(k_b * x + c_b * vx) / m_b, -(k_b * yy + c_b * vy) / m_b,
                         c_b * (vx * vx + vy * vy)])

    s1, s2 = 1.3e-3, 2.1e-3
    c_expected = race.path(s1 + s2)[:2]
    race.advance(s1)
    race.advance(s2)
    assert abs(race.z_b - c_expected[0]) <= 1e-14 * _scales(m_b, k_b, z0, v0)[0]
    assert abs(race.v_b - c_expected[1]) <= 1e-13 * _scales(m_b, k_b, z0, v0)[1]
    sol = solve_ivp(rhs, (0.0, s1 + s2), [z0.real, z0.imag, v0.real, v0.imag, 0.0],
                    method="DOP853", rtol=1e-12, atol=1e-20)
    assert race.E_support == pytest.approx(sol.y[4, -1], rel=1e-10)
    assert race.E_drag == 0.0


def test_energy_and_angular_momentum_in_free_motion() -> None:
    """Over free motion the race's energy falls by exactly E_support + E_drag; with
    c_b = 0 and no drag, its angular momentum about the origin (the spring is central) is
    conserved to rounding (the references written out here)."""
    bp = BearingParams(race_turns=True, support_compliant=True, omega_b0=-40.0)
    race = RealRace(bp, c_r=C_R, R=R, z_b=complex(2e-5, 1e-5), v_b=complex(0.01, -0.03))
    E0 = (0.5 * bp.J_b * 40.0 ** 2 + 0.5 * bp.m_b * abs(race.v_b) ** 2
          + 0.5 * bp.k_b * abs(race.z_b) ** 2)
    assert race.energy() == pytest.approx(E0, rel=1e-15)
    for s in (1e-4, 3e-4, 2e-3):
        race.advance(s)
    assert race.energy() + race.E_support + race.E_drag == pytest.approx(E0, rel=1e-14)
    free = BearingParams(race_turns=True, support_compliant=True, c_b=0.0, T_b0=0.0,
                         c_bw=0.0, omega_b0=7.0)
    race = RealRace(free, c_r=C_R, R=R, z_b=complex(2e-5, 1e-5), v_b=complex(0.01, -0.03))
    L0 = free.m_b * (2e-5 * -0.03 - 1e-5 * 0.01) + free.J_b * 7.0
    assert race.angular_momentum() == pytest.approx(L0, rel=1e-15)
    for _ in range(50):
        race.advance(1.7e-4)
    assert race.angular_momentum() == pytest.approx(L0, rel=1e-12)


def _spin_reference(w0: float, t: float, J: float, T0: float, cw: float) -> float:
    """The docs' closed form, written out: s((|w0| + T0/cw) e^{-cw t/J} - T0/cw) until it
    stops, |w0| - T0 t/J at cw = 0, in mpmath at 40 digits."""
    mpmath.mp.dps = 40
    a, s = mpmath.mpf(abs(w0)), math.copysign(1.0, w0)
    t, J, T0, cw = (mpmath.mpf(x) for x in (t, J, T0, cw))
    if cw == 0:
        w = a - T0 * t / J
    elif T0 == 0:
        w = a * mpmath.exp(-cw * t / J)
    else:
        w = (a + T0 / cw) * mpmath.exp(-cw * t / J) - T0 / cw
    return s * float(max(w, 0))


@pytest.mark.parametrize("T0, cw", [(0.02, 1e-5), (0.02, 0.0), (0.0, 1e-5), (0.0, 0.0),
                                    (1e-4, 1e-8), (5.0, 1e-2)])
def test_spin_drag_law_and_stop_time(T0: float, cw: float) -> None:
    """omega_b(t) against the closed form (mpmath) and solve_ivp; the stop time against
    (J_b/c_bw) ln(1 + c_bw |w0|/T_b0) (J_b |w0|/T_b0 at c_bw = 0); held after it, with
    E_drag = 1/2 J_b w0^2 exactly then."""
    J, w0 = 2e-4, -183.0
    bp = BearingParams(race_turns=True, J_b=J, T_b0=T0, c_bw=cw, omega_b0=w0)
    race = RealRace(bp, c_r=C_R, R=R)
    assert not race.held and race.surface_speed(1j) == (R + C_R) * w0
    mpmath.mp.dps = 40
    if T0 == 0.0:
        t_stop_ref = math.inf
    elif cw == 0.0:
        t_stop_ref = J * abs(w0) / T0
    else:
        t_stop_ref = float(J / mpmath.mpf(cw) * mpmath.log(1 + mpmath.mpf(cw) * abs(w0) / T0))
    t_stop = race.spin_stop_time()
    assert t_stop == pytest.approx(t_stop_ref, rel=4e-16) if math.isfinite(t_stop_ref) \
        else t_stop == math.inf
    horizon = 1.5 * t_stop if math.isfinite(t_stop) else 3.0 * J / max(cw, 1e-6)
    ts = np.linspace(0.0, horizon, 31)
    for t in ts:
        ref = _spin_reference(w0, float(t), J, T0, cw)
        assert race.spin_at(float(t)) == pytest.approx(ref, rel=1e-14, abs=1e-14 * abs(w0))
    # an integration of J w' = -T0 sgn(w) - cw w up to the stop (event w = 0)
    t_int = min(horizon, 0.999 * t_stop) if math.isfinite(t_stop) else horizon
    sol = solve_ivp(lambda t, y: [(-T0 * np.sign(y[0]) - cw * y[0]) / J], (0.0, t_int),
                    [w0], method="DOP853", rtol=1e-12, atol=1e-12, t_eval=ts[ts <= t_int])
    for t, w in zip(sol.t, sol.y[0], strict=True):
        assert race.spin_at(float(t)) == pytest.approx(w, rel=1e-9, abs=1e-9)
    if math.isfinite(t_stop):
        assert abs(race.spin_at(t_stop * (1.0 - 1e-6))) > 0.0 and race.spin_at(t_stop) == 0.0
        exact = RealRace(bp, c_r=C_R, R=R)
        exact.advance(t_stop)  # exactly to the stop: held
        assert exact.held and exact.omega_b == 0.0 and exact.E_drag == 0.5 * J * w0 * w0
        race.advance(0.5 * t_stop)
        assert not race.held and race.drag_torque() != 0.0
        race.advance(t_stop)  # past the stop
        assert race.omega_b == 0.0 and race.held and race.drag_torque() == 0.0
        assert race.E_drag == pytest.approx(0.5 * J * w0 * w0, rel=1e-15)
        assert race.spin_at(1.0) == 0.0 and race.spin_stop_time() == 0.0
    else:
        race.advance(horizon)
        assert race.E_drag == pytest.approx(0.5 * J * (w0 ** 2 - race.omega_b ** 2),
                                            rel=1e-12)


# ------------------------------------------------------------------ impulses
def test_an_impulse_changes_the_race_momentum_exactly() -> None:
    """m_b dv_b = (P_n + i P_t) n and J_b d omega_b = R_b P_t to rounding; a held race
    turns under an impulse; the impulsive and sustained Delassus shares (10.8)."""
    rng = random.Random(7)
    for _ in range(500):
        bp = BearingParams(race_turns=True, support_compliant=True,
                           m_b=10 ** rng.uniform(-2, 3), J_b=10 ** rng.uniform(-6, 1),
                           omega_b0=rng.choice([0.0, rng.uniform(-300, 300)]))
        race = RealRace(bp, c_r=C_R, R=R, z_b=complex(1e-5, -2e-5), v_b=complex(0.1, 0.2))
        held0 = race.held
        R_b = R + C_R
        assert race.delassus(1j) == (1 / bp.m_b, 0.0, 1 / bp.m_b + R_b * R_b / bp.J_b)
        assert race.sustained_delassus(1j) == (
            (1 / bp.m_b, 0.0, 1 / bp.m_b) if held0 else race.delassus(1j))
        n = cmath.exp(1j * rng.uniform(-math.pi, math.pi))
        P_n, P_t = rng.uniform(0, 10), rng.uniform(-3, 3)
        v0, w0 = race.v_b, race.omega_b
        race.apply_impulse(P_n, P_t, n)
        P = complex(P_n, P_t) * n
        assert abs(bp.m_b * (race.v_b - v0) - P) <= 4e-16 * (bp.m_b * abs(v0) + abs(P))
        assert abs(bp.J_b * (race.omega_b - w0) - R_b * P_t) <= 4e-16 * (
            bp.J_b * abs(w0) + R_b * abs(P_t))
        assert race.held == (race.omega_b == 0.0)
    # options off: nothing moves or turns
    race = RealRace(BearingParams(), c_r=C_R, R=R, z_b=1e-5j, v_b=0.3, omega_b=50.0)
    race.apply_impulse(5.0, 2.0, 1j)
    race.advance(1e-3)
    assert (race.z_b, race.v_b, race.omega_b, race.held) == (0j, 0j, 0.0, True)
    assert (race.moves, race.rate, race.surface_speed(1j)) == (False, 0.0, 0.0)
    assert race.delassus(1j) == (0.0, 0.0, 0.0) and race.support_force() == 0j
    assert race.path(1e-3) == (0j, 0j, 0j, 0j) and race.path_bounds(0, 1) == (0.0,) * 5


def test_record_round_trip() -> None:
    bp = BearingParams(race_turns=True, support_compliant=True, omega_b0=12.5)
    race = RealRace(bp, c_r=C_R, R=R, z_b=complex(1e-5, -3e-6), v_b=complex(-0.01, 0.02))
    race.advance(3.7e-4)
    rec = json.loads(json.dumps({"kind": RealRace.KIND, **race.record()}))
    back = RealRace.from_record(bp, rec, c_r=C_R, R=R)
    assert back.record() == race.record()
    assert back.path(1e-3) == race.path(1e-3) and back.spin_at(0.1) == race.spin_at(0.1)
    assert set(rec) == {"kind", "x_b", "y_b", "vx_b", "vy_b", "omega_b", "held", "E_drag",
                        "E_support", "E_fric"}
    assert race.support_force() == bp.k_b * race.z_b + bp.c_b * race.v_b
    with pytest.raises(ValueError, match="fixed-rigid"):
        RealRace.from_record(bp, {**rec, "kind": "fixed-rigid"}, c_r=C_R, R=R)


# ------------------------------------------------------------------ contact law
def _cd_reference(d: float) -> mpmath.mpf:
    """The positive root of ln((1 + c)/(1 - c d)) = c (1 + d) at 60 digits."""
    mpmath.mp.dps = 60
    D = mpmath.mpf(d)
    if d > 0.3:
        def g(c: mpmath.mpf) -> mpmath.mpf:
            return (mpmath.log((1 + c) / (1 - c * D)) - c * (1 + D)) / (c * c)
        c0 = mpmath.mpf(1.5) * (1 - D * D) / (1 + D ** 3)
        return mpmath.findroot(g, (c0 / 4, (1 - mpmath.mpf(10) ** -40) / D),
                               solver="anderson")
    return mpmath.findroot(lambda c: c * D - 1 + (1 + c) * mpmath.exp(-c * (1 + D)), 1 / D)


def test_restitution_damping_digits_and_mpmath() -> None:
    """The docs' digits; over d in (0, 1] (uniform, near 1 down to 1 - 2^-53, near 0 down to
    1e-4), the relative error against mpmath stays within 16 ulp (measured 10.4 ulp)."""
    assert round(restitution_damping(0.95), 7) == 0.0789266
    assert round(restitution_damping(0.9), 7) == 0.1664820
    assert round(restitution_damping(0.5), 6) == 1.432751
    assert restitution_damping(1.0) == 0.0
    rng = random.Random(10)
    ds = ([rng.random() for _ in range(100)] + [1 - 10 ** -rng.uniform(1, 16) for _ in range(50)]
          + [10 ** -rng.uniform(0, 4) for _ in range(50)] + [0.3, 0.3 - 1e-12, 1e-3, 1 - 2 ** -53])
    worst = 0.0
    for d in ds:
        ref = _cd_reference(d)
        worst = max(worst, float(abs(restitution_damping(d) - ref) / ref))
    print(f"c_d: largest relative error {worst:.2e} ({worst / 2 ** -53:.1f} ulp)")
    assert worst <= 16 * 2 ** -53
    with pytest.raises(ValueError, match=r"d = 0\.0"):
        restitution_damping(0.0)


@pytest.mark.parametrize("p", [1.0, 1.5])
@pytest.mark.parametrize("d", [0.95, 0.9, 0.5, 0.2])
def test_single_compliant_impact_exits_with_d_v_in(p: float, d: float) -> None:
    """m x'' = -K x^p (1 + chi x'), chi = c_d/v_in, from x = 0, x' = v_in: DOP853 (rtol
    1e-13) leaves at -d v_in to 1e-9; the law's force matches the integrand."""
    m, k_c, v_in = 50.0, 1e9, 1.3
    K = k_c * DELTA_REF ** (1.0 - p)  # the docs' K, written out
    assert stiffness_coefficient(k_c, p) == pytest.approx(K, rel=1e-15)
    chi = restitution_damping(d) / v_in

    def rhs(t: float, y: list[float]) -> list[float]:
        x, xd = y
        return [xd, -K * max(x, 0.0) ** p * (1.0 + chi * xd) / m]

    def back(t: float, y: list[float]) -> float:
        return y[0]
    back.terminal, back.direction = True, -1.0

    t_max = 50.0 * math.sqrt(m / k_c) * (1e3 if p == 1.5 else 1.0)
    sol = solve_ivp(rhs, (0.0, t_max), [0.0, v_in], method="DOP853", rtol=1e-13,
                    atol=1e-18, events=back)
    assert sol.status == 1
    v_out = sol.y_events[0][0][1]
    assert -v_out / v_in == pytest.approx(d, abs=1e-9)
    for x, xd in zip(sol.y[0][1:-1], sol.y[1][1:-1], strict=True):
        want = K * x ** p * (1.0 + chi * xd)
        assert compliant_normal_force(x, xd, stiffness_coefficient(k_c, p), p, chi) == (
            pytest.approx(want, rel=1e-14))


def test_compliant_force_clamp_and_potential() -> None:
    K = stiffness_coefficient(1e9, 1.5)
    assert compliant_normal_force(0.0, 1.0, K, 1.5, 10.0) == 0.0
    assert compliant_normal_force(-1e-6, 1.0, K, 1.5, 10.0) == 0.0
    assert compliant_normal_force(1e-6, -1.0, K, 1.5, 10.0) == 0.0  # 1 + chi ddelta < 0
    assert compliant_normal_force(DELTA_REF, 0.0, K, 1.5, 0.0) == pytest.approx(
        1e9 * DELTA_REF, rel=1e-15)  # k_c is the secant stiffness at DELTA_REF
    assert contact_potential(2e-5, K, 1.5) == pytest.approx(K * (2e-5) ** 2.5 / 2.5,
                                                            rel=1e-15)
    assert contact_potential(0.0, K, 1.0) == 0.0


# ------------------------------------------------------------------ parameters
NUMERIC = ("J_b", "T_b0", "c_bw", "omega_b0", "m_b", "k_b", "c_b", "k_c", "p_c")


@pytest.mark.parametrize("name", NUMERIC)
def test_parameter_check_names_variable_value_unit_range(name: str) -> None:
    lim = LIMITS[name]
    BearingParams(**{name: lim.lo}).check(0.9)
    BearingParams(**{name: lim.hi}).check(0.9)
    for bad in (lim.hi * 10.0 + 1.0, lim.lo - max(1.0, abs(lim.lo)), math.nan):
        with pytest.raises(ParameterError) as err:
            BearingParams(**{name: bad}).check(0.9)
        msg = str(err.value)
        assert f"{name} = {bad!r}" in msg, msg
        if not math.isnan(bad):
            unit = "" if lim.unit == "1" else f" {lim.unit}"
            assert f"[{lim.lo:g}, {lim.hi:g}]{unit}" in msg, msg


def test_p_c_lies_in_its_interval_and_d_zero_is_refused_under_the_compliant_law() -> None:
    with pytest.raises(ParameterError, match=r"p_c = 1\.6 is out of range"):
        BearingParams(p_c=1.6).check(0.9)
    for p_c in (1.0, 10.0 / 9.0, 1.5):  # linear, Palmgren's line contact, Hertz
        BearingParams(p_c=p_c, contact_compliant=True).check(0.9)
    BearingParams().check(0.0)  # the rigid law takes d = 0
    with pytest.raises(CrossParameterError) as err:
        BearingParams(contact_compliant=True).check(0.0)
    msg = str(err.value)
    assert "d = 0.0" in msg and "(10.7)" in msg and "no root" in msg and "damping" in msg
    with pytest.raises(ParameterError, match=r"d = 1\.5 is out of range"):
        BearingParams().check(1.5)
    assert not BearingParams().any_option
    assert BearingParams(support_compliant=True).any_option


# ------------------------------------------------------------------ the contact search
@pytest.mark.parametrize("excess", [1e-6, 1e-9, -1e-9])
def test_flight_search_finds_a_grazing_contact_with_the_sprung_race(excess: float) -> None:
    """A rotor at rest at the origin (bearing off, no gravity, no imbalance) and a race
    thrown from its rest position with speed V along x on the drop's support (under-damped):
    its centre reaches c_r (1 + excess) at the first peak of V e^{-gam s} sin(wd s)/wd, so
    the gap closes only near it, tangentially as excess -> 0. ``SpinFlight(..., bearing=
    RealRace)`` finds the first contact at the root of that closed form (brentq, written
    out here), and none for excess < 0; without the path's bounds it steps past it."""
    from rotortd.params import RotorParams
    from rotortd.segments.spin_flight import SpinFlight
    from scipy.optimize import brentq

    p = RotorParams(e_c=0.0, g=0.0)
    m_b, k_b, c_b = SUPPORTS["under"]
    gam = c_b / (2 * m_b)
    wd = math.sqrt(k_b / m_b - gam * gam)

    def g(s: float) -> float:
        return math.exp(-gam * s) * math.sin(wd * s) / wd

    s_peak = math.atan2(wd, gam) / wd
    V = p.c_r * (1.0 + excess) / g(s_peak)
    race = RealRace(BearingParams(support_compliant=True, m_b=m_b, k_b=k_b, c_b=c_b),
                    c_r=p.c_r, R=p.R, v_b=complex(V, 0.0))
    rem = 2.0 * s_peak
    end = SpinFlight(p, 0.04, a=0.0, F_ext=0j, T_drive=0.0, z=0j, v=0j, psi=0.0, Omega=0.0,
                     bearing=race).run(rem)
    if excess < 0.0:
        assert end.event is None and end.duration == rem
        return
    s_true = brentq(lambda s: V * g(s) - p.c_r, 0.0, s_peak, xtol=1e-300, rtol=8.9e-16)
    rdot = V * math.exp(-gam * s_true) * (math.cos(wd * s_true) - gam * math.sin(
        wd * s_true) / wd)  # the centre's speed at the crossing
    assert end.event == "contact"
    err = abs(end.duration - s_true) / (2.2e-16 * (p.c_r / rdot + s_true))
    print(f"excess {excess:g}: contact time error {err:.2f} eps (c_r/rdot + s)")
    assert err <= 64.0, (end.duration, s_true)

    class Blind(RealRace):  # the same race without its path's bounds
        __slots__ = ()

        def path_bounds(self, s: float, tau: float) -> tuple[float, ...]:
            return (0.0, 0.0, 0.0, 0.0, 0.0)

    blind = Blind(race.bp, c_r=p.c_r, R=p.R, v_b=complex(V, 0.0))
    missed = SpinFlight(p, 0.04, a=0.0, F_ext=0j, T_drive=0.0, z=0j, v=0j, psi=0.0,
                        Omega=0.0, bearing=blind).run(rem)
    assert missed.event is None  # the bounds are what makes the search find it
