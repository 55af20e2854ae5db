"""The bearing FMU run alone, fed the inputs a coupled run gave it (the equality check).

With a passive drivetrain (torque motor, ``motor = 0``, and no drag, ``b = 0``) the
drivetrain's ``T_drive`` does not depend on the spin, so a coupled run must equal
``RotorTouchdown`` run alone with the same held inputs, step by step, to round-off: the
coupling adds nothing but the one-step Jacobi delay of the torque.

:func:`jacobi_inputs` rebuilds the inputs the bearing held over each step of an engine's
run from what the engine recorded (a Jacobi master feeds the outputs recorded after step
k - 1 into step k; the first step gets the components' initial outputs, or 0 on FMPy's SSP
master, whose connectors start at 0). :func:`run_alone` steps the FMU with them on FMPy's
``FMU2Slave``. Run it in a subprocess (PythonFMU shares the host's interpreter):

    python -m rotortd_cosim.alone SCENE FMU RESULT.npz OUT.npz --step H [--fmpy | --ns-clock]

RESULT.npz is a coupled run of the scene (``python -m rotortd_cosim.run``); an unknown
scene is refused with a message listing the known ones (exit code 2).

Units: SI (s, rad/s, N, N m).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

import numpy as np

from .run import exit_after
from .scenes import ALL_SCENES, Scene

Result = dict[str, np.ndarray]
INPUTS: tuple[tuple[str, str], ...] = (
    ("T_drive", "Drivetrain.T_drive"), ("amb_on", "TouchdownEvents.amb_on"),
    ("F_x", "TouchdownEvents.F_x"), ("F_y", "TouchdownEvents.F_y"))
"""(bearing input, recorded output that feeds it)."""
OUTPUTS = ("Omega_out", "x", "y", "vx", "vy", "psi", "mode", "n_impacts", "T_f", "F_n",
           "F_bx", "F_by", "E_diss", "r_rel", "t_last_impact", "v_last_impact")
"""Bearing outputs the alone run records (as ``RotorTouchdown.<name>``)."""


def jacobi_inputs(res: Result, scene: Scene, zero_first: bool) -> dict[str, np.ndarray]:
    """The inputs the bearing held over each step of a recorded coupled run: step k gets
    the recorded row k - 1; step 0 the initial outputs (T_drive = 0 before any drivetrain
    step, the event schedule at t = 0) or 0 when the engine starts its connectors at 0."""
    ev = scene.events
    first = {"T_drive": 0.0, "amb_on": float(ev.get("amb_before", 1.0)),
             "F_x": 0.0, "F_y": 0.0}
    if ev.get("t_force_on", 1e30) <= 0.0 < ev.get("t_force_off", 1e30):
        first["F_x"], first["F_y"] = ev.get("F_x_step", 0.0), ev.get("F_y_step", 0.0)
    if ev.get("t_fail", 1e30) <= 0.0:
        first["amb_on"] = float(ev.get("amb_after", 0.0))
    out = {}
    for name, col in INPUTS:
        rec = np.asarray(res[col], float)
        out[name] = np.concatenate([[0.0 if zero_first else first[name]], rec[:-1]])
    return out


def run_alone(fmu: Path, scene: Scene, step: float, inputs: dict[str, np.ndarray],
              set_before_init: bool = True, ns_clock: bool = False) -> Result:
    """Step the RotorTouchdown FMU alone at communication step ``step`` [s] from the
    scene's start values, holding ``inputs[name][k]`` over step k; the recorded outputs
    after each step (columns ``time`` and ``RotorTouchdown.<output>``).

    set_before_init: the first step's inputs are also set before initialisation (as libcosim
    and ecos propagate the initial outputs); FMPy's SSP master initialises every component
    with its start values and sets connected inputs only before each step.
    ns_clock: the communication points and step sizes libcosim passes (see _clock)."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(str(fmu))
    var = {v.name: v for v in md.modelVariables}
    unzip = extract(str(fmu))
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzip,
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="alone")
    slave.instantiate()
    slave.setupExperiment(startTime=0.0)
    for name, value in scene.rotor.items():
        v = var[name]
        if v.type == "Boolean":
            slave.setBoolean([v.valueReference], [bool(value)])
        elif v.type == "Integer":
            slave.setInteger([v.valueReference], [int(value)])
        else:
            slave.setReal([v.valueReference], [float(value)])
    n = len(next(iter(inputs.values())))
    in_refs = [var[name].valueReference for name, _ in INPUTS]
    if set_before_init:
        slave.setReal(in_refs, [float(inputs[name][0]) for name, _ in INPUTS])
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    real = [o for o in OUTPUTS if var[o].type == "Real"]
    ints = [o for o in OUTPUTS if var[o].type == "Integer"]
    rrefs = [var[o].valueReference for o in real]
    irefs = [var[o].valueReference for o in ints]
    rows: dict[str, list[float]] = {c: [] for c in ["time", *real, *ints]}
    for k in range(n):
        slave.setReal(in_refs, [float(inputs[name][k]) for name, _ in INPUTS])
        try:
            t_k, h_k = _clock(k, step, ns_clock)
            slave.doStep(currentCommunicationPoint=t_k, communicationStepSize=h_k)
        except Exception as exc:
            raise RuntimeError(f"doStep {k} at t = {k * step!r} s failed: {exc}") from exc
        rows["time"].append((k + 1) * step)
        for o, val in zip(real, slave.getReal(rrefs)):
            rows[o].append(val)
        for o, val in zip(ints, slave.getInteger(irefs)):
            rows[o].append(float(val))
    slave.terminate()
    slave.freeInstance()
    return {("time" if c == "time" else f"RotorTouchdown.{c}"): np.asarray(v, float)
            for c, v in rows.items()}


def _clock(k: int, step: float, ns_clock: bool) -> tuple[float, float]:
    """(communication point, step size) [s] of step k. libcosim keeps time in integer
    nanoseconds and passes each step as the difference of its two time points converted
    to seconds, which differs from ``step`` by an ulp now and then."""
    if not ns_clock:
        return k * step, step
    n = round(step * 1e9)
    t0, t1 = k * n / 1e9, (k + 1) * n / 1e9
    return t0, t1 - t0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", choices=list(ALL_SCENES))
    parser.add_argument("fmu", type=Path)
    parser.add_argument("result", type=Path, help="a coupled run's .npz (rotortd_cosim.run)")
    parser.add_argument("out", type=Path)
    parser.add_argument("--step", type=float, required=True)
    parser.add_argument("--ns-clock", action="store_true",
                        help="the run came from libcosim (integer-nanosecond clock)")
    parser.add_argument("--fmpy", action="store_true",
                        help="the run came from FMPy's SSP master (connectors start at 0)")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    scene = ALL_SCENES[args.scene]
    res: Any = dict(np.load(args.result))
    inputs = jacobi_inputs(res, scene, args.fmpy)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    np.savez(args.out, **run_alone(args.fmu, scene, args.step, inputs,
                                   set_before_init=not args.fmpy,
                                   ns_clock=args.ns_clock))
    print(f"DONE {time.perf_counter() - t0:.2f}", flush=True)
    return 0


if __name__ == "__main__":
    exit_after(main)
