"""Independent direct-integration reference for the rotor / touchdown-bearing model.

This module integrates the *raw* equations of docs/model.md §1 with
:func:`scipy.integrate.solve_ivp`.
It deliberately imports nothing from ``fmu_src`` / ``rotortd``: it is an independent check of the
exact event-driven core, and also the "baseline a user would otherwise write" in benchmarks, so the
integration ``method`` and ``rtol`` / ``atol`` are arguments.

Model (SI units, inertial frame, planar vectors as complex numbers ``z = x + i y``)::

    m z'' = F(t, z, z'),
    F = a (F_bias - c z' - k z) + m e_c Omega^2 exp(i (psi + phi)) + F_ext - i m g
    psi(t) = psi_a + Omega (t - t_a)          (t_a: start of the current input segment)

with ``F_bias = i m g`` if ``levitate`` else 0. The term ``i m e_c Omega' exp(i(psi+phi))`` is
left out because Omega is held constant within a segment. While ``|z| < c_r`` the state
``[x, y, vx, vy]`` is integrated directly. Impacts at ``|z| = c_r`` are located with a terminal
event ``x^2 + y^2 - c_r^2 = 0`` (direction +1) on the dense output, z is projected onto the
circle, and the velocity is reset with docs/model.md §4 plus the Coulomb stick cap. A tangential
touch that the integrator steps over (both step ends inside the disk) is found afterwards from
each accepted step's dense output, a polynomial: a bound on its curvature clears the steps that
stay inside, and on the others ``r`` is evaluated at every interior maximum (roots of the
derivative); an overshoot of more than a few ulp is an impact (see :func:`_missed_graze`). After
a reset, the first ``~delta/|rdot^+|`` (delta = a few ulp of c_r) is taken with a Taylor step so
the event cannot re-detect the same impact (see :func:`_restart_free`).

Sustained contact, integrated in ``(theta, theta')`` with docs/model.md §5::

    N = Re(e^{-i theta} F) + m c_r theta'^2,      m c_r theta'' = Im(e^{-i theta} F) - F_t

sliding: ``F_t = mu s N``, ``s = sign(v_rel)``, ``v_rel = R Omega + c_r theta'``; rolling:
``theta' = -R Omega / c_r`` and ``F_t = Im(e^{-i theta} F)`` while ``|F_t| <= mu N``. Terminal
events: ``N = 0`` decreasing (lift-off), ``v_rel = 0`` (stick or slip reversal) and the friction
cone ``mu N - |Im(e^{-i theta} F)| = 0`` decreasing (leave rolling).

Low-speed (Zeno) rule. An impact counts as *contact* when the contact-free normal force pushes
outward, ``N_free = Re(conj(n) F) + m |v_t|^2 / c_r > 0``, and either ``rdot^- < v_zeno``
(default ``1e-7 c_r |Omega|``) or the rebound apex ``(d rdot^-)^2 / (2 N_free / m)`` would lie
within 16 ulp of c_r (not resolvable in float64). It is then made plastic (``rdot^+ = 0``,
tangential impulse ``mu m rdot^- s`` capped at stick) and the rotor passes to sustained contact.
Error: for ``d < 1`` the cut-off replaces the remaining geometric impact sequence, which would
last ``T_rem = 2 d rdot_0 / (a_n (1 - d))`` (``a_n = N_free / m``), by one plastic impact, so
contact starts up to ``T_rem`` early. Normal momentum is the same in both, so the state after the
accumulation point differs by ``O(rdot_0^2 / a_n)`` in position (the bounce height) and
``O(mu rdot_0 Omega T_rem)`` in velocity: quadratic in ``v_zeno``. With ``d = 1`` impacts never
accumulate; the rule then removes a micro-bounce of speed ``< v_zeno`` (energy
``m v_zeno^2 / 2``): ``O(v_zeno)`` in the normal velocity, ``O(v_zeno^2 / a_n)`` in position.

Limitations: events are located on the integrator's dense output (error near the step tolerance);
bounces just above the cut-off are only ``~10-100`` ulp of ``c_r`` high, so their impact speeds
carry a relative rounding noise ``~ eps c_r a_n / rdot^2`` (a few % at the default cut-off).
Between segments the contact mode is re-checked (a change of Omega ends rolling).
"""

from __future__ import annotations

import cmath
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

MODE_FREE = 0
MODE_SLIDING = 1
MODE_ROLLING = 2

_EPS = float(np.finfo(float).eps)
#: A rebound whose apex stays within this many ulp of c_r is below float64 resolution: contact.
_RES_ULP = 16.0
#: Restart positions on the wall are pulled inside until the computed gap is below -_GAP_MARGIN eps.
_GAP_MARGIN = 8.0


# --------------------------------------------------------------------------------------------
# Parameters, inputs, forces
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Par:
    """Physical parameters (SI): m [kg], c [N s/m], k [N/m], e_c [m], phi [rad], c_r [m], R [m],
    mu [-], d [-], g [m/s^2], levitate (bias force i m g scaled by a)."""

    m: float
    c: float
    k: float
    e_c: float
    phi: float
    c_r: float
    R: float
    mu: float
    d: float
    g: float = 0.0
    levitate: bool = True

    @classmethod
    def from_dict(cls, par: dict[str, Any]) -> Par:
        """Build from a plain dict with keys m, c, k, e_c, phi, c_r, R, mu, d, g, levitate."""
        return cls(
            m=float(par["m"]), c=float(par["c"]), k=float(par["k"]), e_c=float(par["e_c"]),
            phi=float(par["phi"]), c_r=float(par["c_r"]), R=float(par["R"]),
            mu=float(par["mu"]), d=float(par["d"]), g=float(par.get("g", 0.0)),
            levitate=bool(par.get("levitate", True)),
        )

    @property
    def omega_n(self) -> float:
        """Undamped AMB natural frequency sqrt(k/m) [rad/s]."""
        return math.sqrt(max(self.k, 0.0) / self.m)


@dataclass(frozen=True)
class Forcing:
    """Inputs held constant over one segment [t_a, t_end] and the resulting non-contact force.

    ``psi(t) = psi_a + Omega (t - t_a)``; all forces in N, inertial frame.
    """

    par: Par
    t_a: float
    t_end: float
    Omega: float
    F_ext: complex
    a: float
    psi_a: float

    @property
    def f_const(self) -> complex:
        """Constant part a F_bias + F_ext - i m g [N]."""
        p = self.par
        bias = 1j * p.m * p.g if p.levitate else 0.0
        return self.a * bias + self.F_ext - 1j * p.m * p.g

    @property
    def f_imb(self) -> float:
        """Imbalance force amplitude m e_c Omega^2 [N]."""
        return self.par.m * self.par.e_c * self.Omega**2

    def psi(self, t: float) -> float:
        """Spin angle psi(t) [rad] (unwrapped)."""
        return self.psi_a + self.Omega * (t - self.t_a)

    def force(self, t: float, z: complex, v: complex) -> complex:
        """All non-contact forces F(t, z, z') [N] at position z [m], velocity v [m/s]."""
        p = self.par
        ph = self.psi(t) + p.phi
        return (self.f_const - self.a * (p.c * v + p.k * z)
                + self.f_imb * complex(math.cos(ph), math.sin(ph)))

    def force_polar(self, t: float, th: float, thd: float) -> complex:
        """e^{-i theta} F on the circle z = c_r e^{i theta}, theta' = thd [rad/s]; N."""
        p = self.par
        ph = self.psi(t) + p.phi - th
        return (self.f_const * complex(math.cos(th), -math.sin(th))
                - self.a * p.c_r * (p.k + 1j * p.c * thd)
                + self.f_imb * complex(math.cos(ph), math.sin(ph)))

    def normal_force(self, t: float, th: float, thd: float) -> float:
        """Contact normal force N [N] (inward, >= 0 in contact) for given theta, theta'."""
        p = self.par
        return self.force_polar(t, th, thd).real + p.m * p.c_r * thd * thd

    def v_rel(self, thd: float) -> float:
        """Slip velocity at the contact point R Omega + c_r theta' [m/s]."""
        return self.par.R * self.Omega + self.par.c_r * thd

    def theta_dot_roll(self) -> float:
        """Whirl rate of rolling, -R Omega / c_r [rad/s]."""
        return -self.par.R * self.Omega / self.par.c_r

    def freq_scale(self) -> float:
        """Largest input frequency scale max(|Omega|, sqrt(k/m)) [rad/s] (1 if both vanish)."""
        w = max(abs(self.Omega), self.par.omega_n)
        return w if w > 0.0 else 1.0


# --------------------------------------------------------------------------------------------
# Impact law
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ImpactReset:
    """Result of an impact reset at the wall: velocities in m/s (inertial), impulses in N s.

    ``P_n`` is the inward normal impulse on the rotor, ``P_t`` the friction impulse with the sign of
    ``v_rel^-`` (tangential impulse on the rotor is ``-P_t i n``); ``stick`` when the cap fired.
    """

    v_plus: complex
    rdot: float
    P_n: float
    P_t: float
    stick: bool


def _sign(x: float) -> float:
    """sign(x) in {-1, 0, 1}."""
    return float((x > 0.0) - (x < 0.0))


def impact_reset(par: Par, Omega: float, n: complex, v_minus: complex, plastic: bool = False
                 ) -> ImpactReset:
    """Apply docs/model.md §4 with the Coulomb stick cap at the wall point with unit normal n.

    ``v_minus`` [m/s], ``Omega`` [rad/s]. Newton restitution ``rdot^+ = -d rdot^-`` (``0`` if
    ``plastic``); tangential change ``-mu (1 + d) rdot^- s`` (``-mu rdot^- s`` if plastic),
    capped so that ``v_rel^+ = 0`` if it would reverse the slip.
    """
    rd = max((n.conjugate() * v_minus).real, 0.0)
    vt = (n.conjugate() * v_minus).imag
    e_n = 1.0 if plastic else 1.0 + par.d
    vrel = par.R * Omega + vt
    s = _sign(vrel)
    dvt = -par.mu * e_n * rd * s
    stick = False
    if s != 0.0 and abs(dvt) >= abs(vrel):
        dvt = -vrel
        stick = True
    rd_plus = 0.0 if plastic else -par.d * rd
    v_plus = n * complex(rd_plus, vt + dvt)
    return ImpactReset(v_plus=v_plus, rdot=rd, P_n=par.m * e_n * rd, P_t=-par.m * dvt, stick=stick)


# --------------------------------------------------------------------------------------------
# Results
# --------------------------------------------------------------------------------------------


@dataclass
class DirectResult:
    """Output of :func:`direct_simulate` (SI, inertial frame).

    ``impacts``: dicts with t [s], z [m], v_minus, v_plus [m/s], rdot (rdot^-, m/s), P_n, P_t [N s],
    stick (bool), plastic (bool, low-speed rule). ``t, z, v, psi, mode``: final state.
    ``contact_events``: (t, kind), kind in enter_sliding, enter_rolling, leave_rolling, lift_off.
    ``samples``: dict of arrays t, z, v, mode at ``t_eval`` (None if not requested).
    ``nfev``: total right-hand-side evaluations. ``status``: "ok", "max_impacts", "stalled" or
    "solver_failed: ...".
    """

    impacts: list[dict[str, Any]] = field(default_factory=list)
    t: float = 0.0
    z: complex = 0j
    v: complex = 0j
    psi: float = 0.0
    mode: int = MODE_FREE
    contact_events: list[tuple[float, str]] = field(default_factory=list)
    samples: dict[str, np.ndarray] | None = None
    nfev: int = 0
    status: str = "ok"


@dataclass
class _State:
    """Mutable simulation state; theta/thd are valid in contact modes, s is the slip sign."""

    t: float
    z: complex
    v: complex
    mode: int = MODE_FREE
    theta: float = 0.0
    thd: float = 0.0
    s: float = 0.0

    def set_contact(self, c_r: float, theta: float, thd: float) -> None:
        """Set the polar contact state and the Cartesian state that goes with it."""
        self.theta, self.thd = theta, thd
        e = cmath.exp(1j * theta)
        self.z = c_r * e
        self.v = 1j * c_r * thd * e


@dataclass
class _Opts:
    """Integrator settings shared by all phases."""

    method: str
    rtol: float
    atol: float | Sequence[float] | None
    v_zeno: float | None
    t_eval: np.ndarray | None

    def atol_free(self, fc: Forcing) -> float | list[float]:
        """atol for [x, y, vx, vy] (SI)."""
        if self.atol is None:
            ap = 1e-13 * fc.par.c_r
            av = ap * fc.freq_scale()
            return [ap, ap, av, av]
        if np.ndim(self.atol) == 0:
            return float(self.atol)  # type: ignore[arg-type]
        return [float(a) for a in self.atol]  # type: ignore[union-attr]

    def atol_contact(self, fc: Forcing) -> list[float]:
        """atol for [theta, theta'] (rad, rad/s), derived from the free-flight atol."""
        af = self.atol_free(fc)
        if isinstance(af, float):
            af = [af] * 4
        return [af[0] / fc.par.c_r, af[2] / fc.par.c_r]

    def vz(self, fc: Forcing) -> float:
        """Low-speed cut-off v_zeno [m/s]."""
        if self.v_zeno is not None:
            return float(self.v_zeno)
        return 1e-7 * fc.par.c_r * fc.freq_scale()


@dataclass
class _Phase:
    """Outcome of one integration phase: stop time, kind and the stop state."""

    t: float
    kind: str  # "end", "impact", "lift_off", "vrel0", "cone", "fail"
    y: np.ndarray
    nfev: int
    sol: Callable[[Any], np.ndarray] | None = None
    message: str = ""


# --------------------------------------------------------------------------------------------
# Free flight
# --------------------------------------------------------------------------------------------


def _free_rhs(fc: Forcing) -> Callable[[float, np.ndarray], np.ndarray]:
    """RHS of free flight for y = [x, y, vx, vy] (m, m/s)."""
    inv_m = 1.0 / fc.par.m

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        acc = fc.force(t, complex(y[0], y[1]), complex(y[2], y[3])) * inv_m
        return np.array([y[2], y[3], acc.real, acc.imag])

    return rhs


def _wall_gap(c_r: float) -> Callable[[float, np.ndarray], float]:
    """Event (x^2 + y^2) / c_r^2 - 1, terminal, direction +1."""
    inv = 1.0 / (c_r * c_r)

    def gap(t: float, y: np.ndarray) -> float:
        return (y[0] * y[0] + y[1] * y[1]) * inv - 1.0

    gap.terminal = True  # type: ignore[attr-defined]
    gap.direction = 1.0  # type: ignore[attr-defined]
    return gap


#: Degree bound of the dense output of every solve_ivp method on one step (a polynomial in t):
#: LSODA's Adams orders go up to 12; DOP853 is 7, RK45 4, RK23 and Radau 3, BDF at most 5. The
#: gap r^2/c_r^2 - 1 is then a polynomial of degree <= 2 _DENSE_DEG on each step.
_DENSE_DEG = 12


def _cheb_tables(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Tables for polynomials of degree <= n on [-1, 1] sampled at the Chebyshev-Lobatto nodes
    u_k = -cos(pi k / n) (ascending): the nodes, the matrix ``C`` of their Chebyshev coefficients
    (``a = C @ f``, a discrete cosine transform of type I in closed form), the matrix ``D`` of the
    derivative on coefficients (``a' = D @ a``) and ``E`` of the values at the nodes
    (``f = E @ a``)."""
    u = np.array([-math.cos(math.pi * k / n) for k in range(n + 1)])
    u[0], u[-1] = -1.0, 1.0
    c = np.empty((n + 1, n + 1))
    e = np.empty((n + 1, n + 1))
    for j in range(n + 1):
        for k in range(n + 1):
            w = (0.5 if k in (0, n) else 1.0) * (0.5 if j in (0, n) else 1.0)
            cos_jk = math.cos(j * (math.pi - math.pi * k / n))  # T_j(u_k)
            c[j, k] = 2.0 / n * w * cos_jk
            e[k, j] = cos_jk
    d = np.zeros((n + 1, n + 1))  # T_j' = 2 j sum(T_i, i < j, j - i odd), T_0 counted once
    for j in range(1, n + 1):
        for i in range(j - 1, -1, -2):
            d[i, j] = float(j if i == 0 else 2 * j)
    return u, c, d, e


_U, _C, _D, _E = _cheb_tables(2 * _DENSE_DEG)
#: Node values of G -> values of G' at the nodes; node values of G -> coefficients of G''.
_VAL_D1 = _E @ _D @ _C
_VAL_D2 = _D @ _D @ _C
_DU = np.diff(_U)
#: Rounding of the gap at a node (dense output and r^2/c_r^2 - 1) is taken as <= _G_NOISE, and its
#: worst-case effect on G' at a node and on the sum of the |coefficients| of G'' is added to the
#: bounds, so that rounding can only make them weaker.
_G_NOISE = 16.0 * _EPS
_D1_NOISE = _G_NOISE * float(np.abs(_VAL_D1).sum(1).max())
_D2_NOISE = _G_NOISE * float(np.abs(_VAL_D2).sum())


def _step_critical_points(gc: np.ndarray) -> np.ndarray:
    """Points u in (-1, 1) that include every critical point of the polynomial with Chebyshev
    coefficients gc: the real, or nearly real (a double root that rounding split into a complex
    pair), roots of its derivative, from the eigenvalues of the Chebyshev companion matrix."""
    cheb = np.polynomial.chebyshev
    dg = cheb.chebder(gc)
    dg = cheb.chebtrim(dg, tol=64.0 * _EPS * float(np.max(np.abs(dg), initial=0.0)))
    if dg.size < 2:
        return np.empty(0)
    r = cheb.chebroots(dg)
    r = r[np.abs(np.imag(r)) <= 1e-3].real
    return np.sort(r[(r > -1.0) & (r < 1.0)])


def _missed_graze(sol: Any, gap: Callable[[float, np.ndarray], float], t_stop: float,
                  c_r: float) -> float | None:
    """First wall crossing at an interior maximum of r in an accepted step, or None.

    The event sees the sign of the gap G = r^2/c_r^2 - 1 at the ends of a step only; a graze inside
    one step (or a chord that grazes the wall and then passes the centre, so that r has a maximum
    and a minimum in the step) has no sign change there. On each step of ``sol`` (an OdeSolution)
    up to ``t_stop``, G is a polynomial of degree <= 2 _DENSE_DEG in the scaled time u in [-1, 1],
    recovered (up to rounding) from the dense output at 2 _DENSE_DEG + 1 Chebyshev-Lobatto nodes.
    The Chebyshev coefficients c_j of G'' bound it on the step (|T_j| <= 1): G'' >= c_0 - sum
    |c_j|, |G''| <= sum |c_j|, widened by the worst case of the rounding at the nodes. A step is
    cleared without a root search when G is convex on it (no interior maximum), or when each
    interval between two nodes is either below the wall (G <= max(G_k, G_k+1) + max(-G'') du^2/8
    < 0) or monotone (G'_k + G'_k+1 beyond max|G''| du) with no crossing inside. On the other
    steps G is evaluated on the dense output at every critical point (roots of G'); G is monotone
    between them, so the first one with G > _GAP_MARGIN eps brackets the first crossing, which
    brentq locates. An overshoot below that (a few ulp of c_r) is within the rounding of G and is
    not an impact. The decision rests on the value of G at its maxima, not on samples or on signs
    at the step ends, so an overshoot far above rounding is found whatever the step sequence,
    which, where the solution is nearly polynomial, the rounding of the error estimate decides."""
    ts = np.asarray(sol.ts)
    n_steps = int(np.count_nonzero(ts[1:] <= t_stop))
    if n_steps < 1:
        return None
    ip = sol.interpolants
    half = 0.5 * np.diff(ts[:n_steps + 1])
    tt = ts[:n_steps, None] + half[:, None] * (1.0 + _U)
    tt[:, 0], tt[:, -1] = ts[:n_steps], ts[1:n_steps + 1]
    q = np.array([ip[j](tt[j])[:2] for j in range(n_steps)])  # (steps, 2, nodes)
    gn = (q[:, 0] ** 2 + q[:, 1] ** 2) / (c_r * c_r) - 1.0
    d1 = gn @ _VAL_D1.T  # G' at the nodes
    c2 = gn @ _VAL_D2.T  # Chebyshev coefficients of G''
    tail = np.abs(c2[:, 1:]).sum(1) + _D2_NOISE
    neg_curv = np.maximum(tail - c2[:, 0], 0.0)  # >= max(-G'') on the step (|T_j| <= 1)
    lip = np.abs(c2[:, 0]) + tail  # >= max|G''|
    below = (np.maximum(gn[:, :-1], gn[:, 1:]) + _G_NOISE
             + neg_curv[:, None] * (_DU * _DU / 8.0) < 0.0)
    slope = d1[:, :-1] + d1[:, 1:]
    mono = lip[:, None] * _DU + 2.0 * _D1_NOISE
    up = slope > mono
    clear = below | ((-slope > mono) & (gn[:, :-1] < 0.0)) | (up & (gn[:, 1:] < 0.0))
    clear[:, -1] |= up[:, -1]  # rising to the step's end: a crossing there is the event's
    cand = np.nonzero((gn[:, 0] < 0.0) & (neg_curv > 0.0) & ~clear.all(1))[0]
    for j in cand:
        def g_of(t: float, f: Any = ip[j]) -> float:
            return gap(0.0, f(t))

        t_neg = float(ts[j])
        for u in _step_critical_points(gn[j] @ _C.T):
            t = float(ts[j] + half[j] * (1.0 + u))
            if t <= t_neg or t >= ts[j + 1]:
                continue
            gt = g_of(t)
            if gt > _GAP_MARGIN * _EPS:
                return float(brentq(g_of, t_neg, t, xtol=4 * _EPS))
            if gt < 0.0:
                t_neg = t
    return None


def _free_phase(fc: Forcing, st: _State, opts: _Opts, t_end: float) -> _Phase:
    """Integrate free flight from st until t_end or the first impact."""
    gap = _wall_gap(fc.par.c_r)
    y0 = np.array([st.z.real, st.z.imag, st.v.real, st.v.imag])
    res = solve_ivp(_free_rhs(fc), (st.t, t_end), y0, method=opts.method, rtol=opts.rtol,
                    atol=opts.atol_free(fc), events=[gap], dense_output=True)
    if res.status < 0:
        return _Phase(st.t, "fail", y0, res.nfev, message=res.message)
    t_stop = float(res.t[-1])
    t_graze = _missed_graze(res.sol, gap, t_stop, fc.par.c_r)
    if t_graze is not None:
        return _Phase(t_graze, "impact", res.sol(t_graze), res.nfev, res.sol)
    if res.status == 1:
        te = float(res.t_events[0][0])
        return _Phase(te, "impact", np.asarray(res.y_events[0][0]), res.nfev, res.sol)
    return _Phase(t_end, "end", res.y[:, -1], res.nfev, res.sol)


# --------------------------------------------------------------------------------------------
# Sustained contact
# --------------------------------------------------------------------------------------------


def _contact_rhs(fc: Forcing, mode: int, s: float) -> Callable[[float, np.ndarray], np.ndarray]:
    """RHS of eq. (3) for y = [theta, theta'] (rad, rad/s); rolling has theta'' = 0."""
    p = fc.par
    inv = 1.0 / (p.m * p.c_r)
    if mode == MODE_ROLLING:
        def roll(t: float, y: np.ndarray) -> np.ndarray:
            return np.array([y[1], 0.0])

        return roll

    def slide(t: float, y: np.ndarray) -> np.ndarray:
        fp = fc.force_polar(t, y[0], y[1])
        n_force = fp.real + p.m * p.c_r * y[1] * y[1]
        return np.array([y[1], (fp.imag - p.mu * s * n_force) * inv])

    return slide


def _contact_events(fc: Forcing, mode: int, s: float) -> list[Callable[[float, np.ndarray], float]]:
    """Terminal events: [N (dir -1), v_rel (dir -s)] sliding, [N, cone (dir -1)] rolling."""
    p = fc.par
    scale = 1.0 / (p.m * p.c_r * fc.freq_scale() ** 2)

    def normal(t: float, y: np.ndarray) -> float:
        return fc.normal_force(t, y[0], y[1]) * scale

    normal.terminal, normal.direction = True, -1.0  # type: ignore[attr-defined]

    if mode == MODE_SLIDING:
        def vrel(t: float, y: np.ndarray) -> float:
            return fc.v_rel(y[1])

        vrel.terminal, vrel.direction = True, -s  # type: ignore[attr-defined]
        return [normal, vrel]

    def cone(t: float, y: np.ndarray) -> float:
        fp = fc.force_polar(t, y[0], y[1])
        return (p.mu * (fp.real + p.m * p.c_r * y[1] * y[1]) - abs(fp.imag)) * scale

    cone.terminal, cone.direction = True, -1.0  # type: ignore[attr-defined]
    return [normal, cone]


def _contact_phase(fc: Forcing, st: _State, opts: _Opts, t_end: float) -> _Phase:
    """Integrate sustained contact (sliding or rolling) from st until t_end or an event."""
    w = max(fc.freq_scale(), abs(st.thd), abs(fc.Omega - st.thd))
    y0 = np.array([st.theta, st.thd])
    dense = opts.t_eval is not None
    res = solve_ivp(_contact_rhs(fc, st.mode, st.s), (st.t, t_end), y0, method=opts.method,
                    rtol=opts.rtol, atol=opts.atol_contact(fc), max_step=math.pi / (8.0 * w),
                    events=_contact_events(fc, st.mode, st.s), dense_output=dense)
    if res.status < 0:
        return _Phase(st.t, "fail", y0, res.nfev, message=res.message)
    sol = res.sol if dense else None
    if res.status == 1:
        for k, kind in enumerate(("lift_off", "vrel0" if st.mode == MODE_SLIDING else "cone")):
            if len(res.t_events[k]):
                return _Phase(float(res.t_events[k][0]), kind, np.asarray(res.y_events[k][0]),
                              res.nfev, sol)
    return _Phase(t_end, "end", res.y[:, -1], res.nfev, sol)


# --------------------------------------------------------------------------------------------
# Mode logic
# --------------------------------------------------------------------------------------------


def _rolling_admissible(fc: Forcing, t: float, theta: float) -> bool:
    """True if rolling at theta' = -R Omega / c_r satisfies N >= 0 and |F_t| <= mu N."""
    thd = fc.theta_dot_roll()
    fp = fc.force_polar(t, theta, thd)
    n_force = fp.real + fc.par.m * fc.par.c_r * thd * thd
    return n_force >= 0.0 and abs(fp.imag) <= fc.par.mu * n_force


def _stick_or_slip(fc: Forcing, st: _State, res: DirectResult, t: float) -> None:
    """At v_rel = 0 in contact: enter rolling if in the friction cone, else slide with
    s = sign(Im(e^{-i theta} F))."""
    thd = fc.theta_dot_roll()
    if _rolling_admissible(fc, t, st.theta):
        if st.mode != MODE_ROLLING:
            res.contact_events.append((t, "enter_rolling"))
        st.mode = MODE_ROLLING
        st.set_contact(fc.par.c_r, st.theta, thd)
        return
    if st.mode == MODE_ROLLING:
        res.contact_events.append((t, "leave_rolling"))
    elif st.mode == MODE_FREE:
        res.contact_events.append((t, "enter_sliding"))
    st.mode = MODE_SLIDING
    st.s = _sign(fc.force_polar(t, st.theta, thd).imag) or 1.0
    st.set_contact(fc.par.c_r, st.theta, thd)


def _lift_off(st: _State, res: DirectResult, t: float) -> None:
    """Leave contact: free flight from the current polar state."""
    res.contact_events.append((t, "lift_off"))
    st.mode = MODE_FREE


def _enter_segment(fc: Forcing, st: _State, res: DirectResult) -> None:
    """Re-check the contact mode when the inputs change at a segment boundary."""
    if st.mode == MODE_FREE:
        return
    t = st.t
    if fc.normal_force(t, st.theta, st.thd) < 0.0:
        _lift_off(st, res, t)
        return
    if st.mode == MODE_ROLLING:
        vrel = fc.v_rel(st.thd)
        if abs(vrel) <= 1e-12 * (abs(fc.par.R * fc.Omega) + 1e-300) or vrel == 0.0:
            if not _rolling_admissible(fc, t, st.theta):
                _stick_or_slip(fc, st, res, t)
            return
        res.contact_events.append((t, "leave_rolling"))
        st.mode = MODE_SLIDING
        st.s = _sign(vrel)
        return
    vrel = fc.v_rel(st.thd)
    if vrel == 0.0:
        _stick_or_slip(fc, st, res, t)
    else:
        st.s = _sign(vrel)


def _restart_free(fc: Forcing, st: _State, t: float, n: complex, v: complex) -> None:
    """Restart free flight from the wall point c_r n at time t with velocity v (rdot <= 0).

    The event ``r^2/c_r^2 - 1`` must start clearly negative (below its rounding noise ``~eps``),
    else it would re-detect the impact just processed. The state is therefore moved off the wall
    by a tiny first step of duration ``tau ~ delta / |rdot|`` taken with a second-order Taylor
    expansion (error ``O(|jerk| tau^3)``, negligible) until the computed gap is below
    ``-_GAP_MARGIN eps``, i.e. ``delta`` = a few ulp of c_r inside. If the radial speed is too small
    for that (lift-off), the position is instead pulled in by ``delta`` with an energy-neutral
    reduction of the inward speed and no time shift (an O(delta) position error).
    """
    p = fc.par
    gap = _wall_gap(p.c_r)
    z = p.c_r * n
    acc = fc.force(t, z, v) / p.m
    vn = n.conjugate() * v
    rd = min(vn.real, 0.0)
    a_n = fc.normal_force(t, math.atan2(n.imag, n.real), vn.imag / p.c_r) / p.m
    zs, vs, ts = z, v, t
    for k in (1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0):
        delta = p.c_r * k * _EPS
        disc = rd * rd - 2.0 * a_n * delta
        tau = 2.0 * delta / (-rd + math.sqrt(disc)) if disc > 0.0 and rd < 0.0 else math.inf
        if tau * fc.freq_scale() < 1e-6:
            zs, vs, ts = z + v * tau + 0.5 * acc * tau * tau, v + acc * tau, t + tau
        else:
            zs, vs, ts = (p.c_r - delta) * n, n * complex(-math.sqrt(max(disc, 0.0)), vn.imag), t
        if gap(0.0, np.array([zs.real, zs.imag])) < -_GAP_MARGIN * _EPS:
            break
    st.t, st.z, st.v, st.mode = ts, zs, vs, MODE_FREE


def _is_contact(fc: Forcing, t: float, n: complex, rd: float, v_plastic: complex,
                v_zeno: float) -> bool:
    """Low-speed rule: the impact counts as contact if N_free > 0 and either rdot^- < v_zeno or
    the rebound apex (d rdot^-)^2 / (2 N_free / m) would lie within _RES_ULP ulp of c_r."""
    p = fc.par
    thd = (n.conjugate() * v_plastic).imag / p.c_r
    n_free = fc.normal_force(t, math.atan2(n.imag, n.real), thd)
    if n_free <= 0.0:
        return False
    return rd < v_zeno or (p.d * rd) ** 2 < 2.0 * n_free / p.m * _RES_ULP * _EPS * p.c_r


def _handle_impact(fc: Forcing, st: _State, res: DirectResult, opts: _Opts, t: float,
                   y: np.ndarray) -> None:
    """Reset at an impact; apply the low-speed rule (plastic impact + sustained contact)."""
    p = fc.par
    zr = complex(y[0], y[1])
    n = zr / abs(zr)
    v_minus = complex(y[2], y[3])
    rst = impact_reset(p, fc.Omega, n, v_minus)
    cand = impact_reset(p, fc.Omega, n, v_minus, plastic=True)
    plastic = _is_contact(fc, t, n, rst.rdot, cand.v_plus, opts.vz(fc))
    if plastic:
        rst = cand
    res.impacts.append({"t": t, "z": p.c_r * n, "v_minus": v_minus, "v_plus": rst.v_plus,
                        "rdot": rst.rdot, "P_n": rst.P_n, "P_t": rst.P_t, "stick": rst.stick,
                        "plastic": plastic})
    if not plastic:
        _restart_free(fc, st, t, n, rst.v_plus)
        return
    st.t = t
    st.set_contact(p.c_r, math.atan2(n.imag, n.real), (n.conjugate() * rst.v_plus).imag / p.c_r)
    if rst.stick or fc.v_rel(st.thd) == 0.0:
        _stick_or_slip(fc, st, res, t)
        return
    res.contact_events.append((t, "enter_sliding"))
    st.mode = MODE_SLIDING
    st.s = _sign(fc.v_rel(st.thd))


def _apply_phase(fc: Forcing, st: _State, res: DirectResult, opts: _Opts, ph: _Phase) -> None:
    """Advance the state to the phase's stop and process its event."""
    if st.mode == MODE_FREE:
        if ph.kind == "impact":
            _handle_impact(fc, st, res, opts, ph.t, ph.y)
        else:
            st.t, st.z, st.v = ph.t, complex(ph.y[0], ph.y[1]), complex(ph.y[2], ph.y[3])
        return
    st.t = ph.t
    thd = fc.theta_dot_roll() if st.mode == MODE_ROLLING else float(ph.y[1])
    st.set_contact(fc.par.c_r, float(ph.y[0]), thd)
    if ph.kind == "lift_off":
        _lift_off(st, res, ph.t)
        _restart_free(fc, st, ph.t, st.z / fc.par.c_r, st.v)
    elif ph.kind in ("vrel0", "cone"):
        _stick_or_slip(fc, st, res, ph.t)


# --------------------------------------------------------------------------------------------
# Sampling
# --------------------------------------------------------------------------------------------


def _sample(buf: dict[str, list[Any]], t_eval: np.ndarray, ph: _Phase, t_a: float, mode: int,
            c_r: float) -> None:
    """Record dense-output samples with t_a <= t < ph.t (z in m, v in m/s)."""
    if ph.sol is None:
        return
    sel = t_eval[(t_eval >= t_a) & (t_eval < ph.t)]
    if sel.size == 0:
        return
    y = np.atleast_2d(ph.sol(sel).T).reshape(sel.size, -1)
    if mode == MODE_FREE:
        z, v = y[:, 0] + 1j * y[:, 1], y[:, 2] + 1j * y[:, 3]
    else:
        e = np.exp(1j * y[:, 0])
        z, v = c_r * e, 1j * c_r * y[:, 1] * e
    buf["t"].extend(sel)
    buf["z"].extend(z)
    buf["v"].extend(v)
    buf["mode"].extend([mode] * sel.size)


# --------------------------------------------------------------------------------------------
# Driver
# --------------------------------------------------------------------------------------------


def direct_simulate(par: dict[str, Any], z0: complex, v0: complex, psi0: float, t0: float,
                    segments: Sequence[tuple[float, float, complex, float]],
                    method: str = "DOP853", rtol: float = 1e-13,
                    atol: float | Sequence[float] | None = None, v_zeno: float | None = None,
                    max_impacts: int = 100000, t_eval: Sequence[float] | None = None
                    ) -> DirectResult:
    """Integrate the rotor from (t0, z0 [m], v0 [m/s], psi0 [rad]) through input segments.

    ``segments``: list of ``(t_end [s], Omega [rad/s], F_ext [N, complex], a [-])`` held constant on
    consecutive intervals starting at t0. ``method``, ``rtol``: passed to solve_ivp. ``atol``: None
    for ``1e-13 c_r`` (positions) and ``1e-13 c_r max(|Omega|, sqrt(k/m))`` (velocities), or a float
    / 4-sequence in SI for ``[x, y, vx, vy]`` (contact phases use it divided by c_r).
    ``v_zeno`` [m/s]: low-speed cut-off, default ``1e-7 c_r |Omega|`` (``1e-7 c_r sqrt(k/m)`` if
    Omega = 0). ``max_impacts`` caps impacts and contact transitions. ``t_eval``: sample times.
    Starts in free flight; requires ``|z0| < c_r``.
    """
    p = Par.from_dict(par)
    if abs(z0) >= p.c_r:
        raise ValueError(f"|z0| = {abs(z0)} must be < c_r = {p.c_r}")
    te = None if t_eval is None else np.sort(np.asarray(t_eval, dtype=float))
    opts = _Opts(method, rtol, atol, v_zeno, te)
    st = _State(t=float(t0), z=complex(z0), v=complex(v0))
    res = DirectResult()
    buf: dict[str, list[Any]] = {"t": [], "z": [], "v": [], "mode": []}
    psi_a = float(psi0)
    stalls = 0
    t_last = st.t  # end of the previous phase (the restart after an impact may be a few ulp later)
    fc: Forcing | None = None
    for t_end, Omega, F_ext, a in segments:
        fc = Forcing(p, st.t, float(t_end), float(Omega), complex(F_ext), float(a), psi_a)
        _enter_segment(fc, st, res)
        while st.t < fc.t_end and res.status == "ok":
            t_a, mode = st.t, st.mode
            run = _free_phase if mode == MODE_FREE else _contact_phase
            ph = run(fc, st, opts, fc.t_end)
            res.nfev += ph.nfev
            if ph.kind == "fail":
                res.status = f"solver_failed: {ph.message}"
                break
            if te is not None:
                _sample(buf, te, ph, t_last, mode, p.c_r)
            t_last = ph.t
            _apply_phase(fc, st, res, opts, ph)
            stalls = stalls + 1 if st.t <= t_a else 0
            if stalls > 100:
                res.status = "stalled"
            if len(res.impacts) >= max_impacts or len(res.contact_events) >= max_impacts:
                res.status = "max_impacts"
        psi_a = fc.psi(st.t)
        if res.status != "ok":
            break
    res.t, res.z, res.v, res.mode = st.t, st.z, st.v, st.mode
    res.psi = psi_a if fc is None else fc.psi(st.t)
    if te is not None:
        if np.any(te == st.t) and (not buf["t"] or buf["t"][-1] < st.t):
            buf["t"].append(st.t)
            buf["z"].append(st.z)
            buf["v"].append(st.v)
            buf["mode"].append(st.mode)
        res.samples = {"t": np.array(buf["t"], dtype=float), "z": np.array(buf["z"], dtype=complex),
                       "v": np.array(buf["v"], dtype=complex),
                       "mode": np.array(buf["mode"], dtype=int)}
    return res
