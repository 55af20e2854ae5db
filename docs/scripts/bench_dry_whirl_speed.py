"""Cost of dry whirl against the rolling speed: the energy-integral kernel and the integrator.

    python docs/scripts/bench_dry_whirl_speed.py              # ~5 min (callgrind + mpmath)
    python docs/scripts/bench_dry_whirl_speed.py --no-errors  # instructions only
    python docs/scripts/bench_dry_whirl_speed.py --quick driven 60,200,600,2000 --torque 30

Issue #26 item 1 (docs/notes/dry-whirl-quadrature.md). The chapter's rotor (g = 9.81,
J = m R^2/2 = 0.04 kg m^2, ``integrate_spin``: ``SpinCore``) rolls on the fixed race at
Omega = 60, 200, 600 and 2000 rad/s (theta' = -R Omega/c_r, started in rolling at the bottom
of the clearance), stepped by ``SpinCore.step`` at 1e-4 s. Per speed:

1. Instructions per 1e-4 s step (valgrind callgrind; the difference of two runs of 10 and 60
   steps after 5 warm-up steps, in fresh processes with PYTHONHASHSEED = 0, as
   bench_instructions.py and bench_spin.py count), times 1e4: instructions per simulated
   second of rolling, for
   - ``orbit``: the bearing off (a = 0), T_drive = 0, the declared accelerators on, as
     shipped (``dry_whirl_orbit``: the orbit's 2-D Fourier form, kept across steps);
   - ``panels``: the same with ``SpinContact.follow_orbit`` False (``rolling_spin_fast``:
     the direct panel where theta turns at most BETA_DIRECT rad per step, else
     Fourier-Levin; what a drive torque T_drive != 0 takes);
   - ``levin``: the panels with the Fourier-Levin panel at every speed (BETA_DIRECT < 0);
   - ``old``: the bearing off, the accelerators off (``SpinContact.accelerate = False``:
     the extrapolation integrator, at most one radian of beta per step);
   - ``driven``: ``orbit`` with T_drive = T_DRIVE (1 N m) held (``dry_whirl_driven``: the
     orbit's Fourier form with the level as a variable, a table per band of levels);
   - ``driven_panels``: the same with ``SpinContact.follow_orbit`` False (the panels, what
     a held drive torque took before);
   - ``damper``: the bearing on (amb_on = 1, c = 1400 N s/m: the energy integral does not
     hold, the integrator runs), for the cost law of that path.
   Printed with the ratio max/min over the speeds (the issue's target: at most 1.5 between
   60 and 2000 rad/s) and the exponent of a power law through the first and last speed;
   the kernels (``KERNELS``) also at 6000 rad/s (not in the ratio).
2. The error of one 1e-4 s step from (theta, psi) = (-1.3, 0.4) against the 40-digit Taylor
   integration (tests/reference/spin_mp.py), for ``orbit``, ``panels``, ``old`` and
   ``driven`` (with its T_drive; ``driven_panels`` as ``panels`` with it): theta
   over (1 + its turn), psi over (1 + its turn), Omega relative, the impulses over
   max(|int N|, N_peak h) (as tests/test_dry_whirl_fast.py).
3. The floor FMU's step (``bench_spin.rolling_fmu_steps``: FMPy's FMU2Slave loop, every
   output read, the drop from 1000 rad/s over its steps 1500 to 2000) and the ``orbit`` step
   at each speed (6000 rad/s included) over it: issue 26's "rolling steps at most the
   floor's step"; RotorTouchdown's own step there, rolling at about 330 rad/s
   (``--floor-only`` adds these to the file).
Writes docs/bench_dry_whirl_speed.json.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(ROOT / "fmu_src"))
sys.path.insert(1, str(ROOT))

import bench_instructions as BI  # noqa: E402 (docs/scripts: callgrind helpers)

OUT = ROOT / "docs" / "bench_dry_whirl_speed.json"
SPEEDS = (60.0, 200.0, 600.0, 2000.0)
EXTRA = 6000.0
"""A further speed for the kernels alone (KERNELS): where their cost stays."""
KINDS = ("orbit", "panels", "levin", "old", "damper", "driven", "driven_panels")
KERNELS = ("orbit", "panels", "levin", "driven", "driven_panels")
T_DRIVE = 1.0
"""The drive torque (N m) of the ``driven`` kinds."""
H, WARM, N_SHORT, N_LONG = 1e-4, 5, 10, 60

CHILD = '''
import cmath, math, sys
from dataclasses import replace
sys.path.insert(0, sys.argv[1])
from rotortd import RotorParams, SpinCore
from rotortd.segments import rolling_spin_fast, spin_contact
kind, W, n = sys.argv[2], float(sys.argv[3]), int(sys.argv[4])
p = RotorParams(g=9.81)
J = 0.5 * p.m * p.R ** 2
spin_contact.SpinContact.accelerate = kind in ("orbit", "panels", "levin", "driven",
                                               "driven_panels")
spin_contact.SpinContact.follow_orbit = kind in ("orbit", "driven")
T = TDRIVE if kind.startswith("driven") else 0.0
if kind == "levin":
    rolling_spin_fast.BETA_DIRECT = -1.0
core = SpinCore(p, J, Omega0=W)
th, dth = -math.pi / 2, -p.R * W / p.c_r
nn = cmath.exp(1j * th)
core.set_state(replace(core.state, mode=2, theta=th, dtheta=dth, slip=0.0, z=p.c_r * nn,
                       v=1j * p.c_r * dth * nn))
a = 1.0 if kind == "damper" else 0.0
for _ in range(WARM + n):
    core.step(H, amb_on=a, T_drive=T)
assert core.mode == 2, (kind, W, core.mode)
'''.replace("WARM", str(WARM)).replace("H,", f"{H!r},")


def sanity(W: float, kind: str) -> tuple[int, int]:
    """(kernel calls that took a segment, calls that declined) over 5 steps of a kernel kind
    (``KERNELS``) in this process. For ``driven``, the level table's and the panels' calls:
    the table declines where the direct panel costs less (``dry_whirl_driven.TABLE_TURN``),
    so only the panels' declines (to the integrator) count."""
    import cmath
    from dataclasses import replace

    from rotortd import RotorParams, SpinCore
    from rotortd.segments import (
        dry_whirl_driven,
        dry_whirl_orbit,
        rolling_spin_fast,
        spin_contact,
    )

    used = declined = 0
    orig_orbit, orig_panel = dry_whirl_orbit.advance, rolling_spin_fast.DryWhirl.advance
    orig_driven = dry_whirl_driven.advance
    on_orbit = kind in ("orbit", "driven")
    orig = {"orbit": orig_orbit, "driven": orig_driven}.get(kind, orig_panel)

    def counted(*a: Any, **k: Any) -> Any:
        nonlocal used, declined
        out = orig(*a, **k)
        end = out[0] if on_orbit else out
        used += end is not None
        declined += end is None and kind != "driven"
        return out

    def counted_panel(*a: Any, **k: Any) -> Any:
        nonlocal used, declined
        out = orig_panel(*a, **k)
        used += out is not None
        declined += out is None
        return out

    p = RotorParams(g=9.81)
    core = SpinCore(p, 0.5 * p.m * p.R ** 2, Omega0=W)
    th, dth = -math.pi / 2, -p.R * W / p.c_r
    nn = cmath.exp(1j * th)
    core.set_state(replace(core.state, mode=2, theta=th, dtheta=dth, slip=0.0,
                           z=p.c_r * nn, v=1j * p.c_r * dth * nn))
    keep = rolling_spin_fast.BETA_DIRECT
    if kind == "orbit":
        dry_whirl_orbit.advance = counted
    elif kind == "driven":
        dry_whirl_driven.advance = counted
        rolling_spin_fast.DryWhirl.advance = counted_panel  # type: ignore[method-assign]
    else:
        rolling_spin_fast.DryWhirl.advance = counted  # type: ignore[method-assign]
    spin_contact.SpinContact.accelerate = True
    spin_contact.SpinContact.follow_orbit = on_orbit
    try:
        if kind == "levin":
            rolling_spin_fast.BETA_DIRECT = -1.0
        for _ in range(5):
            core.step(H, amb_on=0.0, T_drive=T_DRIVE if kind.startswith("driven") else 0.0)
    finally:
        dry_whirl_orbit.advance = orig_orbit
        dry_whirl_driven.advance = orig_driven
        rolling_spin_fast.DryWhirl.advance = orig_panel  # type: ignore[method-assign]
        rolling_spin_fast.BETA_DIRECT = keep
        spin_contact.SpinContact.follow_orbit = True
    return used, declined


def count(speeds: tuple[float, ...] = SPEEDS, kinds: tuple[str, ...] = KINDS
          ) -> dict[str, dict[str, float]]:
    out: dict[str, dict[str, float]] = {k: {} for k in kinds}
    with tempfile.TemporaryDirectory() as tmp:
        script = Path(tmp) / "child.py"
        script.write_text(CHILD.replace("TDRIVE", repr(T_DRIVE)))
        src = str(ROOT / "fmu_src")
        for W in speeds:
            for kind in kinds:
                if kind in KERNELS:
                    used, declined = sanity(W, kind)
                    assert used >= 5 and declined == 0, (W, kind, used, declined)
                per_step = BI.per_unit(script, [src, kind, repr(W)], N_SHORT, N_LONG)
                out[kind][f"{W:g}"] = per_step / H
                print(f"{kind:>7} Omega = {W:6g} rad/s: {per_step / 1e3:9.1f} k instructions "
                      f"per step, {per_step / H / 1e9:7.3f} G per simulated second",
                      flush=True)
    return out


def summary(ips: dict[str, dict[str, float]]) -> dict[str, dict[str, float]]:
    res = {}
    for kind, row in ips.items():
        v = list(row.values())
        lo_w, hi_w = SPEEDS[0], SPEEDS[-1]
        expo = math.log(row[f"{hi_w:g}"] / row[f"{lo_w:g}"]) / math.log(hi_w / lo_w)
        res[kind] = {"max_over_min": max(v) / min(v), "power_law_exponent": expo}
        print(f"{kind:>7}: max/min over the speeds = {max(v) / min(v):5.2f}, "
              f"cost ~ Omega^{expo:.2f} (60 -> 2000 rad/s)")
    return res


def against_the_floor(orbit: dict[str, float]) -> dict[str, Any]:
    """The floor FMU's step (``bench_spin.rolling_fmu_steps``) and each speed's rolling step
    on the orbit (``orbit``: instructions per simulated second by speed) over it: issue 26's
    "rolling steps at most the floor's step"; and RotorTouchdown's rolling step through
    FMPy at those steps."""
    import bench_spin

    fmu, floor = bench_spin.rolling_fmu_steps()
    ratios = {w: v * H / floor for w, v in orbit.items()}
    print(f"floor FMU step {floor / 1e3:.1f}k instructions; rolling step on the orbit over "
          "it: " + ", ".join(f"{r:.3f} at {w} rad/s" for w, r in ratios.items()))
    print(f"RotorTouchdown rolling through FMPy: {fmu / 1e3:.1f}k per step, "
          f"{fmu / floor:.2f} of the floor's")
    return {"floor_fmu_step": floor, "orbit_step_over_floor": ratios,
            "fmu_rolling_step": fmu}


def step_errors() -> dict[str, dict[str, dict[str, float]]]:
    """Errors of one 1e-4 s step against the 40-digit reference (module docstring, 2.)."""
    from rotortd.params import RotorParams
    from rotortd.segments import spin_contact
    from rotortd.segments.spin_contact import HeldInputs, SpinContact

    from tests.reference.spin_mp import mp_contact

    p = RotorParams(g=9.81)
    par = {f: getattr(p, f) for f in ("m", "c", "k", "e_c", "phi", "c_r", "R", "mu", "d",
                                      "g", "levitate")}
    J, th0, psi0 = 0.5 * p.m * p.R ** 2, -1.3, 0.4
    mc = p.m * p.c_r
    out: dict[str, dict[str, dict[str, float]]] = {
        "orbit": {}, "panels": {}, "old": {}, "driven": {}, "driven_panels": {}}
    for W in SPEEDS:
        refs = {T: mp_contact(par, J, 0, th0, 0.0, psi0, W, H, a=0.0, T_drive=T)
                for T in (0.0, T_DRIVE)}
        for kind in out:
            T = T_DRIVE if kind.startswith("driven") else 0.0
            ref = refs[T]
            seg = SpinContact(HeldInputs(p, J, 0.0, 0j, T), 0.0, th0, 0.0, psi0, W)
            seg.accelerate = kind != "old"
            seg.follow_orbit = kind in ("orbit", "driven")
            end = seg.run(H, 10 ** 9)
            tal = end.tally
            assert tal is not None
            S = max(abs(float(ref["P_n"])), mc * tal.peak * H)
            e = {"theta": abs(end.theta - ref["theta"]) / (1 + abs(end.theta - th0)),
                 "psi": abs(end.psi - ref["psi"]) / (1 + abs(end.psi - psi0)),
                 "Omega": abs(end.Omega - ref["Omega"]) / W,
                 "P_n": abs(mc * tal.I_n - ref["P_n"]) / S,
                 "P_t": abs(mc * tal.I_t - ref["P_t"]) / S,
                 "P_c": abs(mc * tal.I_c - ref["P_c"]) / S}
            out[kind][f"{W:g}"] = {k: float(v) for k, v in e.items()}
            print(f"error of one step, {kind:>4}, Omega = {W:6g}: max "
                  f"{max(out[kind][f'{W:g}'].values()):.1e} "
                  + " ".join(f"{k}={float(v):.1e}" for k, v in e.items()), flush=True)
        spin_contact.SpinContact.accelerate = True
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--no-errors", action="store_true")
    ap.add_argument("--quick", nargs=2, metavar=("KINDS", "SPEEDS"),
                    help="count only these (comma-separated), print, write nothing")
    ap.add_argument("--torque", type=float, metavar="T",
                    help="with --quick: the driven kinds' T_drive (N m) in place of T_DRIVE")
    ap.add_argument("--floor-only", action="store_true",
                    help="only the floor FMU's step (3.), into the existing file, ~2 min")
    args = ap.parse_args()
    if args.floor_only:
        result = json.loads(OUT.read_text())
        result.update(against_the_floor({**result["instructions_per_simulated_s"]["orbit"],
                                         f"{EXTRA:g}": result["kernels_at_6000_rad_s"]["orbit"]}))
        OUT.write_text(json.dumps(result, indent=1) + "\n")
        print(f"wrote {OUT.relative_to(ROOT)}")
        return 0
    if args.quick:
        global T_DRIVE
        T_DRIVE = T_DRIVE if args.torque is None else args.torque
        count(tuple(float(w) for w in args.quick[1].split(",")),
              tuple(args.quick[0].split(",")))
        return 0
    ips = count()
    extra = count((EXTRA,), KERNELS)
    result: dict[str, Any] = {"instructions_per_simulated_s": ips, "summary": summary(ips),
                              "kernels_at_6000_rad_s": {k: v[f"{EXTRA:g}"]
                                                       for k, v in extra.items()}}
    result.update(against_the_floor({**ips["orbit"], **{f"{EXTRA:g}": extra["orbit"][
        f"{EXTRA:g}"]}}))
    if not args.no_errors:
        result["step_error_vs_40_digits"] = step_errors()
    OUT.write_text(json.dumps(result, indent=1) + "\n")
    print(f"wrote {OUT.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
