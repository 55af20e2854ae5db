"""The state of a TouchdownCore as one plain data class, and its JSON form.

Frame and units: inertial, SI. ``CoreState`` holds everything the core needs to continue
bit for bit; ``TouchdownCore.get_state``/``set_state`` are ``CoreState.to_json``/``from_json``
and the core's ``state`` property is the same record, read-only. The JSON schema is
``rotortd-state`` version 2 (floats round-trip exactly through JSON's repr).

Versions: version 2 adds ``J``, the polar inertia (kg m^2) of a core whose spin is a state
(``SpinCore``; then ``inputs[0]`` is the spin speed, a state), null for the held-speed
``TouchdownCore``. A version 1 state reads as a held-speed state. A state of another schema
or version is refused with a message naming both.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .params import ParameterError, RotorParams

STATE_SCHEMA, STATE_VERSION = "rotortd-state", 2
READABLE_VERSIONS = (1, 2)


@dataclass(frozen=True)
class CoreState:
    """A core's state. In flight (mode 0) the motion is (z, v); in contact (mode 1
    sliding, 2 rolling) it is (theta, dtheta) with slip and locked, and (z, v) are derived
    from it (z = c_r e^{i theta}, v = i c_r theta' e^{i theta})."""

    params: RotorParams
    t: float
    """Time (s); t_lo is the compensation of its summation (s)."""
    t_lo: float
    z: complex
    """Position (m) and velocity (m/s) of the rotor centre."""
    v: complex
    psi: float
    """Spin angle (rad), reduced to [-pi, pi); the unwrapped angle adds ``turns`` 2 pi."""
    turns: int
    mode: int
    theta: float
    """Contact angle (rad) and whirl rate (rad/s) on the clearance circle."""
    dtheta: float
    slip: float
    """Slip sign of sliding (+-1; 0 before any contact)."""
    locked: bool
    """On a synchronous forward rub, advanced as a rigid rotation."""
    on_wall: bool
    n_impacts: int
    t_last: float
    """Time (s) and normal speed rdot- (m/s) of the last impact; 0 before any."""
    v_last: float
    E_diss: float
    """Energy dissipated by contact so far (J)."""
    t_contact: float
    """Accumulation point of the last chattering (s); NaN before any."""
    slide_step: float
    """The sliding integrator's next step size (s); inf before any sliding."""
    inputs: tuple[float, complex, float]
    """The held inputs of the last step: Omega (rad/s), F_ext (N), amb_on. With the spin as
    a state (J set), Omega is the spin speed at t."""
    J: float | None = None
    """Polar inertia about the mass centre (kg m^2) when the spin is a state, else None."""
    imb_h: tuple[float, float] = (math.nan, math.nan)
    """Step lengths (s) the imbalance torque's proved-free closed form has seen once and
    holds coefficients for (NaN: none): which of its two roundings the next flight takes."""

    def to_json(self) -> dict:
        """The JSON-serialisable dict of schema ``rotortd-state``, version STATE_VERSION."""
        p, z, v, (W, F, a) = self.params, self.z, self.v, self.inputs
        return {
            "schema": STATE_SCHEMA,
            "version": STATE_VERSION,
            "params": {f: getattr(p, f) for f in p.__dataclass_fields__},
            "t": self.t,
            "t_lo": self.t_lo,
            "z": [z.real, z.imag],
            "v": [v.real, v.imag],
            "psi": self.psi,
            "turns": self.turns,
            "mode": self.mode,
            "theta": self.theta,
            "dtheta": self.dtheta,
            "slip": self.slip,
            "locked": self.locked,
            "on_wall": self.on_wall,
            "n_impacts": self.n_impacts,
            "t_last": self.t_last,
            "v_last": self.v_last,
            "E_diss": self.E_diss,
            "t_contact": None if math.isnan(self.t_contact) else self.t_contact,
            "H": None if math.isinf(self.slide_step) else self.slide_step,
            "inputs": [W, F.real, F.imag, a],
            "J": self.J,
            "imb_h": [None if math.isnan(x) else x for x in self.imb_h],
        }

    @classmethod
    def from_json(cls, st: dict) -> CoreState:
        """The state of a dict made by ``to_json``; ParameterError for another schema or
        version."""
        if st.get("schema") != STATE_SCHEMA or st.get("version") not in READABLE_VERSIONS:
            raise ParameterError(
                f"state schema {st.get('schema')!r} version {st.get('version')!r} is not "
                f"supported: expected {STATE_SCHEMA!r} version "
                f"{' or '.join(map(str, READABLE_VERSIONS))}"
            )
        J = st.get("J") if st["version"] >= 2 else None
        imb_h = tuple(math.nan if x is None else float(x)
                      for x in st.get("imb_h", (None, None)))
        W, fx, fy, a = st["inputs"]
        return cls(
            params=RotorParams(**st["params"]),
            t=float(st["t"]),
            t_lo=float(st["t_lo"]),
            z=complex(*st["z"]),
            v=complex(*st["v"]),
            psi=float(st["psi"]),
            turns=int(st["turns"]),
            mode=int(st["mode"]),
            theta=float(st["theta"]),
            dtheta=float(st["dtheta"]),
            slip=float(st["slip"]),
            locked=bool(st["locked"]),
            on_wall=bool(st["on_wall"]),
            n_impacts=int(st["n_impacts"]),
            t_last=float(st["t_last"]),
            v_last=float(st["v_last"]),
            E_diss=float(st["E_diss"]),
            t_contact=math.nan if st["t_contact"] is None else float(st["t_contact"]),
            slide_step=math.inf if st["H"] is None else float(st["H"]),
            inputs=(float(W), complex(fx, fy), float(a)),
            J=None if J is None else float(J),
            imb_h=(imb_h[0], imb_h[1]),
        )
