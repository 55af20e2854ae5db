"""Synchronous solutions of the chapter's model: equilibria, rub, impacting cycles.

Frame and units: unless a name says otherwise everything here is in the chapter's
*scaled co-rotating* frame (MODEL.md §2): time t = Omega tau (dimensionless), position
U = z e^{-i psi}/c_r (in units of c_r), velocity U' = dU/dt (in units of c_r Omega). The
free flight is

    U'' + (gamma + 2i) U' + (omega^2 - 1 + i gamma) U = rho e^{i phi},   |U| < 1,

autonomous in this frame, so a synchronous impacting limit cycle (one impact per period
T, T found, not fixed) is a fixed point of the impact map

    P: x = (alpha, rdot+, thetadot+) -> x' (next impact, after the reset),

x being the state right after an impact: U = e^{i alpha}, U' = (rdot+ + i thetadot+) U
(rdot+ < 0 is the radial speed, thetadot+ the co-rotating whirl rate). P is evaluated
with the core (SI, inertial): the exact flight ``FlightModel.propagate``, the rigorous
first-contact search ``ContactLocator.find`` and the reset law ``impact.reset`` (with the
Coulomb stick cap), converting with ``RotorParams.from_scaled(sp, Omega, m, c_r)`` and the
``TouchdownCore.from_scaled`` convention z = c_r U e^{i psi}, psi = psi0 + t, psi0 = 0 at
the start of each flight. The Jacobian of P comes from an independent closed form of the
scaled flow (matrix exponential, variational equations, implicit impact time), or from
finite differences of the core map.
"""

from __future__ import annotations

import cmath
import itertools
import math
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.linalg
import scipy.optimize
from rotortd import RotorParams, ScaledParams, TouchdownCore, WallForces, forward_rub_equilibria
from rotortd.events import Contact, ContactLocator, Work
from rotortd.flight import FlightModel
from rotortd.impact import reset

OMEGA = 184.2
"""Spin speed (rad/s) used to realise a scaled set in SI (chapter value)."""
MASS = 50.0
"""Rotor mass (kg) used to realise a scaled set in SI (chapter value)."""
C_R = 0.7e-3
"""Radial clearance (m) used to realise a scaled set in SI (chapter value)."""
T_MAX = 400.0
"""Longest flight (scaled time) searched for the next impact."""
WINDOW = 2.0
MARGIN_STOP = 1e-3
"""Continuation stops when the grazing margin falls below this (grazing located after)."""
"""Length (scaled time) of one contact-search window (see ImpactMap._search)."""


# --------------------------------------------------------------------------- parameters


def chapter_params(**overrides: float) -> ScaledParams:
    """The chapter's scaled set (gamma = 0.152, omega = 0.760, rho = 3/7, ...), dimensionless.

    ``overrides`` replace fields of ``ScaledParams`` (gamma, omega, rho, phi, mu, d, R_over_cr).
    """
    return replace(RotorParams().scaled(OMEGA), **overrides)


def si_params(sp: ScaledParams) -> RotorParams:
    """SI parameters realising ``sp`` at Omega = OMEGA, m = MASS, c_r = C_R (no gravity)."""
    return RotorParams.from_scaled(sp, OMEGA, m=MASS, c_r=C_R)


def regular_equilibrium(sp: ScaledParams) -> complex:
    """U* = rho e^{i phi}/(omega^2 - 1 + i gamma): the steady whirl, scaled co-rotating."""
    return sp.rho * cmath.exp(1j * sp.phi) / complex(sp.omega**2 - 1.0, sp.gamma)


def gamma_beb(sp: ScaledParams) -> float:
    """gamma_BEB = sqrt(rho^2 - (1 - omega^2)^2), where |U*| = 1 (NaN if |U*| < 1 always)."""
    disc = sp.rho**2 - (1.0 - sp.omega**2) ** 2
    return math.sqrt(disc) if disc >= 0.0 else math.nan


def system_matrix(sp: ScaledParams) -> np.ndarray:
    """A of w' = A w + b, w = (U, U') (complex 2x2, scaled co-rotating)."""
    return np.array(
        [[0.0, 1.0], [1.0 - sp.omega**2 - 1j * sp.gamma, -sp.gamma - 2j]], dtype=complex
    )


# --------------------------------------------------------------------------- forward rub


@dataclass(frozen=True)
class RubPoint:
    """A synchronous forward-rub pseudo-equilibrium (sliding, U' = 0), scaled co-rotating.

    alpha: co-rotating contact angle (rad); N: normal force / (m c_r Omega^2) (>= 0);
    stable: both eigenvalues of the linearised sliding motion have Re < 0;
    eig: those eigenvalues (per unit scaled time).
    """

    gamma: float
    alpha: float
    N: float
    stable: bool
    eig: tuple[complex, complex]


def rub_equilibria(sp: ScaledParams) -> list[RubPoint]:
    """Forward-rub equilibria from the core's ``forward_rub_equilibria``, converted to scaled."""
    wf = WallForces.build(si_params(sp), OMEGA, 0j, 1.0)
    out = []
    for eq in forward_rub_equilibria(wf):
        eig = (eq.eig[0] / OMEGA, eq.eig[1] / OMEGA)
        out.append(RubPoint(sp.gamma, eq.alpha, eq.Gn / OMEGA**2, eq.stable, eig))
    return sorted(out, key=lambda e: not e.stable)


def rub_equilibria_scaled(sp: ScaledParams) -> list[RubPoint]:
    """Independent scaled derivation of the forward-rub equilibria (cross-check of the core).

    At U = e^{i alpha}, U' = 0 the contact force is -N (1 + i mu s) U, s = +1 (slip
    R/c_r + 1 > 0), so rho e^{i(phi - alpha)} = omega^2 - 1 + i gamma + N (1 + i mu): all
    roots alpha of gamma + mu N(alpha) = rho sin(phi - alpha) with N = rho cos(phi - alpha)
    + 1 - omega^2 >= 0. Linearising theta'' = -(gamma + 2 mu) theta' - a1 theta with
    a1 = rho (cos x + mu sin x), x = phi - alpha, gives the eigenvalues.
    """
    mu = sp.mu
    amp = sp.rho * math.hypot(1.0, mu)
    S = (sp.gamma + mu * (1.0 - sp.omega**2)) / amp
    if abs(S) > 1.0:
        return []
    delta = math.atan(mu)
    out = []
    for x in (delta + math.asin(S), delta + math.pi - math.asin(S)):
        N = sp.rho * math.cos(x) + 1.0 - sp.omega**2
        if N < 0.0:
            continue
        a1 = sp.rho * (math.cos(x) + mu * math.sin(x))
        b1 = sp.gamma + 2.0 * mu
        root = cmath.sqrt(b1 * b1 / 4.0 - a1)
        eig = (-b1 / 2.0 + root, -b1 / 2.0 - root)
        alpha = math.remainder(sp.phi - x, 2.0 * math.pi)
        out.append(RubPoint(sp.gamma, alpha, N, max(e.real for e in eig) < 0.0, eig))
    return sorted(out, key=lambda e: not e.stable)


def rub_fold_gamma(sp: ScaledParams) -> float:
    """Largest gamma with a forward-rub equilibrium: the smooth fold of the two rub branches.

    gamma_fold = rho sqrt(1 + mu^2) - mu (1 - omega^2) (S = 1 in rub_equilibria_scaled).
    """
    return sp.rho * math.hypot(1.0, sp.mu) - sp.mu * (1.0 - sp.omega**2)


# --------------------------------------------------------------------------- scaled flow


class ScaledFlow:
    """Closed-form free flight in the scaled co-rotating frame (independent of the core).

    w(t) = e^{A t} (w0 - w_eq) + w_eq, w_eq = (U*, 0); also the derivative of w(t) with
    respect to gamma (through A and U*), from the block exponential
    exp([[A, dA], [0, A]] t) whose upper-right block is d/dgamma e^{A t}.
    """

    def __init__(self, sp: ScaledParams) -> None:
        self.sp = sp
        self.A = system_matrix(sp)
        self.U_eq = regular_equilibrium(sp)
        self.w_eq = np.array([self.U_eq, 0.0], dtype=complex)
        self.dA = np.array([[0.0, 0.0], [-1j, -1.0]], dtype=complex)  # dA/dgamma
        den = complex(sp.omega**2 - 1.0, sp.gamma)
        self.dw_eq = np.array([-1j * self.U_eq / den, 0.0], dtype=complex)  # dw_eq/dgamma

    def expA(self, t: float) -> np.ndarray:
        """e^{A t} (complex 2x2)."""
        return scipy.linalg.expm(self.A * t)

    def state(self, w0: np.ndarray, t: float) -> np.ndarray:
        """w(t) from w0 = (U0, U0') after a free flight of scaled time t."""
        return self.expA(t) @ (w0 - self.w_eq) + self.w_eq

    def states(self, w0: np.ndarray, ts: np.ndarray) -> np.ndarray:
        """w at many times (shape (len(ts), 2)), by the eigen-decomposition of A."""
        lam, V = np.linalg.eig(self.A)
        c = np.linalg.solve(V, w0 - self.w_eq)
        modes = np.exp(np.outer(ts, lam)) * c
        return modes @ V.T + self.w_eq

    def rate(self, w: np.ndarray) -> np.ndarray:
        """w' = A w + b = A (w - w_eq)."""
        return self.A @ (w - self.w_eq)

    def dgamma(self, w0: np.ndarray, t: float) -> np.ndarray:
        """d w(t)/d gamma at fixed w0 and t."""
        n = 2
        M = np.zeros((2 * n, 2 * n), dtype=complex)
        M[:n, :n] = self.A * t
        M[n:, n:] = self.A * t
        M[:n, n:] = self.dA * t
        E = scipy.linalg.expm(M)
        eA, deA = E[:n, :n], E[:n, n:]
        return deA @ (w0 - self.w_eq) + (np.eye(n) - eA) @ self.dw_eq


def real_jac(C: np.ndarray) -> np.ndarray:
    """Real 4x4 matrix of the complex-linear map dw -> C dw on (Re U, Im U, Re U', Im U')."""
    n = C.shape[0]
    R = np.zeros((2 * n, 2 * n))
    for i in range(n):
        for j in range(n):
            c = C[i, j]
            R[2 * i : 2 * i + 2, 2 * j : 2 * j + 2] = [[c.real, -c.imag], [c.imag, c.real]]
    return R


def to_real(w: np.ndarray) -> np.ndarray:
    """(U, U') complex -> (Re U, Im U, Re U', Im U')."""
    return np.array([w[0].real, w[0].imag, w[1].real, w[1].imag])


# --------------------------------------------------------------------------- impact map


@dataclass(frozen=True)
class Flight:
    """One flight of the impact map (scaled co-rotating).

    x0: post-impact start (alpha, rdot+, thetadot+); T: flight time to the next contact;
    U, dU: position and velocity at the contact (before the reset); kind: "impact" or
    "touch" (zero normal speed to resolution); rdot: normal speed rdot- (> 0);
    x1: post-impact state after the reset; stick: the Coulomb cap fired.
    """

    x0: np.ndarray
    T: float
    U: complex
    dU: complex
    kind: str
    rdot: float
    x1: np.ndarray
    stick: bool


class NoImpact(RuntimeError):
    """The flight never reaches the clearance circle (within T_MAX)."""


def post_impact_state(x: np.ndarray) -> tuple[complex, complex]:
    """(U, U') of the post-impact section point x = (alpha, rdot+, thetadot+)."""
    U = cmath.exp(1j * float(x[0]))
    return U, complex(float(x[1]), float(x[2])) * U


def section_point(U: complex, dU: complex) -> np.ndarray:
    """x = (arg U, Re(conj U U')/|U|, Im(conj U U')/|U|^2) of a state on (or near) |U| = 1."""
    r = abs(U)
    w = U.conjugate() * dU
    return np.array([cmath.phase(U), w.real / r, w.imag / (r * r)])


class ImpactMap:
    """The impact map P of the module docstring, built on the core (exact flight, locator)."""

    def __init__(self, sp: ScaledParams) -> None:
        self.sp = sp
        self.p = si_params(sp)
        self.fm = FlightModel(self.p, OMEGA, 0j, 1.0)
        self.flow = ScaledFlow(sp)

    def to_si(self, U: complex, dU: complex, psi: float = 0.0) -> tuple[complex, complex]:
        """(z, v) in SI inertial of the scaled co-rotating (U, U') at spin angle psi."""
        rot = cmath.exp(1j * psi)
        c_r = self.p.c_r
        return c_r * U * rot, c_r * OMEGA * (dU + 1j * U) * rot

    def to_scaled(self, z: complex, v: complex, E: complex) -> tuple[complex, complex]:
        """(U, U') of the SI inertial (z, v) at phasor E = e^{i psi}."""
        c_r = self.p.c_r
        return z / (c_r * E), (v - 1j * OMEGA * z) / (c_r * OMEGA * E)

    def flight(self, x: np.ndarray, t_max: float = T_MAX) -> Flight:
        """Fly from the post-impact state x to the first contact; apply the reset there."""
        U0, dU0 = post_impact_state(x)
        z0, v0 = self.to_si(U0, dU0)
        if self.fm.sup_radius_bound(z0, v0, 1.0 + 0j) < self.p.c_r:
            raise NoImpact("the free flight stays inside the clearance for ever")
        hit, s0 = self._search(z0, v0, t_max / OMEGA)
        if hit is None:
            raise NoImpact(f"no contact within t = {t_max} (scaled)")
        z = hit.z * (self.p.c_r / abs(hit.z))
        U, dU = self.to_scaled(z, hit.v, hit.E)
        r = reset(z / self.p.c_r, hit.v, self.p.m, self.p.d, self.p.mu, self.p.R, OMEGA)
        _, dUp = self.to_scaled(z, r.v_plus, hit.E)
        x1 = section_point(U, dUp)
        x1[1] = min(x1[1], 0.0) if hit.kind == "impact" else x1[1]
        rdot = r.rdot / (self.p.c_r * OMEGA)
        T = (s0 + hit.s) * OMEGA
        return Flight(np.asarray(x, float), T, U, dU, hit.kind, rdot, x1, r.stick)

    def _search(self, z0: complex, v0: complex, h: float) -> tuple[Contact | None, float]:
        """First contact within h seconds (SI), searched in windows of WINDOW scaled units.

        Windows keep each ``ContactLocator.find`` call well inside its advance cap; the
        state at a window start comes from the exact flight of the previous window.
        Returns (contact or None, start time of the window that holds it, s).
        """
        win = WINDOW / OMEGA
        s0, z, v = 0.0, z0, v0
        while s0 < h:
            hw = min(win, h - s0)
            E = cmath.exp(1j * OMEGA * s0)
            hit = ContactLocator(self.fm, z, v, E).find(hw, s0 == 0.0, Work())
            if hit is not None and hit.kind == "clear":  # no contact up to hit.s: resume
                z, v, s0 = hit.z, hit.v, s0 + hit.s
                continue
            if hit is not None:
                return hit, s0
            z, v = self.fm.propagate(z, v, E, hw)
            s0 += hw
        return None, s0

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """P(x): the post-impact state of the next impact."""
        return self.flight(x).x1

    # -- derivatives from the scaled closed form -----------------------------------------

    def jacobian(self, fl: Flight) -> tuple[np.ndarray, np.ndarray]:
        """(dP/dx (3x3), dP/dgamma (3,)) at the flight ``fl``, from the variational flow.

        The impact time T(x) is implicit in |U(T)|^2 = 1: dT = -dg/g' with
        g' = 2 rdot-; then the reset is differentiated on the section.
        """
        flow = self.flow
        U0, dU0 = post_impact_state(fl.x0)
        w0 = np.array([U0, dU0])
        # d w0 / d x (4x3)
        e = cmath.exp(1j * float(fl.x0[0]))
        cols = [1j * w0, np.array([0.0, e]), np.array([0.0, 1j * e])]
        Dw0 = np.column_stack([to_real(c) for c in cols])
        Phi = real_jac(flow.expA(fl.T))
        w1 = np.array([fl.U, fl.dU])
        w1dot = to_real(flow.rate(w1))
        Dw1_x = Phi @ Dw0
        Dw1_g = to_real(flow.dgamma(w0, fl.T))
        Ur = to_real(w1)
        grad_g = np.array([2 * Ur[0], 2 * Ur[1], 0.0, 0.0])
        gdot = grad_g @ w1dot
        Dw1_x = Dw1_x - np.outer(w1dot, grad_g @ Dw1_x) / gdot
        Dw1_g = Dw1_g - w1dot * (grad_g @ Dw1_g) / gdot
        H = self._reset_jacobian(fl)
        return H @ Dw1_x, H @ Dw1_g

    def _reset_jacobian(self, fl: Flight) -> np.ndarray:
        """d x1 / d w1 (3x4): section coordinates after the reset, w1 = pre-impact state."""
        sp = self.sp
        U, V = fl.U, fl.dU
        w = U.conjugate() * V
        # rows: d alpha, d rdot, d thetadot as linear forms in (dU, dV)
        rows = []
        for dU, dV in (
            (1.0, 0.0),
            (1j, 0.0),
            (0.0, 1.0),
            (0.0, 1j),
        ):
            dUc = complex(dU)
            dVc = complex(dV)
            da = (U.conjugate() * dUc).imag
            q = dUc.conjugate() * V + U.conjugate() * dVc
            dr = q.real - w.real * (U.conjugate() * dUc).real
            dth = q.imag - 2.0 * w.imag * (U.conjugate() * dUc).real
            rows.append((da, dr, dth))
        J = np.array(rows).T  # 3x4: (alpha, rdot-, thetadot-) wrt (ReU, ImU, ReV, ImV)
        vrel = sp.R_over_cr + 1.0 + w.imag
        s = math.copysign(1.0, vrel) if vrel != 0.0 else 0.0
        if fl.stick:
            T = np.array([[1.0, 0.0, 0.0], [0.0, -sp.d, 0.0], [0.0, 0.0, 0.0]])
        else:
            T = np.array([[1.0, 0.0, 0.0], [0.0, -sp.d, 0.0], [0.0, -sp.mu * (1 + sp.d) * s, 1.0]])
        return T @ J

    def jacobian_fd(self, x: np.ndarray, eps: float = 1e-7) -> np.ndarray:
        """dP/dx by central differences of the core map (independent of ``jacobian``)."""
        J = np.zeros((3, 3))
        for j in range(3):
            dx = np.zeros(3)
            dx[j] = eps
            fp, fm_ = self(x + dx), self(x - dx)
            diff = fp - fm_
            diff[0] = math.remainder(diff[0], 2.0 * math.pi)
            J[:, j] = diff / (2.0 * eps)
        return J


# --------------------------------------------------------------------------- Newton


class NewtonFailed(RuntimeError):
    """Newton on the impact map did not converge."""


def map_residual(P: ImpactMap, x: np.ndarray) -> tuple[np.ndarray, Flight]:
    """F(x) = P(x) - x (angle difference wrapped to (-pi, pi]) and the flight."""
    fl = P.flight(x)
    F = fl.x1 - x
    F[0] = math.remainder(F[0], 2.0 * math.pi)
    return F, fl


def newton_fixed_point(
    P: ImpactMap, x0: np.ndarray, tol: float = 1e-12, max_iter: int = 40
) -> tuple[np.ndarray, Flight, float]:
    """Fixed point of P from the guess x0 by damped Newton (variational Jacobian).

    Returns (x*, flight from x*, max-norm residual |P(x*) - x*|).
    """
    x = np.asarray(x0, float).copy()
    if x[1] >= 0.0:
        raise NewtonFailed("the guess must have rdot+ < 0 (moving inward after the impact)")
    F, fl = map_residual(P, x)
    res = float(np.max(np.abs(F)))
    for _ in range(max_iter):
        if res < tol:
            break
        if fl.kind != "impact":
            raise NewtonFailed("the flight ends in a touch (grazing), not an impact")
        J, _ = P.jacobian(fl)
        dx = np.linalg.solve(J - np.eye(3), -F)
        lam = 1.0
        while lam > 1e-4:
            xn = x + lam * dx
            xn[0] = math.remainder(xn[0], 2.0 * math.pi)
            if xn[1] >= 0.0:  # post-impact motion must point inward
                lam *= 0.5
                continue
            try:
                Fn, fln = map_residual(P, xn)
            except NoImpact:
                lam *= 0.5
                continue
            resn = float(np.max(np.abs(Fn)))
            if resn < (1.0 - 0.25 * lam) * res or resn < tol:
                break
            lam *= 0.5
        else:
            raise NewtonFailed(f"line search failed at residual {res:.3g}")
        x, F, fl, res = xn, Fn, fln, resn
    if res >= max(tol, 1e-10):
        raise NewtonFailed(f"no convergence: residual {res:.3g}")
    if fl.kind != "impact" or fl.T <= 1e-9:
        raise NewtonFailed("degenerate fixed point (zero-length flight or grazing touch)")
    return x, fl, res


# --------------------------------------------------------------------------- closed-form cycles


def _resolvent(sp: ScaledParams, T: float) -> np.ndarray:
    """(e^{A T} - I)^{-1} (complex 2x2); regular for T > 0 since Re(eig A) = -gamma/2 < 0."""
    return np.linalg.inv(scipy.linalg.expm(system_matrix(sp) * T) - np.eye(2))


def _q(sp: ScaledParams) -> complex:
    """q = (1 + d)(1 + i mu s) with forward slip s = +1 (the stick cap not firing)."""
    return (1.0 + sp.d) * complex(1.0, sp.mu)


def period_condition(sp: ScaledParams, T: float) -> float:
    """Re H(T) + d, H = q [(e^{AT} - I)^{-1}]_{22}; zero at the period of every cycle.

    Derivation (scaled co-rotating): a period-one cycle has w(T-) - w_eq = e^{AT}(w0 - w_eq)
    with w(T-) = (U0, V-) and w0 = (U0, V- - q rdot U0), so (e^{AT} - I)(w0 - w_eq) =
    (0, q rdot U0): w0 - w_eq = rdot U0 q (R12, R22), R = (e^{AT} - I)^{-1}. The radial part of
    V+ = rdot U0 H must be -d rdot, i.e. Re H(T) = -d, whatever the amplitude rdot.
    """
    return float((_q(sp) * _resolvent(sp, T)[1, 1]).real + sp.d)


def _period_condition_many(sp: ScaledParams, ts: np.ndarray) -> np.ndarray:
    """period_condition at many T at once (eigen-decomposition of A; A is diagonalisable)."""
    lam, V = np.linalg.eig(system_matrix(sp))
    Vi = np.linalg.inv(V)
    out = np.empty(len(ts))
    for i, t in enumerate(ts):
        E = (V * np.exp(lam * t)) @ Vi - np.eye(2)
        R22 = E[0, 0] / (E[0, 0] * E[1, 1] - E[0, 1] * E[1, 0])
        out[i] = (_q(sp) * R22).real + sp.d
    return out


def period_roots(sp: ScaledParams, t_max: float = 60.0, n: int = 6000) -> list[float]:
    """All roots T in (0, t_max] of ``period_condition`` (scaled time), by sampling + Brent."""
    ts = np.linspace(t_max / n, t_max, n)
    f = _period_condition_many(sp, ts)
    roots = []
    for i in np.nonzero(np.sign(f[:-1]) != np.sign(f[1:]))[0]:
        roots.append(
            scipy.optimize.brentq(lambda t: period_condition(sp, t), ts[i], ts[i + 1], xtol=1e-15)
        )
    return roots


@dataclass(frozen=True)
class AnalyticCycle:
    """A period-one cycle from the closed form (scaled co-rotating), admissible or not.

    T: period; rdot: impact normal speed rdot-; U0: impact point; dU0: post-impact velocity.
    """

    T: float
    rdot: float
    U0: complex
    dU0: complex

    @property
    def x(self) -> np.ndarray:
        """Post-impact section point (alpha, rdot+, thetadot+)."""
        return section_point(self.U0, self.dU0)


def analytic_cycles(sp: ScaledParams, t_max: float = 60.0) -> list[AnalyticCycle]:
    """All period-one cycles with period <= t_max by the closed form (no event location).

    For each period root T, U0 (1 - rdot G) = U* with G = q R12, so |1 - rdot G| = |U*|:
    a quadratic in rdot (roots > 0 kept). Admissibility (no earlier contact in (0, T)) and
    the stick cap are *not* checked here; see ``max_radius_in_flight``.
    """
    Us = regular_equilibrium(sp)
    q = _q(sp)
    out = []
    for T in period_roots(sp, t_max):
        R = _resolvent(sp, T)
        G, H = q * R[0, 1], q * R[1, 1]
        a, b, c = abs(G) ** 2, -2.0 * G.real, 1.0 - abs(Us) ** 2
        disc = b * b - 4.0 * a * c
        if disc < 0.0:
            continue
        sq = math.sqrt(disc)
        for rd in sorted({(-b - sq) / (2 * a), (-b + sq) / (2 * a)}):
            if rd <= 0.0:
                continue
            U0 = Us / (1.0 - rd * G)
            out.append(AnalyticCycle(T, rd, U0, rd * U0 * H))
    return out


def radius_profile(
    sp: ScaledParams, U0: complex, dU0: complex, T: float, n: int = 2000
) -> tuple[np.ndarray, np.ndarray]:
    """(t, |U(t)|) on [0, T] (scaled) along the free flight from (U0, dU0)."""
    ts = np.linspace(0.0, T, n + 1)
    w = ScaledFlow(sp).states(np.array([U0, dU0]), ts)
    return ts, np.abs(w[:, 0])


def max_radius_in_flight(sp: ScaledParams, U0: complex, dU0: complex, T: float) -> float:
    """Largest interior local maximum of |U(t)| on (0, T) (scaled), or 0 when there is none.

    1 - this is the grazing margin of a cycle: it reaches 0 when the flight touches the
    clearance circle tangentially in mid-flight (grazing).
    """
    flow = ScaledFlow(sp)
    w0 = np.array([U0, dU0])
    n = max(400, int(60 * T))
    ts, r = radius_profile(sp, U0, dU0, T, n)
    best = 0.0
    for i in range(1, n):
        if r[i] >= r[i - 1] and r[i] >= r[i + 1]:
            res = scipy.optimize.minimize_scalar(
                lambda t: -abs(flow.state(w0, t)[0]),
                bounds=(ts[i - 1], ts[i + 1]),
                method="bounded",
                options={"xatol": 1e-13},
            )
            best = max(best, -float(res.fun))
    return best


def labelled_cycles(sp: ScaledParams) -> dict[str, AnalyticCycle]:
    """Closed-form cycles keyed "<short|long>-<small|large>".

    short/long: the first/second root of ``period_condition`` (shorter/longer period);
    small/large: the smaller/larger impact speed of that period (below gamma_BEB only the
    large one exists, the small one has passed through rdot = 0 at the BEB).
    """
    out: dict[str, AnalyticCycle] = {}
    by_T: dict[float, list[AnalyticCycle]] = {}
    for c in analytic_cycles(sp):
        by_T.setdefault(c.T, []).append(c)
    for k, T in enumerate(sorted(by_T)[:2]):
        cs = sorted(by_T[T], key=lambda c: c.rdot)
        name = ("short", "long")[k]
        out[f"{name}-large"] = cs[-1]
        if len(cs) > 1:
            out[f"{name}-small"] = cs[0]
    return out


# --------------------------------------------------------------------------- cycles


@dataclass(frozen=True)
class Cycle:
    """A period-one synchronous impacting limit cycle (one impact per period T).

    Scaled co-rotating: ``x`` = (alpha, rdot+, thetadot+) right after the impact, ``U0`` =
    e^{i alpha}, ``dU0`` = dU/dt after the reset, ``T`` the period (flight time), ``alpha``
    the impact angle (rad), ``rdot`` the impact normal speed rdot- (c_r Omega), ``max_radius``
    the largest interior maximum of |U| in flight and ``grazing_margin`` = 1 - max_radius.
    SI inertial (Omega = OMEGA, psi0 = 0): ``z0`` (m), ``v0`` (m/s) right after the impact,
    ``T_si`` (s), ``rdot_si`` (m/s); start a core on it with ``core()``.
    ``multipliers``: eigenvalues of the impact-map Jacobian (the non-trivial Floquet
    multipliers); ``stable`` when all lie inside the unit circle; ``residual``: max-norm
    of P(x) - x evaluated with the core.
    """

    gamma: float
    sp: ScaledParams
    branch: str
    x: np.ndarray
    U0: complex
    dU0: complex
    T: float
    alpha: float
    rdot: float
    multipliers: np.ndarray
    stable: bool
    max_radius: float
    grazing_margin: float
    residual: float
    jacobian: np.ndarray = field(repr=False)
    z0: complex = 0j
    v0: complex = 0j
    T_si: float = 0.0
    rdot_si: float = 0.0

    @property
    def params(self) -> RotorParams:
        """SI parameters (Omega = OMEGA, m = MASS, c_r = C_R)."""
        return si_params(self.sp)

    def core(self) -> TouchdownCore:
        """A TouchdownCore started right after the cycle's impact (psi0 = 0, t0 = 0)."""
        return TouchdownCore(self.params, self.z0, self.v0, 0.0)

    def core_from_scaled(self) -> TouchdownCore:
        """The same start through ``TouchdownCore.from_scaled`` (U0, dU0, psi0 = 0)."""
        return TouchdownCore.from_scaled(self.params, OMEGA, self.U0, self.dU0, 0.0)


def multipliers_of(J: np.ndarray) -> np.ndarray:
    """Eigenvalues of the map Jacobian, sorted by decreasing modulus."""
    lam = np.linalg.eigvals(J)
    return lam[np.argsort(-np.abs(lam))]


def cycle_at(sp: ScaledParams, x: np.ndarray, branch: str = "") -> Cycle:
    """Newton-refine the guess x on the core map at ``sp`` and collect the cycle data."""
    P = ImpactMap(sp)
    xs, fl, res = newton_fixed_point(P, x)
    J, _ = P.jacobian(fl)
    lam = multipliers_of(J)
    U0, dU0 = post_impact_state(xs)
    mr = max_radius_in_flight(sp, U0, dU0, fl.T)
    z0, v0 = P.to_si(U0, dU0)
    return Cycle(
        gamma=sp.gamma,
        sp=sp,
        branch=branch,
        x=xs,
        U0=U0,
        dU0=dU0,
        T=fl.T,
        alpha=float(xs[0]),
        rdot=fl.rdot,
        multipliers=lam,
        stable=bool(np.max(np.abs(lam)) < 1.0),
        max_radius=mr,
        grazing_margin=1.0 - mr,
        residual=res,
        jacobian=J,
        z0=z0,
        v0=v0,
        T_si=fl.T / OMEGA,
        rdot_si=fl.rdot * C_R * OMEGA,
    )


def find_period_one_cycle(
    gamma: float,
    guess: np.ndarray | None = None,
    branch: str = "long-large",
    **scaled_overrides: float,
) -> Cycle:
    """The period-one cycle at ``gamma`` (other scaled parameters from the chapter set).

    ``guess``: a post-impact section point (alpha, rdot+, thetadot+) for Newton; without
    it the closed form (``labelled_cycles``) provides the guess of the named ``branch``
    ("short-small", "short-large", "long-small", "long-large"). Newton then runs on the
    core-based impact map (residual < 1e-12 typically). Raises KeyError when the branch
    does not exist at this gamma, NewtonFailed when Newton does not converge.
    """
    sp = chapter_params(gamma=gamma, **scaled_overrides)
    if guess is None:
        cyc = labelled_cycles(sp)
        if branch not in cyc:
            raise KeyError(f"no {branch!r} cycle at gamma = {gamma}: found {sorted(cyc)}")
        guess = cyc[branch].x
    return cycle_at(sp, np.asarray(guess, float), branch)


# --------------------------------------------------------------------------- continuation


@dataclass(frozen=True)
class BranchPoint:
    """One point of a continued cycle branch (scaled co-rotating), or a located event.

    branch: id of the branch; gamma; x = (alpha, rdot+, thetadot+); T period; rdot impact
    speed rdot-; multipliers; stable; margin = 1 - max interior |U| in flight;
    dgamma_ds: gamma component of the unit tangent (its sign change marks a fold);
    pd: det(DP + I) (its sign change marks a period doubling, a real multiplier at -1);
    event: None, or "fold", "period_doubling", "grazing", "beb_birth", "torus" (a complex
    pair crossing the unit circle).
    """

    branch: str
    gamma: float
    x: tuple[float, float, float]
    T: float
    rdot: float
    multipliers: tuple[complex, ...]
    stable: bool
    margin: float
    dgamma_ds: float
    pd: float
    event: str | None = None


def _fixed_point_system(
    y: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, Flight, np.ndarray]:
    """F(y) = P(x; gamma) - x and its 3x4 Jacobian for y = (x, gamma) (core map, analytic J)."""
    sp = chapter_params(gamma=float(y[3]))
    P = ImpactMap(sp)
    F, fl = map_residual(P, y[:3])
    Jx, Jg = P.jacobian(fl)
    return F, np.column_stack([Jx - np.eye(3), Jg]), fl, Jx


def _tangent(DF: np.ndarray, prev: np.ndarray | None) -> np.ndarray:
    """Unit null vector of the 3x4 DF, oriented along ``prev`` (or towards larger gamma)."""
    _, _, Vt = np.linalg.svd(DF)
    t = Vt[-1]
    ref = prev if prev is not None else np.array([0.0, 0.0, 0.0, 1.0])
    return t if float(t @ ref) >= 0.0 else -t


def _correct(
    y_pred: np.ndarray, t: np.ndarray, tol: float = 1e-11, max_iter: int = 8
) -> tuple[np.ndarray, Flight, np.ndarray, np.ndarray]:
    """Newton on (F(y) = 0, t.(y - y_pred) = 0); returns (y, flight, DF, DP)."""
    y = y_pred.copy()
    for _ in range(max_iter):
        if y[1] >= 0.0 or y[3] <= 0.0:
            raise NewtonFailed("left the physical domain (rdot+ >= 0 or gamma <= 0)")
        F, DF, fl, Jx = _fixed_point_system(y)
        if fl.kind != "impact":
            raise NewtonFailed("grazing touch")
        g = np.append(F, t @ (y - y_pred))
        if np.max(np.abs(g)) < tol:
            return y, fl, DF, Jx
        y = y - np.linalg.solve(np.vstack([DF, t]), g)
        y[0] = math.remainder(y[0], 2.0 * math.pi)
    raise NewtonFailed("corrector did not converge")


def _branch_point(branch: str, y: np.ndarray, fl: Flight, Jx: np.ndarray, t: np.ndarray):
    sp = chapter_params(gamma=float(y[3]))
    lam = multipliers_of(Jx)
    U0, dU0 = post_impact_state(y[:3])
    margin = 1.0 - max_radius_in_flight(sp, U0, dU0, fl.T)
    return BranchPoint(
        branch=branch,
        gamma=float(y[3]),
        x=(float(y[0]), float(y[1]), float(y[2])),
        T=fl.T,
        rdot=fl.rdot,
        multipliers=tuple(complex(v) for v in lam),
        stable=bool(np.max(np.abs(lam)) < 1.0),
        margin=margin,
        dgamma_ds=float(t[3]),
        pd=float(np.real(np.prod(1.0 + lam))),
    )


def continue_branch(
    branch: str,
    x0: np.ndarray,
    gamma0: float,
    direction: float,
    gamma_range: tuple[float, float],
    ds: float = 0.01,
    ds_max: float = 0.04,
    max_points: int = 400,
    rdot_min: float = 1e-7,
) -> list[BranchPoint]:
    """Pseudo-arclength continuation of a cycle of the core map in (x, gamma).

    Stops when gamma leaves ``gamma_range``, at grazing (margin <= 0: beyond it the flight
    would hit the wall earlier, the cycle is virtual), when rdot- < rdot_min (the branch
    reaches the BEB) or when the step size collapses.
    """
    sp = chapter_params(gamma=gamma0)
    xs, fl, _ = newton_fixed_point(ImpactMap(sp), x0)
    y = np.append(xs, gamma0)
    _, DF, fl, Jx = _fixed_point_system(y)
    t = _tangent(DF, np.array([0.0, 0.0, 0.0, direction]))
    pts = [_branch_point(branch, y, fl, Jx, t)]
    while len(pts) < max_points and ds > 1e-6:
        y_pred = y + ds * t
        try:
            y_new, fl, DF, Jx = _correct(y_pred, t)
        except (NewtonFailed, NoImpact, np.linalg.LinAlgError):
            ds *= 0.5
            continue
        if np.linalg.norm(y_new - y) > 3.0 * ds:  # jumped to another branch
            ds *= 0.5
            continue
        t = _tangent(DF, t)
        p = _branch_point(branch, y_new, fl, Jx, t)
        pts.append(p)
        y = y_new
        ds = min(ds * 1.3, ds_max)
        if not gamma_range[0] <= p.gamma <= gamma_range[1]:
            break
        if p.margin <= MARGIN_STOP or p.rdot < rdot_min:
            break
    return pts


def _refine(branch: str, a: BranchPoint, b: BranchPoint, key, event: str) -> BranchPoint:
    """Locate key(point) = 0 between a and b by secant in gamma with Newton at fixed gamma."""
    pa, pb = a, b
    fa, fb = key(a), key(b)
    best = a if abs(fa) < abs(fb) else b
    for _ in range(30):
        w = fa / (fa - fb)
        g = pa.gamma + w * (pb.gamma - pa.gamma)
        x = np.array(pa.x) + w * (np.array(pb.x) - np.array(pa.x))
        try:
            cyc = cycle_at(chapter_params(gamma=g), x, branch)
        except (NewtonFailed, NoImpact):
            break
        lam = cyc.multipliers
        p = BranchPoint(
            branch,
            g,
            tuple(cyc.x),
            cyc.T,
            cyc.rdot,
            tuple(lam),
            cyc.stable,
            cyc.grazing_margin,
            0.0,
            float(np.real(np.prod(1.0 + lam))),
        )
        fp = key(p)
        best = p
        if abs(fp) < 1e-11 or abs(pb.gamma - pa.gamma) < 1e-13:
            break
        if np.sign(fp) == np.sign(fa):
            pa, fa = p, fp
        else:
            pb, fb = p, fp
    return replace(best, event=event)


def _torus_key(p: BranchPoint) -> float:
    """|complex pair| - 1 (0 when there is no complex pair)."""
    cm = [abs(v) for v in p.multipliers if abs(v.imag) > 1e-9]
    return max(cm) - 1.0 if cm else -1.0


def _events(branch: str, pts: list[BranchPoint]) -> list[BranchPoint]:
    """Folds, period doublings and torus bifurcations between consecutive points."""
    ev: list[BranchPoint] = []
    for a, b in itertools.pairwise(pts):
        if a.dgamma_ds * b.dgamma_ds < 0.0:
            w = a.dgamma_ds / (a.dgamma_ds - b.dgamma_ds)
            ev.append(_refine_fold(branch, a, b, w))
        if a.pd * b.pd < 0.0:
            ev.append(_refine(branch, a, b, lambda p: p.pd, "period_doubling"))
        ta, tb = _torus_key(a), _torus_key(b)
        if ta * tb < 0.0 and ta > -1.0 and tb > -1.0:
            ev.append(_refine(branch, a, b, _torus_key, "torus"))
    return ev


def fold_point(gamma0: float, T0: float) -> tuple[float, float]:
    """(gamma, T) of a fold of cycles: a double root in T of ``period_condition``.

    Both cycles of a period root (small and large) fold there, since the period condition
    does not involve the amplitude. Solved by Newton (fsolve) from (gamma0, T0).
    """

    def eqs(v: np.ndarray) -> list[float]:
        sp = chapter_params(gamma=float(v[0]))
        h = 1e-5
        f = period_condition(sp, float(v[1]))
        df = (period_condition(sp, v[1] + h) - period_condition(sp, v[1] - h)) / (2 * h)
        return [f, df]

    sol, _, _ier, _ = scipy.optimize.fsolve(eqs, [gamma0, T0], xtol=1e-13, full_output=True)
    return float(sol[0]), float(sol[1])


def _refine_fold(branch: str, a: BranchPoint, b: BranchPoint, w: float) -> BranchPoint:
    """Fold point near the continuation's turning point between a and b (closed form)."""
    g, T = fold_point(a.gamma + w * (b.gamma - a.gamma), a.T + w * (b.T - a.T))
    near = a if abs(a.dgamma_ds) < abs(b.dgamma_ds) else b
    return replace(near, gamma=g, T=T, dgamma_ds=0.0, event="fold")


def grazing_gamma(branch: str, g_in: float, g_out: float) -> float:
    """gamma where the closed-form ``branch`` cycle grazes (max interior |U| = 1).

    ``g_in``: a gamma with positive margin, ``g_out``: one with negative margin.
    """

    def margin(g: float) -> float:
        sp = chapter_params(gamma=g)
        c = labelled_cycles(sp)[branch]
        return 1.0 - max_radius_in_flight(sp, c.U0, c.dU0, c.T)

    return float(scipy.optimize.brentq(margin, g_in, g_out, xtol=1e-14))


def continue_cycles(
    gamma_values: np.ndarray | list[float], seed_gamma: float = 0.1
) -> list[BranchPoint]:
    """Continue the period-one cycle branches over [min, max] of ``gamma_values``.

    Two branches are seeded from the closed form at ``seed_gamma`` and continued both ways
    by pseudo-arclength on the core map: "large" (through the long-large cycle) and "small"
    (through the long-small cycle, born at the BEB). The step is limited to the spacing of
    ``gamma_values``. Returns the points in branch order plus located events (``event`` set):
    folds, period doublings, torus bifurcations, grazing (end of an admissible branch) and
    the BEB birth (rdot -> 0).
    """
    gv = np.asarray(gamma_values, float)
    rng = (float(gv.min()), float(gv.max()))
    ds_max = max(0.01, float(np.max(np.diff(np.sort(gv)))) if len(gv) > 1 else 0.04)
    seeds = labelled_cycles(chapter_params(gamma=seed_gamma))
    out: list[BranchPoint] = []
    for name, key in (("large", "long-large"), ("small", "long-small")):
        if key not in seeds:
            continue
        x0 = seeds[key].x
        back = continue_branch(name, x0, seed_gamma, -1.0, rng, ds_max=ds_max)
        fwd = continue_branch(name, x0, seed_gamma, +1.0, rng, ds_max=ds_max)
        back = [replace(p, dgamma_ds=-p.dgamma_ds) for p in back]  # orient along fwd
        pts = back[::-1] + fwd[1:]
        out.extend(pts)
        out.extend(_events(name, pts))
        for end in (pts[0], pts[-1]):
            if end.margin <= MARGIN_STOP:
                g = _grazing_from_end(end, pts)
                out.append(replace(end, gamma=g, margin=0.0, event="grazing"))
            elif end.rdot < 1e-6:
                out.append(replace(end, gamma=_birth_gamma(end, pts), event="beb_birth"))
    return out


def _grazing_from_end(end: BranchPoint, pts: list[BranchPoint]) -> float:
    """Grazing gamma past a branch end with a vanishing margin (closed form, bisection)."""
    cands = [
        k
        for k, c in labelled_cycles(chapter_params(gamma=end.gamma)).items()
        if abs(c.T - end.T) < 1e-6
    ]
    key = cands[0]
    inner = next(p for p in (pts if end is pts[-1] else pts[::-1]) if p.margin > 0.05)
    step = end.gamma - inner.gamma
    g_out = end.gamma + 0.1 * step
    for _ in range(20):
        sp = chapter_params(gamma=g_out)
        c = labelled_cycles(sp).get(key)
        if c is not None and max_radius_in_flight(sp, c.U0, c.dU0, c.T) > 1.0:
            break
        g_out += 0.1 * step
    return grazing_gamma(key, end.gamma - 0.5 * step, g_out)


def _birth_gamma(end: BranchPoint, pts: list[BranchPoint]) -> float:
    """gamma where rdot- -> 0, extrapolated linearly from the branch end (rdot ~ gamma - g*)."""
    nxt = pts[1] if end is pts[0] else pts[-2]
    slope = (nxt.rdot - end.rdot) / (nxt.gamma - end.gamma)
    return end.gamma - end.rdot / slope


# --------------------------------------------------------------------------- brute force

REGIMES = ("free whirl", "impacting", "rub/sliding", "dry whip/rolling")


@dataclass(frozen=True)
class Attractor:
    """What a TouchdownCore run settles to (statistics over the recording window).

    max_r: max |z|/c_r at the sample points (and 1 when it touches); impacts: count in the
    window; frac_free / frac_sliding / frac_rolling: fractions of samples in each mode;
    whirl: final inertial whirl rate / Omega (1: synchronous forward rub, -R/c_r: rolling);
    regime: one of REGIMES.
    """

    gamma: float
    start: str
    max_r: float
    impacts: int
    frac_free: float
    frac_sliding: float
    frac_rolling: float
    whirl: float
    regime: str


def classify(impacts: int, fracs: np.ndarray) -> str:
    """Regime from the impact count and mode fractions (free, sliding, rolling)."""
    if fracs[2] > 0.5:
        return REGIMES[3]
    if fracs[1] > 0.5:
        return REGIMES[2]
    if impacts > 0:
        return REGIMES[1]
    return REGIMES[0]


def run_attractor(
    gamma: float,
    U0: complex,
    dU0: complex,
    start: str = "",
    t_end: float = 300.0,
    t_rec: float = 200.0,
    dt: float = 0.5,
) -> Attractor:
    """Run TouchdownCore from the scaled co-rotating (U0, dU0) for t_end (scaled time).

    Steps of dt (scaled); statistics over t > t_rec. Chapter set, Omega = OMEGA.
    """
    p = si_params(chapter_params(gamma=gamma))
    core = TouchdownCore.from_scaled(p, OMEGA, U0, dU0)
    h = dt / OMEGA
    modes: list[int] = []
    n_imp, r_max = 0, 0.0
    for k in range(round(t_end / dt)):
        rep = core.step(h, OMEGA)
        if (k + 1) * dt > t_rec:
            modes.append(rep.mode)
            n_imp += len(rep.impacts)
            r_max = max(r_max, core.kinematics().r_rel, 1.0 if rep.impacts else 0.0)
    fr = np.bincount(modes, minlength=3) / max(len(modes), 1)
    whirl = core.kinematics().whirl_rate / OMEGA
    return Attractor(gamma, start, r_max, n_imp, fr[0], fr[1], fr[2], whirl, classify(n_imp, fr))


def standard_starts(gamma: float) -> dict[str, tuple[complex, complex]]:
    """Four starts (scaled co-rotating U0, dU0): rest, near U*, on a cycle, a large orbit."""
    sp = chapter_params(gamma=gamma)
    Us = regular_equilibrium(sp)
    near = Us * 0.98 if abs(Us) < 1.0 else 0.98 * Us / abs(Us)
    starts = {"rest": (0j, 0j), "near U*": (near + 0.01, 0j)}
    cyc = labelled_cycles(sp)
    for key in ("long-large", "short-large"):
        if key in cyc:
            c = cyc[key]
            starts["cycle"] = (c.U0, c.dU0)
            break
    starts["large orbit"] = (0.9 + 0j, -0.9j)
    return starts
