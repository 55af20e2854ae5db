"""Count processes that abort after a clean run of the RotorTouchdown FMU (issue 18).

Runs a reproducer (default: /work/shared/repro/exit_abort.py, i.e. FMPy's low-level loop with
logging on and the spin input Omega flipping sign every step) N times, each in a fresh
subprocess, under ``MALLOC_CHECK_=3 PYTHONMALLOC=debug`` (heap corruption shows up far more
often), two at a time, and prints the number of non-zero exits by exit code.

    python docs/scripts/exit_abort.py                       # 1000 runs
    python docs/scripts/exit_abort.py --runs 200 --jobs 2 --fmu models/RotorTouchdown.fmu
    python docs/scripts/exit_abort.py --plain               # without the two variables
    python docs/scripts/exit_abort.py --valgrind --runs 4   # memcheck, PYTHONMALLOC=malloc

The abort is a use-after-free at exit in PythonFMU 0.7.0's binary (see
fmu_src/rotortd_fmi/exit_order.py). Whether it corrupts the heap depends on the heap layout
at exit, so the abort itself is rare: issue 18 saw 3 in about 330 runs, and this machine 0 in
1000 with the two variables, 0 in 1000 plain and 0 in 300 of the issue's own loop. Since
glibc 2.34, MALLOC_CHECK_ does nothing unless libc_malloc_debug.so is preloaded.
``--valgrind`` sees the invalid access on every affected run: a run counts as
failed if memcheck reports an error with a frame in the FMU's binary (binaries/linux64/), and
the first such error is printed. Memcheck's usual false positives in CPython and ld.so, which
have no such frame, are not counted. A valgrind run takes about 20 s.

Exit code: 0 if no run failed, 1 otherwise.
"""

from __future__ import annotations

import argparse
import collections
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DEFAULT_REPRO = Path("/work/shared/repro/exit_abort.py")


def fmu_binary_errors(log: str) -> list[str]:
    """Memcheck error records (from a --log-file) with a frame in an FMU binary."""
    records, block = [], []
    for line in [*log.splitlines(), "==0== "]:
        text = line.split("== ", 1)[-1] if line.startswith("==") else line
        if text.strip():
            block.append(text)
            continue
        if block and any("binaries/linux64/" in b for b in block[1:]):
            records.append("\n".join(block))
        block = []
    return records


def run_once(cmd: list[str], env: dict[str, str], timeout: float,
             valgrind: bool = False) -> tuple[int, str]:
    """(exit code, last line of stderr); a timeout counts as code -9999. Each run gets its
    own TMPDIR, removed afterwards (FMPy's extract() leaves the unzipped FMU behind).
    With valgrind, a memcheck error in the FMU binary counts as code -9997."""
    with tempfile.TemporaryDirectory(prefix="exit_abort_") as tmp:
        log = Path(tmp) / "memcheck.log"
        if valgrind:
            cmd = ["valgrind", "--error-exitcode=9", "--num-callers=30",
                   f"--log-file={log}", *cmd]
        try:
            proc = subprocess.run(cmd, env={**env, "TMPDIR": tmp}, cwd=ROOT,
                                  capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            return -9999, "timeout"
        if valgrind:
            errors = fmu_binary_errors(log.read_text(errors="replace"))
            if errors:
                return -9997, errors[0]
            if proc.returncode == 9:      # only errors outside the FMU binary
                return (0, "") if "end of script" in proc.stdout else (-9998, "no end")
    if proc.returncode == 0 and "end of script" not in proc.stdout:
        return -9998, "exit 0 without 'end of script'"
    tail = proc.stderr.strip().splitlines()
    return proc.returncode, tail[-1] if tail else ""


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=1000, help="number of runs (1000)")
    parser.add_argument("--jobs", type=int, default=2, help="runs in parallel (2)")
    parser.add_argument("--fmu", default=str(ROOT / "models" / "RotorTouchdown.fmu"))
    parser.add_argument("--repro", default=str(DEFAULT_REPRO),
                        help="reproducer script, called as `python REPRO FMU`")
    parser.add_argument("--plain", action="store_true",
                        help="do not set MALLOC_CHECK_=3 PYTHONMALLOC=debug")
    parser.add_argument("--valgrind", action="store_true",
                        help="run under valgrind memcheck with PYTHONMALLOC=malloc")
    parser.add_argument("--timeout", type=float, default=None,
                        help="per run [s] (120, with --valgrind 1200)")
    args = parser.parse_args(argv)

    timeout = args.timeout or (1200.0 if args.valgrind else 120.0)
    env = dict(os.environ)
    if args.valgrind:
        env.update(PYTHONMALLOC="malloc")
    elif not args.plain:
        env.update(MALLOC_CHECK_="3", PYTHONMALLOC="debug")
    cmd = [sys.executable, args.repro, args.fmu]
    t0 = time.monotonic()
    codes: collections.Counter[int] = collections.Counter()
    examples: dict[int, str] = {}
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        for code, tail in pool.map(
                lambda _i: run_once(cmd, env, timeout, args.valgrind), range(args.runs)):
            codes[code] += 1
            if code != 0:
                examples.setdefault(code, tail)
    failed = sum(n for code, n in codes.items() if code != 0)
    mode = ("valgrind, PYTHONMALLOC=malloc" if args.valgrind else
            "plain" if args.plain else "MALLOC_CHECK_=3 PYTHONMALLOC=debug")
    print(f"{' '.join(cmd)} ({mode}, {args.jobs} in parallel, "
          f"{time.monotonic() - t0:.0f} s)")
    for code in sorted(c for c in codes if c != 0):
        label = "memcheck error in the FMU binary" if code == -9997 else f"exit {code}"
        print(f"  {label}: {codes[code]}, e.g.:")
        print("    " + examples[code].replace("\n", "\n    "))
    print(f"aborts: {failed} of {args.runs}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
