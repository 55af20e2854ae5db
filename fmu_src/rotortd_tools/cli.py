"""Command line entry point ``rotortd``.

    rotortd plot RESULT.csv|RESULT.npz -o OUT.png [--c-r 0.7e-3]
    rotortd sweep gamma=0.05:0.3:1000 mu=0.15 --starts rest,steady,cycle,large --out S.parquet
    rotortd sweep mu=0.02:0.5:12 J=3.2e-4:1.6:log12 --starts drop --out D.parquet
    rotortd sweep k_b=1e6:1e9:log4 J=0.04 race_turns=1 support_compliant=1 --starts drop
    rotortd sweep-plot S.parquet -o diagram.png
    rotortd simulate models/RotorTouchdown.fmu --stop-time 0.1 --start-values g 9.81 ...

RESULT.csv is an FMPy result file (``fmpy simulate ... --output-file RESULT.csv``),
RESULT.npz a co-simulation result (``python -m rotortd_cosim.run``); ``plot`` is the module
``rotortd_tools.plot``.
``sweep`` and ``sweep-plot`` are described in docs/sweeps.md (code: the package
``rotortd_tools.sweep`` and ``sweep_plot.py``); a bad sweep specification prints an error and
exits with status 2.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from rotortd_tools.plot import add_plot_parser

SWEEP_MODULES = ("dask.distributed", "pyarrow", "tqdm")  # the [sweep] extra


def _missing_sweep_extra(command: str) -> bool:
    """True (after one message on stderr) when the [sweep] extra is not installed."""
    import importlib.util

    missing = []
    for name in SWEEP_MODULES:
        try:
            found = importlib.util.find_spec(name) is not None
        except (ImportError, ValueError):  # the parent package (dask) is missing
            found = False
        if not found:
            missing.append(name)
    if missing:
        print(f"rotortd {command}: error: needs {', '.join(missing)}, from the [sweep] "
              "extra: python -m pip install -e \".[sweep]\"", file=sys.stderr)
    return bool(missing)


def _cmd_sweep(args: argparse.Namespace) -> int:
    if _missing_sweep_extra("sweep"):
        return 2
    from rotortd_tools.sweep import Settings, SweepError, parse_spec, run_sweep

    try:
        spec = parse_spec(args.spec, args.starts, args.seed)
        settings = Settings(args.transient, args.record, args.steps_per_rev, args.section,
                            args.period_tol, args.max_period, args.drop_time,
                            args.drop_window, args.drop_step).validate()
        if args.workers is not None and args.workers <= 0:
            raise SweepError(f"--workers {args.workers}: it must be > 0")
        if args.batch <= 0 or args.chunk <= 0:
            raise SweepError("--batch and --chunk must be > 0")
        counts = run_sweep(spec, settings, args.out, scheduler=args.scheduler,
                           workers=args.workers, serial=args.serial,
                           overwrite=args.overwrite, batch=args.batch, chunk=args.chunk,
                           progress=not args.no_progress, flush_s=args.flush_seconds)
    except SweepError as exc:
        print(f"rotortd sweep: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("rotortd sweep: interrupted; rows written so far are kept, rerun the same "
              "command to resume", file=sys.stderr)
        return 130
    print(f"rotortd sweep: {args.out}: {counts['total']} runs, {counts['resumed']} already "
          f"present, {counts['computed']} computed")
    return 0


def _cmd_sweep_plot(args: argparse.Namespace) -> int:
    if _missing_sweep_extra("sweep-plot"):
        return 2
    from rotortd_tools.sweep import SweepError
    from rotortd_tools.sweep_plot import plot_sweep

    try:
        out = plot_sweep(args.sweep, args.output, args.results, args.title)
    except SweepError as exc:
        print(f"rotortd sweep-plot: error: {exc}", file=sys.stderr)
        return 2
    print(f"rotortd: wrote {out}")
    return 0


def _add_sweep_parsers(sub: argparse._SubParsersAction) -> None:
    sw = sub.add_parser(
        "sweep", help="sweep one or two parameters on Dask, attractor signatures to Parquet",
        description="Sweep scaled parameters (gamma omega rho phi mu d R_over_cr) and/or "
        "Omega (rad/s), J (kg m^2: the spin as a state) and T_drive (N m, needs J), and the "
        "real bearing (docs/model.md §10, docs/bearing.md; needs J, the FMU's integrate_spin "
        "= true): options race_turns, support_compliant, contact_compliant (0 or 1) and "
        "their parameters J_b (kg m^2), T_b0 (N m), c_bw (N m s), omega_b0 (rad/s); m_b "
        "(kg), k_b (N/m), c_b (N s/m); k_c (N/m), p_c (1 to 1.5), each only with its option "
        "on. Others fixed at the chapter set, the spin held when J is not given. SPEC: name=a:b:n "
        "(grid), name=a:b:logn (geometric grid), name=a:b:~n (sorted random samples) or "
        "name=value (fixed).")
    sw.add_argument("spec", nargs="+",
                    help="name=a:b:n | name=a:b:logn | name=a:b:~n | name=value")
    sw.add_argument("--starts", default="rest",
                    help="comma list of rest, steady, large, cycle[:BRANCH], drop, "
                    "up[:SEED], down[:SEED] (default rest)")
    sw.add_argument("--out", type=Path, default=Path("sweep.parquet"),
                    help="output directory of Parquet part files (resumed if it exists)")
    sw.add_argument("--transient", type=float, default=300.0,
                    help="scaled time discarded before recording (default 300)")
    sw.add_argument("--record", type=float, default=100.0,
                    help="scaled time recorded (default 100; 2 pi per revolution)")
    sw.add_argument("--steps-per-rev", dest="steps_per_rev", type=int, default=32,
                    help="core steps per revolution, sampling of r (default 32)")
    sw.add_argument("--section", type=int, default=64,
                    help="impact points (angle, speed) kept per run (default 64)")
    sw.add_argument("--period-tol", dest="period_tol", type=float, default=1e-4,
                    help="tolerance of the period-n test on impact points (default 1e-4)")
    sw.add_argument("--max-period", dest="max_period", type=int, default=32,
                    help="largest n tested for period-n (default 32)")
    sw.add_argument("--drop-time", dest="drop_time", type=float, default=0.4,
                    help="drop start: seconds with the bearing off (default 0.4)")
    sw.add_argument("--drop-window", dest="drop_window", type=float, default=0.1,
                    help="drop start: last seconds classified (default 0.1)")
    sw.add_argument("--drop-step", dest="drop_step", type=float, default=1e-4,
                    help="drop start: core step in seconds (default 1e-4)")
    sw.add_argument("--seed", type=int, default=0, help="seed of random samples (default 0)")
    sw.add_argument("--scheduler", default=None,
                    help="address of an existing Dask scheduler (tcp://host:8786)")
    sw.add_argument("--workers", type=int, default=None,
                    help="workers of the local cluster (default: os.cpu_count())")
    sw.add_argument("--serial", action="store_true",
                    help="run in this process without Dask (debugging, reference)")
    sw.add_argument("--batch", type=int, default=4, help="independent runs per task")
    sw.add_argument("--chunk", type=int, default=8,
                    help="continuation points per chained task")
    sw.add_argument("--flush-seconds", dest="flush_seconds", type=float, default=2.0,
                    help="write a part file at least this often while rows arrive (default 2)")
    sw.add_argument("--overwrite", action="store_true",
                    help="delete the output's part files first instead of resuming")
    sw.add_argument("--no-progress", dest="no_progress", action="store_true",
                    help="no progress bar")
    sw.set_defaults(func=_cmd_sweep)
    sp = sub.add_parser("sweep-plot", help="bifurcation diagram or regime map of a sweep")
    sp.add_argument("sweep", type=Path, help="sweep output directory")
    sp.add_argument("-o", "--output", type=Path, required=True, help="output image (PNG)")
    sp.add_argument("--results", type=Path, default=Path("docs/chapter_results.json"),
                    help="JSON with cycle events (fold, period doubling, grazing) to mark")
    sp.add_argument("--title", default="", help="figure title")
    sp.set_defaults(func=_cmd_sweep_plot)


def make_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="rotortd", description="RotorTouchdown FMU tools")
    sub = parser.add_subparsers(dest="command", required=True)
    add_plot_parser(sub)
    _add_sweep_parsers(sub)
    from rotortd_tools.simulate import add_simulate_parser

    add_simulate_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    args = make_parser().parse_args(argv)
    return int(args.func(args))


if __name__ == "__main__":
    sys.exit(main())
