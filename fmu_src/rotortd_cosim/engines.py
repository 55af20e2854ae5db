"""Run a scene's SSP on one engine; every runner returns {column: numpy array}.

Columns: ``time`` (s, the communication point at the END of the step the values belong
to) and ``Component.variable`` for every recorded output (scenes.RECORDED). Each runner
loads PythonFMU FMUs into the calling process: run them in a subprocess
(``python -m rotortd_cosim.run``), never in a test process.

Engine differences handled here (see docs/cosimulation.md):
- FMPy ``simulate_ssp`` ignores the SSP's parameter bindings: the scene's values are passed
  as its ``parameter_set`` (names ``Component.var``, Python-typed: FMPy sets a Boolean as
  ``value != 0.0``, so the SSV text "false" would become true). It labels each row with the
  step's START time although the values are those after the step: shifted here by +h.
  Its connectors all start at 0.0, so in the first step the bearing sees Omega = 0,
  amb_on = 0, F = 0 whatever the upstream outputs are.
- libcosim counts time in integer nanoseconds: the step is passed as round(h * 1e9), and
  each doStep gets the difference of two time points converted to seconds (an ulp off h
  now and then: rotortd_cosim.alone._clock). Its step call returns False after a
  component's fmi2Discard, and the execution would go on with frozen outputs: refused.
  ecospy goes on after a Discard too, printing the error, and its step returns only the
  time: the runner cannot refuse it.
- ecos: the bundled binaries need chmod +x; the native CLI needs libtbb on LD_LIBRARY_PATH
  (the FMUs' own loader finds libpython: no LD_PRELOAD).
  Both ecospy and the CLI need libtbb.so.12: from the environment's ``tbb`` package,
  loaded by :func:`.tbb.load_libtbb` before ecospy is imported, and put on
  LD_LIBRARY_PATH for the CLI.
- libcosim applies the first parameter set of each component of the SSP, ecos the set
  named after the scene; neither says so when the SSP holds other values or none.
  :func:`run` therefore refuses an SSP that does not carry exactly the scene's parameters
  (:func:`check_ssp`), on every engine, with a :class:`SceneError`.
- Quiet unless asked: libcosim logs 90-odd debug lines per run at its default level; the
  runners set it to warnings (ecos likewise) unless ``verbose``.
"""

from __future__ import annotations

import csv
import os
import shutil
import stat
import subprocess
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from .scenes import ALL_SCENES, RECORDED, Scene
from .ssp import parameter_sets
from .tbb import load_libtbb

Result = dict[str, np.ndarray]
COLUMNS = [f"{c}.{v}" for c, v in RECORDED]


class SceneError(ValueError):
    """An unknown scene, or an SSP that does not carry the scene's parameters."""


def scene_named(name: str) -> Scene:
    """The scene called ``name``; SceneError listing the known scenes otherwise."""
    if name not in ALL_SCENES:
        raise SceneError(f"unknown scene {name!r}; the scenes are "
                         f"{', '.join(ALL_SCENES)}")
    return ALL_SCENES[name]


def _same_value(kind: str, text: str, value: Any) -> bool:
    """Whether an SSV value (element name, value text) is the scene's start value."""
    try:
        if kind == "Boolean":
            return text in ("true", "false") and (text == "true") == bool(value)
        if kind == "Integer":
            return int(text) == int(value)
        if kind == "Real":
            return float(text) == float(value)
    except ValueError:
        return False
    return text == str(value)


def ssp_mismatches(ssp: Path, scene: Scene) -> list[str]:
    """What keeps the engines from applying the scene's parameters from ``ssp``: per
    component, the first parameter set (libcosim applies it) must be named after the scene
    (ecos applies that name) and hold exactly the scene's values; a component without
    values must have no set. Empty when the SSP is the scene's."""
    sets = parameter_sets(ssp)
    problems = []
    for comp, values in scene.components().items():
        have = sets.get(comp, [])
        if not values:
            if have:
                problems.append(f"{comp} has parameter set {have[0][0]!r}, the scene none")
            continue
        if not have:
            problems.append(f"{comp} has no parameter set")
            continue
        name, params = have[0]
        if name != scene.name:
            problems.append(f"{comp}'s parameter set is {name!r}")
        differ = sorted(n for n in {*params, *values} if n not in params or n not in values
                        or not _same_value(*params[n], values[n]))
        if differ:
            problems.append(f"{comp} differs in {', '.join(differ)}")
    return problems


def check_ssp(ssp: Path, scene: Scene) -> None:
    """SceneError unless ``ssp`` exists and carries exactly the scene's parameters."""
    if not ssp.is_file():
        raise SceneError(f"{ssp}: no such SSP file (python -m rotortd_cosim.ssp "
                         f"{scene.name} writes models/systems/{scene.name}.ssp)")
    problems = ssp_mismatches(ssp, scene)
    if problems:
        raise SceneError(
            f"{ssp} does not carry the parameters of scene {scene.name!r} "
            f"({'; '.join(problems)}), and libcosim and ecos take them from the SSP: "
            f"write the scene's own with python -m rotortd_cosim.ssp {scene.name} "
            f"(models/systems/{scene.name}.ssp)")


def _steps(scene: Scene, step: float, stop: float | None) -> tuple[int, float]:
    stop_time = scene.stop_time if stop is None else stop
    return round(stop_time / step), stop_time


# ---------------------------------------------------------------------------- FMPy SSP
def fmpy_parameter_set(scene: Scene) -> Any:
    """The scene's start values as an FMPy ParameterSet (prefixed, Python-typed)."""
    from fmpy.ssp.ssd import Parameter, ParameterSet

    pset = ParameterSet(name=scene.name)
    for comp, values in scene.components().items():
        for name, value in values.items():
            par = Parameter(name=f"{comp}.{name}")
            par.value = value
            pset.parameters.append(par)
    return pset


def run_fmpy_ssp(ssp: Path, scene: Scene, step: float, stop: float | None = None,
                 verbose: bool = False) -> Result:
    """FMPy's fixed-step Jacobi SSP master (it logs nothing: ``verbose`` is not used)."""
    from fmpy.ssp.simulation import simulate_ssp

    _n, stop_time = _steps(scene, step, stop)
    res = simulate_ssp(str(ssp), stop_time=stop_time - 0.5 * step, step_size=step,
                       parameter_set=fmpy_parameter_set(scene))
    out: Result = {"time": np.asarray(res["time"], float) + step}
    for col in COLUMNS:
        out[col] = np.asarray(res[col], float)
    return out


# ---------------------------------------------------------------------------- libcosim
def run_libcosim(ssp: Path, scene: Scene, step: float, stop: float | None = None,
                 verbose: bool = False) -> Result:
    """libcosimpy (Open Simulation Platform) from the SSP; times in integer ns. Its log
    (debug level by default) is cut to warnings unless ``verbose``."""
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.DEBUG if verbose else CosimLogLevel.WARNING)

    n, _ = _steps(scene, step, stop)
    step_ns = round(step * 1e9)
    if step_ns <= 0 or abs(step_ns - step * 1e9) > 1e-6 * step * 1e9:
        raise ValueError(f"step {step!r} s is not a whole number of nanoseconds")
    ex = CosimExecution.from_ssp_file(str(ssp), step_size=step_ns)
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    index, refs = _libcosim_refs(ex)
    rows: dict[str, list[float]] = {c: [] for c in ["time", *COLUMNS]}
    for k in range(n):
        if not ex.step(1):  # a component's fmi2Discard; libcosim would go on silently
            raise RuntimeError(f"libcosim: step {k} at t = {k * step_ns * 1e-9!r} s failed "
                               f"(a component returned fmi2Discard or worse)")
        rows["time"].append((k + 1) * step_ns * 1e-9)
        for col in COLUMNS:
            comp, _var = col.split(".")
            vref, kind = refs[col]
            if kind == CosimVariableType.INTEGER.value:
                val = obs.last_integer_values(index[comp], [vref])[0]
            else:
                val = obs.last_real_values(index[comp], [vref])[0]
            rows[col].append(float(val))
    ex.stop()
    return {k: np.asarray(v, float) for k, v in rows.items()}


def _libcosim_refs(ex: Any) -> tuple[dict[str, int], dict[str, tuple[int, int]]]:
    index = {c: ex.slave_index_from_instance_name(c) for c, _ in RECORDED}
    refs: dict[str, tuple[int, int]] = {}
    for comp, idx in index.items():
        for var in ex.slave_variables(idx):
            name = var.name.decode() if isinstance(var.name, bytes) else var.name
            if f"{comp}.{name}" in COLUMNS:
                refs[f"{comp}.{name}"] = (var.reference, var.type)
    return index, refs


# ---------------------------------------------------------------------------- ecos
def ecos_binaries() -> Path:
    """The ecospy binaries folder, with the executables made executable (chmod +x)."""
    import importlib.util

    spec = importlib.util.find_spec("ecospy")
    assert spec is not None and spec.origin is not None
    folder = Path(spec.origin).parent / "binaries"
    for exe in ("ecos", "proxyfmu"):
        path = folder / exe
        if path.exists() and not os.access(path, os.X_OK):
            path.chmod(path.stat().st_mode | stat.S_IXUSR | stat.S_IXGRP | stat.S_IXOTH)
    return folder


def run_ecospy(ssp: Path, scene: Scene, step: float, stop: float | None = None,
               verbose: bool = False) -> Result:
    """ecospy (Python binding of ecos) from the SSP; its log at warnings unless
    ``verbose`` (then debug)."""
    ecos_binaries()
    load_libtbb()
    from ecospy import EcosSimulation
    from ecospy.lib import EcosLib

    EcosLib.set_log_level("debug" if verbose else "warn")

    n, _ = _steps(scene, step, stop)
    rows: dict[str, list[float]] = {c: [] for c in ["time", *COLUMNS]}
    with EcosSimulation(ssp_path=str(ssp), step_size=step) as sim:
        sim.init(parameter_set=scene.name)
        for k in range(n):
            sim.step(1)
            rows["time"].append((k + 1) * step)
            for col in COLUMNS:
                comp, var = col.split(".")
                ident = f"{comp}::{var}"
                val = sim.get_integer(ident) if var in ("mode", "n_impacts") \
                    else sim.get_real(ident)
                rows[col].append(float(val))
        sim.terminate()
    return {k: np.asarray(v, float) for k, v in rows.items()}


def ecos_cli_env() -> dict[str, str]:
    """The environment for the native ecos CLI: the environment's libtbb directory first on
    LD_LIBRARY_PATH. No LD_PRELOAD: the FMUs' loader finds a libpython itself
    (docs/fmu.md "Native hosts")."""
    env = dict(os.environ)
    env.pop("LD_PRELOAD", None)
    lib = load_libtbb()
    if lib is not None:
        paths = [str(lib.parent), *filter(None, env.get("LD_LIBRARY_PATH", "").split(":"))]
        env["LD_LIBRARY_PATH"] = ":".join(dict.fromkeys(paths))
    return env


def ecos_cli_command(ssp: Path, scene: Scene, step: float, stop: float,
                     verbose: bool = False) -> list[str]:
    """The native ecos command line for a scene (see docs/cosimulation.md); it writes
    <ssp stem>.csv with every variable into the working directory."""
    exe = ecos_binaries() / "ecos"
    return [str(exe), "simulate", "--path", str(ssp), "--stopTime", repr(stop),
            "--stepSize", repr(step), "--parameterSet", scene.name,
            "--logLevel", "debug" if verbose else "warn"]


def run_ecos_cli(ssp: Path, scene: Scene, step: float, stop: float | None = None,
                 verbose: bool = False) -> Result:
    """The native ecos CLI, in the environment of :func:`ecos_cli_env`, in a temporary
    working directory (it writes its CSV there); its output is shown if ``verbose``."""
    n, _ = _steps(scene, step, stop)
    work = Path(tempfile.mkdtemp(prefix="rotortd_ecos_"))
    try:
        env = ecos_cli_env()
        # ecos accumulates t += h in floating point and stops before a stop time it
        # would overshoot by round-off: ask for half a step more, keep n rows
        cmd = ecos_cli_command(ssp.resolve(), scene, step, (n + 0.5) * step, verbose)
        proc = subprocess.run(cmd, cwd=work, env=env, capture_output=True, text=True,
                              timeout=1800)
        if verbose:
            print(proc.stdout + proc.stderr, end="", flush=True)
        path = work / f"{ssp.stem}.csv"
        if proc.returncode != 0 or not path.exists():
            raise RuntimeError(f"ecos failed ({proc.returncode}): {proc.stdout[-2000:]}"
                               f"{proc.stderr[-2000:]}")
        return {k: v[:n] for k, v in _read_ecos_csv(path).items()}
    finally:
        shutil.rmtree(work, ignore_errors=True)


def _read_ecos_csv(path: Path) -> Result:
    """The recorded columns of an ecos CSV (header 'Comp::var[TYPE]'), without the row of
    the initial values at t = 0."""
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    head = [h.strip().split("[")[0].replace("::", ".") for h in rows[0]]
    wanted = {"time": head.index("time")}
    wanted.update({c: head.index(c) for c in COLUMNS})
    body = [r for r in rows[1:] if r and float(r[wanted["time"]]) > 0.0]
    return {k: np.array([float(r[i]) for r in body]) for k, i in wanted.items()}


ENGINES = {"fmpy": run_fmpy_ssp, "libcosim": run_libcosim, "ecospy": run_ecospy,
           "ecos": run_ecos_cli}


def run(engine: str, scene: str, ssp: Path, step: float | None = None,
        stop: float | None = None, verbose: bool = False) -> Result:
    """Run a scene on an engine, from an SSP that carries the scene's parameters (else
    SceneError, as for an unknown scene or engine); quiet unless ``verbose``."""
    if engine not in ENGINES:
        raise SceneError(f"unknown engine {engine!r}; the engines are {', '.join(ENGINES)}")
    sc = scene_named(scene)
    check_ssp(ssp, sc)
    return ENGINES[engine](ssp, sc, sc.step if step is None else step, stop, verbose)
