"""Profiles behind the missed targets of docs/benchmarks.md (needs ``pip install pyinstrument``).

    python docs/scripts/bench_profiles.py > docs/bench_profiles.txt

1. the core on the impacting limit cycle (gamma = 0.1), 1 s in steps of 1e-3 s, 5 runs, and
   on the chattering scene (gamma = 0.3 from rest), the same;
2. the FMU in a lean FMU2Slave loop (free whirl, all outputs read every step), 1000 steps;
3. the same loop on the overhead-floor FMU;
4. a CPU-time split of one FMU step (process_time, medians of 5).
"""

from __future__ import annotations

import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

from pyinstrument import Profiler

sys.path.insert(0, str(Path(__file__).resolve().parent))
import benchmarks as bm
from rotortd import TouchdownCore
from rotortd_tools.cycles import OMEGA, find_period_one_cycle


def profile(title: str, fn: object) -> None:
    prof = Profiler(interval=0.0002)
    prof.start()
    fn()  # type: ignore[operator]
    prof.stop()
    print(f"\n===== {title} =====")
    print(prof.output_text(unicode=False, color=False, show_all=False))


def core_limit_cycle() -> None:
    cyc = find_period_one_cycle(0.1)
    for _ in range(5):
        core = cyc.core()
        for _j in range(1000):
            core.step(1e-3, OMEGA)


def core_scene(sc: bm.Scene) -> None:
    for _ in range(5):
        bm.run_core(sc)


def cpu(fn: object, reps: int = 5) -> float:
    times = []
    for _ in range(reps):
        t0 = time.process_time()
        fn()  # type: ignore[operator]
        times.append(time.process_time() - t0)
    return statistics.median(times)


def split(fmus: dict, sc: bm.Scene) -> None:
    """Per-step CPU microseconds: core alone, FMU doStep, FMU doStep + all outputs, floor."""
    n = 1000
    whirl = sc.params

    def core_only() -> None:
        core = TouchdownCore.on_steady_whirl(whirl, OMEGA)
        for _ in range(n):
            core.step(1e-3, OMEGA)

    fmu, floor = bm.LeanLoop(fmus["RotorTouchdown"], "f"), bm.LeanLoop(
        fmus["RotorTouchdownFloor"], "g")
    rows = {
        "core.step alone": cpu(core_only),
        "FMU doStep only (outputs read once at the end)": cpu(lambda: fmu.run(sc, 1e-3, n)),
        "FMU doStep + all outputs every step": cpu(lambda: fmu.run(sc, 1e-3, 1)),
        "floor doStep only": cpu(lambda: floor.run(sc, 1e-3, n)),
        "floor doStep + all outputs every step": cpu(lambda: floor.run(sc, 1e-3, 1)),
    }
    print("\n===== CPU time per step, free whirl, h = 1e-3 s (microseconds) =====")
    for key, val in rows.items():
        print(f"{key:50s} {val / n * 1e6:8.1f}")


def main() -> None:
    profile("core, limit cycle gamma = 0.1, 5 x 1000 steps of 1e-3 s", core_limit_cycle)
    chatter = next(s for s in bm.make_scenes() if s.name == "chattering")
    profile("core, chattering into rub gamma = 0.3, 5 x 1000 steps of 1e-3 s",
            lambda: core_scene(chatter))
    tmp = Path(tempfile.mkdtemp(prefix="rotortd_prof_"))
    fmus = bm.build_fmus(tmp)
    sc = next(s for s in bm.make_scenes() if s.name == "free_whirl")
    for name in ("RotorTouchdown", "RotorTouchdownFloor"):
        loop = bm.LeanLoop(fmus[name], name)
        profile(f"{name}: FMU2Slave loop, free whirl, 1000 steps of 1e-3 s, all outputs "
                "every step", lambda loop=loop: loop.run(sc, 1e-3, 1))
    split(fmus, sc)
    sys.stdout.flush()
    os._exit(0)


if __name__ == "__main__":
    main()
