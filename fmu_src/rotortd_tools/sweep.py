"""Parameter sweeps of the touchdown model on Dask: attractor signatures and regimes.

Frame and units: parameters are the chapter's *scaled* set (MODEL.md §2: gamma, omega, rho,
phi, mu, d, R_over_cr) plus the spin speed ``Omega`` in rad/s. A point starts from the
chapter's SI set (MODEL.md §3) at ``Omega`` (default 184.2 rad/s), takes its scaled set and
replaces the fields the sweep names (swept or fixed); it is realised in SI with
``RotorParams.from_scaled(sp, Omega, m=50 kg, c_r=0.7e-3 m)`` (no gravity, bearing on).
Sweeping ``Omega`` alone therefore keeps the SI set, so gamma and omega vary as 1/Omega.

Times (transient, record) are scaled, t = Omega tau; one forcing period (revolution) is
2 pi. Positions are in c_r, speeds in c_r Omega, angles in rad, co-rotating (U = z
e^{-i psi}/c_r).

Each point is run with ``TouchdownCore`` from one or more *starts* (coexisting attractors
have different basins):

  rest            U = 0, U' = 0
  steady          on the regular equilibrium U* (free whirl); "no-start" when inadmissible
  large           U = 0.9 U*/|U*|, inertial velocity 0 (released near the wall, no whirl)
  cycle[:BRANCH]  right after the impact of the period-one impacting cycle found by Newton
                  on the impact map (``rotortd_tools.cycles.find_period_one_cycle``)
  up[:SEED], down[:SEED]
                  continuation along the first swept parameter: each point starts from the
                  previous point's final state (``get_state``/``set_state``, exact); the
                  first point of a pass (and any point after a failed one) starts from SEED
                  (rest by default). One chain per value of the second parameter.

After ``transient`` the run records ``record`` of scaled time and summarises the attractor
(``signature``) and classifies it (``classify``).
"""

from __future__ import annotations

import cmath
import contextlib
import itertools
import json
import math
import os
import time
import uuid
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from rotortd import (
    MODE_FREE,
    MODE_ROLLING,
    MODE_SLIDING,
    STATUS_OK,
    ParameterError,
    RotorParams,
    ScaledParams,
    TouchdownCore,
)

CHAPTER = RotorParams()
"""The chapter's SI set (MODEL.md §3)."""
CHAPTER_OMEGA = 184.2
"""Chapter spin speed, rad/s."""
MASS, C_R = CHAPTER.m, CHAPTER.c_r
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
REGIMES = ("free", "period-1", "period-2", "period-n", "irregular", "rub", "whip",
           "no-start", "failed")
"""Regime groups (``regime`` itself says ``period-<n>`` with the exact n)."""
META_FILE = "_sweep.json"
FORMAT_VERSION = 1


class SweepError(ValueError):
    """A sweep specification or output is invalid; the message names the problem."""


# --------------------------------------------------------------------------- specification


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
            _cycle_finder()
        except ImportError as exc:
            raise SweepError(
                "the 'cycle' start needs rotortd_tools.cycles.find_period_one_cycle, "
                f"which is not available: {exc}"
            ) from None


def _cycle_finder() -> Callable[..., Any]:
    from rotortd_tools.cycles import find_period_one_cycle  # lazy: optional, heavier

    return find_period_one_cycle


# --------------------------------------------------------------------------- one run


def point_params(values: dict[str, float]) -> tuple[RotorParams, float, ScaledParams]:
    """SI parameters, Omega (rad/s) and scaled set of a point (see the module docstring)."""
    Omega = float(values.get("Omega", CHAPTER_OMEGA))
    sp = CHAPTER.scaled(Omega)
    sp = replace(sp, **{k: float(v) for k, v in values.items() if k in SCALED_NAMES})
    return RotorParams.from_scaled(sp, Omega, m=MASS, c_r=C_R), Omega, sp


class NoStart(RuntimeError):
    """A start does not exist at this point (inadmissible whirl, no cycle)."""


def make_start(label: str, p: RotorParams, Omega: float, sp: ScaledParams) -> TouchdownCore:
    """A core at the named simple start (rest, steady, large, cycle[:BRANCH])."""
    head, _, branch = label.partition(":")
    if head == "rest":
        return TouchdownCore(p)
    U_star = sp.rho * cmath.exp(1j * sp.phi) / complex(sp.omega**2 - 1.0, sp.gamma)
    if head == "steady":
        try:
            return TouchdownCore.on_steady_whirl(p, Omega)
        except ParameterError as exc:
            raise NoStart(str(exc)) from None
    if head == "large":
        U0 = 0.9 * U_star / abs(U_star) if abs(U_star) > 0 else 0.9 + 0j
        return TouchdownCore(p, C_R * U0, 0j)
    if head == "cycle":
        return _cycle_start(p, Omega, sp, branch)
    raise SweepError(f"unknown start {label!r}")


def _cycle_start(p: RotorParams, Omega: float, sp: ScaledParams, branch: str) -> TouchdownCore:
    find = _cycle_finder()
    overrides = {k: getattr(sp, k) for k in SCALED_NAMES if k != "gamma"}
    kwargs = {"branch": branch} if branch else {}
    try:
        cyc = find(sp.gamma, **kwargs, **overrides)
    except (KeyError, RuntimeError, ValueError, ArithmeticError) as exc:
        raise NoStart(f"no period-one cycle: {type(exc).__name__}: {exc}") from None
    return TouchdownCore.from_scaled(p, Omega, complex(cyc.U0), complex(cyc.dU0))


@dataclass
class Recorder:
    """Accumulates the attractor signature over the record window (scaled units)."""

    c_r: float
    Omega: float
    r_max: float = -math.inf
    r_min: float = math.inf
    t_slide: float = 0.0
    t_roll: float = 0.0
    times: list[float] = field(default_factory=list)
    angles: list[float] = field(default_factory=list)
    speeds: list[float] = field(default_factory=list)

    def step(self, core: TouchdownCore, h: float, Omega: float, t_rec0: float) -> int:
        """Advance the core by h (s) and record; return the step status."""
        t0, psi0, mode = core.t, math.remainder(core.psi, 2.0 * math.pi), core.mode
        rep = core.step(h, Omega)
        for imp in rep.impacts:
            ang = cmath.phase(imp.z) - (psi0 + Omega * (imp.t - t0))
            self.times.append((imp.t - t_rec0) * Omega)
            self.angles.append(math.remainder(ang, 2.0 * math.pi))
            self.speeds.append(imp.rdot / (self.c_r * Omega))
            self.r_max = max(self.r_max, 1.0)
        t_prev = t0
        for t_tr, kind in rep.transitions:
            self._dwell(mode, t_tr - t_prev)
            mode, t_prev = _MODE_OF[kind], t_tr
        self._dwell(mode, core.t - t_prev)
        r = abs(core.z) / self.c_r
        self.r_max, self.r_min = max(self.r_max, r), min(self.r_min, r)
        return rep.status

    def _dwell(self, mode: int, dt: float) -> None:
        if mode == MODE_SLIDING:
            self.t_slide += dt * self.Omega
        elif mode == MODE_ROLLING:
            self.t_roll += dt * self.Omega


_MODE_OF = {"sliding": MODE_SLIDING, "rolling": MODE_ROLLING, "lift_off": MODE_FREE}


def detect_period(angles: Sequence[float], speeds: Sequence[float], tol: float,
                  max_period: int) -> int:
    """Smallest n <= max_period with the impact sequence n-periodic to ``tol``, else 0.

    The impact points (co-rotating angle, normal speed) are compared with those n impacts
    later over the last 4 max_period impacts; at least max(2, n) comparisons are needed.
    """
    a = np.asarray(angles[-4 * max_period - max_period:], float)
    v = np.asarray(speeds[-4 * max_period - max_period:], float)
    for n in range(1, max_period + 1):
        m = len(a) - n
        if m < max(2, n):
            break
        da = np.abs(np.remainder(a[n:] - a[:-n] + math.pi, 2.0 * math.pi) - math.pi)
        dv = np.abs(v[n:] - v[:-n])
        if float(max(da.max(), dv.max())) < tol:
            return n
    return 0


def classify(n_impacts: int, slide_frac: float, roll_frac: float, period: int) -> str:
    """Regime from the record window's signature.

    whip (rolling at least half the time), rub (in contact at least half the time),
    free (no impact, no contact), period-<n> (impact map n-periodic), else irregular.
    """
    if roll_frac >= 0.5:
        return "whip"
    if slide_frac + roll_frac >= 0.5:
        return "rub"
    if n_impacts == 0 and slide_frac + roll_frac == 0.0:
        return "free"
    if period > 0:
        return f"period-{period}"
    return "irregular"


def regime_group(regime: str) -> str:
    """Colour group of a regime: period-<n> with n >= 3 becomes period-n."""
    if regime.startswith("period-") and regime not in ("period-1", "period-2"):
        return "period-n"
    return regime


def simulate(core: TouchdownCore, Omega: float, settings: Settings) -> dict[str, Any]:
    """Run transient then record from the core's state; return the signature columns."""
    h = 2.0 * math.pi / (Omega * settings.steps_per_rev)
    n_tr = round(settings.transient * settings.steps_per_rev / (2.0 * math.pi))
    n_rec = max(1, round(settings.record * settings.steps_per_rev / (2.0 * math.pi)))
    for _ in range(n_tr):
        rep = core.step(h, Omega)
        if rep.status != STATUS_OK:
            return {"status": "work-cap", "message": f"transient: {rep.message}"}
    rec = Recorder(core.params.c_r, Omega)
    t_rec0 = core.t
    for _ in range(n_rec):
        if rec.step(core, h, Omega, t_rec0) != STATUS_OK:
            return {"status": "work-cap", "message": "record window: step stopped at work cap"}
    t_rec = n_rec * 2.0 * math.pi / settings.steps_per_rev
    return signature(rec, core, Omega, t_rec, settings)


def signature(rec: Recorder, core: TouchdownCore, Omega: float, t_rec: float,
              settings: Settings) -> dict[str, Any]:
    """The signature columns from a finished record window of scaled length t_rec."""
    n = len(rec.speeds)
    sp = np.asarray(rec.speeds, float)
    period = detect_period(rec.angles, rec.speeds, settings.period_tol, settings.max_period)
    slide, roll = rec.t_slide / t_rec, rec.t_roll / t_rec
    U = core.z * cmath.exp(-1j * core.psi) / C_R
    dU = (core.v - 1j * Omega * core.z) * cmath.exp(-1j * core.psi) / (C_R * Omega)
    k = settings.section
    return {
        "status": "ok",
        "message": "",
        "regime": classify(n, slide, roll, period),
        "period": period,
        "period_time": _period_time(rec.times, period),
        "r_max": rec.r_max,
        "r_min": rec.r_min,
        "n_impacts": n,
        "impact_rate": n / t_rec,
        "impacts_per_rev": n * 2.0 * math.pi / t_rec,
        "v_mean": float(sp.mean()) if n else math.nan,
        "v_std": float(sp.std()) if n else math.nan,
        "v_min": float(sp.min()) if n else math.nan,
        "v_max": float(sp.max()) if n else math.nan,
        "contact_frac": slide + roll,
        "slide_frac": slide,
        "roll_frac": roll,
        "final_mode": core.mode,
        "U_re": U.real,
        "U_im": U.imag,
        "dU_re": dU.real,
        "dU_im": dU.imag,
        "sec_angle": list(rec.angles[-k:]) if k else [],
        "sec_speed": list(rec.speeds[-k:]) if k else [],
    }


def _period_time(times: Sequence[float], period: int) -> float:
    """Mean scaled time over which the impact sequence repeats (NaN when not periodic)."""
    if period <= 0 or len(times) <= period:
        return math.nan
    t = np.asarray(times, float)
    return float(np.mean(t[period:] - t[:-period]))


# --------------------------------------------------------------------------- jobs and rows


@dataclass(frozen=True)
class Job:
    """One run: point index, swept values, all given values, start label."""

    index: int
    point: tuple[tuple[str, float], ...]
    values: tuple[tuple[str, float], ...]
    start: str

    @property
    def key(self) -> str:
        """Identity in the output: swept values (exact repr) and start label."""
        return point_key(dict(self.point), self.start)


def point_key(point: dict[str, float], start: str) -> str:
    """``name=repr(value)`` of the swept values in order, then ``|start``."""
    return ",".join(f"{k}={float(v)!r}" for k, v in point.items()) + "|" + start


def base_row(job: Job, settings: Settings) -> dict[str, Any]:
    """Identity and parameter columns of a job (signature columns empty)."""
    _p, Omega, sp = point_params(dict(job.values))
    row: dict[str, Any] = {"key": job.key, "index": job.index, "start": job.start}
    row.update({k: float(getattr(sp, k)) for k in SCALED_NAMES})
    row["Omega"] = Omega
    row.update({"transient": settings.transient, "record": settings.record})
    return row


def run_job(job: Job, settings: Settings, state: dict | None = None
            ) -> tuple[dict[str, Any], dict | None]:
    """Run one job (from ``state`` if given, else its start); return (row, final state)."""
    row = base_row(job, settings)
    t0 = time.process_time()
    p, Omega, sp = point_params(dict(job.values))
    try:
        core = _core_for(job.start, p, Omega, sp, state)
        sig = simulate(core, Omega, settings)
        final = core.get_state() if sig["status"] == "ok" else None
    except NoStart as exc:
        sig, final = {"status": "no-start", "message": str(exc)}, None
    except (ValueError, RuntimeError, ArithmeticError) as exc:
        sig, final = {"status": "error", "message": f"{type(exc).__name__}: {exc}"}, None
    row.update(_empty_signature())
    row.update(sig)
    if sig["status"] != "ok":
        row["regime"] = "no-start" if sig["status"] == "no-start" else "failed"
    row["final_state"] = json.dumps(final) if final is not None else None
    row["cpu_s"] = time.process_time() - t0
    return row, final


def _core_for(start: str, p: RotorParams, Omega: float, sp: ScaledParams,
              state: dict | None) -> TouchdownCore:
    """A core at the start, or continued from ``state`` with the point's parameters."""
    head, _, seed = start.partition(":")
    if head in CONTINUATION:
        if state is None:
            return make_start(seed or "rest", p, Omega, sp)
        core = TouchdownCore(p)
        core.set_state(state)
        core.set_params(p)
        return core
    return make_start(start, p, Omega, sp)


def _empty_signature() -> dict[str, Any]:
    ident = {*PARAM_NAMES, "transient", "record"}
    out: dict[str, Any] = {n: math.nan for n, t in COLUMNS if t == "f8" and n not in ident}
    out.update({"period": 0, "n_impacts": 0, "final_mode": -1, "sec_angle": [],
                "sec_speed": [], "status": "", "message": "", "regime": ""})
    return out


def run_batch(jobs: Sequence[Job], settings: Settings) -> list[dict[str, Any]]:
    """Run independent jobs (a Dask task); rows in job order."""
    return [run_job(job, settings)[0] for job in jobs]


def run_segment(jobs: Sequence[Job], settings: Settings, prev: tuple[list, dict | None]
                ) -> tuple[list[dict[str, Any]], dict | None]:
    """Run a continuation segment (a Dask task) from the previous segment's final state."""
    state = prev[1]
    rows = []
    for job in jobs:
        row, state = run_job(job, settings, state)
        rows.append(row)
    return rows, state


# --------------------------------------------------------------------------- output


COLUMNS: tuple[tuple[str, str], ...] = (
    ("key", "str"), ("index", "i8"), ("start", "str"),
    *((n, "f8") for n in PARAM_NAMES),
    ("transient", "f8"), ("record", "f8"),
    ("status", "str"), ("message", "str"), ("regime", "str"), ("period", "i8"),
    ("period_time", "f8"), ("r_max", "f8"), ("r_min", "f8"), ("n_impacts", "i8"),
    ("impact_rate", "f8"), ("impacts_per_rev", "f8"), ("v_mean", "f8"), ("v_std", "f8"),
    ("v_min", "f8"), ("v_max", "f8"), ("contact_frac", "f8"), ("slide_frac", "f8"),
    ("roll_frac", "f8"), ("final_mode", "i8"), ("U_re", "f8"), ("U_im", "f8"),
    ("dU_re", "f8"), ("dU_im", "f8"), ("sec_angle", "list"), ("sec_speed", "list"),
    ("final_state", "str"), ("cpu_s", "f8"),
)
"""Output columns and types (str, int64, float64, list<float64>)."""


def arrow_schema():
    """The pyarrow schema of the output."""
    import pyarrow as pa

    types = {"str": pa.string(), "i8": pa.int64(), "f8": pa.float64(),
             "list": pa.list_(pa.float64())}
    return pa.schema([(name, types[t]) for name, t in COLUMNS])


class ParquetSink:
    """A directory of Parquet part files, appended as rows arrive; resumable.

    Rows are buffered and written as a new part file (via a temporary name and an atomic
    rename, so a killed run never leaves a partial file) every ``flush_rows`` rows or
    ``flush_s`` seconds. ``done`` holds the keys already in the directory.
    """

    def __init__(self, path: Path, flush_rows: int = 64, flush_s: float = 2.0) -> None:
        self.path = Path(path)
        self.flush_rows, self.flush_s = flush_rows, flush_s
        self.buffer: list[dict[str, Any]] = []
        self.run_id = f"{time.strftime('%Y%m%dT%H%M%S')}-{uuid.uuid4().hex[:8]}"
        self.seq = 0
        self.last = time.monotonic()
        self.path.mkdir(parents=True, exist_ok=True)
        self.existing = read_sweep(self.path, columns=["key", "start", "index", "final_state"])
        self.done: set[str] = set(self.existing["key"]) if self.existing else set()

    def add(self, rows: Iterable[dict[str, Any]]) -> int:
        """Buffer new rows (keys already written are dropped); flush when due."""
        n = 0
        for row in rows:
            if row["key"] in self.done:
                continue
            self.done.add(row["key"])
            self.buffer.append(row)
            n += 1
        if len(self.buffer) >= self.flush_rows or time.monotonic() - self.last >= self.flush_s:
            self.flush()
        return n

    def flush(self) -> None:
        """Write the buffer as one part file."""
        self.last = time.monotonic()
        if not self.buffer:
            return
        import pyarrow as pa
        import pyarrow.parquet as pq

        table = pa.Table.from_pylist(self.buffer, schema=arrow_schema())
        name = f"part-{self.run_id}-{self.seq:05d}.parquet"
        tmp = self.path / f".{name}.tmp"
        pq.write_table(table, tmp)
        os.replace(tmp, self.path / name)
        self.seq += 1
        self.buffer = []


def part_files(path: Path) -> list[Path]:
    """The finished part files of an output directory (sorted)."""
    return sorted(Path(path).glob("part-*.parquet"))


def read_sweep(path: Path | str, columns: Sequence[str] | None = None) -> dict[str, list]:
    """Read an output directory as {column: list} (empty dict when there are no rows)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    files = part_files(Path(path))
    if not files:
        return {}
    tables = [pq.read_table(f, columns=list(columns) if columns else None) for f in files]
    return pa.concat_tables(tables).to_pydict()


def read_meta(path: Path | str) -> dict[str, Any] | None:
    """The sweep's description (``_sweep.json``), or None."""
    f = Path(path) / META_FILE
    return json.loads(f.read_text()) if f.exists() else None


def spec_meta(spec: SweepSpec, settings: Settings) -> dict[str, Any]:
    """JSON description of a sweep: what a resume must match."""
    return {
        "format": FORMAT_VERSION,
        "axes": [{"name": a.name, "lo": a.lo, "hi": a.hi, "n": a.n, "random": a.random}
                 for a in spec.axes],
        "fixed": dict(spec.fixed),
        "seed": spec.seed,
        "settings": asdict(settings),
        "starts": list(spec.starts),
    }


def prepare_output(path: Path, spec: SweepSpec, settings: Settings, overwrite: bool) -> None:
    """Create or check the output directory; SweepError when it holds another sweep."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise SweepError(f"output {path} exists and is not a directory of part files")
    if overwrite and path.exists():
        for f in [*part_files(path), path / META_FILE]:
            f.unlink(missing_ok=True)
    new = spec_meta(spec, settings)
    old = read_meta(path)
    if old is not None:
        same = {k: v for k, v in old.items() if k != "starts"}
        if same != {k: v for k, v in new.items() if k != "starts"}:
            raise SweepError(
                f"output {path} holds a different sweep (axes, fixed values, seed or "
                "settings differ); use --overwrite or another --out"
            )
        new["starts"] = list(dict.fromkeys([*old["starts"], *new["starts"]]))
    elif part_files(path):
        raise SweepError(f"output {path} has part files but no {META_FILE}; use --overwrite")
    path.mkdir(parents=True, exist_ok=True)
    (path / META_FILE).write_text(json.dumps(new, indent=1))


# --------------------------------------------------------------------------- planning


@dataclass
class Plan:
    """What remains to run: independent jobs and continuation chains (ordered jobs)."""

    independent: list[Job]
    chains: list[tuple[list[Job], dict | None]]
    n_total: int
    n_done: int

    @property
    def n_todo(self) -> int:
        """Rows still to compute."""
        return len(self.independent) + sum(len(c) for c, _ in self.chains)


def all_jobs(spec: SweepSpec) -> dict[str, list[Job]]:
    """Jobs per start label, in sweep order (first axis fastest)."""
    points = spec.points()
    out: dict[str, list[Job]] = {}
    for start in spec.starts:
        out[start] = [
            Job(i, tuple(pt.items()), tuple(spec.values_of(pt).items()), start)
            for i, pt in enumerate(points)
        ]
    return out


def chains_of(jobs: list[Job], spec: SweepSpec) -> list[list[Job]]:
    """Split a continuation start's jobs into passes along the first axis (up or down)."""
    n1 = spec.axes[0].n if spec.axes else 1
    passes = [jobs[i:i + n1] for i in range(0, len(jobs), n1)]
    if jobs and jobs[0].start.partition(":")[0] == "down":
        passes = [list(reversed(p)) for p in passes]
    return passes


def make_plan(spec: SweepSpec, done: set[str], states: dict[str, str | None]) -> Plan:
    """Remaining work; a continuation pass resumes after its last finished point."""
    independent: list[Job] = []
    chains: list[tuple[list[Job], dict | None]] = []
    n_total = 0
    for start, jobs in all_jobs(spec).items():
        n_total += len(jobs)
        if start.partition(":")[0] not in CONTINUATION:
            independent += [j for j in jobs if j.key not in done]
            continue
        for chain in chains_of(jobs, spec):
            k = 0
            while k < len(chain) and chain[k].key in done:
                k += 1
            if k < len(chain):
                st = states.get(chain[k - 1].key) if k else None
                chains.append((chain[k:], json.loads(st) if st else None))
    n_todo = len(independent) + sum(len(c) for c, _ in chains)
    return Plan(independent, chains, n_total, n_total - n_todo)


# --------------------------------------------------------------------------- execution


def batches(jobs: Sequence[Job], size: int) -> Iterator[list[Job]]:
    """Consecutive batches of at most ``size`` jobs."""
    for i in range(0, len(jobs), size):
        yield list(jobs[i:i + size])


def run_serial(plan: Plan, settings: Settings, sink: Callable[[list[dict]], Any]) -> None:
    """Run a plan in this process (reference for the Dask run; same rows, same numbers)."""
    for job in plan.independent:
        sink([run_job(job, settings)[0]])
    for chain, state in plan.chains:
        for job in chain:
            row, state = run_job(job, settings, state)
            sink([row])


def submit_plan(client: Any, plan: Plan, settings: Settings, batch: int, chunk: int) -> list:
    """Submit the plan to a Dask client: batches of independent jobs and chained segments."""
    futures = [
        client.submit(run_batch, b, settings, pure=False)
        for b in batches(plan.independent, batch)
    ]
    for chain, state in plan.chains:
        prev: Any = ([], state)
        for seg in batches(chain, chunk):
            prev = client.submit(run_segment, seg, settings, prev, pure=False)
            futures.append(prev)
    return futures


def run_dask(client: Any, plan: Plan, settings: Settings, sink: Callable[[list[dict]], Any],
             batch: int = 4, chunk: int = 8, progress: bool = True) -> None:
    """Run a plan on a Dask client; rows go to ``sink`` as tasks complete."""
    from dask.distributed import as_completed
    from tqdm import tqdm

    futures = submit_plan(client, plan, settings, batch, chunk)
    with tqdm(total=plan.n_todo, disable=not progress, unit="run", smoothing=0.05) as bar:
        for fut in as_completed(futures):
            res = fut.result()
            rows = res[0] if isinstance(res, tuple) else res
            sink(rows)
            bar.update(len(rows))


@contextlib.contextmanager
def dask_client(scheduler: str | None = None, workers: int | None = None) -> Iterator[Any]:
    """A client on ``scheduler`` (an existing cluster) or on a new LocalCluster of processes."""
    from dask.distributed import Client, LocalCluster

    if scheduler:
        with Client(scheduler) as client:
            yield client
        return
    n = workers or os.cpu_count() or 1
    with LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        yield client


def run_sweep(spec: SweepSpec, settings: Settings, out: Path | str, *,
              scheduler: str | None = None, workers: int | None = None,
              serial: bool = False, overwrite: bool = False, batch: int = 4,
              chunk: int = 8, progress: bool = True, flush_s: float = 2.0
              ) -> dict[str, int]:
    """Run (or resume) a sweep into the Parquet directory ``out``; return row counts."""
    settings.validate()
    out = Path(out)
    prepare_output(out, spec, settings, overwrite)
    sink = ParquetSink(out, flush_s=flush_s)
    ex = sink.existing or {}
    states = dict(zip(ex.get("key", []), ex.get("final_state", [])))
    plan = make_plan(spec, sink.done, states)
    try:
        if plan.n_todo == 0:
            pass
        elif serial:
            run_serial(plan, settings, sink.add)
        else:
            with dask_client(scheduler, workers) as client:
                run_dask(client, plan, settings, sink.add, batch, chunk, progress)
    finally:
        sink.flush()
    return {"total": plan.n_total, "resumed": plan.n_done, "computed": plan.n_todo}
