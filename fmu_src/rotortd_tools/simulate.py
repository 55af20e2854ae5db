"""``rotortd simulate FMU ...``: run an FMI 2.0 co-simulation FMU on FMPy, and say so when
something goes wrong.

It takes ``fmpy simulate``'s options for a run (``--start-values NAME VALUE ...``,
``--input-file``, ``--start-time``, ``--stop-time``, ``--output-interval``,
``--output-variables``, ``--output-file``, a CSV as ``fmpy simulate`` writes it) and differs
where FMPy is silent:

- before simulating, an unknown variable name (with close matches), a variable that cannot
  be set (an output), a value that does not parse for the variable's type (Real, Integer,
  Boolean: true/false/1/0) or lies outside its declared min/max is refused with a message
  naming the variable, value, unit and range, exit status 2; so is an input file
  (``--input-file``: a CSV whose first column is ``time`` and whose other columns are inputs
  of the FMU, as ``fmpy simulate`` reads it) with an unknown or unsettable column, a time
  column that is not finite and non-decreasing, or a value outside its input's range
  (every problem at once); so is one of the real bearing's
  twelve parameters (docs/model.md §10) set without ``integrate_spin = true``, or a parameter
  of an option left off (``rotortd_tools.bearing_args``);
- a progress line on stderr every 5 s of wall time (simulated time, stop time, percent),
  at communication points (``ROTORTD_PROGRESS_SECONDS`` sets the interval);
- exit status 1, with one line saying at what time (the last successful time) and why (the
  FMU's first error message), when the FMU returned fmi2Discard, fmi2Error or fmi2Fatal, or
  when the result stops short of the stop time. The result up to that time is still
  written to ``--output-file``.

FMPy forwards an FMU's log messages only when the instance logs, so the instance is
created with logging on and the messages are filtered: warnings and errors are shown, other
categories are dropped. The FMUs of this project also write their first error on stderr
themselves; while the FMU runs, lines of that form are held and shown only if the logger did
not deliver the same message.
"""

from __future__ import annotations

import argparse
import contextlib
import difflib
import math
import os
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from itertools import pairwise
from pathlib import Path
from typing import Any, TextIO

from rotortd_tools.bearing_args import bearing_problems

PROGRESS_ENV = "ROTORTD_PROGRESS_SECONDS"
PROGRESS_SECONDS = 5.0  # wall time between progress lines [s]
PROG = "rotortd simulate"
SETTABLE = ("parameter", "input")
STATUS_NAMES = {1: "fmi2Warning", 2: "fmi2Discard", 3: "fmi2Error", 4: "fmi2Fatal",
                5: "fmi2Pending"}


class UsageError(ValueError):
    """A bad command line (exit status 2), found before simulating."""


# ------------------------------------------------------------------ arguments
def add_simulate_parser(sub: argparse._SubParsersAction) -> None:
    """Add the ``simulate`` sub-command to the ``rotortd`` parser."""
    p = sub.add_parser(
        "simulate", help="run an FMU on FMPy; refuse bad start values, fail loudly",
        description="Run an FMI 2.0 co-simulation FMU on FMPy with fmpy simulate's run "
        "options. Unknown names and bad values are refused before the run (exit 2); a run "
        "that the FMU refuses (fmi2Discard, fmi2Error, fmi2Fatal) or that stops short of "
        "the stop time exits 1, saying when and why.")
    p.add_argument("fmu", type=Path, help="the FMU file")
    p.add_argument("--start-values", dest="start_values", nargs="+", default=[],
                   metavar="NAME VALUE", help="name-value pairs of parameters and inputs")
    p.add_argument("--input-file", dest="input_file", type=Path, default=None,
                   help="CSV of inputs over time: a 'time' column [s], then one column per "
                   "input (as fmpy simulate reads it)")
    p.add_argument("--start-time", dest="start_time", type=float, default=None,
                   help="start time in s (default: the FMU's default experiment, or 0)")
    p.add_argument("--stop-time", dest="stop_time", type=float, default=None,
                   help="stop time in s (default: the FMU's default experiment)")
    p.add_argument("--output-interval", dest="output_interval", type=float, default=None,
                   help="communication step and sampling interval in s (default: FMPy's)")
    p.add_argument("--output-variables", dest="output_variables", nargs="+", default=None,
                   help="variables to record (default: the outputs)")
    p.add_argument("--output-file", dest="output_file", type=Path, default=None,
                   help="result CSV, as fmpy simulate writes it")
    p.set_defaults(func=run_command)


def run_command(args: argparse.Namespace) -> int:
    """The ``simulate`` sub-command: 0 on success, 1 when the run failed, 2 on bad usage."""
    try:
        run = prepare(args)
    except UsageError as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
    return execute(run, progress_seconds())


@dataclass
class Run:
    """A checked run: the model description, the typed start values and the times [s]."""

    fmu: Path
    md: Any
    start_values: dict[str, Any]
    start_time: float
    stop_time: float
    output_interval: float | None
    output: list[str] | None
    output_file: Path | None
    input: Any = None
    """The input signals (FMPy's structured array: time, then inputs), or None."""


def prepare(args: argparse.Namespace) -> Run:
    """Read the FMU's model description and check the command line against it; raise
    UsageError naming the first problem found (every bad start value at once)."""
    from fmpy import read_model_description

    if not args.fmu.is_file():
        raise UsageError(f"{args.fmu}: no such file")
    try:
        md = read_model_description(str(args.fmu))
    except Exception as exc:
        raise UsageError(f"{args.fmu}: not a valid FMU: {exc}") from exc
    if md.fmiVersion != "2.0" or md.coSimulation is None:
        raise UsageError(f"{args.fmu}: not an FMI 2.0 co-simulation FMU (FMI "
                         f"{md.fmiVersion}); use fmpy simulate")
    variables = {v.name: v for v in md.modelVariables}
    start, stop = _times(md, args.start_time, args.stop_time)
    if args.output_interval is not None and not 0.0 < args.output_interval < math.inf:
        raise UsageError(f"--output-interval {args.output_interval!r}: it must be a finite "
                         f"time > 0 s")
    if args.output_file is not None and not args.output_file.resolve().parent.is_dir():
        raise UsageError(f"--output-file {args.output_file}: its directory does not exist")
    output = list(args.output_variables) if args.output_variables else None
    for name in output or ():
        if name not in variables:
            raise UsageError(f"--output-variables: {_unknown(name, variables)}")
    values = parse_start_values(args.start_values, variables)
    check_bearing(values, variables)
    signals = (None if getattr(args, "input_file", None) is None
               else read_inputs(args.input_file, variables))
    return Run(args.fmu, md, values, start, stop, args.output_interval, output,
               args.output_file, signals)


def read_inputs(path: Path, variables: dict[str, Any]) -> Any:
    """The input file as FMPy reads it, checked: UsageError listing every column that is
    not an input of the FMU, a time column that is not finite and non-decreasing, and every
    column with a value outside its input's declared range."""
    from fmpy.util import read_csv

    if not path.is_file():
        raise UsageError(f"--input-file {path}: no such file")
    try:
        signals = read_csv(str(path))
    except Exception as exc:
        raise UsageError(f"--input-file {path}: not a CSV of numbers with a header: "
                         f"{exc}") from exc
    names = list(signals.dtype.names or ())
    if not names or names[0] != "time" or len(names) < 2:
        raise UsageError(f"--input-file {path}: the first column must be 'time' and at "
                         f"least one input must follow (columns: {names})")
    problems: list[str] = []
    times = [float(t) for t in signals["time"]]
    if not all(map(math.isfinite, times)) or any(b < a for a, b in pairwise(times)):
        problems.append("the time column must be finite and non-decreasing")
    for name in names[1:]:
        var = variables.get(name)
        if var is None:
            problems.append(_unknown(name, variables))
        elif var.causality != "input":
            problems.append(f"{name} is {_article(var.causality)} {var.causality}: only "
                            f"inputs can be given over time (set it with --start-values)")
        else:
            bad = _out_of_range(var, [float(x) for x in signals[name]])
            if bad:
                problems.append(bad)
    if problems:
        raise UsageError(f"--input-file {path}: " + "; ".join(problems))
    return signals


def _out_of_range(var: Any, values: list[float]) -> str:
    """'' if every value lies in var's declared range, else a message naming the first."""
    for i, x in enumerate(values):
        problem = _range_problem(var, x, repr(x), f" in row {i + 1}")
        if problem:
            return problem
    return ""


def _range_problem(var: Any, value: float, shown: str, where: str = "") -> str:
    """'' if value lies in var's declared range, else the message naming the variable, the
    value as ``shown``, its unit, ``where`` it was given, and the range."""
    lo, hi = _bound(var, "min"), _bound(var, "max")
    if lo <= value <= hi:
        return ""
    what = "is not finite" if value != value else "is out of range"
    return (f"{var.name} = {shown}{_unit(var, ' ')}{where} {what}: it must lie in "
            f"[{lo:g}, {hi:g}]{_unit(var, ' ')}")


def check_bearing(values: dict[str, Any], variables: dict[str, Any]) -> None:
    """UsageError when a real-bearing parameter is set without integrate_spin = true (given
    or the FMU's default), or a parameter with its option off (docs/model.md §10)."""
    if "integrate_spin" not in variables:
        return
    default = str(variables["integrate_spin"].start).strip().lower() in ("true", "1")
    spin = bool(values.get("integrate_spin", default))
    problems = bearing_problems(values, spin, "add --start-values integrate_spin true",
                                "add --start-values {opt} true")
    if problems:
        raise UsageError("--start-values: " + "; ".join(problems))


def _times(md: Any, start: float | None, stop: float | None) -> tuple[float, float]:
    """Start and stop time [s] as FMPy chooses them, checked."""
    exp = md.defaultExperiment
    if start is None:
        start = float(exp.startTime) if exp and exp.startTime is not None else 0.0
    if stop is None:
        stop = float(exp.stopTime) if exp and exp.stopTime is not None else start + 1.0
    if not (math.isfinite(start) and math.isfinite(stop) and stop > start):
        raise UsageError(f"--start-time {start!r} s, --stop-time {stop!r} s: the times must "
                         f"be finite with stop > start")
    return start, stop


def parse_start_values(pairs: Sequence[str], variables: dict[str, Any]) -> dict[str, Any]:
    """{name: typed value} of ``--start-values NAME VALUE ...``; raise UsageError listing
    every unknown name, unsettable variable and bad value."""
    if len(pairs) % 2:
        raise UsageError(f"--start-values takes NAME VALUE pairs; {pairs[-1]!r} has no value")
    values: dict[str, Any] = {}
    problems: list[str] = []
    for name, text in zip(pairs[::2], pairs[1::2]):
        if name not in variables:
            problems.append(_unknown(name, variables))
            continue
        try:
            values[name] = parse_value(variables[name], text)
        except UsageError as exc:
            problems.append(str(exc))
    if problems:
        raise UsageError("--start-values: " + "; ".join(problems))
    return values


def parse_value(var: Any, text: str) -> bool | int | float | str:
    """The value of ``text`` for the model variable ``var`` (FMPy's ScalarVariable), or
    UsageError naming the variable, the value, its type, unit and declared range."""
    if var.causality not in SETTABLE or var.variability == "constant":
        raise UsageError(f"{var.name} is {_article(var.causality)} {var.causality} "
                         f"({var.variability}): only parameters and inputs can be set")
    kind = var.type
    if kind == "Boolean":
        low = text.strip().lower()
        if low not in ("true", "false", "1", "0"):
            raise UsageError(f"{var.name} = {text!r} is not a Boolean (true, false, 1 or 0)")
        return low in ("true", "1")
    if kind == "String":
        return text
    try:
        value: int | float = int(text) if kind in ("Integer", "Enumeration") else float(text)
    except ValueError:
        raise UsageError(f"{var.name} = {text!r} is not {_article(kind)} {kind} value"
                         f"{_unit(var, ' in ')}") from None
    problem = _range_problem(var, value, text)
    if problem:
        raise UsageError(problem)
    return value


def _bound(var: Any, which: str) -> float:
    """The declared min or max of var (its own, else its declared type's), or -inf/inf."""
    raw = getattr(var, which, None)
    if raw is None and var.declaredType is not None:
        raw = getattr(var.declaredType, which, None)
    if raw is None:
        return -math.inf if which == "min" else math.inf
    return float(raw)


def _unit(var: Any, sep: str) -> str:
    unit = var.unit or (var.declaredType.unit if var.declaredType is not None else None)
    return f"{sep}{unit}" if unit and unit != "1" else ""


def _article(word: str) -> str:
    return "an" if word[:1].lower() in "aeiou" else "a"


def _unknown(name: str, variables: dict[str, Any]) -> str:
    """'no variable NAME' with close names and names whose description holds NAME."""
    close = difflib.get_close_matches(name, list(variables), n=3, cutoff=0.6)
    word = name.lower()
    described = [n for n, v in variables.items()
                 if v.causality in SETTABLE and word in (v.description or "").lower().split()]
    hints = list(dict.fromkeys(close + described))[:5]
    tip = "; did you mean " + ", ".join(f"{n} ({_short(variables[n])})" for n in hints) + "?"
    return f"no variable {name!r} in this FMU{tip if hints else ''}"


def _short(var: Any) -> str:
    """The first clause of var's description, at most 60 characters."""
    text = (var.description or "").split(";")[0].split(" [")[0].split(" (")[0]
    return text if len(text) <= 60 else text[:57] + "..."


# ------------------------------------------------------------------ the run
def progress_seconds() -> float:
    """Wall time between progress lines [s]: ``ROTORTD_PROGRESS_SECONDS`` or 5."""
    try:
        return float(os.environ.get(PROGRESS_ENV, PROGRESS_SECONDS))
    except ValueError:
        return PROGRESS_SECONDS


class Progress:
    """FMPy's step_finished callback: records the last communication point reached and
    writes a progress line on ``out`` once ``every`` seconds of wall time have passed."""

    def __init__(self, start: float, stop: float, every: float, out: TextIO,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.start, self.stop, self.every, self.out, self.clock = start, stop, every, out, clock
        self.t = start  # last communication point reached [s]
        self.t0 = clock()
        self.next = self.t0 + every

    def __call__(self, t: float, _recorder: Any = None) -> bool:
        self.t = t
        now = self.clock()
        if now >= self.next:
            self.next = now + self.every
            self.out.write(self.line(t, now - self.t0) + "\n")
            self.out.flush()
        return True

    def line(self, t: float, elapsed: float) -> str:
        """'rotortd simulate: t = 2.5 s of 10 s (25 %), 5.0 s of wall time'."""
        pct = 100.0 * (t - self.start) / (self.stop - self.start)
        return (f"{PROG}: t = {t:.6g} s of {self.stop:.6g} s ({pct:.0f} %), "
                f"{elapsed:.1f} s of wall time")


@dataclass
class Messages:
    """The FMU's log messages (FMPy's logger callback), and its stderr lines held back."""

    instance: str
    out: TextIO
    errors: list[str] = field(default_factory=list)
    held: list[str] = field(default_factory=list)

    def log(self, _env: Any, _inst: Any, status: int, _category: Any, message: Any) -> None:
        text = message.decode("utf-8", "replace") if isinstance(message, bytes) else str(message)
        if status >= 2:  # discard, error, fatal: the reason reported at the end
            self.errors.append(text)
        elif status == 1:
            self.out.write(f"{self.instance}: warning: {' '.join(text.split())}\n")

    def unreported(self) -> list[str]:
        """Held stderr lines of the FMU whose message the logger did not deliver."""
        said = {" ".join(f"{self.instance}: error: {e}".split()) for e in self.errors}
        return [line for line in self.held if line not in said]


class _FmuStderr:
    """sys.stderr while the FMU runs in this process: the FMU's own error lines
    (``<instance>: error: ...``) are held, everything else passes through."""

    def __init__(self, real: TextIO, messages: Messages) -> None:
        self.real, self.messages, self.buf = real, messages, ""
        self.prefix = f"{messages.instance}: error: "

    def write(self, text: str) -> int:
        self.buf += text
        while "\n" in self.buf:
            line, self.buf = self.buf.split("\n", 1)
            if line.startswith(self.prefix):
                self.messages.held.append(line)
            else:
                self.real.write(line + "\n")
        return len(text)

    def flush(self) -> None:
        self.real.flush()

    def __getattr__(self, name: str) -> Any:  # encoding, isatty, fileno, ...
        return getattr(self.real, name)

    def close_out(self) -> None:
        if self.buf:
            self.real.write(self.buf)
            self.buf = ""


@dataclass
class Outcome:
    """How a run ended: the status of the failing FMI call (0: none) and where [s]."""

    status: int = 0
    function: str = ""
    time: float = math.nan
    detail: str = ""


def execute(run: Run, every: float) -> int:
    """Simulate; write the result; report the outcome. 0 reached the stop time, 1 not."""
    from fmpy import extract
    from fmpy.fmi1 import FMICallException
    from fmpy.simulation import instantiate_fmu, simulate_fmu

    real_err = sys.stderr
    instance = run.md.coSimulation.modelIdentifier
    messages = Messages(instance, real_err)
    progress = Progress(run.start_time, run.stop_time, every, real_err)
    outcome = Outcome()
    unzip = extract(str(run.fmu))
    fmu = instantiate_fmu(unzip, run.md, "CoSimulation", debug_logging=True,
                          logger=messages.log)
    _watch_do_step(fmu, outcome, FMICallException)
    recorder: list[Any] = []

    def step_finished(t: float, rec: Any) -> bool:
        if not recorder:
            recorder.append(rec)
        return progress(t, rec)

    result = None
    sys.stderr = filt = _FmuStderr(real_err, messages)  # type: ignore[assignment]
    try:
        result = simulate_fmu(unzip, model_description=run.md, fmu_instance=fmu,
                              start_time=run.start_time, stop_time=run.stop_time,
                              output_interval=run.output_interval, output=run.output,
                              start_values=run.start_values, input=run.input,
                              step_finished=step_finished)
    except FMICallException as exc:
        outcome.status, outcome.function, outcome.time = exc.status, exc.function, progress.t
    except Exception as exc:  # FMPy's own refusals: still a failed run, said plainly
        outcome.status, outcome.time, outcome.detail = 3, progress.t, f"FMPy: {exc}"
    finally:
        filt.close_out()
        sys.stderr = real_err
    if outcome.status != 4:  # after fmi2Fatal no call is allowed
        _free(fmu)
    if result is None and recorder:
        result = recorder[0].result()
    return _finish(run, result, outcome, messages)


def _watch_do_step(fmu: Any, outcome: Outcome, exc_type: type) -> None:
    """Record the status of a refused fmi2DoStep (FMPy swallows fmi2Discard)."""
    do_step = fmu.doStep

    def watched(*args: Any, **kwargs: Any) -> Any:
        try:
            return do_step(*args, **kwargs)
        except exc_type as exc:
            outcome.status, outcome.function = exc.status, exc.function
            raise

    fmu.doStep = watched


def _free(fmu: Any) -> None:
    with contextlib.suppress(Exception):
        fmu.freeInstance()


def _finish(run: Run, result: Any, outcome: Outcome, messages: Messages) -> int:
    """Write the result and report: 0 if the stop time was reached without a refusal."""
    out = sys.stderr
    reached = float(result["time"][-1]) if result is not None and len(result) else math.nan
    if run.output_file is not None and result is not None:
        from fmpy.util import write_csv

        write_csv(filename=str(run.output_file), result=result)
    for line in messages.unreported():
        out.write(line + "\n")
    short = not (reached >= run.stop_time or math.isclose(reached, run.stop_time))
    if not outcome.status and not short:
        return 0
    when = outcome.time if outcome.status and outcome.status != 2 else reached
    what = (f"the FMU returned {STATUS_NAMES.get(outcome.status, outcome.status)} from "
            f"{outcome.function}" if outcome.function else "the run failed")
    if not outcome.status:
        what = "the FMU stopped without an error status"
    why = outcome.detail or (messages.errors[0] if messages.errors
                             else "the FMU gave no message")
    stop = f"short of the stop time {run.stop_time!r} s" if short else "at the stop time"
    where = (f"; the result up to t = {reached!r} s is in {run.output_file}"
             if run.output_file is not None and result is not None else "")
    out.write(" ".join(f"{PROG}: error: {what} at t = {when!r} s (last successful time), "
                       f"{stop}: {why}{where}".split()) + "\n")
    return 1
