"""One variable table per FMU: the single source of its FMI variables.

Each row (``Var``) gives name, causality, type, start, unit, min, max, description and
whether a parameter is tunable. Everything else derives from the table: the PythonFMU
registration (``register``), the unit/min/max that build.py writes into
modelDescription.xml (``meta``), the fixed and tunable sets, the validation ranges (rows of
quantities the core knows take unit, min and max from ``rotortd.limits.LIMITS``, so what the
FMU declares is what the core enforces), and, through the built model description, the SSP
types. Standard library and pythonfmu only; the table is plain data, built once per process.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

from pythonfmu import Boolean, Integer, Real, String
from pythonfmu.enums import Fmi2Causality, Fmi2Initial, Fmi2Variability

PARAMETER, INPUT, OUTPUT = "parameter", "input", "output"
_TYPES = {"Real": Real, "Integer": Integer, "Boolean": Boolean, "String": String}


@dataclass(frozen=True)
class Var:
    """One FMI variable. ``lo``/``hi`` are the inclusive min/max (None: unbounded)."""

    name: str
    causality: str
    type: str
    start: Any
    unit: str
    lo: float | None
    hi: float | None
    description: str
    tunable: bool = False
    shows: str = ""
    """An output that shows the state: the field of the core's ``StateOutputs`` it
    publishes (``touchdown.publish_state`` is compiled from these); "" for the others."""

    @property
    def fmi_description(self) -> str:
        """The description with the unit and the range, both derived from the row."""
        unit = f" [{self.unit or '-'}]"
        if self.lo is None and self.hi is None:
            return f"{self.description}{unit}"
        lo = "-inf" if self.lo is None else f"{self.lo:g}"
        hi = "inf" if self.hi is None else f"{self.hi:g}"
        return f"{self.description}{unit}, in [{lo}, {hi}]"


def limited(name: str, causality: str, start: float, description: str, *,
            tunable: bool = False) -> Var:
    """A Real parameter or input whose unit and range are those the core enforces."""
    from rotortd.limits import LIMITS  # resources/rotortd inside the FMU

    lim = LIMITS[name]
    return Var(name, causality, "Real", start, lim.unit, lim.lo, lim.hi, description, tunable)


def fixed(name: str, type_: str, start: Any, description: str) -> Var:
    """A fixed parameter without a range (Boolean, String)."""
    return Var(name, PARAMETER, type_, start, "", None, None, description)


def output(name: str, unit: str, description: str, lo: float | None = None,
           hi: float | None = None, type_: str = "Real", *, shows: str = "") -> Var:
    """An output computed in doStep (initial exact); ``shows``: the core's StateOutputs
    field it publishes, if it shows the state."""
    start = {"Real": 0.0, "Integer": 0, "Boolean": False}[type_]
    return Var(name, OUTPUT, type_, start, unit, lo, hi, description, shows=shows)


def names(table: Iterable[Var], causality: str, *, tunable: bool | None = None) -> tuple:
    """Names of the rows of one causality (parameters: only tunable or fixed ones if asked)."""
    return tuple(v.name for v in table if v.causality == causality
                 and (tunable is None or v.tunable == tunable))


def meta(table: Iterable[Var]) -> dict[str, tuple[str, float | None, float | None]]:
    """{name: (unit, min, max)} of the Real and Integer rows, for build.py."""
    return {v.name: (v.unit, v.lo, v.hi) for v in table if v.type in ("Real", "Integer")}


def range_message(v: Var, value: Any) -> str | None:
    """None when ``value`` lies in the row's [lo, hi], else the message naming the
    variable, its value, unit and range."""
    x = float(value)
    lo = -math.inf if v.lo is None else v.lo
    hi = math.inf if v.hi is None else v.hi
    if lo <= x <= hi and x - x == 0.0:  # False for NaN and for infinities
        return None
    u = f" {v.unit}" if v.unit and v.unit != "1" else ""
    what = "is not finite" if not math.isfinite(x) else "is out of range"
    return f"{v.name} = {x!r}{u} {what}: it must lie in [{lo:g}, {hi:g}]{u}"


def range_violations(rows: Iterable[Var], slave: Any) -> list[str]:
    """The message of every row whose current value on ``slave`` is outside its range."""
    found = (range_message(v, getattr(slave, v.name)) for v in rows)
    return [msg for msg in found if msg is not None]


def register(slave: Any, table: Iterable[Var], watched: Callable[[str], Any],
             refused: Callable[[str], Any], getters: dict[str, Callable[[], Any]] | None = None
             ) -> None:
    """Set each start value on ``slave`` and register the variable with PythonFMU.

    ``watched(name)`` gives the setter of a parameter or input, ``refused(name)`` that of
    an output (a host may not set it); ``getters`` replaces the plain attribute read of some
    variables."""
    getters = getters or {}
    for v in table:
        setattr(slave, v.name, v.start)
        kwargs: dict[str, Any] = {"causality": getattr(Fmi2Causality, v.causality),
                                  "description": v.fmi_description}
        if v.causality == OUTPUT:
            kwargs["initial"] = Fmi2Initial.exact
            kwargs["setter"] = refused(v.name)
            if v.type != "Real":
                kwargs["variability"] = Fmi2Variability.discrete
        else:
            kwargs["setter"] = watched(v.name)
            if v.causality == PARAMETER:
                kwargs["variability"] = (Fmi2Variability.tunable if v.tunable
                                         else Fmi2Variability.fixed)
        if v.name in getters:
            kwargs["getter"] = getters[v.name]
        slave.register_variable(_TYPES[v.type](v.name, **kwargs))
