"""System-level co-simulation: RotorTouchdown + Drivetrain + TouchdownEvents from SSP files.

Every engine run happens in a subprocess (``python -m rotortd_cosim.run``): PythonFMU FMUs
share the host's interpreter and can crash it at exit. Quick group: FMPy's SSP master,
libcosimpy and ecospy on the three scenes; slow group: the native ecos CLI and the
integrate_spin coupling check. ecospy and the CLI need libtbb.so.12, from the tbb package of
the test extra (rotortd_cosim.tbb loads it in the engine's process).
"""

from __future__ import annotations

import importlib.util
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "fmu_src"))

import rotortd  # noqa: E402
from rotortd_cosim.scenes import DROP, FORCE, RUNDOWN, T_FAIL  # noqa: E402
from rotortd_drive import MOTOR_PI, DriveCore, DriveParams  # noqa: E402

J = 0.04


@pytest.fixture(scope="module")
def systems(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Build the three FMUs (unchecked: build.py's validation runs elsewhere) and SSPs."""
    sys.path.insert(0, str(ROOT))
    from rotortd_cosim.ssp import write_all

    import build

    out = tmp_path_factory.mktemp("cosim")
    build.build_all(out, check=False)
    write_all(out, out / "systems")
    return out / "systems"


def run_engine(systems: Path, engine: str, scene: str, stop: float | None = None,
               step: float | None = None, timeout: float = 300.0) -> dict[str, np.ndarray]:
    """Run an engine on a scene in a subprocess; the result's columns as arrays."""
    out = systems / f"{engine}_{scene}_{stop}_{step}.npz"
    cmd = [sys.executable, "-m", "rotortd_cosim.run", engine, scene,
           str(systems / f"{scene}.ssp"), str(out)]
    cmd += ["--stop", repr(stop)] if stop is not None else []
    cmd += ["--step", repr(step)] if step is not None else []
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout,
                          cwd=ROOT, env=_env())
    assert proc.returncode == 0 and "DONE" in proc.stdout, proc.stdout[-3000:] + \
        proc.stderr[-3000:]
    return dict(np.load(out))


def _env() -> dict[str, str]:
    import os

    path = os.pathsep.join([str(ROOT / "fmu_src"), os.environ.get("PYTHONPATH", "")])
    return dict(os.environ, PYTHONPATH=path)


def _check_reached(res: dict[str, np.ndarray], stop: float, step: float) -> None:
    assert len(res["time"]) == round(stop / step)
    assert res["time"][-1] == pytest.approx(stop, abs=1e-9)


# ---------------------------------------------------------------------------- physics checks
def momentum_residuals(res: dict[str, np.ndarray], step: float, omega0: float
                       ) -> tuple[float, float]:
    """(a) J (Omega - Omega0) - (H_motor + H_drag + H_bearing) at the end [N m s];
    (b) H_bearing at the end minus the sum of the T_f the bearing reported, h T_f,k over
    all steps but the last (the Jacobi master feeds step k's T_f into step k+1) [N m s]."""
    d = "Drivetrain."
    h_tot = res[d + "H_motor"][-1] + res[d + "H_drag"][-1] + res[d + "H_bearing"][-1]
    a = J * (res[d + "Omega"][-1] - omega0) - h_tot
    b = res[d + "H_bearing"][-1] - step * math.fsum(res["RotorTouchdown.T_f"][:-1])
    return a, b


def first_impact_reference(res: dict[str, np.ndarray], step: float, g: float = 9.81
                           ) -> tuple[float, float]:
    """First impact after the failure from the state recorded at t = T_FAIL, by the
    core's exact a = 0 flight (gravity + imbalance) with the recorded spin held per step.
    Returns (time [s], rdot- [m/s])."""
    k = round(T_FAIL / step) - 1                  # row at t = T_FAIL
    assert res["time"][k] == pytest.approx(T_FAIL, abs=1e-12)
    r = "RotorTouchdown."
    z0 = complex(res[r + "x"][k], res[r + "y"][k])
    v0 = complex(res[r + "vx"][k], res[r + "vy"][k])
    core = rotortd.TouchdownCore(rotortd.RotorParams(g=g), z0=z0, v0=v0,
                                 psi0=float(res[r + "psi"][k]), t0=T_FAIL)
    omegas = res["Drivetrain.Omega"]
    for j in range(k, len(omegas) - 1):
        rep = core.step(step, float(omegas[j]), amb_on=0.0)
        if rep.impacts:
            imp = rep.impacts[0]
            return imp.t, imp.rdot
    raise AssertionError("no impact in the reference flight")


def engine_first_impact(res: dict[str, np.ndarray]) -> tuple[float, float]:
    """(time, rdot-) of the first impact an engine run reports."""
    n = res["RotorTouchdown.n_impacts"]
    k = int(np.argmax(n >= 1))
    assert n[k] >= 1
    return float(res["RotorTouchdown.t_last_impact"][k]), float(
        res["RotorTouchdown.v_last_impact"][k])


# ---------------------------------------------------------------------------- drivetrain
def test_drivetrain_exact_for_held_torque_any_step() -> None:
    """Torque motor with drag: closed form for any step, momentum balance to round-off."""
    p = DriveParams(b=0.06)
    ref = 200.0 * math.exp(-p.b / p.J * 0.5) + (-3.0 / p.b) * -math.expm1(-p.b / p.J * 0.5)
    for h in (0.5, 1e-2, 1e-4):
        core = DriveCore(p, 200.0)
        for _ in range(round(0.5 / h)):
            core.step(h, T_bearing=-1.0, T_in=-2.0)
        assert core.Omega == pytest.approx(ref, rel=1e-12)
        assert p.J * (core.Omega - 200.0) == pytest.approx(
            core.H_motor + core.H_drag + core.H_bearing, abs=1e-11)


def test_drivetrain_pi_saturation_is_step_independent() -> None:
    """Limited PI run-up: the piecewise-exact steps agree for h = 0.1 ... 1e-3 s."""
    p = DriveParams(motor=MOTOR_PI, b=1e-3)
    finals = []
    for h in (0.1, 1e-2, 1e-3):
        core = DriveCore(p, 0.0)
        for _ in range(round(20 / h)):
            core.step(h, -1.0, 0.0, 100.0)
        finals.append((core.Omega, core.I, core.psi))
        assert p.J * core.Omega == pytest.approx(
            core.H_motor + core.H_drag + core.H_bearing, abs=1e-10)
    for other in finals[1:]:
        assert other == pytest.approx(finals[0], rel=1e-10, abs=1e-10)


# ---------------------------------------------------------------------------- scene 1: drop
DROP_STOP = 0.14


@pytest.mark.parametrize("engine", ["fmpy", "libcosim", "ecospy"])
def test_drop_scene_physics(systems: Path, engine: str) -> None:
    """Failure at 0.1 s: first impact = exact a = 0 flight from the state at failure;
    momentum balance closes; the impacts spin the drivetrain down."""
    h = DROP.step
    res = run_engine(systems, engine, "drop", stop=DROP_STOP)
    _check_reached(res, DROP_STOP, h)
    t_ref, v_ref = first_impact_reference(res, h)
    t_eng, v_eng = engine_first_impact(res)
    assert t_eng > T_FAIL
    assert t_eng == pytest.approx(t_ref, abs=1e-9)
    assert v_eng == pytest.approx(v_ref, rel=1e-6)
    a, b = momentum_residuals(res, h, DROP.drive["Omega0"])
    assert abs(a) < 1e-11 and abs(b) < 1e-11
    assert res["Drivetrain.Omega"][-1] < DROP.drive["Omega0"] - 1.0


def test_drop_engines_agree(systems: Path) -> None:
    """libcosim and ecospy agree to round-off; FMPy differs from its first step (connected
    inputs start at 0: Omega = amb_on = 0 for 0.1 ms) by a small, measured amount."""
    lc = run_engine(systems, "libcosim", "drop", stop=DROP_STOP)
    ec = run_engine(systems, "ecospy", "drop", stop=DROP_STOP)
    fm = run_engine(systems, "fmpy", "drop", stop=DROP_STOP)
    for col in ("Drivetrain.Omega", "RotorTouchdown.x", "RotorTouchdown.T_f"):
        scale = max(1.0, float(np.max(np.abs(lc[col]))))
        assert np.max(np.abs(lc[col] - ec[col])) <= 1e-9 * scale, col
    k = round(T_FAIL / DROP.step) - 1
    c_r = 0.7e-3
    dz = abs(complex(fm["RotorTouchdown.x"][k] - lc["RotorTouchdown.x"][k],
                     fm["RotorTouchdown.y"][k] - lc["RotorTouchdown.y"][k]))
    assert 0.0 < dz < 3e-2 * c_r           # measured 1.4e-2 c_r (docs/cosimulation.md)
    assert engine_first_impact(fm)[0] == pytest.approx(engine_first_impact(lc)[0], abs=2e-4)


# ---------------------------------------------------------------------------- scene 2: rundown
@pytest.mark.parametrize("engine", ["fmpy", "libcosim"])
def test_rundown_impacts_appear_and_vanish(systems: Path, engine: str) -> None:
    """Coasting from 220 rad/s through 140 rad/s: impacts (and rub) appear near the
    critical speed and vanish below it; the spin-down rate is (T_f - b Omega)/J in every
    mode, in particular while sliding."""
    h, stop = RUNDOWN.step, RUNDOWN.stop_time
    res = run_engine(systems, engine, "rundown")
    _check_reached(res, stop, h)
    om, n = res["Drivetrain.Omega"], res["RotorTouchdown.n_impacts"]
    mode, tf = res["RotorTouchdown.mode"], res["RotorTouchdown.T_f"]
    hit = np.nonzero(np.diff(n) > 0)[0] + 1
    assert len(hit) > 5
    assert om[hit[0]] > 140.0 and om[hit[-1]] < 200.0
    assert n[-1] == n[int(0.8 * len(n))] and mode[-1] == 0     # gone at the end
    assert np.any(mode == 1)                                   # rub in between
    # spin-down rate: J dOmega/dt = T_f(previous step) + T_drag, exact per step
    dw = np.diff(om) / h
    b = RUNDOWN.drive["b"]
    drag = -b * 0.5 * (om[1:] + om[:-1])                      # mean of a near-linear decay
    pred = (tf[:-1] + drag) / J
    sliding = mode[1:] == 1
    assert np.count_nonzero(sliding) > 100
    assert np.max(np.abs(dw[sliding] - pred[sliding])) < 1e-4 * np.max(np.abs(pred))
    a, c = momentum_residuals(res, h, RUNDOWN.drive["Omega0"])
    assert abs(a) < 1e-10 and abs(c) < 1e-10


# ---------------------------------------------------------------------------- scene 3: force
@pytest.mark.parametrize("engine", ["fmpy", "libcosim"])
def test_force_step_pushes_into_bearing_and_releases(systems: Path, engine: str) -> None:
    """-1500 N in y from 0.03 s to 0.1 s: contact (impacts or rub) only while it acts;
    friction brakes the spin against the PI controller, which then recovers."""
    h, stop = FORCE.step, FORCE.stop_time
    res = run_engine(systems, engine, "force")
    _check_reached(res, stop, h)
    t, n = res["time"], res["RotorTouchdown.n_impacts"]
    fn = res["RotorTouchdown.F_n"]
    before = t <= 0.03
    assert n[before][-1] == 0
    during = (t > 0.03) & (t <= 0.11)
    assert n[during][-1] > 0 or np.any(fn[during] > 0)
    after = t > 0.33
    assert np.all(np.diff(n[after]) == 0) and np.all(res["RotorTouchdown.mode"][after] == 0)
    om = res["Drivetrain.Omega"]
    assert om[during].min() < FORCE.drive["Omega0"] - 0.5
    assert abs(om[-1] - FORCE.drive["Omega0"]) < abs(om[during].min() - FORCE.drive["Omega0"])
    a, c = momentum_residuals(res, h, FORCE.drive["Omega0"])
    assert abs(a) < 1e-10 and abs(c) < 1e-10


# ---------------------------------------------------------------------------- slow group
@pytest.mark.slow
def test_ecos_cli_matches_libcosim(systems: Path) -> None:
    """The native ecos CLI (LD_PRELOAD of libpython) runs the drop SSP; its CSV carries
    about 6 significant digits, so it agrees with libcosim to that precision."""
    if importlib.util.find_spec("ecospy") is None:  # not imported here: no native code
        pytest.skip("ecospy is not installed")
    ec = run_engine(systems, "ecos", "drop", stop=DROP_STOP)
    lc = run_engine(systems, "libcosim", "drop", stop=DROP_STOP)
    _check_reached(ec, DROP_STOP, DROP.step)
    assert np.array_equal(ec["RotorTouchdown.n_impacts"], lc["RotorTouchdown.n_impacts"])
    for col in ("Drivetrain.Omega", "RotorTouchdown.r_rel"):
        assert np.max(np.abs(ec[col] - lc[col]) / np.maximum(1.0, np.abs(lc[col]))) < 1e-5


@pytest.mark.slow
def test_integrate_spin_momentum_exact(systems: Path) -> None:
    """Bearing alone with integrate_spin, AMB off from the start under gravity (falls,
    impacts, dry whip): J (Omega_out - Omega0) = sum of h (T_drive + T_f) to round-off."""
    code = (
        "import json, math, numpy as np\n"
        "from fmpy import simulate_fmu\n"
        f"r = simulate_fmu(r'{systems.parent / 'RotorTouchdown.fmu'}', stop_time=0.03,\n"
        "    output_interval=1e-4, start_values={'g': 9.81, 'amb_on': 0.0,\n"
        "    'integrate_spin': True, 'J': 0.04, 'h_spin': 1e-5, 'T_drive': 2.0},\n"
        "    output=['Omega_out', 'T_f', 'mode'])\n"
        "res = 0.04 * (r['Omega_out'][-1] - 184.2) - 1e-4 * math.fsum(2.0 + r['T_f'][1:])\n"
        "print('RES', json.dumps([res, float(r['time'][-1]), float(r['Omega_out'][-1])]))\n"
        "import os; os._exit(0)\n")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=600, env=_env())
    line = [x for x in proc.stdout.splitlines() if x.startswith("RES")]
    assert line, proc.stdout[-2000:] + proc.stderr[-2000:]
    import json

    res, t_end, om = json.loads(line[0][3:])
    assert t_end == pytest.approx(0.03)
    assert abs(res) < 1e-11
    assert om < 184.2


def _drivetrain_slave(**params: float) -> object:
    from Drivetrain import Drivetrain

    slave = Drivetrain(instance_name="guard")
    for name, value in params.items():
        setattr(slave, name, value)
    slave.setup_experiment(0.0, None, None)
    slave.enter_initialization_mode()
    return slave


def _error_messages(slave: object) -> list[str]:
    from pythonfmu.enums import Fmi2Status

    return [m.msg for m in slave.log_queue if m.status == Fmi2Status.error]


def test_drivetrain_errors_are_logged_and_refused_not_raised() -> None:
    """The shared guard (rotortd_fmi.guard): a bad parameter fails initialisation and a bad
    input fails its step, each with a named message and fmi2Discard, and every later step
    is refused; a good step returns True."""
    bad = _drivetrain_slave(J=-1.0)
    assert bad.exit_initialization_mode() is False
    assert bad.do_step(0.0, 1e-3) is False
    assert any("J=-1.0" in m for m in _error_messages(bad))
    good = _drivetrain_slave()
    assert good.exit_initialization_mode() is True
    assert good.do_step(0.0, 1e-3) is True
    good.T_bearing = math.nan
    assert good.do_step(1e-3, 1e-3) is False
    assert good.do_step(2e-3, 1e-3) is False
    msgs = _error_messages(good)
    assert "T_bearing=nan" in msgs[-2] and msgs[-1].startswith("do_step refused")
