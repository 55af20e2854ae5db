"""Independent event-driven reference for the rotor with the spin as a state (docs/model.md §8).

The rotor is one rigid body (translation + spin). This module integrates the raw equations of
docs/model.md §8 with :func:`scipy.integrate.solve_ivp` (DOP853, tight tolerance, dense
output). It imports nothing from ``fmu_src`` / ``rotortd`` (not even the parameters): it is an
independent check of the core's spin extension. SI units, inertial frame, planar vectors as
complex numbers ``z = x + i y``.

Model (held over one call: bearing state ``a``, ``F_ext`` at the geometric centre, ``T_drive``)::

    E = exp(i (psi + phi)),  z_G = z + e_c E,  F_amb = a (F_bias - c z' - k z)
    J Omega' = T_drive + e_c Im(conj(F_amb + F_ext) E)                 (free flight)
    m z''    = F_amb + F_ext - i m g + m e_c (Omega^2 - i Omega') E,   psi' = Omega

``F_bias = i m g`` if ``levitate`` else 0; gravity acts at the mass centre.

Modes and states:

* free (0): ``[x, y, vx, vy, psi, Omega]``; impacts at ``|z| = c_r`` are the terminal event
  ``|z|^2/c_r^2 - 1`` (direction +1). A graze inside one step (no sign change at the step ends)
  is searched on every accepted step's dense output: 17 samples, an interior sample maximum is
  refined with a bounded scalar maximisation when the sample maximum plus the largest second
  difference (a curvature bound on the sampling error) reaches the wall; an overshoot of more
  than ``_GRAZE_MARGIN`` (16 eps of the gap) is an impact located by brentq.
* sliding (1): ``[theta, theta', psi, Omega, int N, int F_t, int Re F_c, int Im F_c, E_fric]``;
  ``F_t = mu s N``; the 2x2 for ``(N, Omega')`` is solved in each RHS call; events: lift-off
  ``N = 0`` (decreasing), slip zero ``v_rel = 0`` (direction ``-s``).
* rolling (2): ``[theta, theta', psi, int N, int F_t, int Re F_c, int Im F_c, E_fric]`` with
  ``Omega = -c_r theta'/R``; the 3x3 for ``(N, F_t, theta'')`` has the closed form
  ``theta'' = (B r1 + A F_on' - r2) / (kappa I_P)`` (see :func:`_roll_forces`); events: lift-off
  ``N = 0``, friction cone ``mu N - |F_t| = 0`` (both decreasing); at the cone it slides with
  ``s = sign(F_t)``.

Contact decision at slip zero (and after a sticking plastic impact): roll if the rolling solution
has ``N > 0`` and ``|F_t| <= mu N``; else slide with the ``s`` whose sliding solution has
``sign(v_rel') = s`` and ``N > 0`` (the developing slip), falling back to ``s = sign(F_t)`` of the
rolling solution; if ``N <= 0`` the rotor lifts off.

Impacts follow the model's law (Newton restitution on ``rdot``, Coulomb friction with the slip
after the impact, stick when admissible, energetic cap), coded here from the model statement in
:func:`impact_law`.

Chattering rule (documented choice). An impact with ``rdot^- > 0`` is made *plastic*
(``d_eff = 0``, same law otherwise) and sustained contact begins when the contact mode found
after the plastic impact has a normal force ``N > 0`` and either the rebound normal speed of the
regular impact is tiny, ``rdot^+ = d_eff rdot^- < V_CHATTER = 1e-9 m/s``, or its rebound apex
``(rdot^+)^2 / (2 N / m)`` is below ``H_CHATTER c_r = 1e-14 c_r`` (not resolvable: the gap is
computed to ~1e-16 and grazes below 16 eps are not impacts). For ``d < 1`` this replaces the rest
of the geometric impact sequence (duration ``~2 rdot^+/(a_n (1 - d))``, a few ns at the
thresholds) by one plastic impact: the error in position is the bounce height (``<= 1e-14
c_r``), in velocity ``O(mu rdot^+)``. With ``d = 1`` it removes a bounce of energy
``m (rdot^+)^2 / 2``.

After an impact free flight restarts a tiny time ``tau`` later, advanced along the flight by a
second-order Taylor step until the gap is ~4 ulp of c_r inside (so the event does not re-detect
the impact just processed); after a lift-off (no inward speed) the position is pulled in by
4 ulp of c_r (a position error of ``~1e-19 m``). A radial pull-in after every impact would
instead add ``m a_n 4 eps c_r`` of energy per bounce, which inflates the last bounces of a
chattering sequence (seen: rebound ratio 0.99 instead of d = 0.95 near the threshold).

Accuracy: ``rtol`` (default 1e-12) and ``atol = rtol * scale`` per component with the scales
``c_r`` (positions), ``c_r w`` (velocities, ``w = max(|Omega0|, sqrt(k/m), 1 rad/s)``), 1 rad
(angles), ``w`` (Omega, theta'), ``m c_r w`` (impulses), ``m (c_r w)^2`` (energy). Contact phases
use ``max_step = pi / (8 w_c)`` with ``w_c`` the largest of ``|Omega|, |theta'|,
|psi' - theta'|`` so that no event pair is stepped over.
"""

from __future__ import annotations

import cmath
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar

MODE_FREE = 0
MODE_SLIDING = 1
MODE_ROLLING = 2
MODE_NAMES = {MODE_FREE: "free", MODE_SLIDING: "sliding", MODE_ROLLING: "rolling"}

V_CHATTER = 1e-9
"""Rebound normal speed [m/s] below which an impact is plastic (if contact has N > 0)."""
H_CHATTER = 1e-14
"""Rebound apex, in units of c_r, below which an impact is plastic (if contact has N > 0)."""

_EPS = float(np.finfo(float).eps)
_GRAZE_MARGIN = 16.0 * _EPS
_PULL_IN = 4.0 * _EPS
_GAP_START = 6.0 * _EPS
_N_SAMPLES = 17
_BISECT = 60


# --------------------------------------------------------------------------------------------
# Parameters
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SpinPar:
    """Rigid-body parameters (SI): m [kg], c [N s/m], k [N/m], e_c [m], phi [rad], c_r [m],
    R [m], mu [-], d [-], g [m/s^2], levitate, J [kg m^2] (polar inertia about the mass centre).
    """

    m: float
    c: float
    k: float
    e_c: float
    phi: float
    c_r: float
    R: float
    mu: float
    d: float
    g: float
    levitate: bool
    J: float

    @classmethod
    def from_dict(cls, params: dict[str, Any], J: float) -> SpinPar:
        """Build from a plain dict with keys m c k e_c phi c_r R mu d g levitate, and J."""
        return cls(m=float(params["m"]), c=float(params["c"]), k=float(params["k"]),
                   e_c=float(params["e_c"]), phi=float(params["phi"]),
                   c_r=float(params["c_r"]), R=float(params["R"]), mu=float(params["mu"]),
                   d=float(params["d"]), g=float(params.get("g", 0.0)),
                   levitate=bool(params.get("levitate", False)), J=float(J))

    @property
    def F_bias(self) -> complex:
        """Bias force i m g if levitate else 0 [N] (scaled by a)."""
        return 1j * self.m * self.g if self.levitate else 0j

    def check_well_posed(self) -> None:
        """Refuse J <= m mu e_c (R + e_c) (the model's sufficient well-posedness bound)."""
        bound = self.m * self.mu * self.e_c * (self.R + self.e_c)
        if not bound < self.J:
            raise ValueError(f"J = {self.J} must exceed m mu e_c (R + e_c) = {bound}")


def _sign(x: float) -> float:
    """sign(x) in {-1, 0, 1}."""
    return float((x > 0.0) - (x < 0.0))


# --------------------------------------------------------------------------------------------
# Impact law
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ImpactOutcome:
    """Impulses and contact-point velocities of one impact (the impact law of docs/model.md §8).

    ``P_n`` [N s] inward normal impulse (>= 0), ``P_t`` [N s] tangential impulse (impulse on the
    rotor ``-(P_n + i P_t) n``); ``rdot_plus = -d_eff rdot^-`` and ``v_rel_plus`` [m/s];
    ``stick`` if the stick candidate was accepted; ``d_eff`` the restitution used; ``dT`` [J] the
    change of the rigid body's kinetic energy (``E_diss = -dT``); ``capped`` if the cap fired.
    """

    P_n: float
    P_t: float
    rdot_plus: float
    v_rel_plus: float
    stick: bool
    d_eff: float
    dT: float
    capped: bool


def delassus(m: float, J: float, e_c: float, R: float, beta: float) -> tuple[float, float, float]:
    """Delassus matrix entries (W_nn, W_nt, W_tt) [1/kg] at the impact angle beta [rad]."""
    B = e_c * math.sin(beta)
    A = R - e_c * math.cos(beta)
    return 1.0 / m + B * B / J, A * B / J, 1.0 / m + A * A / J


def _law_at(w: tuple[float, float, float], mu: float, d_eff: float, rd: float, s: float
            ) -> tuple[float, float, float, float, bool, float]:
    """Steps 1-4 of the impact law at restitution d_eff: (P_n, P_t, rdot+, v_rel+, stick, dT)."""
    wnn, wnt, wtt = w
    D = (1.0 + d_eff) * rd
    det = wnn * wtt - wnt * wnt
    pn = (wtt * D - wnt * s) / det
    pt = (wnn * s - wnt * D) / det
    rd_plus = -d_eff * rd
    if pn >= 0.0 and abs(pt) <= mu * pn:
        vr_plus = 0.0
        stick = True
    else:
        sigma = 1.0 if pt >= 0.0 else -1.0
        pn = D / (wnn + mu * sigma * wnt)
        pt = mu * sigma * pn
        vr_plus = s - (wnt * pn + wtt * pt)
        stick = False
    dT = -(pn * (rd + rd_plus) + pt * (s + vr_plus)) / 2.0
    return pn, pt, rd_plus, vr_plus, stick, dT


def impact_law(m: float, J: float, e_c: float, R: float, mu: float, d: float, beta: float,
               rdot_minus: float, v_rel_minus: float, cap: str = "largest") -> ImpactOutcome:
    """the model's impact law (Newton + Coulomb with the slip after the impact + energetic cap).

    ``rdot_minus`` [m/s] >= 0 approach speed, ``v_rel_minus`` [m/s] slip before, ``beta`` [rad]
    = psi + phi - theta; masses in kg, J in kg m^2, lengths in m.

    Cap: if dT > 0 at d, d_eff is set from the model's closed form for the outcome kind found at
    d (stick or slide sigma), clamped to [0, d]; if the kind is the same at that d_eff it is
    kept (dT(d_eff) = 0 up to rounding). If the kind differs there, the model is ambiguous:
    ``cap="largest"`` (default) follows its stated goal, the largest d_eff in [0, d] with
    dT <= 0, by 60 halvings of [d_formula, d] when dT(d_formula) <= 0 and of [0, d_formula]
    otherwise; ``cap="spec"`` follows its literal recipe (keep d_formula when dT(d_formula) <= 0,
    else 60 halvings of [0, d_formula]). The two differ only when a slide at d turns into a stick
    at d_formula with dT(d_formula) < 0 (3 in 12,000 random impacts of the tests).
    """
    rd, s = float(rdot_minus), float(v_rel_minus)
    w = delassus(m, J, e_c, R, beta)
    res = _law_at(w, mu, d, rd, s)
    d_eff, capped = d, False
    if res[5] > 0.0 and rd > 0.0:
        capped = True
        wnn, wnt, wtt = w
        if res[4]:
            det = wnn * wtt - wnt * wnt
            knn, knt, ktt = wtt / det, -wnt / det, wnn / det
            quad = knn * rd * rd + 2.0 * knt * rd * s + ktt * s * s
            de = math.sqrt(max(quad, 0.0) / (knn * rd * rd))
            kind: tuple[bool, float] = (True, 0.0)
        else:
            sigma = _sign(res[1])
            cc = (wnt + mu * sigma * wtt) / (wnn + mu * sigma * wnt)
            de = ((rd * (1.0 - mu * sigma * cc) + 2.0 * mu * sigma * s)
                  / (rd * (1.0 + mu * sigma * cc)))
            kind = (False, sigma)
        de = min(max(de, 0.0), d)
        trial = _law_at(w, mu, de, rd, s)
        same = trial[4] == kind[0] and (trial[4] or _sign(trial[1]) == kind[1])
        if same or (trial[5] <= 0.0 and cap == "spec"):
            d_eff, res = de, trial
        else:
            lo, hi = (de, d) if trial[5] <= 0.0 else (0.0, de)
            for _ in range(_BISECT):
                mid = 0.5 * (lo + hi)
                if _law_at(w, mu, mid, rd, s)[5] <= 0.0:
                    lo = mid
                else:
                    hi = mid
            d_eff, res = lo, _law_at(w, mu, lo, rd, s)
    pn, pt, rd_plus, vr_plus, stick, dT = res
    return ImpactOutcome(P_n=pn, P_t=pt, rdot_plus=rd_plus, v_rel_plus=vr_plus, stick=stick,
                         d_eff=d_eff, dT=dT, capped=capped)


def apply_impulse(m: float, J: float, e_c: float, R: float, n: complex, beta: float,
                  v: complex, Omega: float, P_n: float, P_t: float) -> tuple[complex, float]:
    """Geometric-centre velocity z' [m/s] and spin [rad/s] after the impulse -(P_n + i P_t) n
    at the rim point z + R n (beta [rad] = psi + phi - theta, n = e^{i theta}).

    The mass centre's velocity changes by ``-(P_n + i P_t) n / m`` and the spin by
    ``-(B P_n + A P_t) / J``; the geometric centre's velocity ``z' = z_G' - i Omega e_c E``
    (``E = n e^{i beta}``) therefore changes by ``-(P_n + i P_t) n / m - i e_c E dOmega``, which
    makes ``(d rdot, d v_rel) = -W (P_n, P_t)`` hold for ``rdot = Re(conj(n) z')`` and
    ``v_rel = R Omega + Im(conj(n) z')``. (the model's line "delta v = -(P_n + i P_t) n / m" is
    the change of ``z_G'``; read as the change of ``z'`` it would contradict its own W.)
    """
    B = e_c * math.sin(beta)
    A = R - e_c * math.cos(beta)
    d_om = -(B * P_n + A * P_t) / J
    E = n * complex(math.cos(beta), math.sin(beta))
    return v - complex(P_n, P_t) * n / m - 1j * e_c * E * d_om, Omega + d_om


# --------------------------------------------------------------------------------------------
# Steady whirl start
# --------------------------------------------------------------------------------------------


def steady_whirl_start(params: dict[str, Any], Omega: float, a: float = 1.0,
                       F_ext: complex = 0j, psi0: float = 0.0) -> tuple[complex, complex]:
    """(z0 [m], v0 [m/s]) of the held-speed steady whirl z = Z0 + Z1 e^{i psi} at psi = psi0.

    Held-speed flight ``m z'' = a (F_bias - c z' - k z) + F_ext - i m g + m e_c Omega^2
    e^{i(psi + phi)}``, ``psi = psi0 + Omega t``: ``Z0 = (a F_bias + F_ext - i m g)/(a k)``,
    ``Z1 = m e_c Omega^2 e^{i phi} / (a k - m Omega^2 + i a c Omega)``; ``z0 = Z0 + Z1 e^{i psi0}``,
    ``v0 = i Omega Z1 e^{i psi0}``. Requires ``a k != 0``.
    """
    m, c, k = float(params["m"]), float(params["c"]), float(params["k"])
    g = float(params.get("g", 0.0))
    e_c, phi = float(params["e_c"]), float(params["phi"])
    bias = 1j * m * g if params.get("levitate", False) else 0j
    if a * k == 0.0:
        raise ValueError("steady whirl needs a k != 0")
    Z0 = (a * bias + complex(F_ext) - 1j * m * g) / (a * k)
    Z1 = m * e_c * Omega**2 * cmath.exp(1j * phi) / (a * k - m * Omega**2 + 1j * a * c * Omega)
    e0 = cmath.exp(1j * psi0)
    return Z0 + Z1 * e0, 1j * Omega * Z1 * e0


# --------------------------------------------------------------------------------------------
# Forces
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Model:
    """Parameters and the inputs held over the run (a, F_ext [N], T_drive [N m])."""

    p: SpinPar
    a: float
    F_ext: complex
    T_drive: float

    def free_acc(self, z: complex, v: complex, psi: float, Om: float) -> tuple[complex, float]:
        """(z'' [m/s^2], Omega' [rad/s^2]) in free flight."""
        p = self.p
        E = complex(math.cos(psi + p.phi), math.sin(psi + p.phi))
        F = self.a * (p.F_bias - p.c * v - p.k * z) + self.F_ext
        omd = (self.T_drive + p.e_c * (F.conjugate() * E).imag) / p.J
        acc = (F - 1j * p.m * p.g) / p.m + p.e_c * complex(Om * Om, -omd) * E
        return acc, omd

    def known(self, th: float, thd: float, psi: float, Om: float
              ) -> tuple[float, float, float, float, float]:
        """(r1, F_on', r2, B, A) on the circle: r1 = F_on + m c_r theta'^2 [N], F_ot [N],
        r2 = T_drive + T_o [N m], B = e_c sin(beta), A = R - e_c cos(beta) [m]."""
        p = self.p
        n = complex(math.cos(th), math.sin(th))
        z = p.c_r * n
        v = 1j * p.c_r * thd * n
        E = complex(math.cos(psi + p.phi), math.sin(psi + p.phi))
        F_ab = self.a * (p.F_bias - p.c * v - p.k * z) + self.F_ext
        F_o = F_ab - 1j * p.m * p.g + p.m * p.e_c * Om * Om * E
        fo = n.conjugate() * F_o
        T_o = p.e_c * (F_ab.conjugate() * E).imag
        beta = psi + p.phi - th
        B = p.e_c * math.sin(beta)
        A = p.R - p.e_c * math.cos(beta)
        return fo.real + p.m * p.c_r * thd * thd, fo.imag, self.T_drive + T_o, B, A

    def slide_forces(self, th: float, thd: float, psi: float, Om: float, s: float
                     ) -> tuple[float, float, float]:
        """Sliding with F_t = mu s N: (N [N], Omega' [rad/s^2], theta'' [rad/s^2])."""
        p = self.p
        r1, fot, r2, B, A = self.known(th, thd, psi, Om)
        q = B + A * p.mu * s
        omd = (r2 - q * r1) / (p.J + p.m * B * q)
        N = r1 + p.m * B * omd
        cb = p.R - A  # e_c cos(beta)
        thdd = (fot - p.mu * s * N - p.m * cb * omd) / (p.m * p.c_r)
        return N, omd, thdd

    def roll_forces(self, th: float, thd: float, psi: float) -> tuple[float, float, float]:
        """Rolling (Omega = -c_r theta'/R): (N [N], F_t [N], theta'' [rad/s^2])."""
        p = self.p
        kap = p.c_r / p.R
        r1, fot, r2, B, A = self.known(th, thd, psi, -kap * thd)
        q = (B * r1 + A * fot - r2) / (kap * (p.J + p.m * (A * A + B * B)))
        return r1 - p.m * B * kap * q, fot - p.m * kap * A * q, q


# --------------------------------------------------------------------------------------------
# Result
# --------------------------------------------------------------------------------------------


@dataclass
class SpinResult:
    """Output of :func:`simulate` (SI, inertial frame).

    ``impacts``: dicts with t [s], z [m], v_minus, v_plus [m/s], Omega_minus, Omega_plus
    [rad/s], rdot_minus [m/s], P_n, P_t [N s], stick, plastic, capped (bool), d_eff, E_diss [J].
    ``transitions``: (t [s], new mode name). ``samples``: arrays t, z, v, psi, Omega, mode,
    theta_dot, v_rel, N at the requested grid (N = 0 in free flight; theta' = Im(conj(z) v)/|z|^2).
    Totals: ``P_n``, ``P_t`` [N s] (contact normal / tangential impulses, impacts included),
    ``P_contact`` [N s, complex] (impulse of the contact force on the rotor), ``E_impacts``,
    ``E_friction`` [J]. Final state ``t, z, v, psi, Omega, mode``; ``nfev``; ``status``
    ("ok", "stalled", "max_events" or "solver_failed: ...").
    """

    impacts: list[dict[str, Any]] = field(default_factory=list)
    transitions: list[tuple[float, str]] = field(default_factory=list)
    samples: dict[str, np.ndarray] = field(default_factory=dict)
    P_n: float = 0.0
    P_t: float = 0.0
    P_contact: complex = 0j
    E_impacts: float = 0.0
    E_friction: float = 0.0
    t: float = 0.0
    z: complex = 0j
    v: complex = 0j
    psi: float = 0.0
    Omega: float = 0.0
    mode: int = MODE_FREE
    nfev: int = 0
    status: str = "ok"

    def first_time(self, mode_name: str) -> float | None:
        """Time [s] of the first transition into mode_name, or None."""
        return next((t for t, nm in self.transitions if nm == mode_name), None)


@dataclass
class _St:
    """Mutable state: t, mode, s (slip sign in sliding) and the mode's ODE vector y."""

    t: float
    mode: int
    y: np.ndarray
    s: float = 0.0


# --------------------------------------------------------------------------------------------
# The simulator
# --------------------------------------------------------------------------------------------


class _Sim:
    """One run of :func:`simulate`."""

    def __init__(self, md: _Model, rtol: float, w: float, t_grid: np.ndarray,
                 max_events: int) -> None:
        self.md, self.p = md, md.p
        self.rtol = rtol
        self.w = w
        self.t_grid = t_grid
        self.max_events = max_events
        p = md.p
        ap, av = p.c_r, p.c_r * w
        ai, ae = p.m * p.c_r * w, p.m * (p.c_r * w) ** 2
        self.atol_free = rtol * np.array([ap, ap, av, av, 1.0, w])
        self.atol_slide = rtol * np.array([1.0, w, 1.0, w, ai, ai, ai, ai, ae])
        self.atol_roll = rtol * np.array([1.0, w, 1.0, ai, ai, ai, ai, ae])
        self.res = SpinResult()
        self.gap_event = self._make_gap()
        self.t_done = 0.0
        self.buf: dict[str, list[Any]] = {k: [] for k in
                                          ("t", "z", "v", "psi", "Omega", "mode", "theta_dot",
                                           "v_rel", "N")}

    # ---------------------------------------------------------------- state conversions
    def kin(self, st: _St, y: np.ndarray | None = None) -> tuple[complex, complex, float, float]:
        """(z, v, psi, Omega) of the state (or of the vector y in st's mode)."""
        p = self.p
        y = st.y if y is None else y
        if st.mode == MODE_FREE:
            return complex(y[0], y[1]), complex(y[2], y[3]), float(y[4]), float(y[5])
        n = complex(math.cos(y[0]), math.sin(y[0]))
        Om = float(y[3]) if st.mode == MODE_SLIDING else -p.c_r * float(y[1]) / p.R
        return p.c_r * n, 1j * p.c_r * float(y[1]) * n, float(y[2]), Om

    def normal_force(self, mode: int, s: float, y: np.ndarray) -> float:
        """Contact normal force N [N] in a contact mode."""
        if mode == MODE_SLIDING:
            return self.md.slide_forces(y[0], y[1], y[2], y[3], s)[0]
        return self.md.roll_forces(y[0], y[1], y[2])[0]

    # ---------------------------------------------------------------- right-hand sides
    def rhs_free(self, t: float, y: np.ndarray) -> np.ndarray:
        """Free flight: d/dt [x, y, vx, vy, psi, Omega]."""
        acc, omd = self.md.free_acc(complex(y[0], y[1]), complex(y[2], y[3]), y[4], y[5])
        return np.array([y[2], y[3], acc.real, acc.imag, y[5], omd])

    def _accum(self, th: float, N: float, Ft: float, dissip: float) -> list[float]:
        """Rates of [int N, int F_t, int F_c (re, im), E_fric]."""
        fc = -complex(N, Ft) * complex(math.cos(th), math.sin(th))
        return [N, Ft, fc.real, fc.imag, dissip]

    def rhs_slide(self, s: float) -> Callable[[float, np.ndarray], np.ndarray]:
        """Sliding: d/dt [theta, theta', psi, Omega, accumulators]."""
        p = self.p

        def f(t: float, y: np.ndarray) -> np.ndarray:
            N, omd, thdd = self.md.slide_forces(y[0], y[1], y[2], y[3], s)
            vrel = p.R * y[3] + p.c_r * y[1]
            return np.array([y[1], thdd, y[3], omd,
                             *self._accum(y[0], N, p.mu * s * N, p.mu * N * abs(vrel))])

        return f

    def rhs_roll(self, t: float, y: np.ndarray) -> np.ndarray:
        """Rolling: d/dt [theta, theta', psi, accumulators] (Omega = -c_r theta'/R)."""
        N, Ft, thdd = self.md.roll_forces(y[0], y[1], y[2])
        return np.array([y[1], thdd, -self.p.c_r * y[1] / self.p.R,
                         *self._accum(y[0], N, Ft, 0.0)])

    # ---------------------------------------------------------------- events
    def _make_gap(self) -> Callable[[float, np.ndarray], float]:
        """Terminal event |z|^2/c_r^2 - 1 (free flight), direction +1."""
        c2 = self.p.c_r * self.p.c_r

        def gap(t: float, y: np.ndarray) -> float:
            return (y[0] * y[0] + y[1] * y[1]) / c2 - 1.0

        gap.terminal, gap.direction = True, 1.0  # type: ignore[attr-defined]
        return gap

    def contact_events(self, mode: int, s: float) -> list[Callable[[float, np.ndarray], float]]:
        """[lift-off N = 0 (dir -1), slip zero v_rel (dir -s) | cone mu N - |F_t| (dir -1)]."""
        p = self.p
        scale = 1.0 / (p.m * p.c_r * self.w * self.w)

        def lift(t: float, y: np.ndarray) -> float:
            return self.normal_force(mode, s, y) * scale

        lift.terminal, lift.direction = True, -1.0  # type: ignore[attr-defined]
        if mode == MODE_SLIDING:
            def vrel(t: float, y: np.ndarray) -> float:
                return (p.R * y[3] + p.c_r * y[1]) / (p.c_r * self.w)

            vrel.terminal, vrel.direction = True, -s  # type: ignore[attr-defined]
            return [lift, vrel]

        def cone(t: float, y: np.ndarray) -> float:
            N, Ft, _ = self.md.roll_forces(y[0], y[1], y[2])
            return (p.mu * N - abs(Ft)) * scale

        cone.terminal, cone.direction = True, -1.0  # type: ignore[attr-defined]
        return [lift, cone]

    # ---------------------------------------------------------------- graze search
    def first_graze(self, sol: Any, t_stop: float) -> float | None:
        """Earliest wall crossing inside any accepted step up to t_stop (see module doc)."""
        ts = np.asarray(sol.ts)
        c2 = self.p.c_r * self.p.c_r
        u = np.linspace(0.0, 1.0, _N_SAMPLES)
        for j in range(len(ts) - 1):
            ta, tb = float(ts[j]), float(min(ts[j + 1], t_stop))
            if tb <= ta:
                break
            f = sol.interpolants[j]
            tt = ta + (tb - ta) * u
            tt[-1] = tb
            q = f(tt)
            g = (q[0] ** 2 + q[1] ** 2) / c2 - 1.0

            def gfun(t: float, f: Any = f) -> float:
                qq = f(t)
                return float((qq[0] ** 2 + qq[1] ** 2) / c2 - 1.0)

            neg = g < 0.0
            over = np.nonzero(g > _GRAZE_MARGIN)[0]
            i_end = int(over[0]) if over.size else _N_SAMPLES
            if over.size:  # a sample beyond the wall: bracket from the last one inside
                inside = np.nonzero(neg[:i_end])[0]
                if inside.size:
                    i0 = int(inside[-1])
                    i1 = i0 + 1 if g[i0 + 1] > 0.0 else i_end
                    return float(brentq(gfun, tt[i0], tt[i1], xtol=4 * _EPS * max(tb, 1.0)))
                continue  # the step starts on or beyond the wall: the previous step's crossing
            # no sample beyond the wall: refine every sample maximum (ends included) that the
            # curvature bound (largest second difference) lets reach the wall
            curv = float(np.max(np.abs(np.diff(g, 2))))
            for i in range(_N_SAMPLES):
                lo, hi = max(i - 1, 0), min(i + 1, _N_SAMPLES - 1)
                if g[i] < g[lo] or g[i] < g[hi] or g[i] + curv <= 0.0:
                    continue
                r = minimize_scalar(lambda t: -gfun(t), bounds=(tt[lo], tt[hi]),
                                    method="bounded", options={"xatol": 1e-10 * (tb - ta)})
                tm = float(r.x)
                inside = np.nonzero(neg & (tt < tm))[0]
                if gfun(tm) > _GRAZE_MARGIN and inside.size:
                    return float(brentq(gfun, tt[int(inside[-1])], tm,
                                        xtol=4 * _EPS * max(tb, 1.0)))
        return None

    # ---------------------------------------------------------------- sampling
    def sample(self, st: _St, sol: Any, t_a: float, t_b: float, last: bool) -> None:
        """Record grid samples with t_a <= t < t_b (or <= t_b if last) from the dense output."""
        tg = self.t_grid
        sel = tg[(tg >= t_a) & ((tg <= t_b) if last else (tg < t_b))]
        p = self.p
        for t in sel:
            y = sol(float(t))
            z, v, psi, Om = self.kin(st, y)
            if st.mode == MODE_FREE:
                N = 0.0
                thd = (z.conjugate() * v).imag / (abs(z) ** 2) if z != 0 else 0.0
                vr = p.R * Om + ((z.conjugate() * v).imag / abs(z) if z != 0 else 0.0)
            else:
                N = self.normal_force(st.mode, st.s, y)
                thd = float(y[1])
                vr = p.R * Om + p.c_r * thd
            for key, val in (("t", float(t)), ("z", z), ("v", v), ("psi", psi), ("Omega", Om),
                             ("mode", st.mode), ("theta_dot", thd), ("v_rel", vr), ("N", N)):
                self.buf[key].append(val)

    # ---------------------------------------------------------------- mode entries
    def transition(self, t: float, mode: int) -> None:
        """Record a mode change."""
        self.res.transitions.append((t, MODE_NAMES[mode]))

    def settle(self, t: float, th: float, thd: float, psi: float, Om: float, stick: bool
               ) -> tuple[int, float, np.ndarray]:
        """Contact mode on the circle (mode, s, y) with its normal force > 0, or MODE_FREE.

        ``stick``: v_rel is zero (a slip-zero event or a sticking impact); Omega is then taken as
        -c_r theta'/R. Otherwise slide with s = sign(v_rel).
        """
        p, md = self.p, self.md
        acc = [0.0] * 5
        vr = p.R * Om + p.c_r * thd
        if not stick and vr != 0.0:
            s = _sign(vr)
            N = md.slide_forces(th, thd, psi, Om, s)[0]
            if N > 0.0:
                return MODE_SLIDING, s, np.array([th, thd, psi, Om, *acc])
            return MODE_FREE, 0.0, np.empty(0)
        N, Ft, _ = md.roll_forces(th, thd, psi)
        Om_r = -p.c_r * thd / p.R
        if N > 0.0 and abs(Ft) <= p.mu * N:
            return MODE_ROLLING, 0.0, np.array([th, thd, psi, *acc])
        cands = []
        for s in (1.0, -1.0):
            Ns, omd, thdd = md.slide_forces(th, thd, psi, Om_r, s)
            if Ns > 0.0 and _sign(p.R * omd + p.c_r * thdd) == s:
                cands.append(s)
        s = cands[0] if len(cands) == 1 else (_sign(Ft) or 1.0)
        if md.slide_forces(th, thd, psi, Om_r, s)[0] > 0.0:
            return MODE_SLIDING, s, np.array([th, thd, psi, Om_r, *acc])
        return MODE_FREE, 0.0, np.empty(0)

    def free_from_wall(self, t: float, n: complex, v: complex, psi: float, Om: float) -> _St:
        """Free flight restarting from the wall point c_r n with velocity v (rdot <= 0).

        The gap must start clearly negative, else the event would re-detect the impact just
        processed. With an inward speed the rotor is moved along its flight by a tiny step
        ``tau`` (second-order Taylor, ``tau w < 1e-6``, error ``O(jerk tau^3)``, negligible) until
        the computed gap is below ``-_GAP_START`` (i.e. ~4 ulp of c_r inside); without one
        (lift-off, or too slow) the position is pulled in radially by 4 ulp of c_r.
        """
        p = self.p
        z = p.c_r * n
        rd = (n.conjugate() * v).real
        if rd < 0.0:
            acc, omd = self.md.free_acc(z, v, psi, Om)
            for k in (1.0, 2.0, 4.0, 8.0, 16.0):
                tau = k * _PULL_IN * p.c_r / -rd
                if tau * self.w > 1e-6:
                    break
                zs = z + v * tau + 0.5 * acc * tau * tau
                if self.gap_event(0.0, np.array([zs.real, zs.imag])) < -_GAP_START:
                    vs = v + acc * tau
                    return _St(t + tau, MODE_FREE,
                               np.array([zs.real, zs.imag, vs.real, vs.imag,
                                         psi + Om * tau + 0.5 * omd * tau * tau, Om + omd * tau]))
        z = p.c_r * (1.0 - _PULL_IN) * n
        return _St(t, MODE_FREE, np.array([z.real, z.imag, v.real, v.imag, psi, Om]))

    def impact(self, t: float, y: np.ndarray) -> _St:
        """Process a wall crossing found in free flight at (t, y)."""
        p = self.p
        z, v, psi, Om = complex(y[0], y[1]), complex(y[2], y[3]), float(y[4]), float(y[5])
        n = z / abs(z)
        th = math.atan2(n.imag, n.real)
        beta = psi + p.phi - th
        vn = n.conjugate() * v
        rd, vr = vn.real, p.R * Om + vn.imag
        if rd <= 0.0:  # a touch without approach speed (rounding at a graze)
            mode, s, yc = self.settle(t, th, vn.imag / p.c_r, psi, Om, stick=False)
            if mode == MODE_FREE:
                return self.free_from_wall(t, n, v, psi, Om)
            self.transition(t, mode)
            return _St(t, mode, yc, s)
        law = impact_law(p.m, p.J, p.e_c, p.R, p.mu, p.d, beta, rd, vr)
        plast = impact_law(p.m, p.J, p.e_c, p.R, p.mu, 0.0, beta, rd, vr)
        vp0, Om0 = apply_impulse(p.m, p.J, p.e_c, p.R, n, beta, v, Om, plast.P_n, plast.P_t)
        mode, s, yc = self.settle(t, th, (n.conjugate() * vp0).imag / p.c_r, psi, Om0,
                                  stick=plast.stick)
        plastic = False
        if mode != MODE_FREE:
            N = self.normal_force(mode, s, yc)
            rp = -law.rdot_plus
            plastic = rp < V_CHATTER or rp * rp / (2.0 * N / p.m) < H_CHATTER * p.c_r
        out = plast if plastic else law
        vp, Omp = (vp0, Om0) if plastic else apply_impulse(p.m, p.J, p.e_c, p.R, n, beta, v, Om,
                                                             law.P_n, law.P_t)
        self.res.impacts.append({
            "t": t, "z": p.c_r * n, "v_minus": v, "v_plus": vp, "Omega_minus": Om,
            "Omega_plus": Omp, "rdot_minus": rd, "P_n": out.P_n, "P_t": out.P_t,
            "stick": out.stick, "plastic": plastic, "capped": out.capped, "d_eff": out.d_eff,
            "E_diss": -out.dT})
        self.res.P_n += out.P_n
        self.res.P_t += out.P_t
        self.res.P_contact += -complex(out.P_n, out.P_t) * n
        self.res.E_impacts += -out.dT
        if plastic:
            self.transition(t, mode)
            return _St(t, mode, yc, s)
        return self.free_from_wall(t, n, vp, psi, Omp)

    # ---------------------------------------------------------------- phases
    def run_phase(self, st: _St, t_end: float) -> tuple[_St, bool]:
        """Integrate the current mode to t_end or its first event; returns (new state, done)."""
        p = self.p
        last_t = st.t
        if st.mode == MODE_FREE:
            sol = solve_ivp(self.rhs_free, (st.t, t_end), st.y, method="DOP853", rtol=self.rtol,
                            atol=self.atol_free, events=[self.gap_event], dense_output=True)
        else:
            z, v, psi, Om = self.kin(st)
            wc = max(abs(Om), abs(st.y[1]), abs(Om - st.y[1]), self.w)
            rhs = self.rhs_slide(st.s) if st.mode == MODE_SLIDING else self.rhs_roll
            atol = self.atol_slide if st.mode == MODE_SLIDING else self.atol_roll
            sol = solve_ivp(rhs, (st.t, t_end), st.y, method="DOP853", rtol=self.rtol, atol=atol,
                            max_step=math.pi / (8.0 * wc),
                            events=self.contact_events(st.mode, st.s), dense_output=True)
        self.res.nfev += sol.nfev
        if sol.status < 0:
            self.res.status = f"solver_failed: {sol.message}"
            return st, True
        t_stop = float(sol.t[-1])
        kind, y_stop = "end", sol.y[:, -1]
        if sol.status == 1:
            for k, ts_k in enumerate(sol.t_events):
                if len(ts_k):
                    kind, t_stop, y_stop = k, float(ts_k[0]), np.asarray(sol.y_events[k][0])
                    break
        if st.mode == MODE_FREE:
            tg = self.first_graze(sol.sol, t_stop)
            if tg is not None and tg < t_stop:
                kind, t_stop, y_stop = 0, tg, sol.sol(tg)
        done = kind == "end"
        # from the previous phase's stop (a restart after an impact begins ~1e-12 s later; the
        # dense output covers that gap to within its own accuracy)
        self.sample(st, sol.sol, min(self.t_done, last_t), t_stop, last=done)
        self.t_done = t_stop
        if done:
            return _St(t_stop, st.mode, np.asarray(y_stop, dtype=float), st.s), True
        if st.mode == MODE_FREE:
            return self.impact(t_stop, np.asarray(y_stop, dtype=float)), False
        # contact event: bank the accumulators, then switch
        acc = y_stop[-5:]
        self.res.P_n += float(acc[0])
        self.res.P_t += float(acc[1])
        self.res.P_contact += complex(acc[2], acc[3])
        self.res.E_friction += float(acc[4])
        stc = _St(t_stop, st.mode, np.asarray(y_stop, dtype=float), st.s)
        z, v, psi, Om = self.kin(stc)
        th, thd = float(y_stop[0]), float(y_stop[1])
        n = z / p.c_r
        if kind == 0:  # lift-off
            self.transition(t_stop, MODE_FREE)
            return self.free_from_wall(t_stop, n, v, psi, Om), False
        if st.mode == MODE_SLIDING:  # slip zero
            mode, s, yc = self.settle(t_stop, th, thd, psi, Om, stick=True)
        else:  # friction cone reached: slide with s = sign(F_t)
            Ft = self.md.roll_forces(th, thd, psi)[1]
            s = _sign(Ft) or 1.0
            mode, yc = MODE_SLIDING, np.array([th, thd, psi, Om, 0.0, 0.0, 0.0, 0.0, 0.0])
            if self.md.slide_forces(th, thd, psi, Om, s)[0] <= 0.0:
                mode = MODE_FREE
        if mode == MODE_FREE:
            self.transition(t_stop, MODE_FREE)
            return self.free_from_wall(t_stop, n, v, psi, Om), False
        if mode != st.mode or s != st.s:
            self.transition(t_stop, mode)
        return _St(t_stop, mode, yc, s), False

    def bank_final(self, st: _St) -> None:
        """Bank the accumulators of a contact phase that ran to the end."""
        if st.mode != MODE_FREE:
            acc = st.y[-5:]
            self.res.P_n += float(acc[0])
            self.res.P_t += float(acc[1])
            self.res.P_contact += complex(acc[2], acc[3])
            self.res.E_friction += float(acc[4])


def simulate(params: dict[str, Any], J: float, Omega0: float, z0: complex, v0: complex,
             psi0: float, t_end: float, t_grid: Sequence[float] | np.ndarray | None = None,
             a: float = 0.0, F_ext: complex = 0j, T_drive: float = 0.0, rtol: float = 1e-12,
             max_events: int = 200000) -> SpinResult:
    """Integrate the rigid rotor (translation + spin) from t = 0 to t_end [s].

    ``params``: dict with keys m c k e_c phi c_r R mu d g levitate (SI); ``J`` [kg m^2];
    initial ``Omega0`` [rad/s], ``z0`` [m] (``|z0| < c_r``), ``v0`` [m/s], ``psi0`` [rad];
    ``t_grid`` sample times [s] in [0, t_end]; held inputs ``a`` [-], ``F_ext`` [N, complex, at
    the geometric centre, gravity excluded], ``T_drive`` [N m]; ``rtol`` of solve_ivp (atol is
    scaled per component, see the module doc). Starts in free flight.
    """
    p = SpinPar.from_dict(params, J)
    p.check_well_posed()
    if not abs(z0) < p.c_r:
        raise ValueError(f"|z0| = {abs(z0)} must be < c_r = {p.c_r}")
    md = _Model(p, float(a), complex(F_ext), float(T_drive))
    w = max(abs(Omega0), math.sqrt(max(p.k, 0.0) / p.m), 1.0)
    tg = np.sort(np.asarray([] if t_grid is None else t_grid, dtype=float))
    sim = _Sim(md, rtol, w, tg, max_events)
    st = _St(0.0, MODE_FREE, np.array([z0.real, z0.imag, v0.real, v0.imag, psi0, Omega0],
                                      dtype=float))
    res = sim.res
    stalls = 0
    while True:
        t_a = st.t
        st, done = sim.run_phase(st, float(t_end))
        if done:
            break
        stalls = stalls + 1 if st.t <= t_a else 0
        if stalls > 50:
            res.status = "stalled"
            break
        if len(res.impacts) + len(res.transitions) > max_events:
            res.status = "max_events"
            break
    sim.bank_final(st)
    res.t = st.t
    res.z, res.v, res.psi, res.Omega = sim.kin(st)
    res.mode = st.mode
    res.samples = {k: np.array(vals, dtype=complex if k in ("z", "v") else
                               (int if k == "mode" else float)) for k, vals in sim.buf.items()}
    return res
