"""The admissible range of every parameter, initial value and input: one table, SI units.

This is the single source of the ranges. The core enforces them (``RotorParams``, the
initial state of ``TouchdownCore``, the inputs of a step); the FMU's variable table
(``rotortd_fmi.variables``) declares the same numbers as ``min``/``max`` in its model
description. Every bound is finite and inclusive (FMI min/max are inclusive), chosen so that
every real machine lies inside and everything inside can be simulated without overflow:
docs/fmu.md ("Ranges") says why each bound is where it is.

The core's own domain checks (``RotorParams``: ``m > 0``, ...) are wider, for scale-free
studies; the FMU checks these ranges (``rotortd_fmi.variables.range_violations``) and
reports every value outside at once. Constraints that tie several values together (a start
inside the clearance, an admissible steady whirl) raise ``CrossParameterError``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


class ParameterError(ValueError):
    """A parameter or initial state is invalid; the message names it and its allowed range."""


class CrossParameterError(ParameterError):
    """Values each inside their range that violate a constraint tying them together."""


class InputError(ValueError):
    """An input held over a step (or the step length) is invalid; the message names it."""


@dataclass(frozen=True)
class Limit:
    """Closed range ``[lo, hi]`` of one quantity, in ``unit`` (FMI unit name)."""

    unit: str
    lo: float
    hi: float


ANGLE = Limit("rad", -1e4, 1e4)
"""Angles: any phase, kept to |angle| <= 1e4 rad so that wrapping loses < 2e-12 rad."""

LIMITS: dict[str, Limit] = {
    # rotor and bearing (RotorParams)
    "m": Limit("kg", 1e-3, 1e6),
    "c": Limit("N.s/m", 0.0, 1e8),
    "k": Limit("N/m", 0.0, 1e10),
    "e_c": Limit("m", 0.0, 0.1),
    "phi": ANGLE,
    "c_r": Limit("m", 1e-6, 0.1),
    "R": Limit("m", 1e-3, 10.0),
    "mu": Limit("1", 0.0, 10.0),
    "d": Limit("1", 0.0, 1.0),
    "g": Limit("m/s2", 0.0, 1e3),
    # initial state
    "x0": Limit("m", -0.1, 0.1),
    "y0": Limit("m", -0.1, 0.1),
    "vx0": Limit("m/s", -1e4, 1e4),
    "vy0": Limit("m/s", -1e4, 1e4),
    "psi0": ANGLE,
    # spin (rotortd_drive)
    "J": Limit("kg.m2", 1e-9, 1e7),
    "h_spin": Limit("s", 1e-8, 1.0),
    # the real bearing (bodies.race.BearingParams, docs/model.md §10)
    "J_b": Limit("kg.m2", 1e-8, 1e3),
    "T_b0": Limit("N.m", 0.0, 1e4),
    "c_bw": Limit("N.m.s", 0.0, 1e3),
    "omega_b0": Limit("rad/s", -1e5, 1e5),
    "m_b": Limit("kg", 1e-3, 1e5),
    "k_b": Limit("N/m", 1e3, 1e11),
    "c_b": Limit("N.s/m", 0.0, 1e8),
    "k_c": Limit("N/m", 1e5, 1e12),
    "p_c": Limit("1", 1.0, 1.5),
    # inputs held over a step
    "Omega": Limit("rad/s", -1e5, 1e5),
    "F_x": Limit("N", -1e12, 1e12),
    "F_y": Limit("N", -1e12, 1e12),
    "amb_on": Limit("1", 0.0, 1.0),
    "T_drive": Limit("N.m", -1e9, 1e9),
}

START_ULPS = 4
"""A start position at most this many ulp of c_r outside the clearance is projected onto it."""


def start_position(z0: complex, c_r: float) -> complex:
    """The initial position (m, inertial), projected onto the clearance circle when it lies
    within START_ULPS ulp of c_r outside it (a point c_r e^{ia} rounds so); farther out it
    raises CrossParameterError."""
    r = abs(z0)
    if r <= c_r:
        return z0
    if r <= c_r + START_ULPS * math.ulp(c_r):
        return z0 * (c_r / r)
    raise CrossParameterError(
        f"initial position |z0| = |(x0, y0)| = {r!r} m is outside the clearance: "
        f"it must satisfy sqrt(x0^2 + y0^2) <= c_r = {c_r!r} m"
    )
