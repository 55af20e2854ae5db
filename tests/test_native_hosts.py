"""The FMUs in native FMI hosts, with no LD_PRELOAD (issue 25; docs/fmu.md "Native hosts").

* A minimal C host (tests/native/fmi_host.c, compiled here) dlopens each FMU's linux64
  binary, which is the project's loader (fmu_src/native/fmu_loader.c), in a clean
  environment (no LD_PRELOAD, no virtual environment, PATH=/usr/bin:/bin): 1000 steps of a
  drop with impacts print every output with %.17g, equal bit for bit to FMPy's
  (``FMU2Slave``, the same calls, in a Python process where the loader loads nothing).
* The same with each CPython 3.10 ... 3.13 shared library found on this machine named by
  ROTORTD_LIBPYTHON, and a 3.9 or a non-library refused with the one message.
* The ``ecos`` CLI (ecospy's native binary) runs the FMU alone with no LD_PRELOAD; its CSV
  equals FMPy's to the digits it prints.

Every host runs in a subprocess. Without gcc the C-host tests skip, except with CI=true,
where a missing compiler fails (build.py refuses to build without the loader there too).
"""

from __future__ import annotations

import importlib.util
import math
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
HOST_SOURCE = ROOT / "tests" / "native" / "fmi_host.c"
STEP, NSTEPS = 1e-4, 1000
CLEAN_ENV = {"PATH": "/usr/bin:/bin", "HOME": os.environ.get("HOME", "/tmp"), "LANG": "C"}
PYENV = Path(os.environ.get("PYENV_ROOT", Path.home() / ".pyenv")) / "versions"

FMPY_SCRIPT = r"""
import sys
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
fmu, step, n, outs = sys.argv[1], float(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
starts = [a.split("=") for a in sys.argv[5:]]
md = read_model_description(fmu)
unzipped = extract(fmu)
slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipped,
                  modelIdentifier=md.coSimulation.modelIdentifier, instanceName="host")
slave.instantiate()
slave.setupExperiment(startTime=0.0)
slave.enterInitializationMode()
for vr, value in starts:
    slave.setReal([int(vr)], [float(value)])
slave.exitInitializationMode()
vrs = [int(v) for v in outs.split(",")]
for k in range(n):
    t = k * step
    slave.doStep(currentCommunicationPoint=t, communicationStepSize=step)
    print(",".join("%.17g" % v for v in [t + step, *slave.getReal(vrs)]))
slave.terminate()
slave.freeInstance()
"""


def _compiler() -> str | None:
    cc = shutil.which("gcc") or shutil.which("cc")
    if cc is None and os.environ.get("CI", "").lower() == "true":
        pytest.fail("no C compiler with CI=true: the native-host tests must run in CI")
    return cc


@pytest.fixture(scope="module")
def fmu_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The three FMUs built by build.py (with the loader) into a temporary folder."""
    if _compiler() is None:
        pytest.skip("no C compiler: the FMUs carry no loader")
    sys.path.insert(0, str(ROOT))
    import build

    out = tmp_path_factory.mktemp("native_fmus")
    build.build_all(out, check=False)
    return out


@pytest.fixture(scope="module")
def host(tmp_path_factory: pytest.TempPathFactory) -> Path:
    cc = _compiler()
    if cc is None:
        pytest.skip("no C compiler")
    exe = tmp_path_factory.mktemp("host") / "fmi_host"
    subprocess.run([cc, "-O2", "-o", str(exe), str(HOST_SOURCE), "-ldl"], check=True)
    return exe


def _unpack(fmu: Path, where: Path) -> tuple[Path, str, str, dict[str, int]]:
    """(binary, resource URI, GUID, {output name: value reference}) of an unpacked FMU."""
    with zipfile.ZipFile(fmu) as zf:
        zf.extractall(where)
    root = ET.parse(where / "modelDescription.xml").getroot()
    ident = root.find("CoSimulation").get("modelIdentifier")
    outs = {sv.get("name"): int(sv.get("valueReference")) for sv in root.iter("ScalarVariable")
            if sv.get("causality") == "output" and sv[0].tag == "Real"}
    binary = where / "binaries" / "linux64" / f"{ident}.so"
    return binary, (where / "resources").as_uri(), root.get("guid"), outs


def _run_host(host: Path, binary: Path, uri: str, guid: str, vrs: list[int],
              starts: list[str], env: dict[str, str], nsteps: int = NSTEPS
              ) -> subprocess.CompletedProcess[str]:
    cmd = [str(host), str(binary), uri, guid, repr(STEP), str(nsteps),
           ",".join(map(str, vrs)), *starts]
    return subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=300)


def _run_fmpy(fmu: Path, vrs: list[int], starts: list[str], nsteps: int = NSTEPS) -> str:
    cmd = [sys.executable, "-c", FMPY_SCRIPT, str(fmu), repr(STEP), str(nsteps),
           ",".join(map(str, vrs)), *starts]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=300, check=True)
    return proc.stdout


def test_fmu_ships_the_loader_and_no_unrun_binary(fmu_dir: Path) -> None:
    with zipfile.ZipFile(fmu_dir / "RotorTouchdown.fmu") as zf:
        names = set(zf.namelist())
        record = zf.read("resources/rotortd_libpython.txt").decode().strip()
    assert {"binaries/linux64/RotorTouchdown.so",
            "binaries/linux64/RotorTouchdown_pythonfmu.so"} <= names
    assert not [n for n in names if n.startswith("binaries/") and "linux64" not in n]
    assert record == "" or Path(record).name.startswith("libpython3.")


def test_c_host_equals_fmpy_bit_for_bit(fmu_dir: Path, host: Path, tmp_path: Path) -> None:
    """A drop (the bearing off from t = 0: impacts, then contact) for 1000 steps of 1e-4 s."""
    fmu = fmu_dir / "RotorTouchdown.fmu"
    binary, uri, guid, outs = _unpack(fmu, tmp_path / "fmu")
    vrs = list(outs.values())
    starts = [f"{_vr(tmp_path / 'fmu', 'amb_on')}=0"]
    proc = _run_host(host, binary, uri, guid, vrs, starts, CLEAN_ENV)
    assert proc.returncode == 0, proc.stderr[-3000:]
    rows = proc.stdout.splitlines()
    assert len(rows) == NSTEPS
    e_diss = float(rows[-1].split(",")[1 + vrs.index(outs["E_diss"])])
    assert e_diss > 0.0  # it did hit the wall
    assert proc.stdout == _run_fmpy(fmu, vrs, starts)


def _vr(unzipped: Path, name: str) -> int:
    root = ET.parse(unzipped / "modelDescription.xml").getroot()
    return next(int(sv.get("valueReference")) for sv in root.iter("ScalarVariable")
                if sv.get("name") == name)


def _pythons() -> list[Path]:
    return sorted(PYENV.glob("3.1[0-9].*/lib/libpython3.1[0-9].so.1.0"))


@pytest.mark.parametrize("minor", [10, 11, 12, 13])
def test_c_host_with_each_python(fmu_dir: Path, host: Path, tmp_path: Path,
                                 minor: int) -> None:
    """ROTORTD_LIBPYTHON names the library: every CPython 3.10 ... 3.13 gives the same
    bits over 200 steps of the drop."""
    libs = [p for p in _pythons() if p.name == f"libpython3.{minor}.so.1.0"]
    if not libs:
        pytest.skip(f"no libpython3.{minor} on this machine")
    binary, uri, guid, outs = _unpack(fmu_dir / "RotorTouchdown.fmu", tmp_path / "fmu")
    starts = [f"{_vr(tmp_path / 'fmu', 'amb_on')}=0"]
    vrs = [outs["x"], outs["y"], outs["Omega_out"], outs["E_diss"]]
    env = dict(CLEAN_ENV, ROTORTD_LIBPYTHON=str(libs[0]))
    proc = _run_host(host, binary, uri, guid, vrs, starts, env, nsteps=200)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert proc.stdout == _run_fmpy(fmu_dir / "RotorTouchdown.fmu", vrs, starts, nsteps=200)


@pytest.mark.parametrize("name", ["Drivetrain", "TouchdownEvents"])
def test_c_host_runs_the_other_fmus(fmu_dir: Path, host: Path, tmp_path: Path,
                                    name: str) -> None:
    binary, uri, guid, outs = _unpack(fmu_dir / f"{name}.fmu", tmp_path / "fmu")
    vrs = list(outs.values())
    proc = _run_host(host, binary, uri, guid, vrs, [], CLEAN_ENV, nsteps=100)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert proc.stdout == _run_fmpy(fmu_dir / f"{name}.fmu", vrs, [], nsteps=100)


@pytest.mark.parametrize("bad", ["not-a-library", "python3.9"])
def test_loader_refuses_with_one_message(fmu_dir: Path, host: Path, tmp_path: Path,
                                         bad: str) -> None:
    """A library named by ROTORTD_LIBPYTHON that is unusable (not a libpython, or 3.9) is
    not replaced by another: instantiation fails with one message naming what was tried
    and the variable, through the host's logger and on stderr."""
    if bad == "python3.9":
        libs = sorted(PYENV.glob("3.9.*/lib/libpython3.9.so.1.0"))
        if not libs:
            pytest.skip("no libpython3.9 on this machine")
        target, reason = str(libs[0]), "Python 3.9, need 3.10 or newer"
    else:
        fake = tmp_path / "libpython3.11.so.1.0"
        fake.write_text("not an ELF file\n" * 256)
        target, reason = str(fake), "invalid ELF header"
    binary, uri, guid, outs = _unpack(fmu_dir / "RotorTouchdown.fmu", tmp_path / "fmu")
    env = dict(CLEAN_ENV, ROTORTD_LIBPYTHON=target)
    proc = _run_host(host, binary, uri, guid, [outs["x"]], [], env, nsteps=1)
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    assert proc.stdout == ""
    stderr_lines = [ln for ln in proc.stderr.splitlines() if ln.startswith("host: error:")]
    logged = [ln for ln in proc.stderr.splitlines() if ln.startswith("[host|3|error]")]
    assert len(stderr_lines) == 1 and len(logged) == 1, proc.stderr
    assert f"ROTORTD_LIBPYTHON: {target}: " in proc.stderr and reason in proc.stderr
    assert "Set ROTORTD_LIBPYTHON" in proc.stderr


def _ecos() -> tuple[Path, dict[str, str]]:
    if importlib.util.find_spec("ecospy") is None:  # not imported: it needs libtbb first
        pytest.skip("ecospy is not installed (the [test] extra installs it)")
    sys.path.insert(0, str(ROOT / "fmu_src"))
    from rotortd_cosim.engines import ecos_binaries
    from rotortd_cosim.tbb import load_libtbb

    lib = load_libtbb()
    env = dict(CLEAN_ENV)
    if lib is not None:
        env["LD_LIBRARY_PATH"] = str(lib.parent)
    return ecos_binaries() / "ecos", env


def test_ecos_cli_without_preload_equals_fmpy(fmu_dir: Path, tmp_path: Path) -> None:
    """ecos simulate --path RotorTouchdown.fmu (the default scene, 0.1 s at 1e-4 s): exit 0
    and every printed value equal to FMPy's to its six decimals."""
    exe, env = _ecos()
    fmu = fmu_dir / "RotorTouchdown.fmu"
    proc = subprocess.run([str(exe), "simulate", "--path", str(fmu), "--stopTime", "0.1",
                           "--stepSize", repr(STEP), "-l", "warn"], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    lines = (tmp_path / "RotorTouchdown.csv").read_text().splitlines()
    head = [h.strip() for h in lines[0].rstrip(", ").split(",")]
    names = {i: h.split("::")[1].split("[")[0] for i, h in enumerate(head) if "::" in h}
    _, _, _, outs = _unpack(fmu, tmp_path / "fmu")
    columns = {i: n for i, n in names.items() if n in outs}
    assert len(columns) >= 20, columns  # every Real output ecos recorded
    vrs = [outs[n] for n in columns.values()]
    body = [[float(v) for v in ln.rstrip(", ").split(",")] for ln in lines[1:] if ln.strip()]
    steps = [r for r in body if r[1] > 0.0]
    reference = [[float(v) for v in ln.split(",")]
                 for ln in _run_fmpy(fmu, vrs, [], nsteps=len(steps)).splitlines()]
    assert len(steps) >= 999
    for row, ref in zip(steps, reference, strict=True):
        assert math.isclose(row[1], ref[0], abs_tol=1e-9)
        for j, i in enumerate(columns):
            # %f: six decimals, then the double's own rounding of the printed value
            assert abs(row[i] - ref[1 + j]) <= 5.000001e-7 + 1e-15 * abs(ref[1 + j]), (
                columns[i], row[1], row[i], ref[1 + j])


def test_python_host_loads_no_libpython(fmu_dir: Path) -> None:
    """In a Python host (FMPy) the loader finds Python already there and loads nothing,
    even with ROTORTD_LIBPYTHON naming another CPython's library: that library is never
    mapped, and the outputs are the same bits as without the variable."""
    others = [p for p in _pythons() if f"3.{sys.version_info.minor}." not in str(p)]
    if not others:
        pytest.skip("no other CPython 3.10+ library on this machine")
    fmu = fmu_dir / "RotorTouchdown.fmu"
    name = others[0].name
    code = FMPY_SCRIPT + (f"\nprint('MAPPED' if any({name!r} in line for line in "
                          "open('/proc/self/maps')) else 'CLEAN')")
    env = dict(os.environ, ROTORTD_LIBPYTHON=str(others[0]))
    proc = subprocess.run([sys.executable, "-c", code, str(fmu), repr(STEP), "50", "1"],
                          env=env, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    *rows, verdict = proc.stdout.splitlines()
    assert verdict == "CLEAN"
    assert "\n".join(rows) + "\n" == _run_fmpy(fmu, [1], [], nsteps=50)
