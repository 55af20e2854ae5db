"""What folding the held spin's declared accelerators into the one definitions would cost.

    python docs/scripts/fold_cost.py [--t 0.1] [--repeats 3]   (~2 min)

Issue 23 asks for fewer logical lines than at e272741 and for no benchmark figure worse than
+2 %. ``loc.py --groups`` shows where the lines are; the held spin's declared accelerators
(closed-form flight and its search, rolling, the rub, the held sliding integrator, the held
impact law) are the only code that could go without losing a capability. This script
measures what that would cost: each benchmark scene (``benchmarks.make_scenes``) run by the
held core and by the same core with the spin a state and J = 1e9 kg m^2, which takes the
one definitions (``SpinFlight``, ``ContactPair.impact``, ``SpinContact``) and follows the
same trajectory (the impact counts and the final radius are printed to show it). CPU time
per simulated second at 1e-3 s steps, the best of ``--repeats`` alternated runs.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import benchmarks as B  # (docs/scripts/benchmarks.py: scenes)
from rotortd import SpinCore, TouchdownCore

H = 1e-3
J_HELD = 1e9
"""kg m^2: the spin-state rotor that holds its speed over the runs (|dOmega| < 1e-9 rad/s)."""


def run(sc: B.Scene, spin: bool, t_end: float) -> tuple[float, int, float]:
    """(CPU s, impacts, final |z|/c_r) of one run of ``sc`` at H-steps."""
    if spin:
        core: TouchdownCore = SpinCore(sc.params, J_HELD, z0=sc.z0, v0=sc.v0, psi0=sc.psi0,
                                       Omega0=B.W)
    else:
        core = TouchdownCore(sc.params, z0=sc.z0, v0=sc.v0, psi0=sc.psi0)
    t0 = time.process_time()
    for j in range(round(t_end / H)):
        rep = core.step(H, B.W, 0j, sc.amb(j * H))
        if rep.status != 0:
            raise RuntimeError(f"{sc.name}: step {j} status {rep.status}")
    return time.process_time() - t0, core.n_impacts, abs(core.z) / sc.params.c_r


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--t", type=float, default=0.1, help="simulated seconds per run")
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args(argv)
    print(f"CPU ms per simulated second at {H:g} s steps (best of {args.repeats}); "
          f"impacts and final r/c_r of both runs")
    for sc in B.make_scenes():
        runs: dict[bool, list[tuple[float, int, float]]] = {False: [], True: []}
        for _ in range(args.repeats):
            for spin in (False, True):
                runs[spin].append(run(sc, spin, args.t))
        held, one = (min(r[0] for r in runs[k]) / args.t * 1e3 for k in (False, True))
        (_, n_h, r_h), (_, n_s, r_s) = runs[False][0], runs[True][0]
        print(f"{sc.name:12s} held {held:7.1f}  one definition {one:7.1f}  ratio "
              f"{one / held:5.1f}   impacts {n_h}/{n_s}  r {r_h:.6f}/{r_s:.6f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
