"""The state of a core as one plain data class, and its JSON form by component.

Frame and units: inertial, SI. ``CoreState`` holds everything the core needs to continue
bit for bit; ``TouchdownCore.get_state``/``set_state`` are ``CoreState.to_json``/``from_json``
and the core's ``state`` property is the same record, read-only. The JSON schema is
``rotortd-state`` version 3: one record per component (floats round-trip exactly through
JSON's repr; a complex number is [re, im])::

    {"schema": "rotortd-state", "version": 3,
     "params":   {...RotorParams fields...},
     "clock":    {"t": s, "t_lo": s (compensation of the clock's summation)},
     "rotor":    {"z": [m, m], "v": [m/s, m/s], "psi": rad in [-pi, pi), "turns": int,
                  "Omega": rad/s (the spin speed: a state when J is set, else the held
                  input), "J": kg m^2 or null (null: the spin is held)},
     "bearing":  {"kind": "fixed-rigid", ...the counter-body's record()...},
     "contact":  {"mode": 0 flight / 1 sliding / 2 rolling, "theta": rad, "dtheta": rad/s,
                  "slip": +-1 (0 before any contact), "locked": bool, "on_wall": bool,
                  "t_contact": s or null (NaN), "slide_step": s or null (inf),
                  "orbit_energy": J or null (NaN; optional: a version 3 document
                  without it reads as null), "orbit_step": s or null (NaN; optional,
                  likewise)},
     "counters": {"n_impacts": int, "t_last": s, "v_last": m/s, "E_diss": J},
     "step":     {"F_ext": [N, N], "amb_on": 1, "imb_h": [s or null, s or null]}}

Each leaf is defined once, in FIELDS (its path, the CoreState attribute and its codec);
``to_json`` and ``from_json`` are loops over that table. The bearing's record is the
counter-body's own (``rotortd.bodies.bearing``: ``KIND`` and ``record()``); the chapter's fixed
rigid bearing has no state of its own, so its record is its kind alone. A future
counter-body (a race that turns, a sprung housing) adds its fields there.

Versions: version 1 and 2 (one flat record: t, t_lo, z, v, psi, turns, mode, theta, dtheta,
slip, locked, on_wall, n_impacts, t_last, v_last, E_diss, t_contact, H (= slide_step),
inputs = [Omega, F_x, F_y, amb_on], from version 2 J and imb_h) still load: ``from_json``
maps them onto version 3 first (LEGACY_PATHS). Version 1 reads as a held-speed state; a
state without imb_h has no imbalance closed form cached. A state of another schema or
version is refused with a message naming both.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from ..bodies.bearing import FixedRigidBearing
from ..params import ParameterError, RotorParams

STATE_SCHEMA, STATE_VERSION = "rotortd-state", 3
READABLE_VERSIONS = (1, 2, 3)


def fixed_bearing_record() -> dict[str, Any]:
    """The record of the chapter's bearing (``bearing.FixedRigidBearing``): its kind."""
    return {"kind": FixedRigidBearing.KIND}


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
    Omega: float
    """Spin speed (rad/s): the held input of the last step, or with J set the state at t."""
    F_ext: complex
    """External force (N) held over the last step."""
    amb_on: float
    """Magnetic bearing switch (1 on, 0 off) held over the last step."""
    J: float | None = None
    """Polar inertia about the mass centre (kg m^2) when the spin is a state, else None."""
    imb_h: tuple[float, float] = (math.nan, math.nan)
    """Step lengths (s) the imbalance torque's proved-free closed form has seen once and
    holds coefficients for (NaN: none): which of its two roundings the next flight takes."""
    bearing: Mapping[str, Any] = field(default_factory=fixed_bearing_record)
    """The counter-body's record: its ``kind`` and its own state fields."""
    orbit_energy: float = math.nan
    """Rolling with the spin a state: the energy (J) of the dry whirl orbit the next step
    continues on (``segments.dry_whirl_orbit``); NaN: none."""
    orbit_step: float = math.nan
    """The length (s) of the last segment taken on that orbit (``Orbit.last_rem``: a segment
    of the same length next uses the orbit's step map); NaN: none."""

    @property
    def inputs(self) -> tuple[float, complex, float]:
        """(Omega (rad/s), F_ext (N), amb_on) of the last step."""
        return self.Omega, self.F_ext, self.amb_on

    def to_json(self) -> dict:
        """The JSON-serialisable dict of schema ``rotortd-state``, version STATE_VERSION."""
        out: dict[str, Any] = {"schema": STATE_SCHEMA, "version": STATE_VERSION}
        for path, attr, codec in FIELDS:
            *parents, leaf = path.split(".")
            node = out
            for part in parents:
                node = node.setdefault(part, {})
            node[leaf] = codec.dump(getattr(self, attr))
        return out

    @classmethod
    def from_json(cls, st: dict) -> CoreState:
        """The state of a dict made by ``to_json`` (version 3), or of version 1 or 2;
        ParameterError for another schema or version."""
        if st.get("schema") != STATE_SCHEMA or st.get("version") not in READABLE_VERSIONS:
            raise ParameterError(
                f"state schema {st.get('schema')!r} version {st.get('version')!r} is not "
                f"supported: expected {STATE_SCHEMA!r} version "
                f"{', '.join(map(str, READABLE_VERSIONS[:-1]))} or {READABLE_VERSIONS[-1]}"
            )
        if st["version"] < 3:
            st = upgrade(st)
        kwargs = {}
        for path, attr, codec in FIELDS:
            node: Any = st
            for part in path.split("."):
                node = node[part] if part in node or path not in OPTIONAL else None
            kwargs[attr] = codec.load(node)
        return cls(**kwargs)


@dataclass(frozen=True)
class Codec:
    """How a CoreState attribute is written to JSON (dump) and read back (load)."""

    dump: Callable[[Any], Any]
    load: Callable[[Any], Any]


def _nan_none(x: float) -> float | None:
    return None if math.isnan(x) else x


def _none_nan(x: float | None) -> float:
    return math.nan if x is None else float(x)


FLOAT = Codec(lambda x: x, float)
INT = Codec(lambda x: x, int)
BOOL = Codec(lambda x: x, bool)
COMPLEX = Codec(lambda z: [z.real, z.imag], lambda p: complex(*p))
NAN_NULL = Codec(_nan_none, _none_nan)
"""A float that is NaN when unset, written as null."""
INF_NULL = Codec(lambda x: None if math.isinf(x) else x,
                 lambda x: math.inf if x is None else float(x))
"""A float that is inf when unset, written as null."""
OPT_FLOAT = Codec(lambda x: x, lambda x: None if x is None else float(x))
NAN_PAIR = Codec(lambda p: [_nan_none(x) for x in p],
                 lambda p: (_none_nan(p[0]), _none_nan(p[1])))
PARAMS = Codec(lambda p: {f: getattr(p, f) for f in p.__dataclass_fields__},
               lambda d: RotorParams(**d))
RECORD = Codec(dict, dict)

FIELDS: tuple[tuple[str, str, Codec], ...] = (
    ("params", "params", PARAMS),
    ("clock.t", "t", FLOAT),
    ("clock.t_lo", "t_lo", FLOAT),
    ("rotor.z", "z", COMPLEX),
    ("rotor.v", "v", COMPLEX),
    ("rotor.psi", "psi", FLOAT),
    ("rotor.turns", "turns", INT),
    ("rotor.Omega", "Omega", FLOAT),
    ("rotor.J", "J", OPT_FLOAT),
    ("bearing", "bearing", RECORD),
    ("contact.mode", "mode", INT),
    ("contact.theta", "theta", FLOAT),
    ("contact.dtheta", "dtheta", FLOAT),
    ("contact.slip", "slip", FLOAT),
    ("contact.locked", "locked", BOOL),
    ("contact.on_wall", "on_wall", BOOL),
    ("contact.t_contact", "t_contact", NAN_NULL),
    ("contact.slide_step", "slide_step", INF_NULL),
    ("contact.orbit_energy", "orbit_energy", NAN_NULL),
    ("contact.orbit_step", "orbit_step", NAN_NULL),
    ("counters.n_impacts", "n_impacts", INT),
    ("counters.t_last", "t_last", FLOAT),
    ("counters.v_last", "v_last", FLOAT),
    ("counters.E_diss", "E_diss", FLOAT),
    ("step.F_ext", "F_ext", COMPLEX),
    ("step.amb_on", "amb_on", FLOAT),
    ("step.imb_h", "imb_h", NAN_PAIR),
)
"""Every leaf of the version 3 JSON: (its path, the CoreState attribute, its codec)."""

OPTIONAL = frozenset({"contact.orbit_energy", "contact.orbit_step"})
"""Leaves a version 3 document may lack (written before they were added): read as null."""

LEGACY_PATHS = {"H": "contact.slide_step"} | {
    path.split(".")[-1]: path for path, _, _ in FIELDS if path.split(".")[-1] != "slide_step"}
"""Where a version 1 or 2 key lives in version 3 (``inputs`` is split by ``upgrade``)."""


def upgrade(st: dict) -> dict:
    """A version 1 or 2 state dict in the version 3 layout (a new dict)."""
    out: dict[str, Any] = {"schema": STATE_SCHEMA, "version": STATE_VERSION,
                           "bearing": fixed_bearing_record()}
    flat = {"J": None, "imb_h": [None, None]} | {k: v for k, v in st.items()
                                                 if k not in ("schema", "version")}
    if st["version"] < 2:
        flat["J"] = None
    W, fx, fy, a = flat.pop("inputs")
    flat |= {"Omega": W, "F_ext": [fx, fy], "amb_on": a}
    for key, value in flat.items():
        if key not in LEGACY_PATHS:
            raise ParameterError(f"state version {st['version']}: unknown key {key!r}")
        *parents, leaf = LEGACY_PATHS[key].split(".")
        node = out
        for part in parents:
            node = node.setdefault(part, {})
        node[leaf] = value
    return out
