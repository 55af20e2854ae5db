"""The sweep grammar: parameter names and ranges, axes, settings, starts, and what a point is.

Parameters are the chapter's scaled set (MODEL.md §2: gamma, omega, rho, phi, mu, d,
R_over_cr) plus the spin speed ``Omega`` in rad/s. A point starts from the chapter's SI set
(MODEL.md §3) at ``Omega`` (default 184.2 rad/s), takes its scaled set and replaces the
fields the sweep names (swept or fixed); it is realised in SI with m = 50 kg, c_r = 0.7e-3 m,
no gravity, bearing on (``point_params``). Sweeping ``Omega`` alone therefore keeps the SI
set, so gamma and omega vary as 1/Omega. Times in ``Settings`` are scaled, t = Omega tau
(one revolution is 2 pi).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from rotortd import ParameterError, RotorParams, ScaledParams
from rotortd.scaled import CHAPTER_OMEGA, chapter_params, si_params

SCALED_NAMES = ("gamma", "omega", "rho", "phi", "mu", "d", "R_over_cr")
PARAM_NAMES = (*SCALED_NAMES, "Omega")
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
}
"""(lo, hi, lo_open) of each parameter; None means unbounded."""
SIMPLE_STARTS = ("rest", "steady", "large", "cycle")
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


@dataclass(frozen=True)
class Settings:
    """How each run is made and summarised (scaled times, t = Omega tau)."""

    transient: float = 300.0
    record: float = 100.0
    steps_per_rev: int = 32
    section: int = 64
    period_tol: float = 1e-4
    max_period: int = 32

    def validate(self) -> Settings:
        """Raise SweepError naming a bad setting; return self."""
        checks = (
            ("transient", self.transient >= 0.0 and math.isfinite(self.transient), ">= 0"),
            ("record", self.record > 0.0 and math.isfinite(self.record), "> 0"),
            ("steps_per_rev", self.steps_per_rev >= 1, ">= 1"),
            ("section", self.section >= 0, ">= 0"),
            ("period_tol", self.period_tol > 0.0, "> 0"),
            ("max_period", self.max_period >= 1, ">= 1"),
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
    return value


def _number(name: str, text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise SweepError(f"{name}: {text!r} is not a number") from None


def parse_axis(name: str, text: str, seed: int, index: int) -> Axis:
    """Parse ``a:b:n`` (grid, both ends included) or ``a:b:~n`` (sorted uniform samples)."""
    parts = text.split(":")
    if len(parts) != 3:
        raise SweepError(f"{name}: bad range {text!r}: write a:b:n (grid) or a:b:~n (random)")
    lo, hi = _number(name, parts[0]), _number(name, parts[1])
    n_text = parts[2].strip()
    random = n_text.startswith("~")
    n_text = n_text[1:] if random else n_text
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
    if random:
        rng = np.random.default_rng([seed, index])
        vals = np.sort(rng.uniform(lo, hi, n))
    else:
        vals = np.linspace(lo, hi, n)
    return Axis(name, lo, hi, n, random, tuple(float(v) for v in vals))


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
        f"unknown start {label!r}: choose from rest, steady, large, cycle[:BRANCH], "
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
    spec = SweepSpec(tuple(axes), tuple(sorted(fixed.items())), parse_starts(starts), seed)
    _check_realisable(spec)
    _check_cycle_available(spec.starts)
    return spec


def _check_realisable(spec: SweepSpec) -> None:
    """Build the SI set at the corners of the sweep so a bad combination fails early."""
    corners = [(a.values[0], a.values[-1]) for a in spec.axes]
    for combo in itertools.product(*corners):
        values = spec.values_of(dict(zip(spec.names, combo)))
        try:
            point_params(values)
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
