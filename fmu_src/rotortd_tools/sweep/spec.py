"""The sweep grammar: parameter names and ranges, axes, settings, starts, and what a point is.

Parameters are the chapter's scaled set (docs/model.md §1: gamma, omega, rho, phi, mu, d,
R_over_cr) plus the spin speed ``Omega`` in rad/s, and the spin-state inputs ``J`` (polar
inertia about the mass centre, kg m^2: the run uses ``rotortd.SpinCore``, Omega is then only
the initial spin) and ``T_drive`` (held drive torque, N m; needs J), and the real bearing's
twelve parameters (docs/model.md §10, ``rotortd_tools.bearing_args``: the options race_turns,
support_compliant, contact_compliant as 0/1 and their parameters in SI; they need J, and a
parameter needs its option on; ``bearing_params``). A point starts from
the chapter's SI set (``rotortd.scaled.CHAPTER``)
at ``Omega`` (default 184.2 rad/s), takes its scaled set
and replaces the fields the sweep names (swept or fixed); it is realised in SI with
m = 50 kg, c_r = 0.7e-3 m, no gravity, bearing on (``point_params``); the ``drop`` start
adds gravity ``DROP_G`` (``drop_params``). Sweeping ``Omega`` alone therefore keeps the SI
set, so gamma and omega vary as 1/Omega. Times in ``Settings`` are scaled, t = Omega tau
(one revolution is 2 pi), except the drop's, which are in seconds.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from rotortd import BearingParams, ParameterError, RotorParams, ScaledParams
from rotortd.bodies.rotor import check_well_posed
from rotortd.limits import LIMITS
from rotortd.scaled import CHAPTER_OMEGA, chapter_params, si_params

from rotortd_tools.bearing_args import BEARING_NAMES, OPTIONS, bearing_problems

SCALED_NAMES = ("gamma", "omega", "rho", "phi", "mu", "d", "R_over_cr")
SPIN_NAMES = ("J", "T_drive")
"""The spin-state inputs: J (kg m^2, selects ``SpinCore``) and T_drive (N m, needs J)."""
PARAM_NAMES = (*SCALED_NAMES, "Omega", *SPIN_NAMES, *BEARING_NAMES)
ALIASES = {"R/c_r": "R_over_cr", "R/cr": "R_over_cr", "Rcr": "R_over_cr", "W": "Omega"}
RANGES: dict[str, tuple[float | None, float | None, bool]] = {
    "gamma": (0.0, None, False),
    "omega": (0.0, None, False),
    "rho": (0.0, None, False),
    "phi": (None, None, False),
    "mu": (0.0, None, False),
    "d": (0.0, 1.0, False),
    "R_over_cr": (0.0, None, True),
    "Omega": (0.0, None, True),
    "J": (0.0, None, True),
    "T_drive": (None, None, False),
    **{n: (0.0, 1.0, False) for n in OPTIONS},
    **{n: (LIMITS[n].lo, LIMITS[n].hi, False) for n in BEARING_NAMES if n not in OPTIONS},
}
"""(lo, hi, lo_open) of each parameter; None means unbounded."""
SIMPLE_STARTS = ("rest", "steady", "large", "cycle", "drop")
DROP_G = 9.81
"""Gravity of the ``drop`` start (m/s^2, downward -y): the bearing fails under it."""
CONTINUATION = ("up", "down")
CYCLE_BRANCHES = ("short-small", "short-large", "long-small", "long-large")


class SweepError(ValueError):
    """A sweep specification or output is invalid; the message names the problem."""



@dataclass(frozen=True)
class Axis:
    """One swept parameter: ``n`` values in [lo, hi], a grid or sorted random samples."""

    name: str
    lo: float
    hi: float
    n: int
    random: bool
    values: tuple[float, ...]
    log: bool = False


@dataclass(frozen=True)
class Settings:
    """How each run is made and summarised.

    transient, record: scaled times (t = Omega tau); steps_per_rev, section, period_tol,
    max_period: see docs/sweeps.md. The ``drop`` start instead runs drop_time seconds at
    steps of drop_step seconds with the bearing off, and classifies the last drop_window
    seconds (``rotortd_tools.attractor.classify_drop``).
    """

    transient: float = 300.0
    record: float = 100.0
    steps_per_rev: int = 32
    section: int = 64
    period_tol: float = 1e-4
    max_period: int = 32
    drop_time: float = 0.4
    drop_window: float = 0.1
    drop_step: float = 1e-4

    def validate(self) -> Settings:
        """Raise SweepError naming a bad setting; return self."""
        checks = (
            ("transient", self.transient >= 0.0 and math.isfinite(self.transient), ">= 0"),
            ("record", self.record > 0.0 and math.isfinite(self.record), "> 0"),
            ("steps_per_rev", self.steps_per_rev >= 1, ">= 1"),
            ("section", self.section >= 0, ">= 0"),
            ("period_tol", self.period_tol > 0.0, "> 0"),
            ("max_period", self.max_period >= 1, ">= 1"),
            ("drop_time", self.drop_time > 0.0 and math.isfinite(self.drop_time), "> 0"),
            ("drop_window", 0.0 < self.drop_window <= self.drop_time,
             "in (0, drop_time]"),
            ("drop_step", 0.0 < self.drop_step <= self.drop_window,
             "in (0, drop_window]"),
        )
        for name, ok, rule in checks:
            if not ok:
                raise SweepError(f"setting {name} = {getattr(self, name)!r}: it must be {rule}")
        return self


@dataclass(frozen=True)
class SweepSpec:
    """Swept axes (0, 1 or 2), fixed parameters, starts and the random seed."""

    axes: tuple[Axis, ...]
    fixed: tuple[tuple[str, float], ...]
    starts: tuple[str, ...]
    seed: int = 0

    @property
    def names(self) -> tuple[str, ...]:
        """Names of the swept parameters, first (continuation) axis first."""
        return tuple(a.name for a in self.axes)

    def points(self) -> list[dict[str, float]]:
        """All parameter points: the first axis varies fastest."""
        if not self.axes:
            return [{}]
        grids = [a.values for a in reversed(self.axes)]
        names = list(reversed(self.names))
        return [dict(zip(names, combo)) for combo in itertools.product(*grids)]

    def values_of(self, point: dict[str, float]) -> dict[str, float]:
        """Fixed plus swept values of a point (only the names the user gave)."""
        return {**dict(self.fixed), **point}


def canonical_name(name: str) -> str:
    """Map an alias (``R/c_r``, ``W``) to its parameter name; SweepError if unknown."""
    key = ALIASES.get(name.strip(), name.strip())
    if key not in PARAM_NAMES:
        raise SweepError(
            f"unknown parameter {name!r}: choose from {', '.join(PARAM_NAMES)} "
            "(aliases R/c_r for R_over_cr, W for Omega)"
        )
    return key


def check_value(name: str, value: float, what: str = "value") -> float:
    """Check one parameter value against its allowed range (SweepError names both)."""
    if not math.isfinite(value):
        raise SweepError(f"{name}: {what} {value!r} is not a finite number")
    lo, hi, lo_open = RANGES[name]
    bad = (lo is not None and (value <= lo if lo_open else value < lo)) or (
        hi is not None and value > hi
    )
    if bad:
        left = "(" if lo_open else "["
        lo_s = "-inf" if lo is None else f"{lo:g}"
        hi_s = "inf)" if hi is None else f"{hi:g}]"
        raise SweepError(f"{name}: {what} {value!r} is out of range {left}{lo_s}, {hi_s}")
    if name in OPTIONS and value not in (0.0, 1.0):
        raise SweepError(f"{name}: {what} {value!r} is not 0 or 1 (an option: off or on)")
    return value


def _number(name: str, text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise SweepError(f"{name}: {text!r} is not a number") from None


def parse_axis(name: str, text: str, seed: int, index: int) -> Axis:
    """Parse ``a:b:n`` (grid, both ends included), ``a:b:logn`` (geometric grid, both ends
    included, a > 0) or ``a:b:~n`` (sorted uniform samples)."""
    parts = text.split(":")
    if len(parts) != 3:
        raise SweepError(f"{name}: bad range {text!r}: write a:b:n (grid), a:b:logn "
                         "(geometric grid) or a:b:~n (random)")
    lo, hi = _number(name, parts[0]), _number(name, parts[1])
    n_text = parts[2].strip()
    random = n_text.startswith("~")
    log = n_text.startswith("log")
    n_text = n_text[1:] if random else n_text[3:] if log else n_text
    try:
        n = int(n_text)
    except ValueError:
        raise SweepError(f"{name}: number of points {parts[2]!r} is not an integer") from None
    if n <= 0:
        raise SweepError(f"{name}: number of points n = {n} must be > 0")
    check_value(name, lo, "lower end")
    check_value(name, hi, "upper end")
    if not lo < hi and not (n == 1 and lo == hi):
        raise SweepError(f"{name}: bad range {text!r}: the lower end must be below the upper")
    if log and not lo > 0.0:
        raise SweepError(f"{name}: geometric grid {text!r} needs a lower end > 0")
    if random:
        rng = np.random.default_rng([seed, index])
        vals = np.sort(rng.uniform(lo, hi, n))
    elif log:
        vals = np.geomspace(lo, hi, n)
        vals[0], vals[-1] = lo, hi
    else:
        vals = np.linspace(lo, hi, n)
    return Axis(name, lo, hi, n, random, tuple(float(v) for v in vals), log)


def parse_starts(text: str | Sequence[str]) -> tuple[str, ...]:
    """Parse a comma-separated list of start labels; SweepError names an unknown one."""
    items = text.split(",") if isinstance(text, str) else list(text)
    out: list[str] = []
    for raw in items:
        label = raw.strip()
        if not label:
            continue
        _check_start(label)
        if label in out:
            raise SweepError(f"start {label!r} is given twice")
        out.append(label)
    if not out:
        raise SweepError("no starts given: use e.g. --starts rest,steady,cycle,large,up,down")
    return tuple(out)


def _check_start(label: str) -> None:
    head, _, tail = label.partition(":")
    if head in CONTINUATION:
        if tail:
            _check_start(tail)
            if tail.partition(":")[0] in CONTINUATION:
                raise SweepError(f"start {label!r}: a continuation seed cannot be up/down")
            if tail == "drop":
                raise SweepError(f"start {label!r}: a drop cannot seed a continuation")
        return
    if head == "cycle":
        if tail and tail not in CYCLE_BRANCHES:
            raise SweepError(
                f"start {label!r}: unknown cycle branch {tail!r}, choose from "
                f"{', '.join(CYCLE_BRANCHES)}"
            )
        return
    if head in SIMPLE_STARTS and not tail:
        return
    raise SweepError(
        f"unknown start {label!r}: choose from rest, steady, large, cycle[:BRANCH], drop, "
        "up[:SEED], down[:SEED]"
    )


def parse_spec(tokens: Sequence[str], starts: str | Sequence[str] = "rest",
               seed: int = 0) -> SweepSpec:
    """Parse ``name=a:b:n``, ``name=a:b:~n`` and ``name=value`` tokens into a SweepSpec."""
    axes: list[Axis] = []
    fixed: dict[str, float] = {}
    seen: set[str] = set()
    for tok in tokens:
        if "=" not in tok:
            raise SweepError(f"bad token {tok!r}: write name=a:b:n, name=a:b:~n or name=value")
        raw, text = tok.split("=", 1)
        name = canonical_name(raw)
        if name in seen:
            raise SweepError(f"parameter {name} is given twice (sweep or fix it once)")
        seen.add(name)
        if ":" in text:
            axes.append(parse_axis(name, text, seed, len(axes)))
        else:
            fixed[name] = check_value(name, _number(name, text))
    if len(axes) > 2:
        raise SweepError(f"at most two parameters can be swept, got {len(axes)}: "
                         f"{', '.join(a.name for a in axes)}")
    if "T_drive" in seen and "J" not in seen:
        raise SweepError("T_drive needs J: with the spin held (no J) a drive torque has no "
                         "effect; give J=... to make the spin a state")
    _check_bearing_names(fixed, {a.name for a in axes}, "J" in seen)
    spec = SweepSpec(tuple(axes), tuple(sorted(fixed.items())), parse_starts(starts), seed)
    if any(n in seen for n in BEARING_NAMES) and any(
            s.partition(":")[0] in CONTINUATION for s in spec.starts):
        raise SweepError("the real bearing's parameters are not continued (up/down): a "
                         "continued state would keep the previous point's bearing; use "
                         "independent starts (rest, steady, large, drop)")
    _check_realisable(spec)
    _check_cycle_available(spec.starts)
    return spec


def _check_bearing_names(fixed: dict[str, float], swept: set[str], has_J: bool) -> None:
    """SweepError when a bearing parameter is given without J or with its option off."""
    given: dict[str, object] = {n: fixed[n] for n in BEARING_NAMES if n in fixed}
    given.update({n: None for n in BEARING_NAMES if n in swept})  # swept: on somewhere
    problems = bearing_problems(
        given, has_J, "give J=... (kg m^2; the FMU's integrate_spin = true)",
        "give {opt}=1")
    if problems:
        raise SweepError("; ".join(problems))


def _check_realisable(spec: SweepSpec) -> None:
    """Build the SI set at the corners of the sweep so a bad combination fails early; with
    J, check that contact is well posed there (J > m mu e_c (R + e_c), monotone in each
    parameter, so the corners decide)."""
    corners = [(a.values[0], a.values[-1]) for a in spec.axes]
    for combo in itertools.product(*corners):
        values = spec.values_of(dict(zip(spec.names, combo)))
        try:
            p = point_params(values)[0]
            J = spin_inputs(values)[0]
            if J is not None:
                check_well_posed(p, J)
            bp = bearing_params(values)
            if bp is not None:
                bp.check(p.d)
        except ParameterError as exc:
            raise SweepError(f"parameters {values} cannot be realised: {exc}") from None


def _check_cycle_available(starts: Iterable[str]) -> None:
    if any("cycle" in s.split(":") for s in starts):
        try:
            cycle_finder()
        except ImportError as exc:
            raise SweepError(
                "the 'cycle' start needs rotortd_tools.cycles.find_period_one_cycle, "
                f"which is not available: {exc}"
            ) from None



def cycle_finder() -> Callable[..., Any]:
    """``rotortd_tools.cycles.find_period_one_cycle``, imported on first use (heavier)."""
    from rotortd_tools.cycles import find_period_one_cycle

    return find_period_one_cycle


def point_params(values: dict[str, float]) -> tuple[RotorParams, float, ScaledParams]:
    """SI parameters, Omega (rad/s) and scaled set of a point (see the module docstring)."""
    Omega = float(values.get("Omega", CHAPTER_OMEGA))
    sp = chapter_params(Omega, **{k: float(v) for k, v in values.items() if k in SCALED_NAMES})
    return si_params(sp, Omega), Omega, sp


def spin_inputs(values: dict[str, float]) -> tuple[float | None, float]:
    """(J in kg m^2 or None for the held spin, T_drive in N m) of a point."""
    J = values.get("J")
    return (None if J is None else float(J)), float(values.get("T_drive", 0.0))


def bearing_params(values: dict[str, float]) -> BearingParams | None:
    """The real bearing of a point (``BearingParams``: the given names, the others at their
    defaults, options off unless given), or None when no bearing name is given (the
    chapter's fixed rigid bearing)."""
    given = {n: values[n] for n in BEARING_NAMES if n in values}
    if not given:
        return None
    return BearingParams(**{n: (bool(v) if n in OPTIONS else float(v))
                            for n, v in given.items()})


def drop_params(p: RotorParams) -> RotorParams:
    """The point's SI set with gravity DROP_G (m/s^2), for the ``drop`` start."""
    return replace(p, g=DROP_G)
