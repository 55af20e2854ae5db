"""FMU-level fuzz of RotorTouchdown (issue 18): random declared-valid cases through FMPy.

    python docs/scripts/fuzz_fmu.py [--cases 3000] [--seed 1] [--jobs 2] [--check]

Every variable's range, causality and variability comes from the FMU's modelDescription.xml,
so the fuzz follows the FMU when its declared ranges change. Each case draws the parameters
across their declared ranges (exact extremes, values next to them, log-uniform across
decades, uniform, the start value), an initial position inside the clearance (sometimes
exactly on it), then runs random steps (1e-12 s to 1 s) with inputs and tunable parameters
changed between steps and state round trips (get/set and serialize/deserialize, replayed
and compared bit for bit). Cases run in batches, one subprocess per batch
(docs/scripts/fuzz_fmu_case.py); a failed batch is re-run case by case.

Counted, and with --check required to be 0: crashes (abnormal subprocess exit), steps
over --step-limit seconds of CPU time (the FMU's own work: the wall time of one step
scatters by 1.7x on this kind of machine; a step is also abandoned after 4x the limit in
wall time), non-finite outputs of an OK step, refusals of
declared-valid input (an initialisation or step refusal whose message says neither
"cross-parameter" nor, for a Discard, "work bound"/"work cap"), positions with
|(x, y) - (x_b, y_b)| > c_r (1 + 1e-12) after an OK step (measured from the race's centre;
not under the compliant contact law, whose contact penetrates), and state round trips that
do not replay bit
for bit. Writes docs/fuzz_results.json and the generated block of docs/fuzz.md.
"""

from __future__ import annotations

import argparse
import contextlib
import hashlib
import json
import math
import os
import queue
import random
import re
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))

from fuzz_fmu_case import HUNG_RC, RADIUS_TOL  # noqa: E402 (docs/scripts/fuzz_fmu_case.py)
from mdblock import replace_block  # noqa: E402 (docs/scripts/mdblock.py)

CASE_SCRIPT = HERE / "fuzz_fmu_case.py"
DEFAULT_FMU = ROOT / "models" / "RotorTouchdown.fmu"
DEFAULT_OUT = ROOT / "docs" / "fuzz_results.json"
DEFAULT_DOC = ROOT / "docs" / "fuzz.md"

OPEN_DECADES = 3.0   # an undeclared bound is drawn as |start| * 10**3 (10**3 if start = 0)
LOG_DECADES = 9.0    # a range from 0 is drawn log-uniform down to 1e-9 of its top
SLOW_MARGIN = 1.5    # a shrunk slow-step reproducer takes at least 1.5x the step limit
POSITION = ("x0", "y0", "c_r")  # drawn together: the initial position inside the clearance
WORK_BOUND_RE = re.compile(r"work[\s_-]*(bound|cap|budget|limit)", re.IGNORECASE)
CROSS_RE = re.compile(r"cross-parameter", re.IGNORECASE)
NUMBER_RE = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|\b(?:inf|nan)\b")

VIOLATIONS = ("crash", "over_step_limit", "nonfinite_ok", "declared_valid_refusal",
              "outside_clearance", "state_roundtrip")
VIOLATION_TITLES = {
    "crash": "crashes (abnormal subprocess exit)",
    "over_step_limit": "steps over the step limit",
    "nonfinite_ok": "non-finite outputs with OK",
    "declared_valid_refusal": "refusals of declared-valid input",
    "outside_clearance": f"|z| > c_r (1 + {RADIUS_TOL:g}) after OK",
    "state_roundtrip": "state round trips not bit-identical",
}


# ---------------------------------------------------------------------------- model
@dataclass(frozen=True)
class Var:
    """One model variable as the fuzz needs it."""

    name: str
    type: str
    causality: str
    variability: str
    start: Any
    lo: float | None
    hi: float | None


@dataclass(frozen=True)
class ModelInfo:
    """The variables of the FMU's model description, grouped for drawing."""

    vars: dict[str, Var]
    default_step: float

    def named(self, causality: str, variability: str | None = None) -> list[Var]:
        return [v for v in self.vars.values() if v.causality == causality
                and (variability is None or v.variability == variability)]


def _start(v: Any) -> Any:
    if v.start is None:
        return {"Real": 0.0, "Boolean": False, "String": ""}.get(v.type, 0)
    if v.type == "Real":
        return float(v.start)
    if v.type == "Boolean":
        return str(v.start).lower() in ("true", "1")
    if v.type in ("Integer", "Enumeration"):
        return int(v.start)
    return str(v.start)


def _bound(v: Any, key: str) -> float | None:
    """The variable's min or max, else its declared type's (FMPy does not inherit them)."""
    x = getattr(v, key)
    if x is None and v.declaredType is not None:
        x = getattr(v.declaredType, key, None)
    return None if x is None else float(x)


def load_model(fmu: Path) -> ModelInfo:
    from fmpy import read_model_description

    md = read_model_description(str(fmu))
    variables = {v.name: Var(v.name, v.type, v.causality, v.variability, _start(v),
                             _bound(v, "min"), _bound(v, "max")) for v in md.modelVariables}
    step = md.defaultExperiment.stepSize if md.defaultExperiment else None
    return ModelInfo(variables, float(step) if step else 1e-4)


# ---------------------------------------------------------------------------- drawing
@dataclass(frozen=True)
class Style:
    """How far from the start values a case goes."""

    name: str
    p_extreme: float   # share of values that are a range's extreme or next to it
    p_start: float     # share of values left at the start value
    nominal: bool      # the rest: near the start value (True) or across the range


STYLES = (Style("nominal", 0.0, 0.3, True), Style("wide", 0.08, 0.1, False),
          Style("edge", 0.35, 0.05, False))
STYLE_WEIGHTS = (0.3, 0.4, 0.3)


def span(var: Var) -> tuple[float, float]:
    """The drawing range: the declared bounds, an undeclared side OPEN_DECADES past start."""
    start = float(var.start)
    reach = (abs(start) if start else 1.0) * 10.0**OPEN_DECADES
    lo = var.lo if var.lo is not None else min(-reach, (var.hi or 0.0) - reach)
    hi = var.hi if var.hi is not None else max(reach, (var.lo or 0.0) + reach)
    return lo, hi


def edge_values(lo: float, hi: float) -> list[float]:
    """The extremes of [lo, hi] and values next to them (one ulp, 1e-9 of the range)."""
    width = hi / 2 - lo / 2
    cand = [lo, hi, math.nextafter(lo, hi), math.nextafter(hi, lo),
            lo + width * 2e-9, hi - width * 2e-9]
    if lo == 0.0:
        cand += [5e-324, 2.2250738585072014e-308, 1e-300]
    if lo < 0.0 < hi:
        cand += [0.0, 5e-324, -5e-324]
    return sorted({x for x in cand if lo <= x <= hi})


def _logu(rng: random.Random, a: float, b: float) -> float:
    x = math.exp(rng.uniform(math.log(a), math.log(b)))
    return min(max(x, a), b)


def log_draw(rng: random.Random, lo: float, hi: float) -> float:
    """Log-uniform magnitude across the decades of [lo, hi] (0 inside: either sign)."""
    if lo >= 0.0:
        a = lo if lo > 0.0 else hi * 10.0**-LOG_DECADES
        return _logu(rng, a, hi) if hi > a else hi
    if hi <= 0.0:
        return -log_draw(rng, -hi, -lo)
    side = hi if rng.random() < 0.5 else lo
    return math.copysign(_logu(rng, abs(side) * 10.0**-LOG_DECADES, abs(side)), side)


def spread(rng: random.Random, lo: float, hi: float) -> float:
    """Across the range: log-uniform if it spans decades (half the time), else uniform."""
    decades = lo <= 0.0 <= hi or (lo > 0.0 and hi / lo >= 100.0) or (hi < 0 and lo / hi >= 100)
    if decades and rng.random() < 0.5:
        return log_draw(rng, lo, hi)
    u = rng.random()
    return min(max(lo * (1.0 - u) + hi * u, lo), hi)


def nominal(rng: random.Random, start: float, lo: float, hi: float) -> float:
    """Near the start value: within half a decade of it, or small around 0."""
    if start != 0.0:
        x = start * 10.0 ** rng.uniform(-0.5, 0.5)
    else:
        x = 0.0 if rng.random() < 0.5 else rng.uniform(-1.0, 1.0) * 10.0 ** rng.uniform(-3, 0)
    return min(max(x, lo), hi)


def draw_real(rng: random.Random, var: Var, style: Style) -> float:
    lo, hi = span(var)
    r = rng.random()
    if r < style.p_extreme:
        return rng.choice(edge_values(lo, hi))
    if r < style.p_extreme + style.p_start:
        return min(max(float(var.start), lo), hi)
    if style.nominal:
        return nominal(rng, float(var.start), lo, hi)
    return spread(rng, lo, hi)


def draw_value(rng: random.Random, var: Var, style: Style) -> Any:
    if var.type == "Real":
        return draw_real(rng, var, style)
    if var.type == "Boolean":
        return rng.random() < 0.5
    if var.type == "String":  # impact_log: mostly empty, sometimes a file in a temp dir
        return "{tmp}/" + var.name + ".csv" if rng.random() < 0.15 else ""
    lo = int(var.lo) if var.lo is not None else -1000
    hi = int(var.hi) if var.hi is not None else 1000
    return rng.randint(lo, hi)


def draw_position(rng: random.Random, model: ModelInfo, c_r: float) -> dict[str, float]:
    """x0, y0 inside the clearance: the centre, exactly on it, next to it, or inside."""
    a = rng.choice([0.0, math.pi / 2, math.pi, -math.pi / 2]) if rng.random() < 0.2 \
        else rng.uniform(-math.pi, math.pi)
    r = rng.random()
    if r < 0.1:
        x, y = 0.0, 0.0
    elif r < 0.35:
        x, y = c_r * math.cos(a), c_r * math.sin(a)  # exactly on the clearance
    else:
        f = 1.0 - 10.0 ** rng.uniform(-16, -6) if r < 0.5 else math.sqrt(rng.random())
        x, y = c_r * f * math.cos(a), c_r * f * math.sin(a)
    out = {}
    for name, value in (("x0", x), ("y0", y)):
        lo, hi = span(model.vars[name])
        out[name] = min(max(value, lo), hi)
    return out


H_CLASSES = (  # (cumulative share, draw) of a communication step
    (0.06, lambda rng, h0: 1e-12), (0.12, lambda rng, h0: 10 ** rng.uniform(-13, -9)),
    (0.40, lambda rng, h0: 10 ** rng.uniform(-7, -4)),
    (0.75, lambda rng, h0: 10 ** rng.uniform(-4, -2)), (0.88, lambda rng, h0: h0),
    (0.94, lambda rng, h0: 10 ** rng.uniform(-2, -1)),
    (0.97, lambda rng, h0: 10 ** rng.uniform(-1, 0)), (1.0, lambda rng, h0: 1.0))


def draw_h(rng: random.Random, default_step: float) -> float:
    """A communication step: tiny (1e-12), small, moderate, the default, large, 1 s."""
    r = rng.random()
    return next(draw for p, draw in H_CLASSES if r < p)(rng, default_step)


def draw_ops(rng: random.Random, model: ModelInfo, style: Style) -> list[dict[str, Any]]:
    """Steps (fixed or variable size), some with new inputs or tunable parameters first."""
    n = rng.randint(1, 16)
    fixed = rng.random() < 0.3
    h0 = draw_h(rng, model.default_step)
    inputs, tunables = model.named("input"), model.named("parameter", "tunable")
    ops = []
    for _ in range(n):
        op: dict[str, Any] = {"h": h0 if fixed else draw_h(rng, model.default_step)}
        changes = {}
        for group, p in ((inputs, 0.2), (tunables, 0.1)):
            if group and rng.random() < p:
                for var in rng.sample(group, min(len(group), rng.randint(1, 2))):
                    changes[var.name] = draw_value(rng, var, style)
        if changes:
            op["set"] = changes
        ops.append(op)
    return ops


def draw_roundtrips(rng: random.Random, n_ops: int) -> list[list[Any]]:
    """Up to two windows [first op, n ops, serialize] to save, run, restore and replay."""
    out: list[list[Any]] = []
    first = 0
    for p in (0.4, 0.15):
        if first >= n_ops or rng.random() >= p:
            break
        start = rng.randint(first, n_ops - 1)
        length = rng.randint(1, min(4, n_ops - start))
        out.append([start, length, rng.random() < 0.5])
        first = start + length
    return out


BEARING_OPTIONS = ("race_turns", "support_compliant", "contact_compliant")
"""The real bearing's options (docs/model.md §10): they need integrate_spin."""
HELD_OPTIONS_KEPT_NOT = 0.9
"""Share of the cases drawn with a bearing option on and the spin held whose options are
turned off: the rest test the cross-parameter refusal; without this, 7 in 10 cases were
refused at the start (docs/fuzz.md, session 13)."""


def draw_case(model: ModelInfo, seed: int, index: int) -> dict[str, Any]:
    """Case ``index`` of the stream ``seed`` (the same on every machine and run)."""
    rng = random.Random(f"fuzz-fmu:{seed}:{index}")
    style = rng.choices(STYLES, STYLE_WEIGHTS)[0]
    params = {v.name: draw_value(rng, v, style) for v in model.named("parameter")}
    if set(POSITION) <= params.keys():
        params.update(draw_position(rng, model, params["c_r"]))
    if (not params.get("integrate_spin") and any(params.get(o) for o in BEARING_OPTIONS)
            and rng.random() < HELD_OPTIONS_KEPT_NOT):
        params.update(dict.fromkeys(BEARING_OPTIONS, False))
    params.update({v.name: draw_value(rng, v, style) for v in model.named("input")})
    ops = draw_ops(rng, model, style)
    return {"id": index, "seed": seed, "style": style.name, "params": params, "ops": ops,
            "roundtrips": draw_roundtrips(rng, len(ops))}


# ---------------------------------------------------------------------------- running
@dataclass(frozen=True)
class Limits:
    step_limit: float = 5.0   # s: a single doStep above it is a violation
    abandon: float = 5.5      # s: a doStep still running then is abandoned (process exits)
    timeout: float = 300.0    # s: wall-clock limit of one case in its subprocess


@dataclass
class ProcOutcome:
    """One subprocess: its case results by id, exit code, timeout flag, stderr tail."""

    results: dict[int, dict[str, Any]]
    rc: int | None
    timed_out: bool
    stderr: str

    def abandoned(self) -> bool:
        """The watchdog ended the process after reporting the case it abandoned."""
        return (not self.timed_out and self.rc == HUNG_RC
                and any(r.get("abandoned") for r in self.results.values()))

    def failed(self, n_specs: int) -> bool:
        """Crash, timeout, non-zero exit other than an abandonment, or missing results."""
        if self.abandoned():
            return False
        return self.timed_out or self.rc != 0 or len(self.results) < n_specs


def run_process(unzipdir: str, specs: list[dict[str, Any]], limits: Limits) -> ProcOutcome:
    """Run specs in one fresh interpreter (fuzz_fmu_case.py), reading its results as they
    come; the process is killed when one case takes longer than ``limits.timeout``."""
    cmd = [sys.executable, str(CASE_SCRIPT), unzipdir, repr(limits.step_limit),
           repr(limits.abandon)]
    proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    lines: queue.Queue[str | None] = queue.Queue()
    err: list[str] = []
    threading.Thread(target=_pump, args=(proc.stdout, lines), daemon=True).start()
    errors = threading.Thread(target=lambda: err.append(proc.stderr.read()), daemon=True)
    errors.start()
    with contextlib.suppress(BrokenPipeError):
        proc.stdin.write(json.dumps(specs))
        proc.stdin.close()
    results, timed_out = _collect(lines, limits.timeout)
    if timed_out:
        proc.kill()
    rc = proc.wait()
    errors.join(timeout=10.0)
    return ProcOutcome(results, None if timed_out else rc, timed_out, "".join(err)[-2000:])


def _pump(stream: Any, lines: queue.Queue) -> None:
    for line in stream:
        lines.put(line)
    lines.put(None)


def _collect(lines: queue.Queue, timeout: float) -> tuple[dict[int, dict[str, Any]], bool]:
    """The ``CASE`` results until the end of the output, or until a case overruns."""
    results: dict[int, dict[str, Any]] = {}
    while True:
        try:
            line = lines.get(timeout=timeout)
        except queue.Empty:
            return results, True
        if line is None:
            return results, False
        if line.startswith("CASE "):
            res = json.loads(line[5:])
            results[res["id"]] = res


def _crash_record(spec: dict[str, Any], out: ProcOutcome, scope: str) -> dict[str, Any]:
    return {"id": spec["id"], "scope": scope, "rc": out.rc, "timed_out": out.timed_out,
            "stderr": out.stderr[-1200:]}


def _merge(alone: dict[str, Any] | None, batch: dict[str, Any] | None) -> dict[str, Any]:
    """The case's own run is authoritative; a slow step seen in the batch run is kept."""
    res = dict(alone or batch or {})
    if batch and alone:
        if batch.get("slow_step") and not alone.get("slow_step"):
            res["slow_step"] = {**batch["slow_step"], "seen": "batch run only"}
        res["max_step_wall"] = max(alone.get("max_step_wall", 0.0),
                                   batch.get("max_step_wall", 0.0))
        res["max_step_cpu"] = max(alone.get("max_step_cpu", 0.0),
                                  batch.get("max_step_cpu", 0.0))
    return res


@dataclass
class Collected:
    """Every case's result and every crash, as the runs come back."""

    results: dict[int, dict[str, Any]] = field(default_factory=dict)
    crashes: list[dict[str, Any]] = field(default_factory=list)
    batch_failures: int = 0
    reruns: int = 0


class Runner:
    """Batches on a pool of ``jobs`` subprocess slots; a failed batch is re-run per case."""

    def __init__(self, unzipdir: str, limits: Limits, jobs: int,
                 progress: bool = False) -> None:
        self.unzipdir, self.limits, self.progress = unzipdir, limits, progress
        self.pool = ThreadPoolExecutor(max_workers=max(1, jobs))
        self.got = Collected()
        self.pending: dict[Future, tuple[str, list[dict[str, Any]], dict]] = {}

    def submit(self, kind: str, specs: list[dict[str, Any]], batch: dict | None = None) -> None:
        fut = self.pool.submit(run_process, self.unzipdir, specs, self.limits)
        self.pending[fut] = (kind, specs, batch or {})

    def run(self, specs: list[dict[str, Any]], batch_size: int) -> Collected:
        for i in range(0, len(specs), batch_size):
            self.submit("batch", specs[i:i + batch_size])
        t0, total = time.perf_counter(), len(specs)
        shown = t0
        while self.pending:
            done, _ = wait(list(self.pending), return_when=FIRST_COMPLETED)
            for fut in done:
                kind, group, batch = self.pending.pop(fut)
                self._handle(kind, group, batch, fut.result())
            if self.progress and time.perf_counter() - shown > 15.0:
                shown = time.perf_counter()
                print(f"  {len(self.got.results)}/{total} cases, {shown - t0:.0f} s",
                      file=sys.stderr)
        self.pool.shutdown()
        return self.got

    def _handle(self, kind: str, specs: list[dict[str, Any]], batch: dict,
                out: ProcOutcome) -> None:
        if kind == "batch" and out.abandoned():
            # attributed already: keep what ran, go on with the rest in a new batch
            self.got.results.update(out.results)
            rest = [s for s in specs if s["id"] not in out.results]
            if rest:
                self.submit("batch", rest)
            return
        if kind == "batch" and out.failed(len(specs)):
            self.got.batch_failures += 1
            self.got.reruns += len(specs)
            ids = [s["id"] for s in specs]
            info = {"ids": ids, "out": out, "left": set(ids), "crashed_alone": False}
            for spec in specs:
                self.submit("alone", [spec], info)
            return
        if kind == "batch":
            self.got.results.update(out.results)
            return
        self._handle_alone(specs[0], batch, out)

    def _handle_alone(self, spec: dict[str, Any], batch: dict, out: ProcOutcome) -> None:
        cid = spec["id"]
        self.got.results[cid] = _merge(out.results.get(cid), batch["out"].results.get(cid))
        self.got.results[cid].setdefault("id", cid)
        if out.failed(1):
            self.got.crashes.append(_crash_record(spec, out, "alone"))
            self.got.results[cid]["crash"] = True
            batch["crashed_alone"] = True
        batch["left"].discard(cid)
        if not batch["left"] and not batch["crashed_alone"]:
            first = {"id": batch["ids"][0]}
            rec = _crash_record(first, batch["out"], "batch only, no case crashes alone")
            rec["ids"] = batch["ids"]
            self.got.crashes.append(rec)


def run_one(unzipdir: str, spec: dict[str, Any], limits: Limits) -> dict[str, Any]:
    """One case in its own subprocess (replay, shrinking); crashes marked in the result."""
    out = run_process(unzipdir, [spec], limits)
    res = dict(out.results.get(spec["id"], {"id": spec["id"]}))
    if out.failed(1):
        res["crash"] = True
        res["crash_info"] = _crash_record(spec, out, "alone")
    return res


# ---------------------------------------------------------------------------- judging
def refusal_kind(res: dict[str, Any]) -> str | None:
    """None, "cross-parameter", "work-bound" or "declared-valid" (all drawn input is)."""
    ref = res.get("refusal")
    if not ref:
        return None
    text = " | ".join(ref.get("messages") or [])
    if CROSS_RE.search(text):
        return "cross-parameter"
    if ref.get("status") == 2 and ref.get("phase", "") != "init" and WORK_BOUND_RE.search(text):
        return "work-bound"
    return "declared-valid"


def violations(res: dict[str, Any], step_limit: float) -> list[str]:
    """The violation kinds of one case result (see VIOLATIONS)."""
    found = []
    if res.get("crash"):
        found.append("crash")
    if res.get("slow_step") or res.get("max_step_cpu", 0.0) > step_limit:
        found.append("over_step_limit")
    if res.get("nonfinite_ok"):
        found.append("nonfinite_ok")
    if refusal_kind(res) == "declared-valid":
        found.append("declared_valid_refusal")
    if res.get("outside"):
        found.append("outside_clearance")
    if res.get("mismatch") or res.get("api_errors"):
        found.append("state_roundtrip")
    return found


def normalise(text: str) -> str:
    """A message without its numbers and per-step prefix, to group like refusals."""
    text = re.sub(r"^do_step at t=\S+, h=\S+ failed: ", "", text)
    return NUMBER_RE.sub("#", text)[:160]


def signature(kind: str, res: dict[str, Any], spec: dict[str, Any]) -> str:
    """The cause group of one violation of a case."""
    if kind == "crash":
        info = res.get("crash_info") or {}
        return "crash: " + ("timeout" if info.get("timed_out") else f"rc={info.get('rc')}")
    if kind == "over_step_limit":
        return "slow step: " + _slow_features(res, spec)
    if kind == "nonfinite_ok":
        first = res["nonfinite_ok"][0]
        return f"non-finite at {first['phase'].split()[0]}: " + ",".join(first["names"][:6])
    if kind in ("declared_valid_refusal",):
        msgs = res["refusal"].get("messages") or ["(no message)"]
        return f"refused at {res['refusal']['phase'].split()[0]}: " + normalise(msgs[0])
    if kind == "outside_clearance":
        return "outside clearance at " + res["outside"]["phase"].split()[0]
    if res.get("api_errors"):
        return "state call failed: " + normalise(res["api_errors"][0])
    return "replay differs in: " + ",".join(res["mismatch"][0]["outputs"][:6])


def _slow_features(res: dict[str, Any], spec: dict[str, Any]) -> str:
    """Coarse features of a slow step: its size class and whether the spin is integrated."""
    h = (res.get("slow_step") or {}).get("h", math.nan)
    size = "h <= 1e-9 s" if h <= 1e-9 else "h < 0.1 s" if h < 0.1 else "h >= 0.1 s"
    spin = "integrate_spin" if spec["params"].get("integrate_spin") else "held spin"
    return f"{size}, {spin}"


# ---------------------------------------------------------------------------- shrinking
class Shrinker:
    """Greedy reduction of a failing spec that keeps the failure's signature: ops after
    the failing one cut, state round trips and mid-run sets dropped, earlier ops dropped,
    then a 1-minimal set of non-default parameters (ddmin), within a trial and time budget.
    Trials abandon a step just past the step limit (that is enough to reproduce it); a slow
    step must exceed SLOW_MARGIN times the limit, so that its reproducer stays slow on a
    less loaded machine."""

    def __init__(self, kind: str, sig: str, model: ModelInfo, unzipdir: str, limits: Limits,
                 trials: int, budget_s: float) -> None:
        self.kind, self.sig, self.model, self.unzipdir = kind, sig, model, unzipdir
        limit = limits.step_limit * (SLOW_MARGIN if kind == "over_step_limit" else 1.0)
        self.limits = Limits(limit, limit + 0.25, limits.timeout)
        self.trials, self.deadline, self.used = trials, time.perf_counter() + budget_s, 0

    def spent(self) -> bool:
        return self.used >= self.trials or time.perf_counter() >= self.deadline

    def still(self, spec: dict[str, Any]) -> bool:
        """Does the candidate still fail the same way? (False once the budget is spent.)"""
        if self.spent():
            return False
        self.used += 1
        res = run_one(self.unzipdir, spec, self.limits)
        return self.kind in violations(res, self.limits.step_limit) and \
            signature(self.kind, res, spec) == self.sig

    def run(self, spec: dict[str, Any]) -> dict[str, Any]:
        self.used += 1
        best = spec
        for cand in self._op_candidates(_truncate(spec, run_one(self.unzipdir, spec,
                                                                   self.limits))):
            if cand != best and self.still(cand):
                best = cand
        return self._params(best)

    def _op_candidates(self, spec: dict[str, Any]) -> list[dict[str, Any]]:
        ops = spec["ops"]
        bare = [{"h": op["h"]} for op in ops]
        return [spec, {**spec, "roundtrips": []},
                {**spec, "roundtrips": [], "ops": bare},
                {**spec, "roundtrips": [], "ops": bare[-1:]}]

    def _params(self, spec: dict[str, Any]) -> dict[str, Any]:
        """ddmin over the parameters that differ from their start values; the initial
        position and the clearance go together (alone, either could leave the disc)."""
        start = {k: self.model.vars[k].start for k in spec["params"]}
        changed = [k for k, v in spec["params"].items() if v != start[k]]
        coupled = [n for n in POSITION if n in changed]
        units = [[k] for k in changed if k not in coupled] + ([coupled] if coupled else [])

        def with_only(kept: list[list[str]]) -> dict[str, Any]:
            names = {k for unit in kept for k in unit}
            params = {k: (v if k in names else start[k]) for k, v in spec["params"].items()}
            return {**spec, "params": params}

        return with_only(ddmin(units, lambda kept: self.still(with_only(kept))))


def ddmin(items: list[Any], test: Any) -> list[Any]:
    """Zeller's delta debugging: a 1-minimal sublist for which test() holds (test(items)
    is assumed true)."""
    n = 2
    while len(items) >= 2:
        size = math.ceil(len(items) / n)
        chunks = [items[i:i + size] for i in range(0, len(items), size)]
        for chunk in chunks:
            if test(chunk):
                items, n = chunk, 2
                break
        else:
            for chunk in chunks:
                rest = [x for x in items if x not in chunk]
                if test(rest):
                    items, n = rest, max(n - 1, 2)
                    break
            else:
                if n >= len(items):
                    break
                n = min(len(items), 2 * n)
    if len(items) == 1 and test([]):
        return []
    return items


def _truncate(spec: dict[str, Any], res: dict[str, Any]) -> dict[str, Any]:
    """Drop the ops after the one that failed (when the result says which)."""
    last = None
    for key in ("slow_step", "outside", "abandoned"):
        if res.get(key) and "op" in res[key]:
            last = res[key]["op"]
    phase = (res.get("refusal") or {}).get("phase", "")
    if phase.split()[-1:] and phase.split()[-1].isdigit():
        last = int(phase.split()[-1])
    if phase == "init":
        last = -1
    if last is None:
        return spec
    n = last + 1
    windows = [[f, min(k, n - f), s] for f, k, s in spec.get("roundtrips", []) if f < n]
    return {**spec, "ops": spec["ops"][:max(n, 1)], "roundtrips": windows}


# ---------------------------------------------------------------------------- summary
def summarise(specs: list[dict[str, Any]], got: Collected, limits: Limits
              ) -> dict[str, Any]:
    """Counts, refusal kinds, and the failing cases grouped by cause."""
    counts = Counter({k: 0 for k in VIOLATIONS})
    refusals: Counter = Counter()
    groups: dict[str, dict[str, Any]] = {}
    by_id = {s["id"]: s for s in specs}
    for cid in sorted(got.results):
        res, spec = got.results[cid], by_id[cid]
        refusals[refusal_kind(res) or "none"] += 1
        for kind in violations(res, limits.step_limit):
            counts[kind] += 1
            sig = signature(kind, res, spec)
            g = groups.setdefault(sig, {"kind": kind, "signature": sig, "ids": []})
            g["ids"].append(cid)
    for crash in got.crashes:
        if crash["scope"] != "alone":  # no case of the batch crashes on its own
            counts["crash"] += 1
            sig = f"crash: {crash['scope']} (rc={crash['rc']}, timeout={crash['timed_out']})"
            groups.setdefault(sig, {"kind": "crash", "signature": sig, "ids": crash["ids"]})
    return {"counts": dict(counts), "refusal_kinds": dict(refusals),
            "groups": sorted(groups.values(), key=lambda g: (VIOLATIONS.index(g["kind"]),
                                                             -len(g["ids"])))}


def run_stats(got: Collected) -> dict[str, Any]:
    res = list(got.results.values())
    walls = [r.get("max_step_wall", 0.0) for r in res]
    cpus = [r.get("max_step_cpu", 0.0) for r in res]
    excess = [r["max_excess"] for r in res if r.get("max_excess") is not None]
    return {"steps": sum(len(r.get("statuses", [])) for r in res),
            "state_round_trips": sum(r.get("roundtrips", 0) for r in res),
            "completed_without_refusal": sum(1 for r in res if not r.get("refusal")
                                             and not r.get("slow_step")),
            "max_step_wall_s": max(walls, default=0.0),
            "max_step_cpu_s": max(cpus, default=0.0),
            "max_excess": max(excess, default=None),
            "batch_failures": got.batch_failures, "cases_rerun_alone": got.reruns}


def _compact(res: dict[str, Any]) -> dict[str, Any]:
    """A failing case's result for the JSON file, without its message log (the refusal
    keeps its own messages)."""
    return {k: v for k, v in res.items() if k not in ("id", "messages")}


def write_results(report: dict[str, Any], path: Path) -> None:
    """The report as JSON: the summary indented, one failing case per line."""
    head = {k: v for k, v in report.items() if k != "failing_cases"}
    lines = [json.dumps(c, separators=(",", ":")) for c in report["failing_cases"]]
    text = json.dumps(head, indent=1)[:-2] + ',\n "failing_cases": [\n'
    text += ",\n".join(lines) + "\n ]\n}\n"
    path.write_text(text, encoding="utf-8")


# ---------------------------------------------------------------------------- driver
@dataclass
class FuzzConfig:
    fmu: Path = DEFAULT_FMU
    cases: int = 3000
    seed: int = 1
    jobs: int = 2
    batch_size: int = 50
    limits: Limits = field(default_factory=Limits)
    shrink_trials: int = 0
    shrink_seconds: float = 300.0
    progress: bool = False


def fmu_digest(fmu: Path) -> str:
    return hashlib.sha256(fmu.read_bytes()).hexdigest()[:16]


def fuzz(cfg: FuzzConfig) -> dict[str, Any]:
    """Run the fuzz; return the report (summary, groups with reproducers, failing cases)."""
    from fmpy import extract

    model = load_model(cfg.fmu)
    specs = [draw_case(model, cfg.seed, i) for i in range(cfg.cases)]
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="fuzz_fmu_unzip_") as tmp:
        unzipdir = extract(str(cfg.fmu), unzipdir=tmp)
        got = Runner(unzipdir, cfg.limits, cfg.jobs, cfg.progress).run(specs, cfg.batch_size)
        wall = time.perf_counter() - t0
        report = summarise(specs, got, cfg.limits)
        _add_reproducers(report, specs, got, model, unzipdir, cfg)
    report.update(config={"fmu": str(cfg.fmu), "fmu_sha256_16": fmu_digest(cfg.fmu),
                          "cases": cfg.cases, "seed": cfg.seed, "jobs": cfg.jobs,
                          "batch_size": cfg.batch_size, **cfg.limits.__dict__,
                          "open_decades": OPEN_DECADES, "log_decades": LOG_DECADES},
                  wall_s=round(wall, 1), stats=run_stats(got), crashes=got.crashes,
                  failing_cases=_failing(specs, got, cfg.limits))
    return report


def _failing(specs: list[dict[str, Any]], got: Collected, limits: Limits) -> list[dict]:
    out = []
    for spec in specs:
        res = got.results.get(spec["id"], {})
        found = violations(res, limits.step_limit)
        if found:
            out.append({"violations": found, "spec": spec, "result": _compact(res)})
    return out


def _add_reproducers(report: dict[str, Any], specs: list[dict[str, Any]], got: Collected,
                     model: ModelInfo, unzipdir: str, cfg: FuzzConfig) -> None:
    """Each group's smallest case as its reproducer, shrunk (cfg.shrink_trials > 0) with
    the groups spread over cfg.jobs subprocess slots."""
    by_id = {s["id"]: s for s in specs}

    def reduce(g: dict[str, Any]) -> None:
        rep = min((by_id[i] for i in g["ids"]), key=lambda s: (len(s["ops"]), s["id"]))
        g["example_id"], g["n"] = rep["id"], len(g["ids"])
        g["ids"] = g["ids"][:40] + (["..."] if len(g["ids"]) > 40 else [])
        if cfg.shrink_trials > 0 and g["kind"] != "crash":
            shrinker = Shrinker(g["kind"], g["signature"], model, unzipdir, cfg.limits,
                                cfg.shrink_trials, cfg.shrink_seconds)
            rep = shrinker.run(rep)
            g["shrink_trials"] = shrinker.used
        g["reproducer"] = _reproducer(rep, model)

    with ThreadPoolExecutor(max_workers=max(1, cfg.jobs)) as pool:
        list(pool.map(reduce, report["groups"]))


def _reproducer(spec: dict[str, Any], model: ModelInfo) -> dict[str, Any]:
    """A spec as a reproducer: the parameters that differ from their start values first."""
    changed = {k: v for k, v in spec["params"].items() if v != model.vars[k].start}
    return {"spec": spec, "non_default": changed}


# ---------------------------------------------------------------------------- output
def count_table(report: dict[str, Any]) -> str:
    counts = report["counts"]
    lines = ["| count | value | required |", "|---|---|---|"]
    for k in VIOLATIONS:
        mark = "ok" if counts[k] == 0 else "**FAIL**"
        lines.append(f"| {_cell(VIOLATION_TITLES[k])} | {counts[k]} | 0 ({mark}) |")
    kinds = report["refusal_kinds"]
    for k in ("cross-parameter", "work-bound"):
        lines.append(f"| refusals: {k} (counted apart) | {kinds.get(k, 0)} | — |")
    return "\n".join(lines)


def group_table(report: dict[str, Any]) -> str:
    lines = ["| count | cases | cause | example | non-default parameters of the reproducer "
             "| steps h (s) |", "|---|---|---|---|---|---|"]
    for g in report["groups"]:
        repro = g["reproducer"]
        params = ", ".join(f"{k}={_fmt(v)}" for k, v in repro["non_default"].items())
        steps = ", ".join(_fmt_op(op) for op in repro["spec"]["ops"][:6])
        if len(repro["spec"]["ops"]) > 6:
            steps += f", … ({len(repro['spec']['ops'])} steps)"
        lines.append(f"| {g['kind']} | {g['n']} | {_cell(g['signature'])} | "
                     f"{g['example_id']} | {_cell(params) or '—'} | {steps} |")
    return "\n".join(lines)


def _fmt(v: Any) -> str:
    return f"{v:.6g}" if isinstance(v, float) else json.dumps(v)


def _fmt_op(op: dict[str, Any]) -> str:
    """A step as ``h`` or ``h (name=value set before it, ...)``."""
    sets = ", ".join(f"{k}={_fmt(v)}" for k, v in op.get("set", {}).items())
    return _fmt(op["h"]) + (f" ({sets})" if sets else "")


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def doc_block(report: dict[str, Any]) -> str:
    c, s = report["config"], report["stats"]
    head = (f"Latest run: {c['cases']} cases, seed {c['seed']}, {c['jobs']} jobs, batches of "
            f"{c['batch_size']}, step limit {c['step_limit']} s; FMU sha256 "
            f"`{c['fmu_sha256_16']}…`; wall time {report['wall_s']:.0f} s. "
            f"{s['steps']} doStep calls, {s['state_round_trips']} state round trips "
            f"replayed, longest doStep {s.get('max_step_cpu_s', math.nan):.3g} s CPU "
            f"({s['max_step_wall_s']:.3g} s wall), "
            f"max |z|/c_r − 1 = {_fmt(s['max_excess'])}.")
    return "\n\n".join([head, count_table(report), "Failing cases by cause "
                        "(`docs/fuzz_results.json` holds every failing case in full):",
                        group_table(report) if report["groups"] else "None."])


def print_summary(report: dict[str, Any]) -> None:
    print(count_table(report))
    print(f"\n{len(report['groups'])} cause groups; wall time {report['wall_s']:.0f} s")
    for g in report["groups"]:
        print(f"  {g['kind']:<24} {g['n']:>5}  {g['signature']}  (e.g. case {g['example_id']})")


def failed_counts(report: dict[str, Any]) -> list[str]:
    return [k for k in VIOLATIONS if report["counts"][k]]


# ---------------------------------------------------------------------------- CLI
def parse_args(argv: list[str]) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cases", type=int, default=3000)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--fmu", type=Path, default=DEFAULT_FMU)
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--batch-size", type=int, default=50)
    p.add_argument("--timeout", type=float, default=300.0,
                   help="wall-clock limit of one case (s): a batch is killed when the case "
                        "it runs takes longer")
    p.add_argument("--step-limit", type=float, default=5.0,
                   help="a single doStep longer than this (CPU time, s) is a violation")
    p.add_argument("--abandon", type=float, default=None,
                   help="abandon a doStep still running after this (CPU s, or 4x in wall "
                        "time; default limit + 0.5)")
    p.add_argument("--shrink-trials", type=int, default=60,
                   help="runs spent shrinking each cause group's example (0: none)")
    p.add_argument("--shrink-seconds", type=float, default=300.0)
    p.add_argument("--out", default=str(DEFAULT_OUT), help="results JSON ('' : none)")
    p.add_argument("--doc", default=str(DEFAULT_DOC), help="page with the fuzz block ('': none)")
    p.add_argument("--check", action="store_true", help="exit 1 unless every count is 0")
    p.add_argument("--replay", type=Path, help="re-run the reproducers of a results JSON")
    return p.parse_args(argv)


def replay(path: Path, fmu: Path, limits: Limits) -> int:
    """Re-run every group's reproducer of a results file; print what each does now."""
    from fmpy import extract

    report = json.loads(path.read_text(encoding="utf-8"))
    bad = 0
    with tempfile.TemporaryDirectory(prefix="fuzz_fmu_unzip_") as tmp:
        unzipdir = extract(str(fmu), unzipdir=tmp)
        for g in report["groups"]:
            res = run_one(unzipdir, g["reproducer"]["spec"], limits)
            found = violations(res, limits.step_limit)
            bad += bool(found)
            print(f"{g['signature']}\n  now: {found or 'passes'}; refusal: "
                  f"{(res.get('refusal') or {}).get('messages')}")
    return 1 if bad else 0


def main(argv: list[str]) -> int:
    args = parse_args(argv)
    limits = Limits(args.step_limit, args.abandon or args.step_limit + 0.5, args.timeout)
    if args.replay:
        return replay(args.replay, args.fmu, limits)
    cfg = FuzzConfig(args.fmu, args.cases, args.seed, args.jobs, args.batch_size, limits,
                     args.shrink_trials, args.shrink_seconds, progress=True)
    report = fuzz(cfg)
    print_summary(report)
    if args.out:
        write_results(report, Path(args.out))
        print(f"wrote {args.out}")
    if args.doc:
        with contextlib.suppress(ValueError):  # a page without the markers is left alone
            replace_block(Path(args.doc), "fuzz", doc_block(report))
            print(f"updated the fuzz block of {args.doc}")
    return 1 if args.check and failed_counts(report) else 0


if __name__ == "__main__":
    os.environ.setdefault("PYTHONHASHSEED", "0")
    sys.exit(main(sys.argv[1:]))
