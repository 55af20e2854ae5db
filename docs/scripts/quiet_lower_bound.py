"""The least a held-speed quiet FMU step can cost in CPython: issue 26, item 3, measured.

    python docs/scripts/quiet_lower_bound.py          # ~12 min (valgrind's callgrind)

Issue 26 item 3 asks for RotorTouchdown's quiet step (the free whirl, doStep at 1e-3 s, all
outputs read every step: ``bench_instructions.py``'s FMU loop) at most 1.10 times the floor
FMU's instructions. The floor (``benchmarks.FLOOR_TEMPLATE``) is RotorTouchdown's variables
and publishing with a ``do_step`` that computes nothing, so 1.10 leaves the model 10 % of
the floor's count for everything it does per step.

This script builds a third FMU beside the two of ``bench_instructions.py``: the floor with a
``do_step`` that does only the arithmetic a quiet step cannot skip, as lean as it can be
written, and counts it in the same loop. Per step it

- advances the state (z, v) by the flight map of the step, whose eight coefficients are
  precomputed (the core's ``FlightModel.coeffs``, here constants of the FMU);
- advances the spin angle with the core's wrap and the clock with its compensated sum;
- computes T_imb from its four precomputed coefficients (``FlightModel.imb_impulse``);
- computes the 20 state outputs with the formulas of ``TouchdownCore.output_values`` and
  publishes them, and the report's, exactly as the floor does.

It checks nothing: no input, time, step-size or non-finite check, no work bound, no report,
no proof of clearance (the whirl is known clear), no call into a core. Any FMU that
publishes these outputs of a moving state in CPython does at least this, so its ratio to
the floor is a lower bound of the ratio that item 3 can reach. The script first checks that
this lean step is the model: after 1000 steps its outputs equal the core's to 1e-12
relative (the same formulas and the core's own flight map: they differ only by the
rounding of the terms' order, 1e-16 per step).
The three FMUs are counted under several memory layouts of the interpreter
(``bench_instructions.LAYOUT_PADS``: the same code counts up to about 1.5 % apart from one
to another); prints the counts under each, and the medians, the FMU ratio's range and the
own work of RotorTouchdown and of the lean step; writes docs/quiet_lower_bound.json.
"""

from __future__ import annotations

import json
import pickle
import statistics
import sys
import tempfile
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "fmu_src"))

import bench_instructions as BI
import benchmarks as B
from rotortd import TouchdownCore
from rotortd.scaled import TWO_PI_HI, TWO_PI_LO

H = 1e-3
"""The communication step (s) of bench_instructions.py's FMU loop."""

LEAN_STEP = '''
    def do_step(self, current_time, step_size):
        z, v, psi, t, t_lo = self._lean
        E = exp(1j * psi)
        z1 = P11 * z + P12 * v + QZ
        z1 += GZ * E
        v1 = P21 * z + P22 * v + QV
        v1 += GV * E
        P = (E.conjugate() * (BZ * z + BV * v + B0)).imag + BE
        x = psi + DPSI
        k = floor((x + PI) / TWO_PI_HI)
        if k:
            x = (x - k * TWO_PI_HI) - k * TWO_PI_LO
        y = H - t_lo
        t1 = t + y
        self._lean = (z1, v1, x, t1, (t1 - t) - y)
        rot = exp(1j * x).conjugate()
        U = z1 * rot
        dU = (v1 - IW * z1) * rot / DEN
        r = abs(z1)
        rr = r * r
        zr, zi, vr, vi = z1.real, z1.imag, v1.real, v1.imag
        whirl = (zr * vi - zi * vr) / rr
        F = BIAS - C * v1 - K * z1
        _publish(self, (zr, zi, vr, vi, r / CR, U.real / CR, U.imag / CR, dU.real, dU.imag,
                        x, whirl, RW + CR * whirl, F.real, F.imag, W, 0, 0, T_LAST, V_LAST,
                        E_DISS), False)
        _REPORT.T_imb = P / H
        self._publish_step_outputs(_REPORT)
        return True
'''


def lean_constants(core: TouchdownCore, h: float) -> dict[str, Any]:
    """The lean step's constants for ``core``'s held inputs and the step h (s)."""
    W, _F, a = core._inputs
    fm = core._fm
    co = fm.coeffs(h)
    imb = fm.imb_impulse(h)
    p = core._p
    return {"P11": co.p11, "P12": co.p12, "P21": co.p21, "P22": co.p22,
            "QZ": fm.f0 * co.qz0, "QV": fm.f0 * co.qv0, "GZ": fm.F1 * co.qzs,
            "GV": fm.F1 * co.qvs, "BZ": imb.bz, "BV": imb.bv, "B0": imb.b0,
            "BE": imb.bE.imag, "DPSI": W * h, "H": h, "IW": 1j * W, "DEN": p.c_r * W,
            "CR": p.c_r, "RW": p.R * W, "BIAS": a * core._bias_force, "C": a * p.c,
            "K": a * p.k, "W": W, "T_LAST": core._t_last, "V_LAST": core._v_last,
            "E_DISS": core._E_diss}


def prelude(consts: dict[str, Any]) -> str:
    """The lean step's module-level names: imports and constants."""
    return ("from cmath import exp\nfrom math import floor, pi as PI\n"
            f"TWO_PI_HI = {TWO_PI_HI!r}\nTWO_PI_LO = {TWO_PI_LO!r}\n"
            + "".join(f"{k} = {v!r}\n" for k, v in consts.items()))


def check_lean(sc: B.Scene, n: int = 1000) -> float:
    """Run the lean step n times in-process against the core; the largest relative
    difference of the 20 state outputs and T_imb after n steps."""
    core = TouchdownCore(sc.params, z0=sc.z0, v0=sc.v0, psi0=sc.psi0)
    core.step(H, B.W, 0j, 1.0)
    ns: dict[str, Any] = {}
    exec(prelude(lean_constants(core, H)) + "\n\nclass Lean:\n" + LEAN_STEP, ns)
    published: dict[str, Any] = {}

    class Report:
        T_imb = 0.0

    ns["_REPORT"] = Report()
    ns["_publish"] = lambda _s, out, _e: published.update(out=out)
    slave = ns["Lean"]()
    slave._publish_step_outputs = lambda rep: published.update(T_imb=rep.T_imb)
    slave._lean = (core._z, core._v, core._psi, core._t, core._t_lo)
    for _ in range(n):
        slave.do_step(0.0, H)
        rep = core.step(H, B.W, 0j, 1.0)
    ref = (*core.output_values(), rep.T_imb)
    got = (*published["out"], published["T_imb"])
    fields = (*core.outputs()._fields, "T_imb")
    # du_re, du_im: the whirl is steady, so they are zero to rounding (~1e-16) in both
    return max(abs(a - b) / (abs(b) if not f.startswith("du_") else 1.0)
               for f, a, b in zip(fields, got, ref) if a != b)


def lean_template(consts: dict[str, Any], start: tuple) -> str:
    """The floor FMU's slave module with the lean do_step in place of the floor's, its
    state (z, v, psi, t, t_lo) starting at ``start``."""
    floor = B.FLOOR_TEMPLATE.format(**B._adapter_tables())
    marker = "    def do_step(self, current_time, step_size):\n"
    head, tail = floor.split(marker)
    rest = tail.split("\n    def _publish_state", 1)[1]
    start = ("\n    def exit_initialization_mode(self):\n"
             f"        self._lean = {start!r}\n        return True\n")
    return (prelude(consts) + head + LEAN_STEP.lstrip("\n") + start
            + "\n    def _publish_state" + rest)


def build_lean(tmp: Path, consts: dict[str, Any], start: tuple) -> tuple[str, Any]:
    """Build the lean FMU into tmp (as benchmarks.build_fmus builds the floor)."""
    from fmpy import extract, read_model_description

    import build

    pkg = tmp / "rotortd_floor_lean"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "slave.py").write_text(lean_template(consts, start))
    script = tmp / "RotorTouchdownLean.py"
    script.write_text(B.FLOOR_SCRIPT.replace("rotortd_floor", "rotortd_floor_lean")
                      .replace("RotorTouchdownFloor(", "RotorTouchdownLean("))
    fmu = build.build_fmu(build.FmuSpec(name="RotorTouchdownLean", script=script,
                                        project_dirs=(pkg,)), tmp / "fmus")
    return extract(str(fmu), str(tmp / "RotorTouchdownLean")), read_model_description(str(fmu))


def count_layout(child: Path, pkl: Path, names: dict[str, str], pad: int) -> dict[str, Any]:
    """The three FMUs' instructions per step under the environment padded by ``pad``
    characters (``bench_instructions.LAYOUT_PADS``)."""
    env = BI.layout_env(pad)
    counts = {k: BI.per_unit(child, [str(pkl), k, "free_whirl"], 200, 4200, env)
              for k in names}
    return {"pad": pad, "counts_per_step": counts,
            "fmu_ratio": counts["fmu"] / counts["floor"],
            "lean_ratio": counts["lean"] / counts["floor"]}


def summary(layouts: list[dict[str, Any]], err: float) -> dict[str, Any]:
    """Medians over the layouts (each figure's own median) and the FMU ratio's range."""
    def med(key: str) -> float:
        return statistics.median(lay[key] for lay in layouts)

    counts = {k: statistics.median(lay["counts_per_step"][k] for lay in layouts)
              for k in layouts[0]["counts_per_step"]}
    floor = counts["floor"]
    return {
        "counts_per_step": counts,
        "fmu_own_work": counts["fmu"] - floor,
        "lean_own_work": counts["lean"] - floor,
        "fmu_ratio": med("fmu_ratio"),
        "fmu_ratio_min": min(lay["fmu_ratio"] for lay in layouts),
        "fmu_ratio_max": max(lay["fmu_ratio"] for lay in layouts),
        "lean_ratio": med("lean_ratio"),
        "budget_at_1.10": 0.10 * floor,
        "lean_vs_core_max_rel_diff": err,
        "layouts": layouts,
    }


def main() -> None:
    sc = next(s for s in B.make_scenes() if s.name == "free_whirl")
    err = check_lean(sc)
    print(f"lean step against the core after 1000 steps: largest relative difference "
          f"{err:.1e}", flush=True)
    if not err <= 1e-12:
        raise SystemExit("the lean step is not the model")
    core = TouchdownCore(sc.params, z0=sc.z0, v0=sc.v0, psi0=sc.psi0)
    core.step(H, B.W, 0j, 1.0)  # (the held inputs set; the whirl is proved clear)
    consts = lean_constants(core, H)
    start = (core._z, core._v, core._psi, core._t, core._t_lo)
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        fmus = B.build_fmus(tmp)
        fmus["RotorTouchdownLean"] = build_lean(tmp, consts, start)
        data: dict[str, Any] = {"outputs": (B.REAL_OUT, B.INT_OUT, B.BOOL_OUT),
                                "free_whirl": B.start_values(sc)}
        names = {"fmu": "RotorTouchdown", "floor": "RotorTouchdownFloor",
                 "lean": "RotorTouchdownLean"}
        for key, name in names.items():
            unzip, md = fmus[name]
            data[key] = {"unzip": unzip, "guid": md.guid,
                         "mid": md.coSimulation.modelIdentifier,
                         "vr": {v.name: v.valueReference for v in md.modelVariables}}
        pkl = tmp / "fmu.pkl"
        pkl.write_bytes(pickle.dumps(data))
        child = BI.write_children(tmp)["fmu"]
        layouts = [count_layout(child, pkl, names, pad) for pad in BI.LAYOUT_PADS]
    result = summary(layouts, err)
    for lay in layouts:
        c = lay["counts_per_step"]
        print(f"layout {lay['pad']:5d}: " + ", ".join(
            f"{names[k]} {c[k] / 1e3:.1f}k" for k in names)
            + f"; RotorTouchdown/floor {lay['fmu_ratio']:.4f}, lean/floor {lay['lean_ratio']:.4f}")
    print(f"median over {len(layouts)} layouts: RotorTouchdown/floor {result['fmu_ratio']:.4f} "
          f"(from {result['fmu_ratio_min']:.4f} to {result['fmu_ratio_max']:.4f}), "
          f"lean/floor {result['lean_ratio']:.4f}; RotorTouchdown's own work "
          f"{result['fmu_own_work'] / 1e3:.1f}k, the lean step's "
          f"{result['lean_own_work'] / 1e3:.1f}k, the 1.10 budget "
          f"{result['budget_at_1.10'] / 1e3:.1f}k")
    out = Path(__file__).resolve().parents[1] / "quiet_lower_bound.json"
    out.write_text(json.dumps(result, indent=1) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
