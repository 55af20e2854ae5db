"""FMU-versus-reference validation: scene files, FMU runs through FMPy, errors, tolerances.

Used by tests/test_validation.py and docs/scripts/validation.py. The scenes and their
references live in models/scenes/ (written by tests/reference/make_references.py).

Units of every error: scaled (docs/model.md §1) -- positions in c_r, velocities in c_r Omega,
times in 1/Omega.

**Tolerance rule.** Every compared quantity q (an impact's time, position, velocity before
and after; the state (z, v) at a reference grid point; the end state) has a measured
amplification a_q: the largest scaled change of q when the initial state is perturbed by
1e-12 (scaled, 8 directions), divided by 1e-12 (``<Scene>_sens.json``). The tolerance is

    tol_q = max(1, a_q) * (TOL_UNIT + K_ROUND * eps * S_q),   TOL_UNIT = 1e-13, K_ROUND = 4,
    S_q = t_q/h + sum over the reference impacts j up to q of (1 + |v_j-|)/rdot_j-

(scaled units, h the communication step). Each term is an initial-state-equivalent error,
amplified at most like a start error:

* TOL_UNIT = 1e-13 (about 450 eps): the rounding of the start values and of the closed-form
  flight (a few eps each, docs/model.md §2);
* t_q/h: every communication step restarts the exact flight from a float64 state, so each
  step adds about one rounding of the state (the error therefore grows as h shrinks);
* (1 + |v|)/rdot per impact: the event-location limit of docs/model.md §3, eps c_r/rdot, with the
  flight's rounding scaled by the speed |v| (large in dry whirl, |v| ~ R Omega);
* K_ROUND = 4: "a small multiple" -- the largest ratio measured over all 11 scenes, 4 steps
  and both interfaces when the rule was set was 1.3 (docs/validation.md).

An impact that does not exist in every perturbed run (the impact count is not stable under a
1e-12 perturbation: the last impacts of a chattering cascade) has a_q = None: it is beyond
float64's reach and only reported; the impact count may then differ by as much as the
perturbed counts do.
"""

from __future__ import annotations

import csv
import json
import math
import os
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
SCENE_DIR = ROOT / "models" / "scenes"
RUNNER = Path(__file__).resolve().parent / "validation_runner.py"
STEPS = (1e-5, 1e-4, 1e-3, 1e-2)
"""Communication steps (s) of the full matrix."""
TOL_UNIT = 1e-13
"""Allowed initial-state-equivalent error (scaled), multiplied by the amplification."""
K_ROUND = 4.0
"""Multiple of eps per communication step and per impact conditioning (tolerance rule)."""
EPS = float(np.finfo(float).eps)
OUTPUTS = ("x", "y", "vx", "vy", "r_rel", "u_re", "u_im", "du_re", "du_im", "mode",
           "n_impacts")


# ------------------------------------------------------------------------------ scenes


@dataclass
class SceneData:
    """A scene's start values, experiment, references and sensitivity (SI in the files)."""

    name: str
    meta: dict[str, Any]
    ref: dict[str, np.ndarray]
    impacts: np.ndarray
    direct: dict[str, np.ndarray]
    direct_impacts: np.ndarray
    sens: dict[str, Any]

    @property
    def c_r(self) -> float:
        """Clearance (m)."""
        return float(self.meta["start_values"]["c_r"])

    @property
    def omega(self) -> float:
        """Spin speed (rad/s)."""
        return float(self.meta["Omega"])

    @property
    def stop(self) -> float:
        """Stop time (s)."""
        return float(self.meta["stop_time"])

    @property
    def input_file(self) -> Path | None:
        """<Scene>_in.csv if the scene has a varying input."""
        path = SCENE_DIR / f"{self.name}_in.csv"
        return path if path.exists() else None


def scene_names() -> list[str]:
    """Names of all committed scenes (one <Scene>_par.json each), in file order."""
    return sorted(p.name[: -len("_par.json")] for p in SCENE_DIR.glob("*_par.json"))


def read_table(path: Path) -> dict[str, np.ndarray]:
    """A CSV with a (quoted) header as a dict of float arrays."""
    with path.open() as fh:
        rows = list(csv.reader(fh))
    header = [h.strip('"') for h in rows[0]]
    data = np.array([[_num(x) for x in r] for r in rows[1:]], dtype=float).reshape(
        len(rows) - 1, len(header))
    return {h: data[:, j] for j, h in enumerate(header)}


def _num(text: str) -> float:
    """A CSV cell as float (True/False as 1/0)."""
    if text in ("True", "False"):
        return float(text == "True")
    return float(text)


def _impact_array(path: Path) -> np.ndarray:
    """Impacts CSV -> (n, 8) array t, x, y, vx-, vy-, vx+, vy+, rdot (SI)."""
    tab = read_table(path)
    cols = ["t" if "t" in tab else "time", "x", "y", "vx_minus", "vy_minus", "vx_plus",
            "vy_plus", "rdot"]
    if not len(tab[cols[0]]):
        return np.zeros((0, 8))
    return np.column_stack([tab[c] for c in cols])


def load_scene(name: str) -> SceneData:
    """Read every file of one scene."""
    meta = json.loads((SCENE_DIR / f"{name}_par.json").read_text())
    return SceneData(
        name=name, meta=meta, ref=read_table(SCENE_DIR / f"{name}_ref.csv"),
        impacts=_impact_array(SCENE_DIR / f"{name}_impacts.csv"),
        direct=read_table(SCENE_DIR / f"{name}_direct.csv"),
        direct_impacts=_impact_array(SCENE_DIR / f"{name}_direct_impacts.csv"),
        sens=json.loads((SCENE_DIR / f"{name}_sens.json").read_text()))


# ------------------------------------------------------------------------------ FMU runs


@dataclass
class FmuRun:
    """One FMU simulation through FMPy: result table, impact log, process outcome."""

    result: dict[str, np.ndarray] | None
    impacts: np.ndarray
    returncode: int
    stderr: str
    seconds: float


def _start_values(sc: SceneData, log: Path) -> dict[str, Any]:
    """FMU start values of the scene plus the impact log path."""
    return {**sc.meta["start_values"], "impact_log": str(log)}


def cli_command(fmu: Path, sc: SceneData, h: float, out: Path, log: Path) -> list[str]:
    """``fmpy simulate`` command line of one run (communication step = --output-interval)."""
    cmd = [sys.executable, "-m", "fmpy", "simulate", str(fmu), "--output-interval", repr(h),
           "--stop-time", repr(sc.stop), "--output-file", str(out), "--output-variables",
           *OUTPUTS, "--start-values"]
    for key, value in _start_values(sc, log).items():
        cmd += [key, value if isinstance(value, str) else cli_number(value)]
    if sc.input_file is not None:
        cmd += ["--input-file", str(sc.input_file)]
    return cmd


def cli_number(value: float) -> str:
    """Exact, exponent-free decimal of a float for the FMPy command line.

    argparse takes "-2.5e-05" for an option (its negative-number pattern has no exponent) and
    rejects the command; the positional form "-0.000025" round-trips exactly and is accepted.
    """
    return np.format_float_positional(float(value), unique=True, trim="-")


def api_command(fmu: Path, sc: SceneData, h: float, out: Path, log: Path) -> list[str]:
    """Command running ``fmpy.simulate_fmu`` in tests/validation_runner.py (own process)."""
    spec = {"fmu": str(fmu), "stop_time": sc.stop, "output_interval": h,
            "start_values": _start_values(sc, log), "output": list(OUTPUTS),
            "input_file": str(sc.input_file) if sc.input_file else None, "out": str(out)}
    return [sys.executable, str(RUNNER), json.dumps(spec)]


def run_fmu(fmu: Path, sc: SceneData, h: float, api: str, workdir: Path,
            timeout: float = 600.0) -> FmuRun:
    """Run the FMU for one scene and communication step ``h`` (s) in a subprocess.

    ``api``: "cli" (``python -m fmpy simulate``) or "api" (``fmpy.simulate_fmu``). A crash
    of the FMU ends only that process; the result is then ``None``.
    """
    import time

    tag = f"{sc.name}_{api}_{h:g}"
    out, log = workdir / f"{tag}.csv", workdir / f"{tag}_impacts.csv"
    for path in (out, log):
        if path.exists():
            path.unlink()
    make = cli_command if api == "cli" else api_command
    t0 = time.perf_counter()
    proc = subprocess.run(make(fmu, sc, h, out, log), capture_output=True, text=True,
                          timeout=timeout, cwd=str(workdir), env={**os.environ})
    secs = time.perf_counter() - t0
    result = read_table(out) if out.exists() and out.stat().st_size else None
    imps = _impact_array(log) if log.exists() else np.zeros((0, 8))
    return FmuRun(result, imps, proc.returncode, proc.stderr[-2000:], secs)


# ------------------------------------------------------------------------------ errors


@dataclass
class Comparison:
    """Scaled errors of one FMU run against the mp reference, with tolerances.

    ``imp_*``: per impact (time, position, velocity before, velocity after); ``grid``: max of
    position and velocity error at each compared reference grid point; ``end``: at the stop
    time. ``*_tol`` alongside (inf where the amplification is None). ``failures``: text.
    """

    scene: str
    h: float
    api: str
    t_final: float = math.nan
    n_fmu: int = 0
    n_ref: int = 0
    imp_t: np.ndarray = field(default_factory=lambda: np.zeros(0))
    imp_z: np.ndarray = field(default_factory=lambda: np.zeros(0))
    imp_v: np.ndarray = field(default_factory=lambda: np.zeros(0))
    imp_t_tol: np.ndarray = field(default_factory=lambda: np.zeros(0))
    imp_z_tol: np.ndarray = field(default_factory=lambda: np.zeros(0))
    imp_v_tol: np.ndarray = field(default_factory=lambda: np.zeros(0))
    grid: np.ndarray = field(default_factory=lambda: np.zeros(0))
    grid_tol: np.ndarray = field(default_factory=lambda: np.zeros(0))
    end: float = math.nan
    end_tol: float = math.nan
    discrete_mismatch: int = 0
    count_slack: int = 0
    seconds: float = 0.0
    failures: list[str] = field(default_factory=list)

    def worst_ratio(self) -> float:
        """Largest error/tolerance over everything compared (finite tolerances)."""
        ratios = [0.0]
        for e, t in ((self.imp_t, self.imp_t_tol), (self.imp_z, self.imp_z_tol),
                     (self.imp_v, self.imp_v_tol), (self.grid, self.grid_tol),
                     (np.array([self.end]), np.array([self.end_tol]))):
            ok = np.isfinite(t) & np.isfinite(e)
            if ok.any():
                ratios.append(float(np.max(e[ok] / t[ok])))
        return max(ratios)

    def summary(self) -> dict[str, Any]:
        """Headline numbers (max errors, max amplification-based tolerance, pass)."""
        return {"scene": self.scene, "h": self.h, "api": self.api, "n_fmu": self.n_fmu,
                "n_ref": self.n_ref, "t_final": self.t_final,
                "max_dt": _max(self.imp_t), "max_dz": _max(self.imp_z),
                "max_dv": _max(self.imp_v), "max_grid": _max(self.grid), "end": self.end,
                "end_tol": self.end_tol, "worst_ratio": self.worst_ratio(),
                "seconds": self.seconds, "pass": not self.failures,
                "failures": self.failures[:5]}


def _max(a: np.ndarray) -> float:
    """Max of an array (0 if empty)."""
    return float(np.max(a)) if len(a) else 0.0


def tolerance(amp: list[Any] | float | None, s: np.ndarray | float) -> np.ndarray:
    """The tolerance rule: max(1, a) (TOL_UNIT + K_ROUND eps S); inf where a is None."""
    arr = np.atleast_1d(np.array(amp, dtype=object))
    ss = np.broadcast_to(np.asarray(s, dtype=float), arr.shape)
    return np.array([math.inf if a is None else max(1.0, float(a)) * (
        TOL_UNIT + K_ROUND * EPS * si) for a, si in zip(arr, ss)])


def conditioning_sum(sc: SceneData) -> np.ndarray:
    """Cumulative sum over the reference impacts of (1 + |v-|)/rdot- (scaled)."""
    vs = sc.c_r * sc.omega
    if not len(sc.impacts):
        return np.zeros(0)
    vmag = np.hypot(sc.impacts[:, 3], sc.impacts[:, 4]) / vs
    return np.cumsum((1.0 + vmag) / (sc.impacts[:, 7] / vs))


def rounding_count(sc: SceneData, h: float, t: np.ndarray, n_imp: np.ndarray) -> np.ndarray:
    """S of the tolerance rule at times t (s) with n_imp reference impacts before or at t."""
    loc = np.concatenate([[0.0], conditioning_sum(sc)])
    return np.asarray(t) / h + loc[np.asarray(n_imp, dtype=int)]


def count_slack(sc: SceneData) -> int:
    """How much the impact count changed under the 1e-12 perturbations."""
    counts = sc.sens["counts"]
    return int(max(counts) - min(counts))


def crossed_cutoffs(sc: SceneData, imps: np.ndarray) -> int:
    """Reference low-speed decisions that the FMU's own speed error reaches across.

    For each reference impact j recorded near its cut-off speed v_stop (``cutoffs`` in the
    scene's reference: plastic iff rdot- <= v_stop), the decision is undetermined at the
    FMU's accuracy when |rdot_fmu_j - rdot_ref_j| >= |v_stop - rdot_ref_j|: the cascade may
    then end one impact later or earlier. The speed error itself is checked against its
    tolerance like every other impact quantity, so this admits only what that check admits.
    """
    n = 0
    for j, v_stop in sc.meta["reference"].get("cutoffs", []):
        if j < len(imps):
            rdot = sc.impacts[j, 7]
            n += abs(imps[j, 7] - rdot) >= abs(v_stop - rdot)
    return int(n)


def impact_errors(sc: SceneData, imps: np.ndarray, ref: np.ndarray) -> dict[str, np.ndarray]:
    """Scaled errors of matched impacts (by index): time, position, velocity -/+ (max)."""
    n = min(len(imps), len(ref))
    a, b = imps[:n], ref[:n]
    vs = sc.c_r * sc.omega
    dt = np.abs(a[:, 0] - b[:, 0]) * sc.omega
    dz = np.hypot(a[:, 1] - b[:, 1], a[:, 2] - b[:, 2]) / sc.c_r
    dvm = np.hypot(a[:, 3] - b[:, 3], a[:, 4] - b[:, 4]) / vs
    dvp = np.hypot(a[:, 5] - b[:, 5], a[:, 6] - b[:, 6]) / vs
    return {"t": dt, "z": dz, "vm": dvm, "vp": dvp}


def grid_errors(sc: SceneData, res: dict[str, np.ndarray], ref: dict[str, np.ndarray]
                ) -> tuple[np.ndarray, np.ndarray, int]:
    """Scaled state errors at the reference grid times present in ``res``.

    Returns (reference grid indices, max(|dz|/c_r, |dv|/(c_r Omega)) there, number of grid
    points where mode or n_impacts differ).
    """
    t_res = res["time"]
    idx_ref, idx_res = [], []
    for j, t in enumerate(ref["time"]):
        k = int(np.searchsorted(t_res, t - 1e-9))
        if k < len(t_res) and abs(t_res[k] - t) <= 1e-9:
            idx_ref.append(j)
            idx_res.append(k)
    jr, kr = np.array(idx_ref, dtype=int), np.array(idx_res, dtype=int)
    dz = np.hypot(res["x"][kr] - ref["x"][jr], res["y"][kr] - ref["y"][jr]) / sc.c_r
    dv = np.hypot(res["vx"][kr] - ref["vx"][jr], res["vy"][kr] - ref["vy"][jr]) / (
        sc.c_r * sc.omega)
    bad = int(np.sum((res["mode"][kr] != ref["mode"][jr])
                     | (res["n_impacts"][kr] != ref["n_impacts"][jr])))
    return jr, np.maximum(dz, dv), bad


def compare(sc: SceneData, run: FmuRun, h: float, api: str) -> Comparison:
    """Compare one FMU run with the mp reference; fill errors, tolerances and failures."""
    cmp = Comparison(sc.name, h, api, seconds=run.seconds)
    if run.result is None or not len(run.result["time"]):
        cmp.failures.append(f"no result (rc={run.returncode}): {run.stderr[-500:]}")
        return cmp
    res = run.result
    cmp.t_final = float(res["time"][-1])
    if abs(cmp.t_final - sc.stop) > 1e-9:
        cmp.failures.append(f"stopped at t={cmp.t_final} before {sc.stop} (fmi2Discard?)")
        return cmp
    slack = count_slack(sc) + crossed_cutoffs(sc, run.impacts)
    _compare_impacts(sc, run.impacts, cmp, h, slack)
    jr, err, bad = grid_errors(sc, res, sc.ref)
    s = rounding_count(sc, h, sc.ref["time"][jr], sc.ref["n_impacts"][jr])
    cmp.grid, cmp.grid_tol = err, tolerance([sc.sens["s"][j] for j in jr], s)
    cmp.discrete_mismatch = bad
    cmp.end, cmp.end_tol = float(err[-1]), float(cmp.grid_tol[-1])
    _check(cmp, "grid state", cmp.grid, cmp.grid_tol)
    if bad and not slack:
        cmp.failures.append(f"mode/n_impacts differ at {bad} grid points")
    return cmp


def _compare_impacts(sc: SceneData, imps: np.ndarray, cmp: Comparison, h: float,
                     slack: int) -> None:
    """Impact-by-impact part of :func:`compare`; ``slack``: the allowed count difference."""
    cmp.n_fmu, cmp.n_ref = len(imps), len(sc.impacts)
    cmp.count_slack = slack
    if abs(cmp.n_fmu - cmp.n_ref) > slack:
        cmp.failures.append(f"impact count {cmp.n_fmu} != reference {cmp.n_ref}")
    e = impact_errors(sc, imps, sc.impacts)
    n = len(e["t"])
    s = sc.sens
    rc = rounding_count(sc, h, sc.impacts[:n, 0], np.arange(1, n + 1))
    cmp.imp_t, cmp.imp_t_tol = e["t"], tolerance(s["t"][:n], rc)
    cmp.imp_z, cmp.imp_z_tol = e["z"], tolerance(s["z"][:n], rc)
    cmp.imp_v = np.maximum(e["vm"], e["vp"])
    amp_v = [None if a is None or b is None else max(a, b) for a, b in zip(s["vm"][:n],
                                                                          s["vp"][:n])]
    cmp.imp_v_tol = tolerance(amp_v, rc) if n else np.zeros(0)
    for label, err, tol in (("impact time", cmp.imp_t, cmp.imp_t_tol),
                            ("impact position", cmp.imp_z, cmp.imp_z_tol),
                            ("impact velocity", cmp.imp_v, cmp.imp_v_tol)):
        _check(cmp, label, err, tol)


def _check(cmp: Comparison, label: str, err: np.ndarray, tol: np.ndarray) -> None:
    """Append a failure for every error above its tolerance (or not finite)."""
    bad = np.nonzero(~(err <= tol))[0]
    for i in bad[:3]:
        cmp.failures.append(f"{label} #{i}: error {err[i]:.3e} > tol {tol[i]:.3e}")


def direct_errors(sc: SceneData) -> dict[str, float]:
    """Scaled differences direct integrator vs mp reference (impacts matched by index, grid,
    end): how well the two independent references agree."""
    e = impact_errors(sc, sc.direct_impacts, sc.impacts)
    d = {"time": sc.direct["time"], "x": sc.direct["x"], "y": sc.direct["y"],
         "vx": sc.direct["vx"], "vy": sc.direct["vy"], "mode": sc.direct["mode"],
         "n_impacts": np.zeros_like(sc.direct["time"])}
    _, err, _ = grid_errors(sc, d, {**sc.ref, "n_impacts": np.zeros_like(sc.ref["time"])})
    return {"n_direct": len(sc.direct_impacts), "n_ref": len(sc.impacts),
            "max_dt": _max(e["t"]), "max_dz": _max(e["z"]),
            "max_dv": _max(np.maximum(e["vm"], e["vp"])) if len(e["t"]) else 0.0,
            "max_grid": _max(err), "end": float(err[-1]) if len(err) else math.nan}
