"""The impact map P: x = (alpha, rdot+, thetadot+) -> the same after the next impact.

x is the state right after an impact (scaled co-rotating: U = e^{i alpha}, U' = (rdot+ +
i thetadot+) U). P is evaluated with the core (SI, inertial: exact flight, rigorous contact
search, reset law with the stick cap) at the chapter's SI realisation (Omega = 184.2 rad/s,
m = 50 kg, c_r = 0.7 mm, psi0 = 0 at the start of each flight); its Jacobian comes from
the independent scaled closed form (``flow``) or finite differences of the core map.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass

import numpy as np
from rotortd import ScaledParams
from rotortd.contact.impact import reset
from rotortd.contact.search import Contact, ContactLocator, Work
from rotortd.scaled import CHAPTER_OMEGA as OMEGA
from rotortd.scaled import si_params, wrap_angle
from rotortd.segments.flight import FlightModel

from rotortd_tools.cycles.flow import ScaledFlow, real_jac, to_real

T_MAX = 400.0
"""Longest flight (scaled time) searched for the next impact."""
WINDOW = 2.0
"""Length (scaled time) of one contact-search window (see ImpactMap._search)."""


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
            diff[0] = wrap_angle(diff[0])
            J[:, j] = diff / (2.0 * eps)
        return J
