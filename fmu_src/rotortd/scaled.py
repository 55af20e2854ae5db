"""The chapter's scaled co-rotating frame (docs/model.md §1) and its example rotor
(``CHAPTER``).

Frames and units. The core works in SI and the inertial frame: time tau (s), position z (m),
velocity z' (m/s), spin angle psi (rad). The scaled co-rotating frame, defined for a spin
speed Omega != 0 (rad/s), has

    t = Omega tau                      (dimensionless; one revolution is 2 pi)
    U = z e^{-i psi} / c_r             (position in units of c_r, co-rotating)
    U' = dU/dt = (z' - i Omega z) e^{-i psi} / (c_r Omega)   (in units of c_r Omega)

and the scaled parameter set ``ScaledParams`` (gamma = c/(m |Omega|), omega =
sqrt(k/m)/|Omega|, rho = e_c/c_r, phi, mu, d, R_over_cr = R/c_r). With a = 1, no bias, no
external force and Omega constant the free flight is

    U'' + (gamma + 2i) U' + (omega^2 - 1 + i gamma) U = rho e^{i phi}    (|U| < 1).

Everything here is pure Python (``math``/``cmath``). The parameter conversions are those of
``RotorParams`` (``scaled``, ``from_scaled``); the state conversions and ``wrap_angle`` are
written to give the same bits as the core's own expressions (see the notes on each), so that
the core can call them without any change in its results.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import replace

from .params import RotorParams, ScaledParams

TWO_PI_HI = 6.283185307179586
"""2 pi rounded to a double (rad)."""
TWO_PI_LO = 2.4492935982947064e-16
"""2 pi - TWO_PI_HI (rad): the two-part 2 pi that keeps long angle reductions from drifting."""

CHAPTER = RotorParams()
"""The chapter's experimental set in SI (`rotortd.scaled.CHAPTER`): m = 50 kg, c = 1400 N s/m,
k = 9.8e5 N/m, e_c = 0.3 mm, phi = 0.21 rad, c_r = 0.7 mm, R = 0.04 m, mu = 0.15,
d = 0.95, no gravity (the ``RotorParams`` defaults)."""
CHAPTER_OMEGA = 184.2
"""The chapter's spin speed (rad/s); with CHAPTER it gives gamma = 0.152009, omega = 0.760043,
rho = 3/7, R/c_r = 57.14."""
CHAPTER_MASS = CHAPTER.m
"""Rotor mass (kg) with which the tools realise a scaled set in SI."""
CHAPTER_C_R = CHAPTER.c_r
"""Radial clearance (m) with which the tools realise a scaled set in SI."""


# --------------------------------------------------------------------------- angles


def wrap_angle(x: float) -> float:
    """An angle (rad) reduced to [-pi, pi) by the two-part 2 pi (no drift over long runs).

    The reduction is by the true 2 pi, so a result can lie a rounding or so outside the
    doubles -pi, pi. An angle in [-pi, pi) is returned unchanged (bit for bit), except in
    the last few ulp below pi, where (x + pi)/(2 pi) rounds to 1. Same bits as
    ``TouchdownCore._advance_psi``'s reduction.
    """
    k = math.floor((x + math.pi) / (2.0 * math.pi))
    if k == 0:
        return x
    return (x - k * TWO_PI_HI) - k * TWO_PI_LO


# --------------------------------------------------------------------------- parameters


def scaled_params(p: RotorParams, Omega: float) -> ScaledParams:
    """The scaled set of the SI parameters ``p`` at spin speed ``Omega`` (rad/s).

    ParameterError at Omega = 0 or non-finite. The conversion itself is
    ``RotorParams.scaled`` (one implementation, next to the parameter validation).
    """
    return p.scaled(Omega)


def si_params(
    sp: ScaledParams,
    Omega: float = CHAPTER_OMEGA,
    *,
    m: float = CHAPTER_MASS,
    c_r: float = CHAPTER_C_R,
    g: float = 0.0,
    levitate: bool = True,
) -> RotorParams:
    """SI parameters realising the scaled set ``sp`` at ``Omega`` (rad/s), mass ``m`` (kg)
    and clearance ``c_r`` (m); gravity ``g`` (m/s^2) in -y, bias on when ``levitate``.

    The conversion itself is ``RotorParams.from_scaled``; here the default Omega, m and c_r
    are the chapter's. ParameterError names an invalid value.
    """
    return RotorParams.from_scaled(sp, Omega, m=m, c_r=c_r, g=g, levitate=levitate)


def chapter_params(Omega: float = CHAPTER_OMEGA, **overrides: float) -> ScaledParams:
    """The chapter's scaled set at ``Omega`` (rad/s), with ``overrides`` replacing fields.

    At the default Omega = 184.2 rad/s: gamma = 0.152009, omega = 0.760043, rho = 3/7,
    phi = 0.21 rad, mu = 0.15, d = 0.95, R_over_cr = 57.14. Other Omega keep the SI set, so
    gamma and omega vary as 1/Omega. Overrides are the ``ScaledParams`` field names.
    """
    return replace(scaled_params(CHAPTER, Omega), **overrides)


# --------------------------------------------------------------------------- states


def to_inertial(
    U: complex, dU: complex, Omega: float, c_r: float, psi: float = 0.0
) -> tuple[complex, complex]:
    """(z (m), z' (m/s)) inertial of the scaled co-rotating (U, U') at spin angle psi (rad).

    z = c_r U e^{i psi}, z' = c_r Omega (U' + i U) e^{i psi}; Omega in rad/s, c_r in m.
    Same bits as ``TouchdownCore.from_scaled``.
    """
    rot = cmath.exp(1j * psi)
    z = c_r * complex(U) * rot
    v = c_r * (Omega * complex(dU) + 1j * Omega * complex(U)) * rot
    return z, v


def to_scaled(
    z: complex, v: complex, Omega: float, c_r: float, psi: float
) -> tuple[complex, complex]:
    """(U, U') scaled co-rotating of the inertial (z (m), z' (m/s)) at spin angle psi (rad).

    U = z e^{-i psi}/c_r, U' = (z' - i Omega z) e^{-i psi}/(c_r Omega); U' = 0 where it is
    undefined (Omega = 0) or overflows (|Omega| so small that c_r Omega underflows or the
    quotient is not finite). ``TouchdownCore.output_values`` has the same expressions inline
    (every FMU step; bit for bit, tests/test_scaled.py).
    """
    rot = cmath.exp(-1j * psi)
    zr = z * rot
    den = c_r * Omega
    dU = (v - 1j * Omega * z) * rot / den if den != 0.0 else 0j
    if not (math.isfinite(dU.real) and math.isfinite(dU.imag)):
        dU = 0j
    return complex(zr.real / c_r, zr.imag / c_r), dU


# --------------------------------------------------------------------------- free whirl


def regular_equilibrium(sp: ScaledParams) -> complex:
    """U* = rho e^{i phi}/(omega^2 - 1 + i gamma): the steady free whirl, scaled co-rotating
    (in c_r). Admissible (inside the clearance) when |U*| < 1. ZeroDivisionError at undamped
    resonance (gamma = 0, omega = 1)."""
    return sp.rho * cmath.exp(1j * sp.phi) / complex(sp.omega**2 - 1.0, sp.gamma)


def gamma_beb(sp: ScaledParams) -> float:
    """gamma_BEB = sqrt(rho^2 - (1 - omega^2)^2) (dimensionless): the damping at which
    |U*| = 1, the free whirl reaching the wall (admissible for gamma > gamma_BEB); NaN when
    |U*| < 1 for every gamma. Only rho and omega of ``sp`` are used."""
    disc = sp.rho**2 - (1.0 - sp.omega**2) ** 2
    return math.sqrt(disc) if disc >= 0.0 else math.nan
