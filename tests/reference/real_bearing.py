"""Independent reference for the real touchdown bearing (docs/model.md §10).

The rotor (one rigid body, the spin a state, docs/model.md §8) meets a bearing whose race
turns (``race_turns``: ``J_b``, bore ``R_b = R + c_r``, drag ``T_b0 sgn(omega_b) + c_bw
omega_b``, static friction at rest), whose race centre sits on a spring-damper support
(``support_compliant``: ``m_b``, ``k_b``, ``c_b``) and whose contact is compliant
(``contact_compliant``: ``N = max(0, K delta^p (1 + chi delta'))``, ``K = k_c delta_ref^(1-p)``,
``delta_ref`` = 10 um, ``p`` in {1, 3/2}, ``chi = c_d(d)/max(v_in, v_floor)``). It imports
nothing from ``fmu_src`` / ``rotortd`` and shares no code with the other references: every
equation is coded here again from docs/model.md §10. SI units, inertial frame, planar vectors
as complex numbers.

What it offers:

* (a) closed forms: :func:`c_d` (the exact damping constant of the contact law, mpmath root to
  30 digits), :func:`flores_c_d`, :func:`single_impact` (peak force, maximal penetration,
  duration and exit speed of an isolated compliant impact, exact for every ``d`` from the
  law's energy integral), :func:`catch_up` (the race catching up under a steady load),
  :func:`rigid_impact_sprung` and :func:`pair_impact` (rigid impacts on a moving, turning race
  through the Delassus matrix of the pair), :func:`support_free` and :func:`race_drag_free`
  (the race and its support in free motion);
* (b) :func:`simulate`: a direct integrator of the whole system under the compliant law (scipy
  DOP853, ``rtol`` 1e-12 by default, dense output) with located events: contact closing,
  opening and grazing, the normal force clamping at zero, slip zero, the friction cone, the
  race stopping and breaking away, and the peaks of the normal force;
* (c) :func:`energy_terms` and :func:`momentum_terms`: the balances of energy and angular
  momentum about the support's anchor along a trajectory, from the integrated dissipations,
  works and torques carried as extra components;
* (d) :func:`black_whirls`: Black's problem (spin held, ``e_c = g = 0``): the steady rolling and
  sliding whirls of the two-mass system with their existence and the eigenvalues of their
  linearisation;
* :func:`drop_scene`: the drop of issue 24 (the chapter's rotor from its levitated whirl at
  184.2 rad/s, the bearing failed at t = 0).

Error of the integrator: each phase is one DOP853 run at ``rtol`` with ``atol = rtol *
scale`` per component (positions ``c_r``, velocities ``c_r w``, angles 1 rad, speeds ``w``,
energies ``m (c_r w)^2``, with ``w = max(|Omega0|, sqrt(k/m), 1 rad/s)``); events are located on
the dense output to 4 ulp of time by scipy's root finder. ``max_step`` is a quarter of the
fastest period (contact, support, spin, whirl), so that no event pair is stepped over. A graze
of the contact (``delta`` rising above 0 and back within one step) is found on every open step
from the sign change of ``delta'`` and located by brentq. The error is measured, not assumed:
the balances close to the integrator's tolerance, and rtol 1e-11 against 1e-12 gives the
spread quoted in docs/model.md §10.
"""

from __future__ import annotations

import cmath
import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import cache
from typing import Any

import mpmath
import numpy as np
from scipy.integrate import solve_ivp
from scipy.linalg import expm
from scipy.optimize import brentq, minimize_scalar

DELTA_REF = 1e-5
"""Reference penetration [m] at which ``k_c`` is the contact stiffness."""
V_FLOOR = 1e-3
"""Default floor [m/s] of the approach speed that sets the contact damping chi."""
RIGID_V_MIN = 1e-6
"""Rigid law: an impact slower than this [m/s] stops the run (sustained contact follows)."""

NY = 22
"""Length of the state vector (see :data:`STATE`)."""
STATE = ("x", "y", "vx", "vy", "psi", "Omega", "xb", "yb", "vxb", "vyb", "omega_b",
         "E_amb", "E_sup", "E_drag", "E_cdamp", "E_fric", "W_drive", "W_ext", "W_bias",
         "L_ext", "P_n", "L_couple")
"""Components: rotor centre, velocity, spin angle and speed; race centre, velocity, spin;
then the integrals: AMB damper, support damper and race-drag heat, contact damping, contact
friction heat [J], work of T_drive, F_ext, a F_bias [J], the external angular impulse about
the origin [N m s], the normal impulse [N s], and the contact couple's angular impulse
``int -delta F_t dt`` [N m s]."""


# --------------------------------------------------------------------------------------------
# Parameters
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Par:
    """Rotor, bearing and held inputs (SI).

    Rotor (docs/model.md §8): m [kg], c [N s/m], k [N/m], e_c [m], phi [rad], c_r [m], R [m],
    mu, d, g [m/s^2], levitate, J [kg m^2]. Bearing (docs/model.md §10): race_turns, J_b
    [kg m^2], T_b0 [N m], c_bw [N m s]; support_compliant, m_b [kg], k_b [N/m], c_b [N s/m];
    k_c [N/m, at delta_ref], p_c (1 or 1.5), v_floor [m/s]. Held inputs: a (AMB state),
    F_ext [N] at the geometric centre (without gravity), T_drive [N m].
    """

    m: float = 50.0
    c: float = 1400.0
    k: float = 9.8e5
    e_c: float = 0.3e-3
    phi: float = 0.21
    c_r: float = 0.7e-3
    R: float = 0.04
    mu: float = 0.15
    d: float = 0.9
    g: float = 9.81
    levitate: bool = True
    J: float = 0.04
    race_turns: bool = True
    J_b: float = 2e-4
    T_b0: float = 0.02
    c_bw: float = 1e-5
    support_compliant: bool = True
    m_b: float = 2.0
    k_b: float = 5e7
    c_b: float = 2e3
    contact_compliant: bool = True
    k_c: float = 1e9
    p_c: float = 1.0
    v_floor: float = V_FLOOR
    a: float = 0.0
    F_ext: complex = 0j
    T_drive: float = 0.0

    def __post_init__(self) -> None:
        if self.p_c not in (1.0, 1.5):
            raise ValueError(f"p_c = {self.p_c!r} must be 1 or 1.5")
        if self.contact_compliant and not 0.0 < self.d <= 1.0:
            raise ValueError(f"d = {self.d!r} must lie in (0, 1] under the compliant law")
        if not 0.0 <= self.d <= 1.0:
            raise ValueError(f"d = {self.d!r} must lie in [0, 1]")
        for name in ("m", "c_r", "R", "J", "k_c", "v_floor"):
            if not getattr(self, name) > 0.0:
                raise ValueError(f"{name} = {getattr(self, name)!r} must be > 0")
        if self.race_turns and not self.J_b > 0.0:
            raise ValueError(f"J_b = {self.J_b!r} kg m^2 must be > 0 when the race turns")
        if self.support_compliant and not self.m_b > 0.0:
            raise ValueError(f"m_b = {self.m_b!r} kg must be > 0 with a compliant support")

    @property
    def R_b(self) -> float:
        """Bore radius of the race [m]."""
        return self.R + self.c_r

    @property
    def K(self) -> float:
        """Contact coefficient ``k_c delta_ref^(1-p)`` [N/m^p]."""
        return self.k_c * DELTA_REF ** (1.0 - self.p_c)

    @property
    def F_bias(self) -> complex:
        """AMB bias force [N] (scaled by a): i m g when levitating."""
        return 1j * self.m * self.g if self.levitate else 0j

    def with_(self, **kw: Any) -> Par:
        """A copy with changes."""
        return replace(self, **kw)


def _sgn(x: float) -> float:
    x = float(x)
    return float((x > 0.0) - (x < 0.0))


# --------------------------------------------------------------------------------------------
# (a) Closed forms
# --------------------------------------------------------------------------------------------


@cache
def c_d_mp(d: float, dps: int = 30) -> mpmath.mpf:
    """The positive root ``c`` of ``ln((1 + c)/(1 - c d)) = c (1 + d)`` (0 at d = 1), mpmath.

    Found by bisection-safe Anderson on ``(0, 1/d)`` after a series start; returned to ``dps``
    digits (the equation's residual below 10^-dps of ``c^3``).
    """
    if not 0.0 < d <= 1.0:
        raise ValueError(f"d = {d!r} has no damping constant: it must lie in (0, 1]")
    if d == 1.0:
        return mpmath.mpf(0)
    with mpmath.workdps(dps + 10):
        dd = mpmath.mpf(d)

        def f(c: Any) -> Any:
            return (mpmath.log1p(c) - mpmath.log1p(-c * dd)) / c**2 - (1 + dd) / c

        lo = mpmath.mpf("1e-30")
        hi = (1 - mpmath.mpf("1e-30")) / dd
        # f < 0 near 0 for d < 1 (f ~ (d^2 - 1)/2), f -> +inf at 1/d: bracket and bisect-secant.
        root = mpmath.findroot(f, (lo, hi), solver="anderson", tol=mpmath.mpf(10) ** (-dps - 5))
        return +root


def c_d(d: float) -> float:
    """The damping constant ``c_d(d)`` of docs/model.md §10 as a float (correctly rounded)."""
    return float(c_d_mp(d))


def flores_c_d(d: float) -> float:
    """Flores et al.'s approximation ``8 (1 - d)/(5 d)`` of ``c_d`` (for comparison only)."""
    return 8.0 * (1.0 - d) / (5.0 * d)


def restitution_of(c: float) -> float:
    """The restitution an isolated impact gets from the damping constant ``c`` = chi v_in:
    the root ``e`` in [0, 1) of ``c - ln(1 + c) = -c e - ln(1 - c e)`` (the energy integral)."""
    if c == 0.0:
        return 1.0
    target = c - math.log1p(c)

    def h(e: float) -> float:
        return -c * e - math.log1p(-c * e) - target

    hi = min(1.0, (1.0 - 1e-15) / c)
    return brentq(h, 0.0, hi, xtol=1e-16, rtol=4 * np.finfo(float).eps)


@dataclass(frozen=True)
class SingleImpact:
    """An isolated normal compliant impact: peak force N_max [N] and its time t_peak [s],
    maximal penetration delta_max [m] (reached at t_max [s]), duration T [s] (delta > 0;
    the force never clamps), exit speed v_out [m/s] (= d v_in)."""

    N_max: float
    t_peak: float
    delta_max: float
    t_max: float
    T: float
    v_out: float


def single_impact(m_eff: float, v_in: float, k_c: float, p: float, d: float, dps: int = 20
                  ) -> SingleImpact:
    """Exact single-impact figures of ``m_eff delta'' = -K delta^p (1 + chi delta')``,
    ``chi = c_d(d)/v_in``, from the law's energy integral (no time stepping):

    with ``u = chi v`` and ``G(u) = (u - ln(1 + u))/chi^2``, ``G(chi v) = G(chi v_in) - K
    delta^(p+1)/(m (p+1))`` along the impact, so ``delta_max^(p+1) = (p+1) m G(c)/K``, the exit
    ``G(chi v_out) = G(c)`` gives ``v_out = -d v_in``; the time is ``int dv/(K delta(v)^p
    (1 + chi v)/m)`` (tanh-sinh quadrature, 30 digits) and the peak force maximises
    ``K delta^p (1 + chi v)`` over the compression branch. At d = 1 these are the undamped
    forms (p = 1: ``T = pi sqrt(m/k_c)``; p = 3/2: ``T = 2.9432752 delta_max/v_in``).
    """
    K = k_c * DELTA_REF ** (1.0 - p)
    with mpmath.workdps(dps):
        c = +c_d_mp(d)
        mm, vi, KK, pp = (mpmath.mpf(x) for x in (m_eff, v_in, K, p))
        if c == 0:
            def G(v: Any) -> Any:
                return v * v / 2
        else:
            chi = c / vi

            def G(v: Any) -> Any:
                u = chi * v
                return (u - mpmath.log1p(u)) / chi**2
        Gin = G(vi)
        dmax = ((pp + 1) * mm * Gin / KK) ** (1 / (pp + 1))
        chi_ = c / vi
        vout = -mpmath.mpf(d) * vi

        def gdiff_in(w: Any) -> Any:
            """G(v_in) - G(v_in - w), without cancellation at w -> 0."""
            if c == 0:
                return w * (2 * vi - w) / 2
            u = chi_ * (vi - w)
            return (chi_ * w - mpmath.log1p(chi_ * w / (1 + u))) / chi_**2

        def gdiff_out(w: Any) -> Any:
            """G(v_out) - G(v_out + w) (= G(v_in) - G(v) on the restitution branch)."""
            if c == 0:
                return w * (2 * (-vout) - w) / 2
            u = chi_ * (vout + w)
            return (-chi_ * w - mpmath.log1p(-chi_ * w / (1 + u))) / chi_**2

        def rate(gd: Any, v: Any) -> Any:
            x = ((pp + 1) * mm * gd / KK) ** (1 / (pp + 1))
            return mm / (KK * x**pp * (1 + chi_ * v))

        def delta_of(v: Any) -> Any:
            return ((pp + 1) * mm * gdiff_in(vi - v) / KK) ** (1 / (pp + 1))

        t_max = mpmath.quad(lambda w: rate(gdiff_in(w), vi - w), [0, vi])
        T = t_max + mpmath.quad(lambda w: rate(gdiff_out(w), vout + w), [0, -vout])

        def negN(v: float) -> float:
            return -float(KK * delta_of(mpmath.mpf(v)) ** pp * (1 + chi_ * v))

        # the peak lies on the compression branch (v > 0) for d < 1, at v = 0 for d = 1
        if c == 0:
            vpk = mpmath.mpf(0)
        else:
            res = minimize_scalar(negN, bounds=(0.0, float(vi)), method="bounded",
                                  options={"xatol": 1e-14 * float(vi)})
            vpk = mpmath.mpf(res.x)
            if negN(0.0) < res.fun:
                vpk = mpmath.mpf(0)
        N_max = -negN(float(vpk))
        t_peak = (mpmath.quad(lambda w: rate(gdiff_in(w), vi - w), [0, vi - vpk])
                  if vpk < vi else mpmath.mpf(0))
        return SingleImpact(N_max=float(N_max), t_peak=float(t_peak), delta_max=float(dmax),
                            t_max=float(t_max), T=float(T), v_out=float(vout))


HERTZ_DURATION = float(2 * mpmath.mpf(2) / 5 * mpmath.beta(mpmath.mpf(2) / 5, mpmath.mpf(1) / 2))
"""``T v_in/delta_max`` of an undamped Hertz impact: ``(4/5) B(2/5, 1/2)`` = 2.9432752..."""


def catch_up(par: Par, N: float, Omega0: float, omega_b0: float = 0.0) -> tuple[float, float]:
    """(t* [s], common surface speed [m/s]) of a rotor held at rest on a turning race by a
    steady load at the friction angle (rigid support, e_c = 0, c_bw = 0, break-away
    ``R_b mu N > T_b0``): ``t* = (R Omega0 - R_b omega_b0)/(R (R mu N - T_drive)/J
    + R_b (R_b mu N - T_b0)/J_b)``."""
    R, Rb, mu = par.R, par.R_b, par.mu
    rate = R * (R * mu * N - par.T_drive) / par.J + Rb * (Rb * mu * N - par.T_b0) / par.J_b
    ts = (R * Omega0 - Rb * omega_b0) / rate
    return ts, R * (Omega0 + (par.T_drive - R * mu * N) / par.J * ts)


def stick_force_after_catch_up(par: Par, N: float) -> float:
    """The static friction [N] that keeps the slip at zero right after t* in the catch-up
    scene: the rotor's centre then starts to move along the race (it is free to), and
    ``F_t = (mu N/m + R T_drive/J + R_b T_b0/J_b)/(1/m + R^2/J + R_b^2/J_b)`` (< mu N
    exactly when the slip was falling before t*)."""
    R, Rb = par.R, par.R_b
    return ((par.mu * N / par.m + R * par.T_drive / par.J + Rb * par.T_b0 / par.J_b)
            / (1.0 / par.m + R * R / par.J + Rb * Rb / par.J_b))


def rigid_impact_sprung(m: float, m_b: float, d: float, rdot: float) -> tuple[float, float]:
    """Normal speeds after a rigid frictionless impact (e_c = 0) on a race at rest on its
    support: (rotor's ``rdot (m - d m_b)/(m + m_b)``, race's ``rdot (1 + d) m/(m + m_b)``)."""
    return rdot * (m - d * m_b) / (m + m_b), rdot * (1.0 + d) * m / (m + m_b)


def pair_delassus(par: Par, beta: float) -> tuple[float, float, float]:
    """(W_nn, W_nt, W_tt) [1/kg] of the rotor-race pair at ``beta = psi + phi - arg(z - z_b)``:
    the rotor's ``I/m + a a^T/J``, ``a = (e_c sin beta, R - e_c cos beta)``, plus the race's
    ``diag(1/m_b, 1/m_b + R_b^2/J_b)`` (each term only with its option on)."""
    B = par.e_c * math.sin(beta)
    A = par.R - par.e_c * math.cos(beta)
    wnn = 1.0 / par.m + B * B / par.J
    wnt = A * B / par.J
    wtt = 1.0 / par.m + A * A / par.J
    if par.support_compliant:
        wnn += 1.0 / par.m_b
        wtt += 1.0 / par.m_b
    if par.race_turns:
        wtt += par.R_b**2 / par.J_b
    return wnn, wnt, wtt


def _law(w: tuple[float, float, float], mu: float, de: float, rd: float, s: float
         ) -> tuple[float, float, float, bool, float]:
    """Newton + Coulomb with the slip after the impact: (P_n, P_t, v_rel+, stick, dT)."""
    wnn, wnt, wtt = w
    D = (1.0 + de) * rd
    det = wnn * wtt - wnt * wnt
    pn = (wtt * D - wnt * s) / det
    pt = (wnn * s - wnt * D) / det
    if pn >= 0.0 and abs(pt) <= mu * pn:
        vr, stick = 0.0, True
    else:
        sig = 1.0 if pt >= 0.0 else -1.0
        pn = D / (wnn + mu * sig * wnt)
        pt = mu * sig * pn
        vr, stick = s - (wnt * pn + wtt * pt), False
    dT = -(pn * (rd - de * rd) + pt * (s + vr)) / 2.0
    return pn, pt, vr, stick, dT


def pair_impact(par: Par, y: np.ndarray) -> tuple[np.ndarray, dict[str, float]]:
    """A rigid impact on the moving, turning race at the state ``y`` (on the circle
    ``|z - z_b| = c_r``, approaching): Newton restitution ``d`` on ``delta'``, Coulomb ``mu``
    with the slip after the impact through the pair's Delassus matrix, the restitution lowered
    (60 halvings) to the largest value that creates no energy. Returns the new state and
    ``{P_n, P_t, d_eff, dT, stick}``; the rotor gets ``-(P_n + i P_t) n`` at ``z + R n``, the
    race ``+(P_n + i P_t) n`` at ``z_b + R_b n``."""
    y = np.array(y, dtype=float)
    z, v, psi, Om = complex(y[0], y[1]), complex(y[2], y[3]), y[4], y[5]
    zb, vb, wb = complex(y[6], y[7]), complex(y[8], y[9]), y[10]
    D = z - zb
    n = D / abs(D)
    th = cmath.phase(n)
    beta = psi + par.phi - th
    w = pair_delassus(par, beta)
    rd = (n.conjugate() * (v - vb)).real
    s = par.R * Om + (n.conjugate() * (v - vb)).imag - par.R_b * wb
    de = par.d
    res = _law(w, par.mu, de, rd, s)
    if res[4] > 0.0:
        lo, hi = 0.0, de
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            if _law(w, par.mu, mid, rd, s)[4] <= 0.0:
                lo = mid
            else:
                hi = mid
        de = lo
        res = _law(w, par.mu, de, rd, s)
    pn, pt, _vr, stick, dT = res
    B = par.e_c * math.sin(beta)
    A = par.R - par.e_c * math.cos(beta)
    dOm = -(B * pn + A * pt) / par.J
    E = cmath.exp(1j * (psi + par.phi))
    P = complex(pn, pt) * n
    v2 = v - P / par.m - 1j * par.e_c * E * dOm
    y[2], y[3], y[5] = v2.real, v2.imag, Om + dOm
    if par.support_compliant:
        vb2 = vb + P / par.m_b
        y[8], y[9] = vb2.real, vb2.imag
    if par.race_turns:
        y[10] = wb + par.R_b * pt / par.J_b
    return y, {"P_n": pn, "P_t": pt, "d_eff": de, "dT": dT, "stick": float(stick)}


def support_free(zb0: complex, vb0: complex, t: float, m_b: float, k_b: float, c_b: float
                 ) -> tuple[complex, complex]:
    """The race centre in free motion (contact open): the isotropic damped oscillator
    ``m_b z_b'' + c_b z_b' + k_b z_b = 0`` in closed form (2x2 matrix exponential)."""
    A = np.array([[0.0, 1.0], [-k_b / m_b, -c_b / m_b]])
    M = expm(A * t)
    x = M @ np.array([zb0.real, vb0.real])
    yv = M @ np.array([zb0.imag, vb0.imag])
    return complex(x[0], yv[0]), complex(x[1], yv[1])


def race_drag_free(omega0: float, t: float, J_b: float, T_b0: float, c_bw: float) -> float:
    """The race speed [rad/s] under its drag alone, ``J_b omega' = -T_b0 sgn(omega) - c_bw
    omega``, held at 0 once it stops: ``(omega0 + s T_b0/c_bw) e^{-c_bw t/J_b} - s T_b0/c_bw``
    until ``t_stop = (J_b/c_bw) ln(1 + c_bw |omega0|/T_b0)`` (``|omega0| - T_b0 t/J_b`` at
    c_bw = 0)."""
    s = _sgn(omega0)
    w = abs(omega0)
    if c_bw == 0.0:
        return s * max(0.0, w - T_b0 * t / J_b)
    t_stop = (J_b / c_bw) * math.log1p(c_bw * w / T_b0) if T_b0 > 0 else math.inf
    if t >= t_stop:
        return 0.0
    a = c_bw / J_b
    return s * ((w + T_b0 / c_bw) * math.exp(-a * t) - T_b0 / c_bw)


# --------------------------------------------------------------------------------------------
# (b) The direct integrator (compliant law)
# --------------------------------------------------------------------------------------------


@dataclass
class Mode:
    """The discrete state: contact closed, force clamped at 0, friction stick or slip sign s,
    race held by static friction or turning in direction sigma, and the contact's chi [s/m]."""

    contact: bool = False
    clamped: bool = False
    stick: bool = False
    s: float = 0.0
    held: bool = True
    sigma: float = 0.0
    chi: float = 0.0

    def name(self) -> str:
        """Short label: free / slide± / stick / clamped, with the race's state."""
        if not self.contact:
            c = "free"
        elif self.clamped:
            c = "clamped"
        elif self.stick:
            c = "stick"
        else:
            c = "slide+" if self.s > 0 else ("slide-" if self.s < 0 else "slide0")
        return c + ("/race-held" if self.held else "/race-turning")


@dataclass
class Kin:
    """Kinematics of a state: centres, speeds, n, delta, delta', slip and whirl rate."""

    z: complex
    v: complex
    psi: float
    Om: float
    zb: complex
    vb: complex
    wb: float
    n: complex
    dist: float
    delta: float
    ddelta: float
    thd: float
    vrel: float


def kin(par: Par, y: np.ndarray) -> Kin:
    """The contact kinematics of docs/model.md §10 at the state ``y``."""
    z = complex(y[0], y[1])
    v = complex(y[2], y[3])
    zb = complex(y[6], y[7])
    vb = complex(y[8], y[9])
    D = z - zb
    dist = abs(D)
    n = D / dist if dist > 0.0 else 1.0 + 0j
    rel = n.conjugate() * (v - vb)
    return Kin(z=z, v=v, psi=float(y[4]), Om=float(y[5]), zb=zb, vb=vb, wb=float(y[10]),
               n=n, dist=dist, delta=dist - par.c_r, ddelta=rel.real,
               thd=rel.imag / dist if dist > 0.0 else 0.0,
               vrel=par.R * float(y[5]) + rel.imag - par.R_b * float(y[10]))


class Model:
    """Forces and accelerations of the compliant system (docs/model.md §10, eqs. (10.1)-(10.5))."""

    def __init__(self, par: Par) -> None:
        self.p = par

    def normal(self, k: Kin, mode: Mode) -> tuple[float, float]:
        """(N, N_el) [N]: the contact force and its elastic part ``K delta^p``."""
        p = self.p
        if not mode.contact or k.delta <= 0.0:
            return 0.0, 0.0
        nel = p.K * k.delta**p.p_c
        if mode.clamped:
            return 0.0, nel
        return max(0.0, nel * (1.0 + mode.chi * k.ddelta)), nel

    def drag(self, k: Kin, mode: Mode) -> float:
        """Race drag T_b [N m] while turning (direction sigma)."""
        return -self.p.T_b0 * mode.sigma - self.p.c_bw * k.wb

    def acc(self, k: Kin, mode: Mode, N: float, Ft: float
            ) -> tuple[complex, float, complex, float, float]:
        """(z'', Omega', z_b'', omega_b', v_rel') for the contact force ``-(N + i F_t) n``."""
        p = self.p
        E = cmath.exp(1j * (k.psi + p.phi))
        famb = p.a * (p.F_bias - p.c * k.v - p.k * k.z)
        fc = -complex(N, Ft) * k.n
        fg = famb + p.F_ext + fc
        omd = (p.T_drive - p.R * Ft + p.e_c * (fg.conjugate() * E).imag) / p.J
        zdd = (fg - 1j * p.m * p.g) / p.m + p.e_c * complex(k.Om * k.Om, -omd) * E
        zbdd = (-p.k_b * k.zb - p.c_b * k.vb - fc) / p.m_b if p.support_compliant else 0j
        turning = p.race_turns and not mode.held
        wbd = (p.R_b * Ft + self.drag(k, mode)) / p.J_b if turning else 0.0
        vrd = (p.R * omd + (k.n.conjugate() * (zdd - zbdd)).imag - k.thd * k.ddelta
               - p.R_b * wbd)
        return zdd, omd, zbdd, wbd, vrd

    def stick_force(self, k: Kin, mode: Mode, N: float) -> float:
        """The tangential force [N] that keeps ``v_rel' = 0`` (the equations are affine in F_t)."""
        a0 = self.acc(k, mode, N, 0.0)[4]
        a1 = self.acc(k, mode, N, 1.0)[4]
        return -a0 / (a1 - a0)

    def forces(self, k: Kin, mode: Mode) -> tuple[float, float, float]:
        """(N, N_el, F_t) in the mode."""
        N, nel = self.normal(k, mode)
        if N <= 0.0:
            return N, nel, 0.0
        if mode.stick:
            return N, nel, self.stick_force(k, mode, N)
        return N, nel, self.p.mu * mode.s * N

    def rhs(self, mode: Mode) -> Callable[[float, np.ndarray], np.ndarray]:
        """Right-hand side of the state of :data:`STATE` in the mode."""
        p = self.p

        def f(t: float, y: np.ndarray) -> np.ndarray:
            k = kin(p, y)
            N, nel, Ft = self.forces(k, mode)
            zdd, omd, zbdd, wbd, _ = self.acc(k, mode, N, Ft)
            famb = p.a * (p.F_bias - p.c * k.v - p.k * k.z)
            zG = k.z + p.e_c * cmath.exp(1j * (k.psi + p.phi))
            if p.race_turns:
                Tb = self.drag(k, mode) if not mode.held else -p.R_b * Ft
            else:
                Tb = -p.R_b * Ft
            delta = max(k.delta, 0.0) if mode.contact else 0.0
            out = np.empty(NY)
            out[0], out[1], out[2], out[3] = k.v.real, k.v.imag, zdd.real, zdd.imag
            out[4], out[5] = k.Om, omd
            out[6], out[7], out[8], out[9] = k.vb.real, k.vb.imag, zbdd.real, zbdd.imag
            out[10] = wbd
            out[11] = p.a * p.c * abs(k.v) ** 2
            out[12] = p.c_b * abs(k.vb) ** 2 if p.support_compliant else 0.0
            out[13] = -self.drag(k, mode) * k.wb if (p.race_turns and not mode.held) else 0.0
            out[14] = (N - nel) * k.ddelta if mode.contact else 0.0
            out[15] = Ft * k.vrel
            out[16] = p.T_drive * k.Om
            out[17] = (p.F_ext.conjugate() * k.v).real
            out[18] = p.a * (p.F_bias.conjugate() * k.v).real
            out[19] = (p.T_drive + (k.z.conjugate() * (famb + p.F_ext)).imag
                       - p.m * p.g * zG.real
                       - (p.c_b * (k.zb.conjugate() * k.vb).imag if p.support_compliant else 0.0)
                       + Tb)
            out[20] = N
            out[21] = -delta * Ft
            return out

        return f

    def dNdt(self, k: Kin, mode: Mode) -> float:
        """dN/dt [N/s] in an unclamped contact (for the peaks of N)."""
        p = self.p
        N, nel, Ft = self.forces(k, mode)
        zdd, _, zbdd, _, _ = self.acc(k, mode, N, Ft)
        dd2 = (k.n.conjugate() * (zdd - zbdd)).real + k.dist * k.thd**2
        pp = p.p_c
        dnel = p.K * pp * k.delta ** (pp - 1.0) * k.ddelta
        return dnel * (1.0 + mode.chi * k.ddelta) + nel * mode.chi * dd2


def energy(par: Par, y: np.ndarray) -> float:
    """Mechanical energy [J]: kinetic energies of rotor (mass centre and spin) and race,
    ``1/2 a k |z|^2``, ``m g Im(z_G)``, ``1/2 k_b |z_b|^2`` and the contact's ``V_c``."""
    k = kin(par, y)
    E = cmath.exp(1j * (k.psi + par.phi))
    vG = k.v + 1j * k.Om * par.e_c * E
    zG = k.z + par.e_c * E
    T = 0.5 * par.m * abs(vG) ** 2 + 0.5 * par.J * k.Om**2
    T += 0.5 * par.m_b * abs(k.vb) ** 2 + 0.5 * (par.J_b if par.race_turns else 0.0) * k.wb**2
    V = 0.5 * par.a * par.k * abs(k.z) ** 2 + par.m * par.g * zG.imag
    V += 0.5 * par.k_b * abs(k.zb) ** 2
    if k.delta > 0.0 and par.contact_compliant:
        V += par.K * k.delta ** (par.p_c + 1.0) / (par.p_c + 1.0)
    return T + V


def momentum(par: Par, y: np.ndarray) -> float:
    """Angular momentum [N m s] about the support's anchor (the origin)."""
    k = kin(par, y)
    E = cmath.exp(1j * (k.psi + par.phi))
    vG = k.v + 1j * k.Om * par.e_c * E
    zG = k.z + par.e_c * E
    L = par.m * (zG.conjugate() * vG).imag + par.J * k.Om
    L += par.m_b * (k.zb.conjugate() * k.vb).imag
    if par.race_turns:
        L += par.J_b * k.wb
    return L


@dataclass
class Result:
    """A trajectory: grid samples (``t``, ``y``, ``modes``), contact intervals (``contacts``:
    t_close, t_open, v_in, v_out, N_peak), located peaks of N (``peaks``) and N at phase ends
    in contact (``boundary_N``), mode transitions, rigid impacts, the final state."""

    t: np.ndarray
    y: np.ndarray
    modes: list[str]
    contacts: list[dict[str, float]] = field(default_factory=list)
    peaks: list[tuple[float, float]] = field(default_factory=list)
    transitions: list[tuple[float, str]] = field(default_factory=list)
    y_end: np.ndarray | None = None
    t_end: float = 0.0
    nfev: int = 0
    phases: int = 0
    impacts: list[dict[str, float]] = field(default_factory=list)
    status: str = "ok"
    boundary_N: list[tuple[float, float]] = field(default_factory=list)

    @property
    def N_peak(self) -> float:
        """Largest normal force [N]: located peaks (zeros of dN/dt) and the values at phase
        ends in contact (0 without contact)."""
        return max((n for _, n in self.peaks + self.boundary_N), default=0.0)

    def first(self, label: str) -> float | None:
        """Time of the first transition whose mode name starts with ``label``."""
        return next((t for t, nm in self.transitions if nm.startswith(label)), None)


class Simulator:
    """The event-driven integration (one DOP853 run per phase between events)."""

    def __init__(self, par: Par, rtol: float = 1e-12, w: float | None = None) -> None:
        self.p = par
        self.md = Model(par)
        self.rtol = rtol
        mt = 1.0 / (1.0 / par.m + (1.0 / par.m_b if par.support_compliant else 0.0))
        w_c = math.sqrt(par.k_c / mt * (1.0 if par.p_c == 1.0 else 10.0))
        self.w_contact = w_c
        self.w = w if w is not None else max(w_c, math.sqrt(par.k / par.m),
                                             math.sqrt(par.k_b / par.m_b) if par.m_b else 0.0)
        self.atol = self._atol(max(math.sqrt(par.k / par.m), 1.0))
        self.v_tol = 1e-9 * max(1.0, par.R)
        self.nfev = 0

    def _atol(self, w0: float) -> np.ndarray:
        """Absolute tolerances: rtol times the scales c_r, c_r w0, 1 rad, w0, m (c_r w0)^2."""
        cr, par = self.p.c_r, self.p
        sc = [cr, cr, cr * w0, cr * w0, 1.0, w0, cr, cr, cr * w0, cr * w0, w0]
        es = par.m * (cr * w0) ** 2
        sc += [es] * 8 + [es / w0, par.m * cr * w0, es / w0]
        return np.array(sc) * self.rtol

    # ---- decisions -------------------------------------------------------------------------

    def _race_for(self, k: Kin, mode: Mode, Ft: float) -> None:
        """Set the race's state (held / turning sigma) for a tangential force Ft at rest."""
        p = self.p
        if not p.race_turns:
            mode.held, mode.sigma = True, 0.0
        elif k.wb != 0.0:
            mode.held, mode.sigma = False, _sgn(k.wb)
        elif p.R_b * abs(Ft) <= p.T_b0:
            mode.held, mode.sigma = True, 0.0
        else:
            mode.held, mode.sigma = False, _sgn(Ft)

    def decide(self, y: np.ndarray, mode: Mode, force: str = "") -> Mode:
        """The consistent friction and race state at ``y`` (contact flags already set).

        ``force``: 'slip' after a cone event (slip with the stick force's sign), 'turn' after
        a break-away (race turns with the friction's sign)."""
        p, md = self.p, self.md
        k = kin(p, y)
        m = replace(mode)
        N, _ = md.normal(k, m) if m.contact else (0.0, 0.0)
        if not m.contact or N <= 0.0:
            m.stick, m.s = False, _sgn(k.vrel)
            self._race_for(k, m, 0.0)
            return m
        if abs(k.vrel) > self.v_tol and force != "slip":
            m.stick, m.s = False, _sgn(k.vrel)
            self._race_for(k, m, p.mu * m.s * N)
            if force == "turn" and m.held:
                m.held, m.sigma = False, m.s
            return m
        # zero slip: try to stick, with the race held if it is at rest and can be held
        for _ in range(3):
            m.stick = True
            if force == "turn":
                m.held = False
            Ft = md.stick_force(k, m, N)
            race_ok = m.held is False or not p.race_turns or p.R_b * abs(Ft) <= p.T_b0
            if m.held and p.race_turns and not race_ok:
                m.held, m.sigma = False, _sgn(Ft)
                continue
            if abs(Ft) <= p.mu * N and force != "slip":
                return m
            m.stick, m.s = False, _sgn(Ft)
            force = ""
            if m.held and p.race_turns and p.R_b * p.mu * N > p.T_b0:
                m.held, m.sigma = False, m.s
            return m
        return m

    # ---- events ----------------------------------------------------------------------------

    def events(self, mode: Mode) -> list[Callable[..., float]]:
        """Event functions of the mode (names in ``.name``)."""
        p, md = self.p, self.md
        evs: list[Callable[..., float]] = []

        def ev(name: str, direction: float, terminal: bool = True):
            def deco(fn: Callable[[float, np.ndarray], float]) -> Callable[..., float]:
                fn.terminal = terminal  # type: ignore[attr-defined]
                fn.direction = direction  # type: ignore[attr-defined]
                fn.name = name  # type: ignore[attr-defined]
                evs.append(fn)
                return fn
            return deco

        if not mode.contact:
            @ev("close", 1.0)
            def close(t: float, y: np.ndarray) -> float:
                return kin(p, y).delta / p.c_r
        else:
            @ev("open", -1.0)
            def open_(t: float, y: np.ndarray) -> float:
                return kin(p, y).delta / p.c_r

            @ev("kink", 1.0 if mode.clamped else -1.0)
            def kink(t: float, y: np.ndarray) -> float:
                return 1.0 + mode.chi * kin(p, y).ddelta

            if not mode.clamped:
                @ev("peak", -1.0, terminal=False)
                def peak(t: float, y: np.ndarray) -> float:
                    return md.dNdt(kin(p, y), mode)

                if mode.stick:
                    @ev("cone", -1.0)
                    def cone(t: float, y: np.ndarray) -> float:
                        k = kin(p, y)
                        N, _, Ft = md.forces(k, mode)
                        return p.mu * N - abs(Ft)
                elif mode.s != 0.0 and p.mu > 0.0:
                    @ev("slip0", -mode.s)
                    def slip0(t: float, y: np.ndarray) -> float:
                        return kin(p, y).vrel

                if p.race_turns and mode.held:
                    @ev("breakaway", -1.0)
                    def brk(t: float, y: np.ndarray) -> float:
                        k = kin(p, y)
                        return p.T_b0 - p.R_b * abs(md.forces(k, mode)[2])
        if p.race_turns and not mode.held:
            @ev("race_stop", -mode.sigma)
            def stop(t: float, y: np.ndarray) -> float:
                return float(y[10])
        return evs

    # ---- graze ------------------------------------------------------------------------------

    def first_graze(self, sol: Any, t_stop: float) -> float | None:
        """First time in an open phase where delta rises above 0 inside a step (both ends
        below 0): located by the sign change of delta' and brentq on delta."""
        p = self.p
        ts = sol.ts

        def dd(t: float) -> float:
            return kin(p, sol(t)).ddelta

        def de(t: float) -> float:
            return kin(p, sol(t)).delta

        for a, b0 in itertools.pairwise(ts):
            b = min(b0, t_stop)
            if b <= a:
                break
            da, db = dd(a), dd(b)
            if da > 0.0 >= db:
                tm = brentq(dd, a, b, xtol=1e-16, rtol=4 * np.finfo(float).eps)
                if de(tm) > 0.0:
                    return brentq(de, a, tm, xtol=1e-16, rtol=4 * np.finfo(float).eps)
        return None

    def _rigid_impact(self, res: Result, t: float, y: np.ndarray) -> bool:
        """Apply a rigid impact in place (impulses and dissipation into the integrals); False
        (status set) when the impacts have become too slow to resolve: sustained rigid
        contact is not implemented in this reference."""
        p = self.p
        k = kin(p, y)
        if k.ddelta < RIGID_V_MIN:
            res.status = "rigid sustained contact (not implemented)"
            return False
        y1, out = pair_impact(p, y)
        y1[14] += -out["dT"]  # impacts dissipate into the contact's column
        y1[20] += out["P_n"]
        if not p.race_turns:  # the frame holds the race's spin: external angular impulse
            y1[19] += -p.R_b * out["P_t"]
        y[:] = y1
        res.impacts.append({"t": t, "v_in": k.ddelta, "v_rel_in": k.vrel, **out})
        return True

    # ---- run ---------------------------------------------------------------------------------

    def run(self, y0: np.ndarray, t0: float, t_end: float, grid: np.ndarray | None = None,
            v_in0: float | None = None, max_phases: int = 200000) -> Result:
        """Integrate from ``y0`` at ``t0`` to ``t_end``; sample at ``grid`` (default none)."""
        p, md = self.p, self.md
        y = np.array(y0, dtype=float)
        t = float(t0)
        self.atol = self._atol(max(abs(float(y[5])), math.sqrt(p.k / p.m), 1.0))
        grid = np.array([] if grid is None else grid, dtype=float)
        gy = np.full((len(grid), NY), np.nan)
        gmode: list[str] = [""] * len(grid)
        k = kin(p, y)
        mode = Mode(contact=p.contact_compliant and k.delta > 0.0)
        if mode.contact:
            vin = k.ddelta if v_in0 is None else v_in0
            mode.chi = c_d(p.d) / max(vin, p.v_floor)
        if p.race_turns and y[10] != 0.0:
            mode.held, mode.sigma = False, _sgn(y[10])
        mode = self.decide(y, mode)
        res = Result(t=grid, y=gy, modes=gmode)
        res.transitions.append((t, mode.name()))
        cur_contact: dict[str, float] | None = None
        if mode.contact:
            cur_contact = {"t_close": t, "v_in": max(k.ddelta, 0.0), "N_peak": 0.0}
        zero_len = 0
        w = self.w
        max_step = 2.0 * math.pi / (8.0 * w)
        while t < t_end and res.phases < max_phases:
            res.phases += 1
            evs = self.events(mode)
            sol = solve_ivp(md.rhs(mode), (t, t_end), y, method="DOP853", rtol=self.rtol,
                            atol=self.atol, events=evs, dense_output=True, max_step=max_step)
            self.nfev += sol.nfev
            if sol.status < 0:
                raise RuntimeError(f"integration failed at t = {t}: {sol.message}")
            t_stop, y_stop, fired = float(sol.t[-1]), sol.y[:, -1].copy(), ""
            for i, fn in enumerate(evs):
                if fn.terminal and len(sol.t_events[i]) and sol.t_events[i][-1] == t_stop:
                    fired = fn.name
            if not mode.contact:
                tg = self.first_graze(sol.sol, t_stop)
                if tg is not None and tg < t_stop:
                    t_stop, y_stop, fired = tg, sol.sol(tg), "close"
            for i, fn in enumerate(evs):
                if fn.name == "peak":
                    for te, ye in zip(sol.t_events[i], sol.y_events[i], strict=False):
                        if te <= t_stop:
                            Nk = md.normal(kin(p, ye), mode)[0]
                            res.peaks.append((float(te), Nk))
                            if cur_contact is not None:
                                cur_contact["N_peak"] = max(cur_contact["N_peak"], Nk)
            sel = (grid >= t) & (grid <= t_stop) if len(grid) else np.zeros(0, bool)
            if sel.any():
                gy[sel] = sol.sol(grid[sel]).T
                for i in np.nonzero(sel)[0]:
                    gmode[i] = mode.name()
            if mode.contact and not mode.clamped:
                # N's largest value can sit at a phase end (dN/dt jumps where F_t does)
                Nb = md.normal(kin(p, y_stop), mode)[0]
                res.boundary_N.append((t_stop, Nb))
                if cur_contact is not None:
                    cur_contact["N_peak"] = max(cur_contact["N_peak"], Nb)
            zero_len = zero_len + 1 if t_stop - t <= 1e-15 * max(1.0, abs(t)) else 0
            if zero_len > 20:
                raise RuntimeError(f"no progress at t = {t}: mode {mode.name()}, event {fired}")
            t, y = t_stop, y_stop
            if not fired:
                break
            new = replace(mode)
            force = ""
            k = kin(p, y)
            if fired == "close" and not p.contact_compliant:
                if not self._rigid_impact(res, t, y):
                    break
                mode = self.decide(y, Mode(contact=False, held=mode.held, sigma=mode.sigma))
                res.transitions.append((t, "impact/" + mode.name()))
                continue
            if fired == "close":
                new = Mode(contact=True, held=mode.held, sigma=mode.sigma,
                           chi=c_d(p.d) / max(k.ddelta, p.v_floor))
                cur_contact = {"t_close": t, "v_in": k.ddelta, "N_peak": 0.0}
            elif fired == "open":
                new = Mode(contact=False, held=mode.held, sigma=mode.sigma)
                if cur_contact is not None:
                    cur_contact["t_open"] = t
                    cur_contact["v_out"] = -k.ddelta
                    res.contacts.append(cur_contact)
                    cur_contact = None
            elif fired == "kink":
                new.clamped = not mode.clamped
            elif fired == "cone":
                force = "slip"
            elif fired == "breakaway":
                force = "turn"
            elif fired == "race_stop":
                y[10] = 0.0
                new.held, new.sigma = True, 0.0
                k = kin(p, y)
                N = md.normal(k, new)[0]
                Ft = md.forces(k, new)[2] if N > 0.0 else 0.0
                if p.R_b * abs(Ft) > p.T_b0:
                    new.held, new.sigma = False, _sgn(Ft)
            mode = self.decide(y, new, force)
            res.transitions.append((t, mode.name()))
        if cur_contact is not None:
            res.contacts.append(cur_contact)
        res.y_end, res.t_end, res.nfev = y, t, self.nfev
        return res


def simulate(par: Par, y0: np.ndarray, t_end: float, grid: np.ndarray | None = None,
             rtol: float = 1e-12, t0: float = 0.0) -> Result:
    """Integrate the compliant system from ``y0`` (see :data:`STATE`; the integrals start at 0)."""
    return Simulator(par, rtol=rtol).run(y0, t0, t_end, grid)


def state(z: complex = 0j, v: complex = 0j, psi: float = 0.0, Omega: float = 0.0,
          zb: complex = 0j, vb: complex = 0j, omega_b: float = 0.0) -> np.ndarray:
    """A state vector with zero integrals."""
    y = np.zeros(NY)
    y[:11] = [z.real, z.imag, v.real, v.imag, psi, Omega, zb.real, zb.imag, vb.real, vb.imag,
              omega_b]
    return y


# --------------------------------------------------------------------------------------------
# (c) Balances
# --------------------------------------------------------------------------------------------


def energy_terms(par: Par, y0: np.ndarray, y1: np.ndarray) -> dict[str, float]:
    """The energy balance between two states of one run: ``dE + dissipations - works = 0``.

    Terms [J]: ``dE`` (mechanical energy, :func:`energy`), ``E_amb`` (AMB damper), ``E_sup``
    (support damper), ``E_drag`` (race drag heat), ``E_cdamp`` (contact damping, incl. the
    elastic energy left when N clamps), ``E_fric`` (friction heat), ``-W_drive``, ``-W_ext``,
    ``-W_bias``; ``residual`` their sum and ``scale`` the sum of their magnitudes."""
    d = {"dE": energy(par, y1) - energy(par, y0)}
    for i, nm in enumerate(STATE[11:19], start=11):
        sign = -1.0 if nm.startswith("W_") else 1.0
        d[nm] = sign * (float(y1[i]) - float(y0[i]))
    terms = list(d.values())
    d["residual"] = math.fsum(terms)
    d["scale"] = math.fsum(abs(x) for x in terms)
    return d


def momentum_terms(par: Par, y0: np.ndarray, y1: np.ndarray) -> dict[str, float]:
    """The angular-momentum balance about the origin, its terms signed to sum to 0 [N m s]:
    ``dL + L_ext + L_couple = 0``, ``L_ext = -int(external torques)``,
    with ``L_ext`` the angular impulse of the drive, the AMB and external forces, gravity at
    the mass centre, the support damper and the race drag (or the static torque holding the
    race), and ``L_couple = -int(-delta F_t) dt`` from the compliant contact's internal
    couple ``-delta F_t``."""
    d = {"dL": momentum(par, y1) - momentum(par, y0),
         "L_ext": -(float(y1[19]) - float(y0[19])),
         "L_couple": -(float(y1[21]) - float(y0[21]))}
    terms = list(d.values())
    d["residual"] = math.fsum(terms)
    d["scale"] = math.fsum(abs(x) for x in terms)
    return d


# --------------------------------------------------------------------------------------------
# (d) Black's problem
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Whirl:
    """A steady whirl of the two-mass system at held spin Omega: whirl rate nu [rad/s],
    penetration delta [m], rotor and race amplitudes A, B (complex, along n = e^{i nu t}),
    normal and tangential force N, F_t [N], slip v_rel [m/s], kind 'rolling' or 'sliding',
    existence (N >= 0 and, rolling, |F_t| <= mu N; sliding, sign(v_rel) = s), the eigenvalues
    of the linearisation in the whirling frame (the trivial zero ones removed) and
    stability (all real parts < 0)."""

    kind: str
    nu: float
    delta: float
    A: complex
    B: complex
    N: float
    Ft: float
    vrel: float
    exists: bool
    eig: tuple[complex, ...]
    stable: bool


def _whirl_force(par: Par, nu: float, rho: float) -> tuple[complex, complex, complex]:
    """(F = N + i F_t, A, B) of the steady whirl z = A e^{i nu t}, z_b = B e^{i nu t}, with
    A - B = rho (race fixed in spin; rigid support: B = 0)."""
    Dr = par.a * par.k - par.m * nu * nu + 1j * par.a * par.c * nu
    if par.support_compliant:
        Db = par.k_b - par.m_b * nu * nu + 1j * par.c_b * nu
        F = -rho * Dr * Db / (Dr + Db)
        return F, -F / Dr, F / Db
    F = -rho * Dr
    return F, rho + 0j, 0j


def black_whirls(par: Par, Omega: float, chi: float | None = None,
                 nu_range: tuple[float, float] = (-2e4, 2e4), n_scan: int = 4000
                 ) -> list[Whirl]:
    """The steady rolling and sliding whirls of Black's problem (e_c = g = 0, spin Omega
    held, race not turning or turning at the steady speed where its drag takes R_b F_t;
    here the race's spin is held at 0: ``race_turns`` must be False).

    Rolling: ``v_rel = R Omega + (c_r + delta) nu = 0`` and ``N(nu, delta) = K delta^p`` (one
    equation in delta, scanned and solved by brentq). Sliding with ``s = +-1``: ``F_t = mu s
    N`` and ``N = K delta^p`` (two equations in (nu, delta): delta from the modulus, nu from
    the argument; scanned over ``nu_range``). ``chi`` [s/m] is the contact damping the
    linearisation uses (default ``c_d/v_floor``)."""
    if par.race_turns:
        raise ValueError("black_whirls: race_turns must be False (the race's spin held at 0)")
    if par.e_c != 0.0 or par.g != 0.0:
        raise ValueError("black_whirls: e_c and g must be 0")
    chi = c_d(par.d) / par.v_floor if chi is None else chi
    out: list[Whirl] = []
    K, pc, cr, R, mu = par.K, par.p_c, par.c_r, par.R, par.mu

    def roll_eq(delta: float) -> float:
        rho = cr + delta
        F, _, _ = _whirl_force(par, -R * Omega / rho, rho)
        return F.real - K * delta**pc

    # rolling: scan delta over (0, 10 c_r]
    ds = np.geomspace(1e-12 * cr, 10.0 * cr, 2001)
    vals = [roll_eq(x) for x in ds]
    for i in range(len(ds) - 1):
        if vals[i] == 0.0 or vals[i] * vals[i + 1] < 0.0:
            dl = brentq(roll_eq, ds[i], ds[i + 1], xtol=1e-300, rtol=1e-15)
            rho = cr + dl
            nu = -R * Omega / rho
            F, A, B = _whirl_force(par, nu, rho)
            exists = F.real >= 0.0 and abs(F.imag) <= mu * F.real
            eig, stable = _stability(par, Omega, nu, A, B, chi, stick=True, s=0.0)
            out.append(Whirl("rolling", nu, dl, A, B, F.real, F.imag, 0.0, exists, eig, stable))
    # sliding: for each s, F_t/N = mu s  <=>  arg condition in nu at the rho where N = K delta^p
    for s in (1.0, -1.0):
        def delta_at(nu: float) -> float | None:
            def h(delta: float) -> float:
                F, _, _ = _whirl_force(par, nu, cr + delta)
                return F.real - K * delta**pc
            hv = [h(x) for x in ds]
            for i in range(len(ds) - 1):
                if hv[i] * hv[i + 1] < 0.0:
                    return brentq(h, ds[i], ds[i + 1], xtol=1e-300, rtol=1e-15)
            return None

        def slide_eq(nu: float, s: float = s) -> float:
            # the argument of F does not depend on rho (F is linear in rho)
            F, _, _ = _whirl_force(par, nu, cr)
            return F.imag - mu * s * F.real

        nus = np.linspace(nu_range[0], nu_range[1], n_scan)
        sv = [slide_eq(x) for x in nus]
        for i in range(len(nus) - 1):
            if sv[i] * sv[i + 1] < 0.0:
                nu = brentq(slide_eq, nus[i], nus[i + 1], xtol=1e-13, rtol=1e-15)
                dl = delta_at(nu)
                if dl is None:
                    continue
                rho = cr + dl
                F, A, B = _whirl_force(par, nu, rho)
                vrel = R * Omega + rho * nu
                exists = F.real >= 0.0 and _sgn(vrel) == s
                eig, stable = _stability(par, Omega, nu, A, B, chi, stick=False, s=s)
                out.append(Whirl("sliding", nu, dl, A, B, F.real, F.imag, vrel, exists, eig,
                                 stable))
    return out


def _stability(par: Par, Omega: float, nu: float, A: complex, B: complex, chi: float,
               stick: bool, s: float) -> tuple[tuple[complex, ...], bool]:
    """Eigenvalues of the linearisation of the whirl in the frame turning at nu (central
    differences, relative step 1e-6; accurate to ~1e-6 of the largest rate). Trivial zero
    eigenvalues (the rotation of the whole whirl; in rolling, the conserved slip) are removed:
    the ``n0`` eigenvalues of smallest modulus, below 1e-4 of the largest."""
    p = par.with_(T_drive=0.0, J=1e300)  # the spin held
    md = Model(p)
    mode = Mode(contact=True, stick=stick, s=s, held=True, chi=chi)
    comp = par.support_compliant

    def full(u: np.ndarray) -> np.ndarray:
        # u = [ux, uy, wx, wy, ubx, uby, wbx, wby] in the frame turning at nu
        zu, wu = complex(u[0], u[1]), complex(u[2], u[3])
        ub, wb = (complex(u[4], u[5]), complex(u[6], u[7])) if comp else (0j, 0j)
        v = wu + 1j * nu * zu
        vb = wb + 1j * nu * ub
        y = state(zu, v, 0.0, Omega, ub, vb, 0.0)
        k = kin(p, y)
        N, _, Ft = md.forces(k, mode)
        zdd, _, zbdd, _, _ = md.acc(k, mode, N, Ft)
        dw = zdd - 2j * nu * wu + nu * nu * zu
        dwb = (zbdd - 2j * nu * wb + nu * nu * ub) if comp else 0j
        out = [wu.real, wu.imag, dw.real, dw.imag]
        if comp:
            out += [wb.real, wb.imag, dwb.real, dwb.imag]
        return np.array(out)

    u0 = [A.real, A.imag, 0.0, 0.0]
    if comp:
        u0 += [B.real, B.imag, 0.0, 0.0]
    u0a = np.array(u0)
    nvar = len(u0a)
    scale = np.array([par.c_r, par.c_r, par.c_r * abs(nu), par.c_r * abs(nu)] * (nvar // 4))
    Jm = np.zeros((nvar, nvar))
    for j in range(nvar):
        h = 1e-6 * scale[j]
        up, um = u0a.copy(), u0a.copy()
        up[j] += h
        um[j] -= h
        Jm[:, j] = (full(up) - full(um)) / (2 * h)
    ev = np.linalg.eigvals(Jm)
    order = np.argsort(np.abs(ev))
    big = np.max(np.abs(ev))
    n0 = 2 if stick else 1
    drop = [i for i in order[:n0] if abs(ev[i]) < 1e-4 * big]
    keep = tuple(complex(ev[i]) for i in range(nvar) if i not in drop)
    return keep, all(e.real < 0.0 for e in keep)


# --------------------------------------------------------------------------------------------
# The drop of issue 24
# --------------------------------------------------------------------------------------------

OMEGA0 = 184.2
"""Spin speed [rad/s] of the levitated whirl the drop starts from."""


def drop_par(**kw: Any) -> Par:
    """The drop's parameters (the chapter's rotor, g = 9.81, mu = 0.15, d = 0.9, J = m R^2/2;
    the bearing of issue 24), with changes ``kw``."""
    return Par().with_(**kw)


def drop_start(par: Par, Omega0: float = OMEGA0) -> np.ndarray:
    """The levitated steady whirl at psi = 0 (bearing on): ``z = Z1``, ``z' = i Omega Z1``,
    ``Z1 = m e_c Omega^2 e^{i phi}/(k - m Omega^2 + i c Omega)``; race at rest, centred."""
    Z1 = par.m * par.e_c * Omega0**2 * cmath.exp(1j * par.phi) / (
        par.k - par.m * Omega0**2 + 1j * par.c * Omega0)
    return state(Z1, 1j * Omega0 * Z1, 0.0, Omega0)


def drop_scene(t_end: float = 0.3, rtol: float = 1e-12, n_grid: int = 3001, **kw: Any
               ) -> Result:
    """The drop (bearing failed at t = 0, a = 0), sampled on ``n_grid`` points; returns the
    trajectory with its contact intervals (``contacts``: t_close, t_open, v_in, v_out,
    N_peak) and the peaks of the normal force."""
    par = drop_par(**kw)
    grid = np.linspace(0.0, t_end, n_grid)
    return simulate(par, drop_start(par), t_end, grid, rtol=rtol)
