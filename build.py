"""Build, post-process and validate the project's FMUs.

    python build.py                 # builds every FMU in FMU_SPECS into models/
    python build.py --dest /tmp/x   # elsewhere

For each spec: PythonFMU builds the zip; then modelDescription.xml inside it is
post-processed (units with <UnitDefinitions>, min/max of bounded variables, a complete
<ModelStructure>, capability flags) and documentation/index.html is added. On Linux the
native loader (fmu_src/native/fmu_loader.c, docs/fmu.md "Native hosts") is compiled and
becomes binaries/linux64/<id>.so, PythonFMU's binary moving beside it as <id>_pythonfmu.so,
and the build interpreter's libpython is recorded in resources/rotortd_libpython.txt; with no
C compiler the FMU keeps PythonFMU's binary alone (a warning; an error when CI=true).
PythonFMU's win64 binary is not shipped: nothing here has run it. Finally the FMU is
validated with fmpy and, where fmu-manipulation-toolbox is installed (the [test] extra),
`fmutool -check` (skipped with a message otherwise, so `pip install -e .` suffices to build);
the script exits non-zero on any problem.

To add an FMU (e.g. Drivetrain), write its adapter as a module of ``rotortd_fmi`` with a
``VARIABLE_META`` dict {name: (unit, min, max)}, and a few-line script in fmu_src/ that
subclasses the adapter and re-exports ``VARIABLE_META`` (PythonFMU 0.7 compiles the script on
every fmi2Instantiate, and takes the Fmi2Slave subclass with the longest MRO); then append an
FmuSpec to FMU_SPECS. Script and package names must be the project's own: every PythonFMU
instance in a process shares ``sys.modules``.
"""

from __future__ import annotations

import argparse
import hashlib
import html
import importlib.util
import io
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import uuid
import zipfile
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from xml.dom.minidom import parseString
from xml.etree import ElementTree as ET

ROOT = Path(__file__).resolve().parent
LOADER_SOURCE = ROOT / "fmu_src" / "native" / "fmu_loader.c"
LIBPYTHON_RECORD = "resources/rotortd_libpython.txt"  # read by the loader (same name there)
SIBLING_SUFFIX = "_pythonfmu.so"  # PythonFMU's binary beside the loader (same there)

# unit name -> exponents of the SI base units (kg, m, s, A, K, mol, cd, rad)
BASE_UNITS: dict[str, dict[str, int]] = {
    "1": {},
    "kg": {"kg": 1},
    "m": {"m": 1},
    "s": {"s": 1},
    "rad": {"rad": 1},
    "m/s": {"m": 1, "s": -1},
    "m/s2": {"m": 1, "s": -2},
    "rad/s": {"rad": 1, "s": -1},
    "N": {"kg": 1, "m": 1, "s": -2},
    "N.s": {"kg": 1, "m": 1, "s": -1},
    "N.m": {"kg": 1, "m": 2, "s": -2},
    "N/m": {"kg": 1, "s": -2},
    "N.s/m": {"kg": 1, "s": -1},
    "J": {"kg": 1, "m": 2, "s": -2},
    "kg.m2": {"kg": 1, "m": 2},
    "N.m.s": {"kg": 1, "m": 2, "s": -1},
    "W": {"kg": 1, "m": 2, "s": -3},
}


@dataclass(frozen=True)
class FmuSpec:
    """One FMU of the project."""

    name: str                                   # model identifier = class name = FMU name
    script: Path                                # PythonFMU script (relative to ROOT)
    project_dirs: tuple[Path, ...] = ()         # copied to resources/<dir name>/
    options: dict[str, bool] = field(default_factory=dict)  # FMI2 CoSimulation flags
    equations_html: str = ""                    # extra HTML for documentation/index.html


ROTOR_EQUATIONS = """
<h2>Equations (docs/model.md &sect;1, outputs for a system model)</h2>
<p>Position z = x + i y (inertial frame), spin angle &psi; with &psi;' = &Omega;.
Free flight while |z| &lt; c<sub>r</sub>:</p>
<pre>m z'' = a (F_bias &minus; c z' &minus; k z)
        + m e_c &Omega;&sup2; exp(i(&psi; + &phi;)) + F_ext,
F_bias = +i m g (levitate = true),  F_ext = F_x + i F_y &minus; i m g,  a = amb_on</pre>
<p>&Omega;, F_ext and a are held constant over a communication step; the flow is then
propagated in closed form (no time-discretisation error). The term
i m e_c &Omega;' exp(i(&psi;+&phi;)) from a changing speed is left out.</p>
<p>Impact at |z| = c<sub>r</sub> with &rdot;<sup>&minus;</sup> &gt; 0, n = z/|z|,
s = sign(v_rel), v_rel = R &Omega; + c<sub>r</sub> &theta;':</p>
<pre>z'+ = z'- &minus; (1 + d) rdot- (1 + i &mu; s) n</pre>
<p>(friction impulse capped at stick, v_rel = 0). Sustained contact on the circle
z = c<sub>r</sub> e<sup>i&theta;</sup> with F the sum of all non-contact forces:</p>
<pre>N = Re(e^{-i&theta;} F) + m c_r &theta;'&sup2;
m c_r &theta;'' = Im(e^{-i&theta;} F) &minus; F_t
sliding: F_t = &mu; s N;   rolling: &theta;' = &minus;R &Omega;/c_r, |F_t| &le; &mu; N</pre>
<h3>Outputs (each force/torque averaged over the step; an impulse P in a step h counts as
P/h)</h3>
<ul>
<li>F_bx, F_by: bearing (contact) force on the rotor; the housing feels the opposite.
P_n: normal impulse in the step; F_n_peak: peak normal force.</li>
<li>T_f = &minus;R F_t (sliding, rolling) &minus; R P_t/h (impulses); negative when it brakes a
positive spin.</li>
<li>T_imb = e_c Im(conj(F_amb + F_ext + F_c) exp(i(&psi; + &phi;))), the imbalance reaction
torque on the spin (F_ext without gravity, F_c the contact force, impacts as P/h), exact
with &Omega; held; a drivetrain that owns the spin inertia integrates
J &Omega;' = T_drive + T_f + T_imb.</li>
<li>F_amb_x, F_amb_y = a (F_bias &minus; c z' &minus; k z) at the end of the step.</li>
<li>x, y, vx, vy; U = z e<sup>&minus;i&psi;</sup>/c<sub>r</sub> (u_re, u_im) and dU/dt with
t = &Omega; &tau; (du_re, du_im; 0 when &Omega; = 0); r_rel = r/c<sub>r</sub>; whirl_rate =
&theta;'; v_rel.</li>
<li>mode (0 free, 1 sliding, 2 rolling), in_contact = (mode &ne; 0), n_impacts (total),
n_impacts_step, t_last_impact, v_last_impact (rdot&minus; of the last impact, 0 before any),
E_diss = &sum; [&frac12; m (1&minus;d&sup2;) rdot&minus;&sup2; + P_t (v_rel&minus; + v_rel+)/2]
+ &int; &mu; N |v_rel| dt.</li>
</ul>
"""

DRIVE_EQUATIONS = """
<h2>Equations</h2>
<pre>J &Omega;' = T_motor &minus; b &Omega; + T_bearing,   &psi;' = &Omega;
motor = 0: T_motor = T_motor_in
motor = 1: u = Kp (&Omega;_set &minus; &Omega;) + Ki I,  I' = &Omega;_set &minus; &Omega;,
           T_motor = u clipped to [&minus;T_max, T_max], I frozen while saturated</pre>
<p>Inputs are held over a communication step; each regime is a linear ODE advanced in
closed form and regime switches are located on the closed form, so a step is exact.
H_motor + H_drag + H_bearing = J (&Omega; &minus; &Omega;0) to round-off.
With follow_speed, &Omega; = Omega_in (held) and only the torques are computed.</p>
"""

EVENTS_EQUATIONS = """
<h2>Schedule</h2>
<pre>amb_on = amb_before (t &lt; t_fail), amb_after (t &ge; t_fail)
F_x, F_y = F_x_step, F_y_step (t_force_on &le; t &lt; t_force_off), else 0</pre>
<p>The outputs after doStep(t, h) are the values at t + h.</p>
"""

FMU_SPECS: tuple[FmuSpec, ...] = (
    FmuSpec(
        name="RotorTouchdown",
        script=Path("fmu_src/RotorTouchdown.py"),
        project_dirs=(Path("fmu_src/rotortd"), Path("fmu_src/rotortd_drive"),
                      Path("fmu_src/rotortd_fmi")),
        options={"canHandleVariableCommunicationStepSize": True,
                 "canGetAndSetFMUstate": True, "canSerializeFMUstate": True},
        equations_html=ROTOR_EQUATIONS,
    ),
    FmuSpec(
        name="Drivetrain",
        script=Path("fmu_src/Drivetrain.py"),
        project_dirs=(Path("fmu_src/rotortd_drive"), Path("fmu_src/rotortd_fmi")),
        options={"canHandleVariableCommunicationStepSize": True,
                 "canGetAndSetFMUstate": True, "canSerializeFMUstate": True},
        equations_html=DRIVE_EQUATIONS,
    ),
    FmuSpec(
        name="TouchdownEvents",
        script=Path("fmu_src/TouchdownEvents.py"),
        project_dirs=(Path("fmu_src/rotortd_fmi"),),
        options={"canHandleVariableCommunicationStepSize": True},
        equations_html=EVENTS_EQUATIONS,
    ),
)


# ---------------------------------------------------------------------------- metadata
def load_variable_meta(script: Path) -> dict[str, tuple[str, float | None, float | None]]:
    """Read VARIABLE_META from the FMU script without registering it in sys.modules."""
    spec = importlib.util.spec_from_file_location(f"_meta_{script.stem}", script)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.path.insert(0, str(script.parent))
    try:
        spec.loader.exec_module(module)
    finally:
        sys.path.remove(str(script.parent))
    return dict(module.VARIABLE_META)


def _fmt(value: float) -> str:
    return repr(float(value))


# ---------------------------------------------------------------------------- XML
def add_units_and_ranges(root: ET.Element, meta: dict) -> None:
    """Put unit/min/max on the type elements and write <UnitDefinitions>."""
    used: list[str] = []
    for sv in root.iter("ScalarVariable"):
        name = sv.get("name", "")
        type_el = sv[0]
        if name not in meta:
            if type_el.tag == "Real":
                raise SystemExit(f"build: Real variable '{name}' has no entry in VARIABLE_META")
            continue
        unit, lo, hi = meta[name]
        if type_el.tag == "Real" and unit:
            if unit not in BASE_UNITS:
                raise SystemExit(f"build: unit '{unit}' of '{name}' not in BASE_UNITS")
            type_el.set("unit", unit)
            if unit not in used:
                used.append(unit)
        if type_el.tag in ("Real", "Integer"):
            conv: Callable[[float], str] = _fmt if type_el.tag == "Real" else str
            if lo is not None:
                type_el.set("min", conv(lo))
            if hi is not None:
                type_el.set("max", conv(hi))
    _insert_unit_definitions(root, used)


def _insert_unit_definitions(root: ET.Element, units: list[str]) -> None:
    old = root.find("UnitDefinitions")
    if old is not None:
        root.remove(old)
    if not units:
        return
    defs = ET.Element("UnitDefinitions")
    for unit in units:
        u = ET.SubElement(defs, "Unit", name=unit)
        ET.SubElement(u, "BaseUnit", {k: str(v) for k, v in BASE_UNITS[unit].items()})
    # schema order: CoSimulation, UnitDefinitions, TypeDefinitions, LogCategories, ...
    index = list(root).index(root.find("CoSimulation")) + 1
    root.insert(index, defs)


def fix_model_structure(root: ET.Element) -> None:
    """<Outputs> lists every output; <InitialUnknowns> lists outputs whose initial is
    approx/calculated and calculated parameters (FMI 2.0 section 2.2.8). Outputs are computed
    in doStep only (no direct feedthrough from inputs), hence dependencies=""."""
    variables = list(root.find("ModelVariables"))
    old = root.find("ModelStructure")
    if old is not None:
        root.remove(old)
    structure = ET.SubElement(root, "ModelStructure")
    outputs = ET.SubElement(structure, "Outputs")
    initial_unknowns: list[int] = []
    for index, sv in enumerate(variables, start=1):
        causality = sv.get("causality", "local")
        if causality == "output":
            ET.SubElement(outputs, "Unknown", index=str(index), dependencies="")
            if sv.get("initial", "calculated") in ("approx", "calculated"):
                initial_unknowns.append(index)
        elif causality == "calculatedParameter":
            initial_unknowns.append(index)
    if not len(outputs):
        structure.remove(outputs)
    if initial_unknowns:
        unknowns = ET.SubElement(structure, "InitialUnknowns")
        for index in initial_unknowns:
            ET.SubElement(unknowns, "Unknown", index=str(index))


def set_capabilities(root: ET.Element, options: dict[str, bool]) -> None:
    cs = root.find("CoSimulation")
    for key, value in options.items():
        cs.set(key, "true" if value else "false")


def content_guid(root: ET.Element, payload: list[tuple[str, bytes]]) -> str:
    """A GUID that depends only on the FMU's content (model description without guid and
    date, plus every other file), so that rebuilding unchanged sources gives the same GUID.
    PythonFMU's binary never checks the GUID; hosts compare it with the XML."""
    digest = hashlib.sha256()
    probe = ET.fromstring(ET.tostring(root))
    for attr in ("guid", "generationDateAndTime"):
        probe.attrib.pop(attr, None)
    digest.update(ET.tostring(probe))
    for name, data in sorted(payload):
        digest.update(name.encode() + b"\0" + hashlib.sha256(data).digest())
    return "{" + str(uuid.uuid5(uuid.NAMESPACE_URL, "rotortd:" + digest.hexdigest())) + "}"


def postprocess_xml(xml_bytes: bytes, spec: FmuSpec, meta: dict,
                    payload: list[tuple[str, bytes]]) -> bytes:
    root = ET.fromstring(xml_bytes)
    add_units_and_ranges(root, meta)
    fix_model_structure(root)
    set_capabilities(root, spec.options)
    root.set("guid", content_guid(root, payload))
    pretty = parseString(ET.tostring(root, encoding="utf-8")).toprettyxml(
        indent="  ", encoding="UTF-8")
    return b"\n".join(line for line in pretty.splitlines() if line.strip()) + b"\n"


# ---------------------------------------------------------------------------- docs
def variable_rows(xml_bytes: bytes) -> list[dict[str, str]]:
    """One dict per variable (name, type, causality, variability, start, unit, min, max,
    description), read from a modelDescription.xml."""
    root = ET.fromstring(xml_bytes)
    rows = []
    for sv in root.iter("ScalarVariable"):
        t = sv[0]
        rows.append({
            "name": sv.get("name", ""), "type": t.tag,
            "causality": sv.get("causality", "local"),
            "variability": sv.get("variability", "continuous"),
            "start": t.get("start", ""), "unit": t.get("unit", ""),
            "min": t.get("min", ""), "max": t.get("max", ""),
            "description": sv.get("description", ""),
        })
    return rows


def documentation_html(xml_bytes: bytes, spec: FmuSpec) -> str:
    root = ET.fromstring(xml_bytes)
    cols = ["name", "type", "causality", "variability", "start", "unit", "min", "max",
            "description"]
    head = "".join(f"<th>{c}</th>" for c in cols)
    body = "\n".join(
        "<tr>" + "".join(f"<td>{html.escape(r[c])}</td>" for c in cols) + "</tr>"
        for r in variable_rows(xml_bytes))
    title = html.escape(spec.name)
    desc = html.escape(root.get("description", ""))
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<style>body{{font-family:sans-serif;max-width:70em}}table{{border-collapse:collapse}}
td,th{{border:1px solid #999;padding:2px 6px;font-size:90%}}pre{{background:#f4f4f4}}</style>
</head><body>
<h1>{title}</h1>
<p>{desc}</p>
<p>FMI 2.0 co-simulation, generated by {html.escape(root.get("generationTool", ""))}.
Runs in Python hosts (FMPy, libcosimpy, ecospy) and, on Linux, in native hosts: its
loader finds a libpython 3.10 or newer (ROTORTD_LIBPYTHON, the build interpreter's, the
linker's path, python3 on PATH).</p>
<h2>Variables</h2>
<table><tr>{head}</tr>
{body}
</table>
{spec.equations_html}
</body></html>
"""


# ---------------------------------------------------------------------------- build
def _pythonfmu_build(spec: FmuSpec, out_dir: Path) -> Path:
    from pythonfmu import FmuBuilder

    flags = {k: v for k, v in spec.options.items()}
    return Path(FmuBuilder.build_FMU(
        ROOT / spec.script, dest=out_dir,
        project_files=[ROOT / d for d in spec.project_dirs], **flags))


def compile_loader(out_dir: Path) -> bytes | None:
    """The native loader compiled for this platform, or None (not Linux, or no compiler:
    a warning; with CI=true a missing compiler is an error)."""
    if not sys.platform.startswith("linux"):
        print("build: warning: the native loader is built on Linux only; the FMU keeps "
              "PythonFMU's binary, which needs a Python host")
        return None
    cc = os.environ.get("CC") or shutil.which("gcc") or shutil.which("cc")
    if not cc:
        msg = ("no C compiler (gcc, cc or $CC) found: the FMU keeps PythonFMU's binary, which "
               "loads only in Python hosts (FMPy, libcosimpy, ecospy), not in native ones")
        if os.environ.get("CI", "").lower() == "true":
            raise SystemExit(f"build: error: {msg}")
        print(f"build: warning: {msg}")
        return None
    out = out_dir / "fmu_loader.so"
    cmd = [cc, "-shared", "-fPIC", "-O2", "-std=gnu11", "-Wall", "-Wextra",
           "-fvisibility=hidden", "-o", str(out), str(LOADER_SOURCE), "-ldl", "-lpthread"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0 or proc.stderr.strip():
        raise SystemExit(f"build: error: compiling the loader failed:\n$ {' '.join(cmd)}\n"
                         f"{proc.stderr}")
    return out.read_bytes()


def build_libpython() -> str:
    """The build interpreter's shared libpython ('' when it has none, e.g. a static build)."""
    libdir, soname = sysconfig.get_config_var("LIBDIR"), sysconfig.get_config_var("INSTSONAME")
    if not libdir or not soname or not sysconfig.get_config_var("Py_ENABLE_SHARED"):
        return ""
    path = Path(libdir) / soname
    return str(path) if path.is_file() else ""


def _binaries(items: list[tuple[zipfile.ZipInfo, bytes]], spec: FmuSpec,
              loader: bytes | None) -> list[tuple[zipfile.ZipInfo | str, bytes]]:
    """The FMU's members with the loader in front of PythonFMU's Linux binary and the
    libpython record added (when there is a loader); win64 dropped (never run here)."""
    linux = f"binaries/linux64/{spec.name}.so"
    out: list[tuple[zipfile.ZipInfo | str, bytes]] = []
    for item, data in items:
        if item.filename.startswith("binaries/win64/"):
            continue
        if loader is not None and item.filename == linux:
            out.append((f"binaries/linux64/{spec.name}{SIBLING_SUFFIX}", data))
            out.append((linux, loader))
            continue
        out.append((item, data))
    if loader is not None:
        out.append((LIBPYTHON_RECORD, (build_libpython() + "\n").encode()))
    return out


def _rewrite_zip(src: Path, dst: Path, spec: FmuSpec, meta: dict,
                 loader: bytes | None) -> None:
    with zipfile.ZipFile(src) as zin:
        kept = [(item, zin.read(item.filename)) for item in zin.infolist()
                if _keep_member(item.filename)]
        items = _binaries(kept, spec, loader)
        payload = [(getattr(item, "filename", item), data) for item, data in items]
        xml_bytes = postprocess_xml(zin.read("modelDescription.xml"), spec, meta, payload)
        buf = io.BytesIO()
        with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as zout:
            for item, data in items:
                zout.writestr(item, data)
            zout.writestr("modelDescription.xml", xml_bytes)
            zout.writestr("documentation/index.html", documentation_html(xml_bytes, spec))
    dst.write_bytes(buf.getvalue())


def _keep_member(name: str) -> bool:
    if name == "modelDescription.xml" or name.startswith("documentation/"):
        return False
    return "__pycache__" not in name and not name.endswith(".pyc")


def build_fmu(spec: FmuSpec, dest_dir: Path) -> Path:
    """Build, post-process and return the path of <dest_dir>/<name>.fmu (not validated)."""
    dest_dir.mkdir(parents=True, exist_ok=True)
    meta = load_variable_meta(ROOT / spec.script)
    with tempfile.TemporaryDirectory(prefix="rotortd_build_") as tmp:
        raw = _pythonfmu_build(spec, Path(tmp))
        final = dest_dir / f"{spec.name}.fmu"
        staged = Path(tmp) / "staged.fmu"
        _rewrite_zip(raw, staged, spec, meta, compile_loader(Path(tmp)))
        shutil.move(str(staged), final)       # atomic enough: never a half-written FMU
    return final


def validate(fmu: Path, require_fmutool: bool = False) -> list[str]:
    """Problems found by fmpy.validation and `fmutool -check` (empty list = clean).

    Without fmutool (fmu-manipulation-toolbox, in the [test] extra) its check is skipped,
    said on stdout, unless ``require_fmutool``: then its absence is a problem."""
    from fmpy.validation import validate_fmu

    problems = [f"fmpy: {p}" for p in validate_fmu(str(fmu))]
    cmd = fmutool_command()
    if cmd is not None:
        problems += [f"fmutool: {p}" for p in _fmutool_check(cmd, fmu)]
    elif require_fmutool:
        problems.append(f"fmutool: not installed ({FMUTOOL_MISSING})")
    else:
        print(f"build: {fmu.name}: fmutool -check skipped: {FMUTOOL_MISSING}")
    return problems


FMUTOOL_MISSING = ("no fmutool on PATH and no module fmu_manipulation_toolbox; "
                   "pip install fmu-manipulation-toolbox==2.0 (or the [test] extra) to run it")


def fmutool_command() -> list[str] | None:
    """The command that runs fmutool: this interpreter's package first, else an fmutool on
    PATH; None when neither is installed."""
    if importlib.util.find_spec("fmu_manipulation_toolbox") is not None:
        return [sys.executable, "-m", "fmu_manipulation_toolbox.cli.fmutool"]
    exe = shutil.which("fmutool")
    return [exe] if exe else None


def _fmutool_check(cmd: list[str], fmu: Path) -> list[str]:
    proc = subprocess.run([*cmd, "-input", str(fmu), "-check"], capture_output=True,
                          text=True, timeout=300)
    out = proc.stdout + proc.stderr
    print(out.rstrip())
    problems = [line for line in out.splitlines()
                if line.split("|")[0].strip() in ("WARNING", "ERROR", "CRITICAL")]
    for expected in ("seems to be compliant with FMI-2.0", "No semantic error"):
        if expected not in out:
            problems.append(f"fmutool output lacks '{expected}'")
    if proc.returncode != 0:
        problems.append(f"fmutool exited with {proc.returncode}")
    return problems


def build_all(dest_dir: Path, names: list[str] | None = None, check: bool = True) -> list[Path]:
    built = []
    for spec in FMU_SPECS:
        if names and spec.name not in names:
            continue
        fmu = build_fmu(spec, dest_dir)
        print(f"build: wrote {fmu}")
        if check:
            problems = validate(fmu)
            if problems:
                print(f"build: {fmu.name}: {len(problems)} problem(s):")
                for p in problems:
                    print(f"  - {p}")
                raise SystemExit(1)
            checks = "fmpy validate and fmutool -check" if fmutool_command() else \
                "fmpy validate (fmutool -check skipped)"
            print(f"build: {fmu.name}: {checks}: no problems")
        built.append(fmu)
    return built


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dest", type=Path, default=ROOT / "models",
                        help="output directory (default: models/)")
    parser.add_argument("--only", nargs="*", help="names of FMUs to build (default: all)")
    parser.add_argument("--no-check", action="store_true", help="skip validation")
    args = parser.parse_args(argv)
    build_all(args.dest, args.only, check=not args.no_check)
    return 0


if __name__ == "__main__":
    sys.exit(main())
