"""Command line entry point ``rotortd``.

    rotortd plot RESULT.csv -o OUT.png [--c-r 0.7e-3]

RESULT.csv is an FMPy result file (``fmpy simulate ... --output-file RESULT.csv``).
"""

from __future__ import annotations

import argparse
import csv
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

REQUIRED = ("time", "x", "y", "u_re", "u_im", "r_rel", "F_n", "T_f", "mode")


def read_result_csv(path: Path) -> dict[str, np.ndarray]:
    """Read an FMPy result CSV (quoted header names) into {column: array}."""
    with open(path, newline="", encoding="utf-8") as fh:
        reader = csv.reader(fh)
        header = [h.strip().strip('"') for h in next(reader)]
        rows = [[_to_float(v) for v in row] for row in reader if row]
    data = np.array(rows, dtype=float).reshape(len(rows), len(header))
    return {name: data[:, i] for i, name in enumerate(header)}


def _to_float(text: str) -> float:
    t = text.strip().strip('"').lower()
    if t in ("true", "false"):
        return 1.0 if t == "true" else 0.0
    return float(t)


def plot_result(columns: dict[str, np.ndarray], out: Path, c_r: float,
                title: str = "") -> Path:
    """Draw the orbits in the clearance circle and r_rel, F_n, T_f, mode over time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    missing = [c for c in REQUIRED if c not in columns]
    if missing:
        raise SystemExit(f"rotortd plot: result lacks column(s) {', '.join(missing)}; "
                         "record them (fmpy simulate records all outputs by default)")
    t = columns["time"]
    fig = plt.figure(figsize=(12, 7), layout="constrained")
    grid = fig.add_gridspec(4, 2, width_ratios=(1, 1.4))
    ax_orbit = fig.add_subplot(grid[:, 0])
    _draw_orbits(ax_orbit, columns, c_r)
    series = (("r_rel", "r / c_r [1]"), ("F_n", "F_n [N]"), ("T_f", "T_f [N m]"),
              ("mode", "mode"))
    first = None
    for row, (name, label) in enumerate(series):
        ax = fig.add_subplot(grid[row, 1], sharex=first)
        first = first or ax
        style = {"drawstyle": "steps-post"} if name == "mode" else {}
        ax.plot(t, columns[name], lw=0.8, **style)
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
        if name == "mode":
            ax.set_yticks([0, 1, 2], ["free", "slide", "roll"])
            ax.set_xlabel("time [s]")
        else:
            ax.tick_params(labelbottom=False)
    if title:
        fig.suptitle(title)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


def _draw_orbits(ax, columns: dict[str, np.ndarray], c_r: float) -> None:
    theta = np.linspace(0.0, 2.0 * np.pi, 361)
    ax.plot(np.cos(theta), np.sin(theta), "k-", lw=1.2, label="clearance |z| = c_r")
    ax.plot(columns["x"] / c_r, columns["y"] / c_r, lw=0.7, label="inertial (x, y)/c_r")
    ax.plot(columns["u_re"], columns["u_im"], lw=0.7, label="co-rotating U")
    ax.set_aspect("equal")
    ax.set_xlim(-1.15, 1.15)
    ax.set_ylim(-1.15, 1.15)
    ax.set_xlabel("x / c_r,  Re U")
    ax.set_ylabel("y / c_r,  Im U")
    ax.legend(loc="lower left", fontsize="small")
    ax.grid(True, alpha=0.3)


def _cmd_plot(args: argparse.Namespace) -> int:
    columns = read_result_csv(args.result)
    out = plot_result(columns, args.output, args.c_r, title=args.title or args.result.name)
    print(f"rotortd: wrote {out}")
    return 0


def make_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="rotortd", description="RotorTouchdown FMU tools")
    sub = parser.add_subparsers(dest="command", required=True)
    plot = sub.add_parser("plot", help="plot an FMPy result CSV of the RotorTouchdown FMU")
    plot.add_argument("result", type=Path, help="FMPy result CSV")
    plot.add_argument("-o", "--output", type=Path, required=True, help="output image (PNG)")
    plot.add_argument("--c-r", dest="c_r", type=float, default=0.7e-3,
                      help="radial clearance c_r in m used to scale (x, y) (default 0.7e-3)")
    plot.add_argument("--title", default="", help="figure title (default: file name)")
    plot.set_defaults(func=_cmd_plot)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    args = make_parser().parse_args(argv)
    return int(args.func(args))


if __name__ == "__main__":
    sys.exit(main())
