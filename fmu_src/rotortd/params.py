"""Physical parameters of the rotor–touchdown-bearing model and their scaled form.

Everything here is SI and frame-free (parameters, not states). The scaled set is the
chapter's non-dimensional form (docs/model.md §1), defined for a spin speed ``Omega != 0``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

from .limits import CrossParameterError, InputError, ParameterError

__all__ = ["CrossParameterError", "InputError", "ParameterError"]


def check_finite(name: str, value: float, error: type[ValueError] = ParameterError) -> float:
    """Return ``float(value)`` or raise ``error`` naming ``name`` when it is NaN or infinite."""
    x = float(value)
    if not math.isfinite(x):
        raise error(f"{name} = {value!r} is not finite: it must be a finite real number")
    return x


def check_range(
    name: str,
    value: float,
    lo: float | None = None,
    hi: float | None = None,
    *,
    lo_open: bool = False,
    error: type[ValueError] = ParameterError,
    unit: str = "",
) -> float:
    """Check ``lo (<|<=) value <= hi``; raise ``error`` naming the value and the range."""
    x = check_finite(name, value, error)
    bad_lo = lo is not None and (x <= lo if lo_open else x < lo)
    bad_hi = hi is not None and x > hi
    if bad_lo or bad_hi:
        left = "(" if lo_open else "["
        lo_s = "-inf" if lo is None else f"{lo:g}"
        hi_s = "inf)" if hi is None else f"{hi:g}]"
        u = f" {unit}" if unit else ""
        raise error(f"{name} = {x!r}{u} is out of range: it must lie in {left}{lo_s}, {hi_s}{u}")
    return x


@dataclass(frozen=True)
class ScaledParams:
    """The chapter's scaled parameter set (docs/model.md §1), dimensionless.

    gamma = c/(m |Omega|), omega = sqrt(k/m)/|Omega|, rho = e_c/c_r, phi (rad), mu, d,
    R_over_cr = R/c_r. Time is t = Omega*tau, positions are in units of c_r.
    """

    gamma: float
    omega: float
    rho: float
    phi: float
    mu: float
    d: float
    R_over_cr: float


@dataclass(frozen=True)
class RotorParams:
    """Rotor and bearing parameters, SI units (docs/model.md §1; the chapter's set is
    ``rotortd.scaled.CHAPTER``), within the model's mathematical domain below. The FMU
    accepts the narrower physical ranges of ``limits.LIMITS``, all inside this domain
    (tests/test_core_params.py checks it).

    m    rotor mass, kg (> 0)
    c    AMB damping, N s/m (>= 0)
    k    AMB stiffness, N/m (>= 0)
    e_c  imbalance eccentricity, m (>= 0)
    phi  imbalance phase, rad
    c_r  radial clearance of the touchdown bearing, m (> 0)
    R    rotor radius at the contact, m (> 0)
    mu   Coulomb friction coefficient (>= 0)
    d    Newton restitution coefficient, [0, 1]
    g    gravity acceleration acting in -y, m/s^2 (>= 0)
    levitate  when true, the AMB bias force i m g cancels gravity while the bearing is on
    """

    m: float = 50.0
    c: float = 1400.0
    k: float = 9.8e5
    e_c: float = 0.3e-3
    phi: float = 0.21
    c_r: float = 0.7e-3
    R: float = 0.04
    mu: float = 0.15
    d: float = 0.95
    g: float = 0.0
    levitate: bool = True

    def __post_init__(self) -> None:
        check_range("m", self.m, 0.0, lo_open=True, unit="kg")
        check_range("c", self.c, 0.0, unit="N s/m")
        check_range("k", self.k, 0.0, unit="N/m")
        check_range("e_c", self.e_c, 0.0, unit="m")
        check_finite("phi", self.phi)
        check_range("c_r", self.c_r, 0.0, lo_open=True, unit="m")
        check_range("R", self.R, 0.0, lo_open=True, unit="m")
        check_range("mu", self.mu, 0.0)
        check_range("d", self.d, 0.0, 1.0)
        check_range("g", self.g, 0.0, unit="m/s^2")
        for f in fields(self):
            if f.name != "levitate":
                object.__setattr__(self, f.name, float(getattr(self, f.name)))
        object.__setattr__(self, "levitate", bool(self.levitate))

    def replace(self, **changes: float) -> RotorParams:
        """Return a validated copy with ``changes`` applied (used for tunable parameters)."""
        return replace(self, **changes)

    @property
    def bias_force(self) -> complex:
        """AMB bias force F_bias, N, inertial frame: i m g when levitating, else 0."""
        return 1j * self.m * self.g if self.levitate else 0j

    def amb_force(self, a: float, z: complex, v: complex) -> complex:
        """The AMB force on the rotor centre at (z (m), v (m/s)), N, inertial: the one
        definition a (F_bias - c v - k z), a = amb_on in [0, 1]. The integrators' kernels
        expand it in their own variables (segments.spin_flight, segments.spin_contact,
        segments.flight, contact.wall), and the outputs inline it (TouchdownCore.output_values,
        every FMU step; tests/test_spin_core.py checks it there)."""
        return a * (self.bias_force - self.c * v - self.k * z)

    @property
    def gravity_force(self) -> complex:
        """Gravity on the rotor, N, inertial frame: -i m g."""
        return -1j * self.m * self.g

    def scaled(self, Omega: float) -> ScaledParams:
        """The chapter's scaled set at spin speed ``Omega`` (rad/s); undefined at Omega = 0."""
        W = check_finite("Omega", Omega)
        if W == 0.0:
            raise ParameterError(
                "Omega = 0.0 rad/s: the scaled set (gamma, omega, rho) is undefined; "
                "it needs Omega != 0"
            )
        w = abs(W)
        return ScaledParams(
            gamma=self.c / (self.m * w),
            omega=math.sqrt(self.k / self.m) / w,
            rho=self.e_c / self.c_r,
            phi=self.phi,
            mu=self.mu,
            d=self.d,
            R_over_cr=self.R / self.c_r,
        )

    @classmethod
    def from_scaled(
        cls,
        sp: ScaledParams,
        Omega: float,
        *,
        m: float = 50.0,
        c_r: float = 0.7e-3,
        g: float = 0.0,
        levitate: bool = True,
    ) -> RotorParams:
        """Build SI parameters from a scaled set, a speed ``Omega`` (rad/s), ``m`` and ``c_r``."""
        W = check_finite("Omega", Omega)
        if W == 0.0:
            raise ParameterError("Omega = 0.0 rad/s: a scaled set needs Omega != 0")
        check_range("gamma", sp.gamma, 0.0)
        check_range("omega", sp.omega, 0.0)
        check_range("rho", sp.rho, 0.0)
        check_range("R_over_cr", sp.R_over_cr, 0.0, lo_open=True)
        w = abs(W)
        return cls(
            m=m,
            c=sp.gamma * m * w,
            k=m * (sp.omega * w) ** 2,
            e_c=sp.rho * c_r,
            phi=sp.phi,
            c_r=c_r,
            R=sp.R_over_cr * c_r,
            mu=sp.mu,
            d=sp.d,
            g=g,
            levitate=levitate,
        )


TUNABLE = ("c", "k", "mu", "d", "e_c", "phi")
"""Parameters that may change between steps (blade loss, bearing retuning)."""
