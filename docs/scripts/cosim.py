"""Regenerate the co-simulation figures of docs/cosimulation.md (about 2 minutes).

    python docs/scripts/cosim.py            # needs models/*.fmu (python build.py)

Writes models/systems/<scene>.ssp, runs each scene on libcosimpy in a subprocess, plots
speed, orbit, contact force and mode to docs/img/cosim_<scene>.png, and measures the
coupling error against the communication step (docs/img/cosim_coupling.png, printed).
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "fmu_src"))

from rotortd_cosim.coupling import jacobi_drop, spin_drop  # noqa: E402
from rotortd_cosim.scenes import SCENES  # noqa: E402
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
    ax[0, 0].plot(t, res["Drivetrain.Omega"])
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


def coupling_study(t_end: float = 0.13) -> Path:
    """Omega(t_end) error of the drop scene against the communication step."""
    hs = [1e-3, 1e-4, 1e-5]
    ref, _, _ = jacobi_drop(1e-6, t_end)
    held = [abs(jacobi_drop(h, t_end)[0] - ref) for h in hs]
    spin = [abs(spin_drop(h, 1e-6, t_end)[0] - ref) for h in hs]
    print("h [s]   |dOmega| held [rad/s]   |dOmega| integrate_spin [rad/s]")
    for h, a, b in zip(hs, held, spin):
        print(f"{h:7.0e} {a:12.3e} {b:12.3e}")
    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.loglog(hs, held, "o-", label="Omega held over the step")
    ax.loglog(hs, spin, "s-", label="integrate_spin, h_spin = 1e-6 s")
    ax.loglog(hs, [held[1] * h / 1e-4 for h in hs], "k:", label="O(h)")
    ax.set(xlabel="communication step h [s]", ylabel=f"|Omega({t_end} s) - ref| [rad/s]",
           title="drop scene, reference h = 1e-6 s")
    ax.legend()
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
