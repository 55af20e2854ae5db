"""Regenerate the co-simulation figures and numbers of docs/cosimulation.md (about 8 minutes).

    python docs/scripts/cosim.py            # needs models/*.fmu (python build.py)

Writes models/systems/<scene>.ssp, runs each scene on libcosimpy in a subprocess, plots
speed, orbit, contact force and mode to docs/img/cosim_<scene>.png, and measures the
coupling error of the drop scene with the PI drive against the communication step with the
in-process master (rotortd_cosim.coupling.spin_jacobi, bit-identical to ecospy): the error
at 0.2 s, at 0.35 s and the largest over the run, against the O(h)-extrapolated limit of
h = 1e-5 and 5e-6 s; and the former held-Omega coupling's chatter in the dry whirl
(docs/img/cosim_coupling.png, printed).
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import matplotlib
import matplotlib.ticker

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "fmu_src"))

from rotortd_cosim.coupling import Trace, jacobi_drop_trace, spin_jacobi  # noqa: E402
from rotortd_cosim.scenes import DROP, SCENES  # noqa: E402
from rotortd_cosim.ssp import write_all  # noqa: E402

IMG = ROOT / "docs" / "img"
C_R = 0.7e-3


def run_scene(name: str, tmp: Path) -> dict[str, np.ndarray]:
    """One scene on libcosimpy, in a subprocess."""
    out = tmp / f"{name}.npz"
    subprocess.run([sys.executable, "-m", "rotortd_cosim.run", "libcosim", name,
                    str(ROOT / "models" / "systems" / f"{name}.ssp"), str(out)],
                   check=True, cwd=ROOT, capture_output=True)
    return dict(np.load(out))


def plot_scene(name: str, res: dict[str, np.ndarray]) -> Path:
    """Speed, orbit, contact force and mode of one scene."""
    t, r = res["time"], "RotorTouchdown."
    fig, ax = plt.subplots(2, 2, figsize=(11, 7.5))
    ax[0, 0].plot(t, res["RotorTouchdown.Omega_out"])
    ax[0, 0].set(xlabel="t [s]", ylabel="Omega [rad/s]", title="spin speed")
    th = np.linspace(0, 2 * np.pi, 400)
    ax[0, 1].plot(np.cos(th), np.sin(th), "k", lw=0.8)
    ax[0, 1].plot(res[r + "x"] / C_R, res[r + "y"] / C_R, lw=0.4)
    ax[0, 1].set(xlabel="x/c_r", ylabel="y/c_r", title="orbit", aspect="equal")
    ax[1, 0].plot(t, np.hypot(res[r + "F_bx"], res[r + "F_by"]), lw=0.6, label="|F_b|")
    ax[1, 0].plot(t, np.abs(res[r + "T_f"]) / 0.04, lw=0.6, label="|T_f|/R")
    ax[1, 0].set(xlabel="t [s]", ylabel="N (step averages)", title="contact force",
                 yscale="symlog")
    ax[1, 0].legend()
    ax[1, 1].plot(t, res[r + "mode"], drawstyle="steps-post", label="mode")
    ax[1, 1].plot(t, res[r + "n_impacts"] / max(1.0, res[r + "n_impacts"][-1]) * 2,
                  label="impacts (scaled)")
    ax[1, 1].set(xlabel="t [s]", title="mode (0 free, 1 sliding, 2 rolling)")
    ax[1, 1].legend()
    fig.suptitle(f"{SCENES[name].title} (libcosimpy, h = {SCENES[name].step:g} s)")
    fig.tight_layout()
    path = IMG / f"cosim_{name}.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


STEPS = (4e-4, 2e-4, 1e-4, 5e-5, 2e-5)      # s, all multiples of the reference grid
REF_STEPS = (1e-5, 5e-6)                      # s, the limit: 2 Omega(5e-6) - Omega(1e-5)
GRID = 1e-5                                   # s, where the errors are compared


def _on_grid(tr: Trace, h: float) -> np.ndarray:
    """Omega [rad/s] of a trace at the communication points on the 1e-5 s grid."""
    om = np.asarray(tr.Omega)
    stride = round(GRID / h)
    if stride >= 1:   # h <= GRID: every stride-th point
        return om[stride - 1::stride]
    raise ValueError(h)


def coupling_study() -> Path:
    """Error of Omega_out against the communication step, drop scene, PI drive."""
    t0 = time.process_time()
    fine, finer = (spin_jacobi(DROP, h) for h in REF_STEPS)
    lim = 2.0 * _on_grid(finer, REF_STEPS[1]) - _on_grid(fine, REF_STEPS[0])
    t_grid = GRID * np.arange(1, len(lim) + 1)
    # grid points with no impact of the reference within +-0.5 ms: an impact changes Omega
    # by up to several rad/s at once, so an O(h) shift of its time is an O(1) error there
    n_ref = np.concatenate([[0], np.asarray(fine.n_impacts)])
    w = round(5e-4 / GRID)
    quiet = np.array([n_ref[max(0, i - w)] == n_ref[min(len(lim), i + w + 1)]
                      for i in range(len(lim))])
    rows = []
    for h in STEPS:
        tr = spin_jacobi(DROP, h)
        om, t = np.asarray(tr.Omega), np.asarray(tr.time)
        k = np.round(t / GRID).astype(int) - 1
        err = np.abs(om - lim[k])
        at = {x: float(err[round(x / h) - 1]) for x in (0.2, 0.35)}
        q = np.where(quiet[k], err, 0.0)
        worst = int(np.argmax(q))
        rows.append({"h": h, "err_0.2": at[0.2], "err_0.35": at[0.35],
                     "err_roll": float(np.max(err[t > 0.265])),
                     "err_max": float(q[worst]), "t_max": float(t[worst]),
                     "err_all": float(np.max(err)), "impacts": tr.n_impacts[-1]})
    held = jacobi_drop_trace(1e-4, DROP.stop_time)
    spin = spin_jacobi(DROP, 1e-4)
    hs = np.array([r["h"] for r in rows])
    slopes = {key: float(np.polyfit(np.log(hs[:4]), np.log([r[key] for r in rows[:4]]), 1)[0])
              for key in ("err_0.2", "err_0.35", "err_roll", "err_max")}
    late = np.asarray(held.time) > 0.3
    chatter = np.asarray(held.Omega)[late]
    print("h [s]   |dOmega| at 0.2 s, at 0.35 s, max rolling (t > 0.265 s), max away from "
          "impacts (at t), max at all points; impacts [rad/s]")
    for r in rows:
        print(f"{r['h']:7.0e} {r['err_0.2']:10.3e} {r['err_0.35']:10.3e} {r['err_roll']:10.3e}"
              f" {r['err_max']:10.3e} ({r['t_max']:.4f} s) {r['err_all']:10.3e} "
              f"{r['impacts']:6d}")
    print("fitted slopes over h = 4e-4 ... 5e-5 s:", json.dumps(slopes))
    print(f"held Omega at 1e-4 s after 0.3 s: {chatter.min():.2f} ... {chatter.max():.2f} "
          f"rad/s, mean step-to-step change {np.mean(np.abs(np.diff(chatter))):.2f} rad/s; "
          f"spin state: {min(spin.Omega[-500:]):.2f} ... {max(spin.Omega[-500:]):.2f} rad/s")
    print(f"CPU {time.process_time() - t0:.0f} s")
    fig, ax = plt.subplots(1, 2, figsize=(12, 4.5))
    for key, label in (("err_0.2", "at 0.2 s (26 impacts)"),
                       ("err_0.35", "at 0.35 s (dry whirl)"),
                       ("err_roll", "largest while rolling (t > 0.265 s)"),
                       ("err_max", "largest 0.5 ms or more from an impact")):
        ax[0].loglog(hs, [r[key] for r in rows], "o-", label=label)
    ax[0].loglog(hs, [rows[2]["err_max"] * h / 1e-4 for h in hs], "k:", label="O(h)")
    ax[0].axhline(0.1, color="grey", lw=0.6)
    ax[0].xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax[0].set_xticks(hs, [f"{h:.0e}" for h in hs])
    ax[0].set(xlabel="communication step h [s]", ylabel="|Omega_out - limit| [rad/s]",
              title="drop scene, PI drive, spin a state of the bearing")
    ax[0].legend()
    ax[1].plot(held.time, held.Omega, lw=0.5, label="held Omega (former coupling), h = 1e-4")
    ax[1].plot(spin.time, spin.Omega, lw=1.0, label="spin a state (integrate_spin), h = 1e-4")
    ax[1].plot(t_grid, lim, "k--", lw=0.8, label="spin a state, limit h -> 0")
    ax[1].set(xlabel="t [s]", ylabel="Omega [rad/s]", xlim=(0.24, DROP.stop_time),
              title="into dry whirl: held Omega chatters, the spin state does not")
    ax[1].legend()
    fig.tight_layout()
    path = IMG / "cosim_coupling.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main() -> int:
    write_all(ROOT / "models", ROOT / "models" / "systems")
    with tempfile.TemporaryDirectory() as tmp:
        for name in SCENES:
            print("wrote", plot_scene(name, run_scene(name, Path(tmp))))
    print("wrote", coupling_study())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
