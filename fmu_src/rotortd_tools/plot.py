"""``rotortd plot``: one figure of a RotorTouchdown run.

    rotortd plot RESULT.csv -o OUT.png             # FMPy result (fmpy simulate --output-file)
    rotortd plot RESULT.npz -o OUT.png             # python -m rotortd_cosim.run ... OUT.npz
    rotortd plot RESULT.npz -o OUT.png --component RotorTouchdown --c-r 0.7e-3

Left: the orbit in the clearance circle, inertial (x, y)/c_r and co-rotating U. Right, over
time: r/c_r, F_n, T_f, the spin Omega_out, the impacts and the contact mode.

c_r (m) is taken from the data, |(x, y)| / r_rel at the rows with r_rel > 0, unless --c-r
is given. A co-simulation result (.npz: ``time`` and ``Component.variable`` columns) holds
every component's outputs; the bearing's are those of ``--component``. It records ``psi``
but not ``u_re``/``u_im``: U is then computed as (x + i y) exp(-i psi) / c_r, the
definition of docs/fmu.md. Columns a panel needs but the result lacks are named on stderr
and the panel is left out; a result without the required columns is refused.
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

Columns = dict[str, np.ndarray]

REQUIRED = ("time", "x", "y", "r_rel", "mode")
C_R_RTOL = 1e-6          # relative spread of |(x, y)|/r_rel accepted as one c_r
DEFAULT_COMPONENT = "RotorTouchdown"

# (column, y label) of the time panels; the impacts panel is chosen in _impact_panel
PANELS = (("r_rel", "r / c_r [1]"), ("F_n", "F_n [N]"), ("T_f", "T_f [N m]"),
          ("Omega_out", "spin Omega_out [rad/s]"))


class PlotError(Exception):
    """A result that cannot be plotted; the message says why and what to do."""


# ---------------------------------------------------------------------------- reading
def load_result(path: Path, component: str = DEFAULT_COMPONENT) -> Columns:
    """The bearing's columns of an FMPy result .csv or a co-simulation .npz."""
    if not path.is_file():
        raise PlotError(f"{path}: no such file")
    suffix = path.suffix.lower()
    if suffix == ".csv":
        return read_result_csv(path)
    if suffix == ".npz":
        return read_cosim_npz(path, component)
    raise PlotError(f"{path}: unknown file type '{path.suffix}'; expected an FMPy result "
                    "'.csv' (fmpy simulate --output-file) or a co-simulation '.npz' "
                    "(python -m rotortd_cosim.run ENGINE SCENE SSP OUT.npz)")


def read_result_csv(path: Path) -> Columns:
    """Read an FMPy result CSV (quoted header names, true/false booleans) into
    {column: array}."""
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            rows = list(csv.reader(fh))
    except UnicodeDecodeError as exc:
        raise PlotError(f"{path}: not a text CSV ({exc.reason} at byte {exc.start}); "
                        "expected an FMPy result file") from exc
    if not rows:
        raise PlotError(f"{path}: empty file; expected an FMPy result CSV")
    header = [h.strip().strip('"') for h in rows[0]]
    body = [row for row in rows[1:] if row]
    data = np.empty((len(body), len(header)))
    for i, row in enumerate(body, start=2):
        if len(row) != len(header):
            raise PlotError(f"{path}: line {i} has {len(row)} values, the header "
                            f"{len(header)}")
        try:
            data[i - 2] = [_to_float(v) for v in row]
        except ValueError as exc:
            raise PlotError(f"{path}: line {i}: {exc}") from exc
    return {name: data[:, j] for j, name in enumerate(header)}


def _to_float(text: str) -> float:
    t = text.strip().strip('"').lower()
    if t in ("true", "false"):
        return 1.0 if t == "true" else 0.0
    return float(t)


def read_cosim_npz(path: Path, component: str = DEFAULT_COMPONENT) -> Columns:
    """The ``time`` column and the ``component.*`` columns of a rotortd_cosim.run result,
    without the prefix."""
    try:
        with np.load(path, allow_pickle=False) as npz:
            arrays = {k: np.asarray(npz[k], float) for k in npz.files}
    except (OSError, ValueError, zipfile.BadZipFile) as exc:
        raise PlotError(f"{path}: not a readable .npz ({exc})") from exc
    prefix = f"{component}."
    cols = {k[len(prefix):]: v for k, v in arrays.items() if k.startswith(prefix)}
    if not cols:
        found = sorted({k.split(".", 1)[0] for k in arrays if "." in k})
        raise PlotError(f"{path}: no columns of component '{component}' (found components: "
                        f"{', '.join(found) or 'none'}); choose one with --component")
    if "time" not in arrays:
        raise PlotError(f"{path}: no 'time' column")
    return {"time": arrays["time"], **cols}


# ---------------------------------------------------------------------------- checks
def check_columns(columns: Columns, source: str) -> list[str]:
    """Refuse a result without the required columns; return notes naming the optional
    columns that are missing (their panels are left out)."""
    missing = [c for c in REQUIRED if c not in columns]
    if missing:
        raise PlotError(f"{source}: result lacks column(s) {', '.join(missing)} (has: "
                        f"{', '.join(sorted(columns)) or 'none'}); record them (fmpy "
                        "simulate records every output unless --output-variables is given)")
    if len(columns["time"]) == 0:
        raise PlotError(f"{source}: the result has no rows")
    notes = [f"no column '{name}': its panel is left out"
             for name, _label in PANELS if name not in columns]
    if "n_impacts" not in columns and "n_impacts_step" not in columns:
        notes.append("no column 'n_impacts' or 'n_impacts_step': the impacts panel is "
                     "left out")
    if not ({"u_re", "u_im"} <= columns.keys() or "psi" in columns):
        notes.append("no columns 'u_re', 'u_im' or 'psi': the co-rotating orbit U is left "
                     "out")
    return notes


def clearance_from_data(columns: Columns) -> float:
    """c_r in m as |(x, y)| / r_rel over the rows with r_rel > 0; PlotError when no row
    has r_rel > 0 or the rows disagree by more than C_R_RTOL relative."""
    r_rel = columns["r_rel"]
    rows = np.isfinite(r_rel) & (r_rel > 0.0)
    if not rows.any():
        raise PlotError("c_r cannot be determined from the data (r_rel is 0 or not finite "
                        "in every row); give it with --c-r (m)")
    ratio = np.hypot(columns["x"][rows], columns["y"][rows]) / r_rel[rows]
    lo, hi = float(np.min(ratio)), float(np.max(ratio))
    if not (math.isfinite(lo) and math.isfinite(hi) and lo > 0.0):
        raise PlotError(f"c_r cannot be determined from the data (|(x, y)|/r_rel from {lo!r} "
                        f"to {hi!r} m); give it with --c-r (m)")
    if hi - lo > C_R_RTOL * hi:
        raise PlotError(f"c_r varies in the data: |(x, y)|/r_rel goes from {lo:.6g} to "
                        f"{hi:.6g} m (more than {C_R_RTOL:g} relative); is this one run? "
                        "Give c_r with --c-r (m)")
    return float(np.median(ratio))


def co_rotating(columns: Columns, c_r: float) -> np.ndarray | None:
    """U = z exp(-i psi) / c_r (complex, 1): the recorded u_re + i u_im, else computed
    from x, y and psi; None when neither is there."""
    if "u_re" in columns and "u_im" in columns:
        return columns["u_re"] + 1j * columns["u_im"]
    if "psi" in columns:
        z = columns["x"] + 1j * columns["y"]
        return z * np.exp(-1j * columns["psi"]) / c_r
    return None


# ---------------------------------------------------------------------------- figure
def make_figure(columns: Columns, c_r: float, title: str = "") -> Any:
    """The figure (matplotlib, Agg): orbits on the left, the time panels on the right."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = columns["time"]
    panels = [(columns[name], label, {}) for name, label in PANELS if name in columns]
    impacts = _impact_panel(columns)
    if impacts is not None:
        panels.append(impacts)
    panels.append((columns["mode"], "mode", {"drawstyle": "steps-post"}))
    fig = plt.figure(figsize=(12, 1.6 * len(panels) + 1.0), layout="constrained")
    grid = fig.add_gridspec(len(panels), 2, width_ratios=(1, 1.4))
    _draw_orbits(fig.add_subplot(grid[:, 0]), columns, c_r)
    first = None
    for row, (values, label, style) in enumerate(panels):
        ax = fig.add_subplot(grid[row, 1], sharex=first)
        first = first or ax
        ax.plot(t, values, lw=0.8, **style)
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
        ax.tick_params(labelbottom=False)
    ax.tick_params(labelbottom=True)
    ax.set_yticks([0, 1, 2], ["free", "slide", "roll"])
    ax.set_xlabel("time [s]")
    if title:
        fig.suptitle(title)
    return fig


def _impact_panel(columns: Columns) -> tuple[np.ndarray, str, dict] | None:
    if "n_impacts" in columns:
        return columns["n_impacts"], "impacts (total)", {"drawstyle": "steps-post"}
    if "n_impacts_step" in columns:
        return columns["n_impacts_step"], "impacts per step", {"drawstyle": "steps-post"}
    return None


def _draw_orbits(ax: Any, columns: Columns, c_r: float) -> None:
    theta = np.linspace(0.0, 2.0 * np.pi, 361)
    ax.plot(np.cos(theta), np.sin(theta), "k-", lw=1.2,
            label=f"clearance |z| = c_r = {c_r * 1e3:.4g} mm")
    ax.plot(columns["x"] / c_r, columns["y"] / c_r, lw=0.7, label="inertial (x, y)/c_r")
    u = co_rotating(columns, c_r)
    if u is not None:
        ax.plot(u.real, u.imag, lw=0.7, label="co-rotating U")
    ax.set_aspect("equal")
    ax.set_xlim(-1.15, 1.15)
    ax.set_ylim(-1.15, 1.15)
    ax.set_xlabel("x / c_r,  Re U")
    ax.set_ylabel("y / c_r,  Im U")
    ax.legend(loc="lower left", fontsize="small")
    ax.grid(True, alpha=0.3)


def plot_result(columns: Columns, out: Path, c_r: float, title: str = "") -> Path:
    """Draw the figure of ``columns`` (c_r in m) into ``out`` (PNG)."""
    import matplotlib.pyplot as plt

    fig = make_figure(columns, c_r, title)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


# ---------------------------------------------------------------------------- command
def choose_clearance(columns: Columns, given: float | None) -> tuple[float, str]:
    """(c_r in m, a line saying where it came from): --c-r if given, else the data's."""
    if given is None:
        c_r = clearance_from_data(columns)
        return c_r, f"c_r = {c_r:.9g} m (from |(x, y)|/r_rel in the data)"
    if not (math.isfinite(given) and given > 0.0):
        raise PlotError(f"--c-r {given!r} m: the radial clearance must be finite and > 0")
    line = f"c_r = {given!r} m (--c-r)"
    try:
        data = clearance_from_data(columns)
    except PlotError:
        return given, line
    if abs(data - given) > C_R_RTOL * data:
        line += f"; note: the data gives {data:.9g} m"
    return given, line


def cmd_plot(args: argparse.Namespace) -> int:
    """``rotortd plot``: exit 0 with the image written, 2 with a message on stderr."""
    try:
        columns = load_result(args.result, args.component)
        notes = check_columns(columns, str(args.result))
        c_r, origin = choose_clearance(columns, args.c_r)
    except PlotError as exc:
        print(f"rotortd plot: error: {exc}", file=sys.stderr)
        return 2
    for note in notes:
        print(f"rotortd plot: {args.result}: {note}", file=sys.stderr)
    print(f"rotortd plot: {origin}")
    out = plot_result(columns, args.output, c_r, title=args.title or args.result.name)
    print(f"rotortd: wrote {out}")
    return 0


def add_plot_parser(sub: Any) -> None:
    """Register ``plot`` on the ``rotortd`` subparsers."""
    plot = sub.add_parser(
        "plot", help="plot a RotorTouchdown result: FMPy CSV or co-simulation .npz",
        description=__doc__.split("\n\n", 2)[2])
    plot.add_argument("result", type=Path,
                      help="FMPy result .csv, or .npz of python -m rotortd_cosim.run")
    plot.add_argument("-o", "--output", type=Path, required=True, help="output image (PNG)")
    plot.add_argument("--c-r", dest="c_r", type=float, default=None,
                      help="radial clearance c_r in m used to scale (x, y) (default: from "
                      "the data, |(x, y)|/r_rel)")
    plot.add_argument("--component", default=DEFAULT_COMPONENT,
                      help="the bearing's instance name in a .npz (default RotorTouchdown)")
    plot.add_argument("--title", default="", help="figure title (default: file name)")
    plot.set_defaults(func=cmd_plot)
