"""Run one engine on one scene in this process and save the result as .npz.

    python -m rotortd_cosim.run ENGINE SCENE SSP OUT.npz [--step H] [--stop T] [--verbose]

SSP must carry the scene's parameters (``python -m rotortd_cosim.ssp SCENE`` writes it);
an unknown scene or engine, or an SSP of another scene, is refused with a message and exit
code 2 before anything runs. The engines' own logs are cut to warnings unless
``--verbose``. OUT's directory is created. Leaves with ``os._exit``: PythonFMU can corrupt
the heap at interpreter shutdown in some hosts, which must not turn a finished run into a
failure. Prints ``DONE <seconds>``.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import traceback
from collections.abc import Callable
from pathlib import Path

import numpy as np

from .engines import ENGINES, SceneError, check_ssp, run, scene_named


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("engine", choices=sorted(ENGINES))
    parser.add_argument("scene")
    parser.add_argument("ssp", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--step", type=float, default=None, help="communication step (s)")
    parser.add_argument("--stop", type=float, default=None, help="stop time (s)")
    parser.add_argument("--verbose", action="store_true", help="the engines' own logs")
    args = parser.parse_args(argv)
    try:
        check_ssp(args.ssp, scene_named(args.scene))
    except SceneError as exc:
        parser.error(str(exc))
    t0 = time.perf_counter()
    res = run(args.engine, args.scene, args.ssp, args.step, args.stop, args.verbose)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    np.savez(args.out, **res)
    print(f"DONE {time.perf_counter() - t0:.2f}", flush=True)
    return 0


def exit_after(main: Callable[[], int]) -> None:
    """Run an engine subprocess's ``main`` and leave with os._exit (PythonFMU FMUs share the
    interpreter and can crash it at a normal exit): its exit code (argparse's 2 included),
    1 on an exception."""
    try:
        code = main()
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    except Exception:
        traceback.print_exc()
        code = 1
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)


if __name__ == "__main__":
    exit_after(main)
