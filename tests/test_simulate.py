"""``rotortd simulate`` (fmu_src/rotortd_tools/simulate.py), run as a user runs it, in a
subprocess: a good run writes the CSV ``fmpy simulate`` writes and exits 0; bad names and
values are refused before the run with exit status 2 and a message naming them; a run the
FMU refuses exits 1 saying when and why; long runs print progress lines."""

from __future__ import annotations

import io
import os
import subprocess
import sys
from pathlib import Path

import pytest
from rotortd_tools.simulate import Progress, UsageError, parse_start_values

ROOT = Path(__file__).resolve().parent.parent


def _simulate(fmu: Path, *args: str, cwd: Path, env: dict[str, str] | None = None,
              ) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "rotortd_tools.cli", "simulate", str(fmu),
                           *args], capture_output=True, text=True, timeout=300,
                          cwd=str(cwd), env={**os.environ, **(env or {})})


def test_good_run_writes_fmpy_csv_and_exits_0(fmu_path: Path, tmp_path: Path) -> None:
    """The CSV reaches the stop time and equals, byte for byte, what fmpy simulate writes
    for the same options; nothing goes to stderr."""
    opts = ["--stop-time", "0.01", "--output-interval", "1e-3",
            "--start-values", "g", "9.81", "amb_on", "0", "levitate", "false"]
    proc = _simulate(fmu_path, *opts, "--output-file", "ours.csv", cwd=tmp_path)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr[-2000:]
    ref = subprocess.run([sys.executable, "-m", "fmpy", "simulate", str(fmu_path), *opts,
                          "--output-file", "fmpy.csv"], capture_output=True, text=True,
                         timeout=300, cwd=str(tmp_path))
    assert ref.returncode == 0, ref.stderr[-2000:]
    ours = (tmp_path / "ours.csv").read_text()
    assert ours == (tmp_path / "fmpy.csv").read_text()
    rows = ours.splitlines()
    assert rows[0].startswith('"time","x","y"') and len(rows) == 12
    assert float(rows[-1].split(",")[0]) == pytest.approx(0.01, abs=1e-15)
    assert float(rows[-1].split(",")[2]) < 0.0  # it fell: the start values were applied


@pytest.mark.parametrize(("values", "says"), [
    (["mass", "50"], "--start-values: no variable 'mass' in this FMU; did you mean m (Rotor mass)"),
    (["m", "heavy"], "--start-values: m = 'heavy' is not a Real value in kg"),
    (["d", "2"], "--start-values: d = 2 is out of range: it must lie in [0, 1]"),
    (["c_r", "1e-9"], "c_r = 1e-9 m is out of range: it must lie in [1e-06, 0.1] m"),
    (["integrate_spin", "yes"], "integrate_spin = 'yes' is not a Boolean (true, false, 1 or 0)"),
    (["x", "1"], "x is an output (continuous): only parameters and inputs can be set"),
    (["race_turns", "true"], "race_turns: the real bearing (docs/model.md §10) needs the spin "
     "as a state: add --start-values integrate_spin true"),
    (["integrate_spin", "true", "support_compliant", "false", "k_b", "1e8"],
     "k_b has no effect with support_compliant off"),
])
def test_bad_start_values_exit_2_before_the_run(fmu_path: Path, tmp_path: Path,
                                                values: list[str], says: str) -> None:
    proc = _simulate(fmu_path, "--start-values", *values, "--output-file", "out.csv",
                     cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr[-2000:]
    assert says in proc.stderr and proc.stderr.startswith("rotortd simulate: error: ")
    assert len(proc.stderr.splitlines()) == 1
    assert not (tmp_path / "out.csv").exists()


def test_work_bound_stop_exits_1_saying_when_and_why(fmu_path: Path, tmp_path: Path) -> None:
    """The scene of issue 25 (one 100 s step with integrate_spin in rolling, driven by
    0.01 N m: without a drive the orbit of segments.dry_whirl_orbit takes a step of any
    length at one cost): fmpy simulate exits 0 there; rotortd simulate exits 1 with one
    line naming the status, the last successful time and the FMU's message, and keeps the
    truncated result."""
    proc = _simulate(fmu_path, "--start-values", "integrate_spin", "true", "amb_on", "0",
                     "g", "9.81", "T_drive", "0.01", "--stop-time", "100",
                     "--output-interval", "100",
                     "--output-file", "wb.csv", cwd=tmp_path)
    assert proc.returncode == 1
    lines = proc.stderr.splitlines()
    assert len(lines) == 1, proc.stderr[-3000:]
    assert lines[0].startswith("rotortd simulate: error: the FMU returned fmi2Discard from "
                               "fmi2DoStep at t = 0.0 s (last successful time), short of "
                               "the stop time 100.0 s: step incomplete: core status 1 (work "
                               "bound reached: ")
    assert "model time stays at t=" in lines[0] and lines[0].endswith("is in wb.csv")
    assert (tmp_path / "wb.csv").read_text().splitlines()[-1].startswith("0.0,")


def test_progress_lines_on_long_runs(fmu_path: Path, tmp_path: Path) -> None:
    """ROTORTD_PROGRESS_SECONDS=0: a line at every communication point (5 s by default)."""
    proc = _simulate(fmu_path, "--stop-time", "0.004", "--output-interval", "1e-3",
                     cwd=tmp_path, env={"ROTORTD_PROGRESS_SECONDS": "0"})
    assert proc.returncode == 0, proc.stderr[-2000:]
    lines = proc.stderr.splitlines()
    assert len(lines) == 4 and lines[1].startswith(
        "rotortd simulate: t = 0.002 s of 0.004 s (50 %), "), proc.stderr


def test_progress_every_five_seconds_of_wall_time() -> None:
    now = [100.0]
    out = io.StringIO()
    progress = Progress(0.0, 10.0, 5.0, out, clock=lambda: now[0])
    for t, wall in ((1.0, 101.0), (2.0, 104.9), (2.5, 105.0), (3.0, 109.0), (4.0, 110.5)):
        now[0] = wall
        assert progress(t) is True
    assert out.getvalue().splitlines() == [
        "rotortd simulate: t = 2.5 s of 10 s (25 %), 5.0 s of wall time",
        "rotortd simulate: t = 4 s of 10 s (40 %), 10.5 s of wall time"]
    assert progress.t == 4.0


def test_start_values_are_typed(fmu_path: Path) -> None:
    from fmpy import read_model_description

    variables = {v.name: v for v in read_model_description(str(fmu_path)).modelVariables}
    got = parse_start_values(["levitate", "0", "integrate_spin", "TRUE", "m", "60",
                              "impact_log", "a b.csv"], variables)
    assert got == {"levitate": False, "integrate_spin": True, "m": 60.0,
                   "impact_log": "a b.csv"}
    with pytest.raises(UsageError, match="Omega = nan rad/s is not finite"):
        parse_start_values(["Omega", "nan"], variables)


ERROR_AT_THIRD_STEP = """
import sys
import fmpy.simulation as sim
from fmpy.fmi1 import FMICallException
from rotortd_tools.cli import main

real = sim.simulate_fmu

def failing(*args, step_finished=None, **kwargs):
    def finished(t, rec):
        step_finished(t, rec)
        if t > 2.5e-3:
            raise FMICallException("fmi2DoStep", int(sys.argv[1]))
        return True
    return real(*args, step_finished=finished, **kwargs)

sim.simulate_fmu = failing
sys.exit(main(sys.argv[2:]))
"""


@pytest.mark.parametrize(("status", "name"), [(3, "fmi2Error"), (4, "fmi2Fatal")])
def test_error_status_exits_1_with_the_last_time(fmu_path: Path, tmp_path: Path,
                                                 status: int, name: str) -> None:
    """An fmi2Error or fmi2Fatal (FMPy raises; simulated here after the third step, since
    this project's FMUs never return them) exits 1 naming the status and the last
    successful time, and the result up to it is written."""
    proc = subprocess.run(
        [sys.executable, "-c", ERROR_AT_THIRD_STEP, str(status), "simulate", str(fmu_path),
         "--stop-time", "0.01", "--output-interval", "1e-3", "--output-file", "e.csv"],
        capture_output=True, text=True, timeout=300, cwd=str(tmp_path))
    assert proc.returncode == 1, proc.stderr[-2000:]
    assert proc.stderr.splitlines() == [
        f"rotortd simulate: error: the FMU returned {name} from fmi2DoStep at t = 0.003 s "
        f"(last successful time), short of the stop time 0.01 s: the FMU gave no message; "
        f"the result up to t = 0.003 s is in e.csv"]
    assert len((tmp_path / "e.csv").read_text().splitlines()) == 5


def test_input_file_drives_the_inputs_as_fmpy_simulate_does(fmu_path: Path,
                                                            tmp_path: Path) -> None:
    """--input-file: the AMB switched off at 5 ms from a CSV; the result equals fmpy
    simulate's with the same file, byte for byte, and differs from the run without it."""
    (tmp_path / "in.csv").write_text('"time","amb_on"\n0,1\n0.005,1\n0.005,0\n0.02,0\n')
    opts = ["--stop-time", "0.02", "--output-interval", "1e-3", "--start-values", "g", "9.81"]
    proc = _simulate(fmu_path, *opts, "--input-file", "in.csv", "--output-file", "ours.csv",
                     cwd=tmp_path)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr[-2000:]
    ref = subprocess.run([sys.executable, "-m", "fmpy", "simulate", str(fmu_path), *opts,
                          "--input-file", "in.csv", "--output-file", "fmpy.csv"],
                         capture_output=True, text=True, timeout=300, cwd=str(tmp_path))
    assert ref.returncode == 0, ref.stderr[-2000:]
    ours = (tmp_path / "ours.csv").read_text()
    assert ours == (tmp_path / "fmpy.csv").read_text()
    plain = _simulate(fmu_path, *opts, "--output-file", "plain.csv", cwd=tmp_path)
    assert plain.returncode == 0
    assert ours.splitlines()[-1] != (tmp_path / "plain.csv").read_text().splitlines()[-1]


@pytest.mark.parametrize("csv, says", [
    ('"time","no_such_input"\n0,1\n', "no variable 'no_such_input'"),
    ('"time","k"\n0,1\n', "k is a parameter: only inputs can be given over time"),
    ('"time","amb_on"\n0,1\n0.01,2\n', "amb_on = 2.0 in row 2 is out of range"),
    ('"time","amb_on"\n0.01,1\n0,1\n', "the time column must be finite and non-decreasing"),
    ('"amb_on","time"\n1,0\n', "the first column must be 'time'"),
])
def test_bad_input_files_exit_2_before_the_run(fmu_path: Path, tmp_path: Path, csv: str,
                                               says: str) -> None:
    (tmp_path / "in.csv").write_text(csv)
    proc = _simulate(fmu_path, "--input-file", "in.csv", "--output-file", "out.csv",
                     cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr[-2000:]
    assert says in proc.stderr and proc.stderr.startswith("rotortd simulate: error: ")
    assert len(proc.stderr.splitlines()) == 1
    assert not (tmp_path / "out.csv").exists()
