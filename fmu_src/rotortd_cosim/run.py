"""Run one engine on one scene in this process and save the result as .npz.

    python -m rotortd_cosim.run ENGINE SCENE SSP OUT.npz [--step H] [--stop T]

Leaves with ``os._exit``: PythonFMU can corrupt the heap at interpreter shutdown in some
hosts, which must not turn a finished run into a failure. Prints ``DONE <seconds>``.
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

from .engines import ENGINES, run


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("engine", choices=sorted(ENGINES))
    parser.add_argument("scene")
    parser.add_argument("ssp", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--step", type=float, default=None)
    parser.add_argument("--stop", type=float, default=None)
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    res = run(args.engine, args.scene, args.ssp, args.step, args.stop)
    np.savez(args.out, **res)
    print(f"DONE {time.perf_counter() - t0:.2f}", flush=True)
    return 0


def exit_after(main: Callable[[], int]) -> None:
    """Run an engine subprocess's ``main`` and leave with os._exit (PythonFMU FMUs share the
    interpreter and can crash it at a normal exit): its exit code, 1 on an exception."""
    try:
        code = main()
    except Exception:
        traceback.print_exc()
        code = 1
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)


if __name__ == "__main__":
    exit_after(main)
