"""The wall's forces and what every contact segment shares (docs/model.md §5).

Frame and units: inertial, SI; forces per unit m c_r (1/s^2), as in ``rotortd.segments``'s
docstring. WallForces: the contact-free forces at the wall under held inputs.
ContactTally: a segment's contact integrals. SegmentEnd: what every segment's
``run(rem, limit)`` returns, flight or contact, the spin held or a state.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass
from typing import Any

from ..params import RotorParams
from ..segments.divdiff import dd2
from .events import Event
from .search import G2_FLOOR


class ContactWorkExceeded(RuntimeError):
    """A contact segment hit its work cap; ``work`` is what it had used."""

    def __init__(self, message: str, work: int = 0) -> None:
        super().__init__(message)
        self.work = work


def phase_integral(nu: float, x: float) -> complex:
    """int_0^x e^{i nu u} du (s), accurate for nu -> 0."""
    return x * dd2(1j * nu * x, 0j)


@dataclass(frozen=True)
class WallForces:
    """Contact-free forces at the wall per unit m c_r (1/s^2), inertial frame, held inputs."""

    q0: complex
    eu: complex
    beta: float
    kappa: float
    Omega: float
    wr: float
    mu: float
    gn_floor: float = 0.0
    """Absolute part of Gn's rounding band (1/s^2): the underflow error of subnormal
    forces. A quarter of the free flight's band of g'' = 2 c_r^2 Gn (events.G2_FLOOR)."""

    @classmethod
    def build(cls, p: RotorParams, Omega: float, F_ext: complex, amb: float) -> WallForces:
        """Forces for parameters ``p`` and the inputs held over a step."""
        mc = p.m * p.c_r
        return cls(
            q0=(amb * p.bias_force + p.gravity_force + complex(F_ext)) / mc,
            eu=p.e_c * Omega * Omega * cmath.exp(1j * p.phi) / p.c_r,
            beta=amb * p.c / p.m,
            kappa=amb * p.k / p.m,
            Omega=Omega,
            wr=p.R * Omega / p.c_r,
            mu=p.mu,
            gn_floor=G2_FLOOR / (8.0 * p.c_r * p.c_r),
        )

    def gn_gt(self, theta: float, dtheta: float, E: complex) -> tuple[float, float]:
        """(Gn, Gt) in 1/s^2 at angle theta, whirl rate dtheta and phasor E = e^{i psi}."""
        Q = self.q0 + self.eu * E
        co, sn = math.cos(theta), math.sin(theta)  # P = Q e^{-i theta}, as real parts:
        return ((Q.real * co + Q.imag * sn) - self.kappa + dtheta * dtheta,
                (Q.imag * co - Q.real * sn) - self.beta * dtheta)

    def gn_rate(self, theta: float, dtheta: float, E: complex, ddtheta: float) -> float:
        """dGn/dt (1/s^3) along a contact motion with angular acceleration ddtheta."""
        w = complex(math.cos(theta), -math.sin(theta))
        Q = self.q0 + self.eu * E
        dP = (1j * self.Omega * self.eu * E - 1j * dtheta * Q) * w
        return dP.real + 2.0 * dtheta * ddtheta

    def cone_margin(self, theta: float, dtheta: float, E: complex) -> tuple[float, float]:
        """(mu Gn - |Gt|, its rate along rolling) in 1/s^2 and 1/s^3: rolling holds while > 0."""
        gn, gt = self.gn_gt(theta, dtheta, E)
        w = complex(math.cos(theta), -math.sin(theta))
        dP = (1j * self.Omega * self.eu * E - 1j * dtheta * (self.q0 + self.eu * E)) * w
        rate = self.mu * (dP.real) - math.copysign(1.0, gt) * dP.imag
        return self.mu * gn - abs(gt), rate

    def gn_tol(self, dtheta: float) -> float:
        """Rounding band of Gn (1/s^2): inside it the sign of dGn/dt decides lift-off."""
        return 64.0 * 2.220446049250313e-16 * self.force_scale(dtheta) + self.gn_floor

    def force_scale(self, dtheta: float) -> float:
        """|q0| + |eu| + kappa + theta'^2 (1/s^2): the size of the terms of Gn and Gt."""
        return abs(self.q0) + abs(self.eu) + self.kappa + dtheta * dtheta

    def omega_ref(self, dtheta: float) -> float:
        """A frequency scale (rad/s) of the contact motion, for step limits and tolerances."""
        return max(
            abs(self.Omega),
            abs(dtheta),
            math.sqrt(self.kappa),
            self.beta,
            math.sqrt(abs(self.q0) + abs(self.eu)),
            1e-6,
        )


@dataclass(slots=True)
class ContactTally:
    """Integrals of the contact force over a segment, per unit m c_r (SI otherwise).

    I_n = int Gn (1/s), I_c = int of the contact force on the rotor / (m c_r) (complex,
    1/s), I_t = int Ft (1/s), I_e = int Ft (wr + theta') (1/s^2; times m c_r^2 gives J),
    peak = max Gn seen (1/s^2), I_z = int e^{i(theta(u) - Omega u)} du (s; times c_r: the
    integral of z e^{-i Omega u} over the segment, u from its start, for the imbalance
    reaction torque, TouchdownCore._imb_add).
    """

    I_n: float = 0.0
    I_c: complex = 0j
    I_t: float = 0.0
    I_e: float = 0.0
    peak: float = 0.0
    work: int = 0
    """Work units (events.Work) counted while the segment runs; its SegmentEnd.work."""
    I_z: complex = 0j


@dataclass(slots=True)
class SegmentEnd:
    """Where a segment stopped: after ``duration`` seconds, its state, and its event.

    Every segment returns one from ``run(rem, limit)``: advance at most ``rem`` seconds, at
    most ``limit`` work units, and stop at the first event. The segments: free flight
    (``flight_step.Flight``; with the spin a state ``spin_flight.SpinFlight``), sliding,
    rolling, the linear and quadratic rub and the locked rotation (``Sliding``,
    ``Rolling``, ``LinearRub``, ``QuadraticRub``, ``LockedRub``; with the spin a state
    ``spin_contact.SpinContact``). A flight ends in (z, v), a contact segment in (theta,
    theta') with its contact integrals ``tally``; a segment whose spin is a state also ends
    in (psi, Omega), which are NaN where the spin is held (the core advances psi by
    Omega duration)."""

    duration: float
    """Length of the segment (s), from its start to its end or event."""
    theta: float = math.nan
    """Contact: polar angle of the contact point at the end (rad, inertial)."""
    dtheta: float = math.nan
    """Contact: whirl rate theta' at the end (rad/s)."""
    event: Event | None = None
    """None (rem reached), else the ``Event`` that ended the segment."""
    tally: ContactTally | None = None
    """Contact: the segment's contact integrals (per unit m c_r); None for a flight."""
    next_step: float = math.inf
    """Integrated contact: the integrator's step size (s) for the next such segment."""
    z: complex = 0j
    """Flight: position of the rotor centre at the end (m, inertial)."""
    v: complex = 0j
    """Flight: its velocity (m/s, inertial)."""
    psi: float = math.nan
    """Spin a state: spin angle at the end (rad, unwrapped: the start's + increment)."""
    Omega: float = math.nan
    """Spin a state: spin speed at the end (rad/s)."""
    work: int = 0
    """Deterministic work units the segment used (events.Work)."""
    orbit: Any = None
    """Rolling with the spin a state: the orbit (``segments.dry_whirl_orbit.Orbit``) the
    segment was advanced on or refused, for the next step; None otherwise."""
