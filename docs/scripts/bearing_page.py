"""The figures and numbers of docs/bearing.md: the drop of issue 24 on the real bearing
(docs/model.md §10), the same drop with each option off, and the drop-outcome map over the
race drag T_b0 and the support stiffness k_b.

    python docs/scripts/bearing_page.py [--quick] [--map] [--no-drops]
        [--n-tb 7] [--n-kb 7] [--map-time 0.3] [--workers 1]

Runs the core directly (``rotortd.TouchdownCore`` with ``BearingParams``; faster than the
FMU, same numbers). The drop: the chapter's rotor with gravity, mu = 0.15, d = 0.9,
J = 0.04 kg m^2, from the levitated whirl at 184.2 rad/s with the bearing failed at t = 0,
steps of 1e-4 s, amb_on = 0, T_drive = 0, for 0.3 s (0.05 s with --quick). Writes
docs/img/bearing_*.png and docs/bearing_page.json (the figures quoted on the page).
--map adds the map (docs/img/bearing_map.png, docs/bearing_map.json); --map alone with
--no-drops skips the drops.
"""

from __future__ import annotations

import argparse
import cmath
import json
import math
import multiprocessing
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "fmu_src"))

from rotortd import BearingParams, RotorParams, TouchdownCore  # noqa: E402

IMG = ROOT / "docs" / "img"
W0 = 184.2
"""Spin at the failure (rad/s)."""
H = 1e-4
"""Core step (s)."""
J_ROTOR = 0.04
"""Polar inertia of the rotor (kg m^2), m R^2 / 2."""
DROP_BEARING: dict[str, Any] = dict(
    race_turns=True, J_b=2e-4, T_b0=0.02, c_bw=1e-5, omega_b0=0.0,
    support_compliant=True, m_b=2.0, k_b=5e7, c_b=2e3,
    contact_compliant=True, k_c=1e9, p_c=1.0)
"""The issue's bearing, every option on (SI)."""
VARIANTS: dict[str, dict[str, Any]] = {
    "drop": {},
    "fixed race": {"race_turns": False},
    "rigid support": {"support_compliant": False},
    "rigid contact": {"contact_compliant": False},
    "fixed race, rigid support": {"race_turns": False, "support_compliant": False},
}
"""The drop and the drop with options off (overrides of DROP_BEARING)."""
SMOOTH = 5e-3
"""Window of the whirl rate's moving average (s)."""
WHIRL_WINDOW = 0.05
"""The last seconds over which the map's outcome is judged."""
WHIRL_MIN = 2.0 * math.pi / WHIRL_WINDOW
"""|mean whirl rate| (rad/s) above which the map calls the end a whirl: at least one turn
of the contact point round the bearing in WHIRL_WINDOW (125.7 rad/s)."""
BACKWARD_SHARE = 0.9
"""Share of the window's step ends with a negative whirl rate that backward whirl needs."""
SETTLED_LAG = 0.1
"""The map's verdict is also taken this many seconds before the end (s): a cell whose two
verdicts differ is marked unsettled."""
T_B0 = (0.002, 20.0)
"""Range of the map's race drag (N m, log): up to 20 N m, where the race no longer breaks
away under the rotor's weight (R_b mu m g = 3.0 N m)."""
K_B = (1e6, 1e9)
"""Range of the map's support stiffness (N/m, log)."""


def drop_core(**overrides: Any) -> TouchdownCore:
    """The issue's drop with the bearing DROP_BEARING updated by ``overrides``."""
    p = RotorParams(g=9.81, d=0.9, mu=0.15)
    Z1 = p.m * p.e_c * W0**2 * cmath.exp(1j * p.phi) / (p.k - p.m * W0**2 + 1j * p.c * W0)
    return TouchdownCore(p, J=J_ROTOR, z0=Z1, v0=1j * W0 * Z1, Omega0=W0,
                         bearing=BearingParams(**{**DROP_BEARING, **overrides}))


@dataclass
class Trace:
    """Step-end samples of one drop (SI: s, m, rad/s, N, J)."""

    t: list[float] = field(default_factory=list)
    z: list[complex] = field(default_factory=list)
    z_b: list[complex] = field(default_factory=list)
    Omega: list[float] = field(default_factory=list)
    omega_b: list[float] = field(default_factory=list)
    whirl: list[float] = field(default_factory=list)
    F_n_peak: list[float] = field(default_factory=list)
    F_s: list[float] = field(default_factory=list)
    E_fric: list[float] = field(default_factory=list)
    E_drag: list[float] = field(default_factory=list)
    transitions: list[tuple[float, str]] = field(default_factory=list)
    cpu_s: float = 0.0
    R: float = 0.0
    R_b: float = 0.0
    c_r: float = 0.0


def whirl_rate(core: TouchdownCore) -> float:
    """Rate of arg(z - z_b) (rad/s): the whirl relative to the race centre."""
    race = core.race
    zb, vb = (race.z_b, race.v_b) if race is not None else (0j, 0j)
    d, dv = core.z - zb, core.v - vb
    rr = abs(d) ** 2
    return (d.conjugate() * dv).imag / rr if rr > 0.0 else 0.0


def run_drop(T: float, overrides: dict[str, Any], record: bool = True) -> Trace:
    """Step the drop for T seconds; record every step end when ``record``."""
    core = drop_core(**overrides)
    race = core.race
    assert race is not None
    tr = Trace(R=core.params.R, R_b=core.params.R + core.params.c_r, c_r=core.params.c_r)
    E_fric = 0.0
    t0 = time.process_time()
    for i in range(1, round(T / H) + 1):
        rep = core.step(H, None, 0j, 0.0, T_drive=0.0)
        if rep.status != 0:
            raise RuntimeError(f"step {i}: status {rep.status}")
        E_fric += rep.E_fric
        tr.transitions += rep.transitions
        tr.F_n_peak.append(rep.F_n_peak)
        tr.whirl.append(whirl_rate(core))
        tr.Omega.append(core.Omega)
        tr.omega_b.append(race.omega_b)
        tr.t.append(i * H)
        if record:
            tr.z.append(core.z)
            tr.z_b.append(race.z_b)
            tr.F_s.append(abs(rep.F_support))
            tr.E_fric.append(E_fric)
            tr.E_drag.append(race.E_drag)
    tr.cpu_s = time.process_time() - t0
    return tr


def smooth(x: list[float], n: int) -> list[float]:
    """Centred moving average over n samples (shorter at the ends)."""
    out, k = [], n // 2
    csum = [0.0]
    for v in x:
        csum.append(csum[-1] + v)
    for i in range(len(x)):
        a, b = max(0, i - k), min(len(x), i + k + 1)
        out.append((csum[b] - csum[a]) / (b - a))
    return out


def summary(tr: Trace, window: float) -> dict[str, Any]:
    """The figures the page quotes for one drop."""
    n = max(1, round(window / H))
    roll = [t for t, m in tr.transitions if m == "rolling"]
    whirl_mean = sum(tr.whirl[-n:]) / len(tr.whirl[-n:])
    i_pk = max(range(len(tr.F_n_peak)), key=tr.F_n_peak.__getitem__)
    return {
        "t_end": tr.t[-1], "first_sticking_s": roll[0] if roll else None,
        "Omega_end": tr.Omega[-1], "Omega_min": min(tr.Omega), "omega_b_end": tr.omega_b[-1],
        "whirl_mean": whirl_mean, "whirl_window_s": window,
        "F_n_peak_max": tr.F_n_peak[i_pk], "t_peak": tr.t[i_pk],
        "F_s_max": max(tr.F_s) if tr.F_s else None,
        "z_b_max_over_c_r": max(abs(z) for z in tr.z_b) / tr.c_r if tr.z_b else None,
        "E_fric_end": tr.E_fric[-1] if tr.E_fric else None,
        "E_drag_end": tr.E_drag[-1] if tr.E_drag else None,
        "last_transition": tr.transitions[-1] if tr.transitions else None,
        "cpu_s": tr.cpu_s,
    }


def plot_drop(tr: Trace, path: Path) -> None:
    """Six panels: orbit, speeds, contact force, support force, whirl rate, heats."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    c_r, t_ms = tr.c_r, [1e3 * t for t in tr.t]
    fig, ax = plt.subplots(3, 2, figsize=(11, 11))
    a = ax[0][0]
    rel = [z - zb for z, zb in zip(tr.z, tr.z_b)]
    a.plot([d.real / c_r for d in rel], [d.imag / c_r for d in rel], lw=0.4,
           label="rotor centre − race centre")
    a.plot([zb.real / c_r for zb in tr.z_b], [zb.imag / c_r for zb in tr.z_b], lw=0.8,
           color="C3", label="race centre")
    th = [2 * math.pi * k / 200 for k in range(201)]
    a.plot([math.cos(x) for x in th], [math.sin(x) for x in th], "k--", lw=0.6,
           label="clearance c_r")
    a.set_aspect("equal")
    a.set_xlabel("x / c_r")
    a.set_ylabel("y / c_r")
    a.set_title("orbit")
    a.legend(fontsize=7, loc="upper right")
    a = ax[0][1]
    a.plot(t_ms, tr.Omega, label="Ω (rotor)")
    a.plot(t_ms, tr.omega_b, label="ω_b (race)")
    a.set_ylabel("rad/s")
    a2 = a.twinx()
    a2.plot(t_ms, [tr.R * w for w in tr.Omega], "C0:", lw=0.8, label="R Ω")
    a2.plot(t_ms, [tr.R_b * w for w in tr.omega_b], "C1:", lw=0.8, label="R_b ω_b")
    a2.set_ylabel("surface speed, m/s")
    a.set_title("spin of rotor and race (dotted: surface speeds, right axis)")
    a.legend(loc="center right", fontsize=7)
    a2.legend(loc="lower right", fontsize=7)
    a = ax[1][0]
    a.plot(t_ms, [f / 1e3 for f in tr.F_n_peak], lw=0.6)
    a.set_ylabel("F_n_peak, kN")
    a.set_title("contact force: its peak in each 0.1 ms step")
    a = ax[1][1]
    a.plot(t_ms, [f / 1e3 for f in tr.F_s], lw=0.6, color="C3")
    a.set_ylabel("|F_s|, kN")
    a.set_title("force of the support on the frame (step mean)")
    a = ax[2][0]
    a.plot(t_ms, tr.whirl, lw=0.3, color="0.7", label="step end")
    a.plot(t_ms, smooth(tr.whirl, round(SMOOTH / H)), lw=1.0,
           label=f"moving mean {1e3 * SMOOTH:g} ms")
    a.axhline(0.0, color="k", lw=0.5)
    a.set_ylabel("whirl_rate, rad/s")
    a.set_title("whirl relative to the race centre (> 0 forward)")
    a.legend(fontsize=7)
    a = ax[2][1]
    a.plot(t_ms, tr.E_fric, label="E_fric (contact friction)")
    a.plot(t_ms, tr.E_drag, label="E_drag (race drag)")
    a.set_ylabel("J")
    a.set_title("heat put into the bearing (cumulative)")
    a.legend(fontsize=7)
    for a in (ax[0][1], ax[1][0], ax[1][1], ax[2][0], ax[2][1]):
        a.set_xlabel("t, ms")
        a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def plot_variants(traces: dict[str, Trace], path: Path) -> None:
    """Omega, smoothed whirl rate and per-step peak force of every variant."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(3, 1, figsize=(10, 10), sharex=True)
    for k, (name, tr) in enumerate(traces.items()):
        t_ms = [1e3 * t for t in tr.t]
        ax[0].plot(t_ms, tr.Omega, color=f"C{k}", label=name)
        ax[1].plot(t_ms, smooth(tr.whirl, round(SMOOTH / H)), color=f"C{k}", lw=0.8,
                   label=name)
        ax[2].semilogy(t_ms, [max(f, 1.0) / 1e3 for f in tr.F_n_peak], color=f"C{k}",
                       lw=0.5, label=name)
    ax[0].set_ylabel("Ω, rad/s")
    ax[1].set_ylabel(f"whirl_rate, {1e3 * SMOOTH:g} ms mean, rad/s")
    ax[1].axhline(0.0, color="k", lw=0.5)
    ax[2].set_ylabel("F_n_peak, kN")
    ax[2].set_xlabel("t, ms")
    ax[0].legend(fontsize=8)
    ax[0].set_title("the drop with each option off")
    for a in ax:
        a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def geomspace(lo: float, hi: float, n: int) -> list[float]:
    """n values from lo to hi, geometric, both ends exact."""
    if n == 1:
        return [lo]
    return [lo * (hi / lo) ** (k / (n - 1)) for k in range(n - 1)] + [hi]


def window_verdict(tr: Trace, t_end: float) -> dict[str, Any]:
    """The map's rule over the WHIRL_WINDOW seconds before ``t_end``: backward whirl when
    the mean whirl rate is below -WHIRL_MIN (at least one turn backward round the race) and
    the whirl rate is negative at BACKWARD_SHARE of the step ends (a steady backward whirl,
    not a rocking swing)."""
    i1 = round(t_end / H)
    w = tr.whirl[i1 - round(WHIRL_WINDOW / H):i1]
    mean = sum(w) / len(w)
    share = sum(x < 0.0 for x in w) / len(w)
    return {"whirl_mean": mean, "neg_share": share,
            "backward": mean < -WHIRL_MIN and share >= BACKWARD_SHARE}


def map_cell(args: tuple[float, float, float]) -> dict[str, Any]:
    """One cell of the map: the drop with T_b0 (N m) and k_b (N/m) for T seconds; the
    verdict at T and, as a check that it is settled, at T - SETTLED_LAG."""
    T_b0, k_b, T = args
    tr = run_drop(T, {"T_b0": T_b0, "k_b": k_b}, record=False)
    s = summary(tr, WHIRL_WINDOW)
    end = window_verdict(tr, T)
    early = window_verdict(tr, T - SETTLED_LAG) if T - SETTLED_LAG >= WHIRL_WINDOW else end
    return {"T_b0": T_b0, "k_b": k_b, **end, "backward_early": early["backward"],
            "whirl_mean_early": early["whirl_mean"], "settled": early["backward"] ==
            end["backward"], "Omega_end": s["Omega_end"], "omega_b_end": s["omega_b_end"],
            "F_n_peak_max": s["F_n_peak_max"], "first_sticking_s": s["first_sticking_s"],
            "cpu_s": s["cpu_s"]}


def run_map(n_tb: int, n_kb: int, T: float, workers: int) -> dict[str, Any]:
    """The grid n_tb x n_kb over T_B0 and K_B (log), each cell a drop of T seconds."""
    cells = [(tb, kb, T) for kb in geomspace(*K_B, n_kb) for tb in geomspace(*T_B0, n_tb)]
    t0 = time.perf_counter()
    with multiprocessing.get_context("spawn").Pool(max(1, min(workers, 1))) as pool:
        rows = pool.map(map_cell, cells, chunksize=1)
    return {"n_tb": n_tb, "n_kb": n_kb, "drop_time_s": T, "window_s": WHIRL_WINDOW,
            "whirl_min": WHIRL_MIN, "backward_share": BACKWARD_SHARE,
            "settled_lag_s": SETTLED_LAG, "wall_s": time.perf_counter() - t0, "cells": rows}


def plot_map(res: dict[str, Any], path: Path) -> None:
    """Two panels: mean whirl rate of the window (backward marked) and the peak load."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm, TwoSlopeNorm

    rows = res["cells"]
    tb = sorted({r["T_b0"] for r in rows})
    kb = sorted({r["k_b"] for r in rows})
    grid = {(r["T_b0"], r["k_b"]): r for r in rows}
    W = [[grid[(x, y)]["whirl_mean"] for x in tb] for y in kb]
    P = [[grid[(x, y)]["F_n_peak_max"] / 1e3 for x in tb] for y in kb]
    fig, ax = plt.subplots(1, 2, figsize=(12, 5))
    lim = max(abs(v) for row in W for v in row) or 1.0
    m0 = ax[0].pcolormesh(tb, kb, W, shading="nearest", cmap="coolwarm_r",
                          norm=TwoSlopeNorm(0.0, -lim, lim))
    fig.colorbar(m0, ax=ax[0], label=f"mean whirl_rate, last {res['window_s']:g} s (rad/s)")
    m1 = ax[1].pcolormesh(tb, kb, P, shading="nearest", cmap="viridis",
                          norm=LogNorm(min(min(r) for r in P), max(max(r) for r in P)))
    fig.colorbar(m1, ax=ax[1], label="peak load max F_n_peak (kN)")
    for a in ax:
        for r in rows:
            a.plot(r["T_b0"], r["k_b"], "kx" if r["backward"] else "wo", ms=7, mfc="none")
            if not r["settled"]:
                a.plot(r["T_b0"], r["k_b"], "ks", ms=12, mfc="none")
        a.plot(DROP_BEARING["T_b0"], DROP_BEARING["k_b"], "k*", ms=12, mfc="gold")
        a.set_xscale("log")
        a.set_yscale("log")
        a.set_xlabel("race drag T_b0, N m")
        a.set_ylabel("support stiffness k_b, N/m")
    ax[0].set_title("whirl at the end (x: backward, o: not; square: verdict changed "
                    f"in the last {SETTLED_LAG:g} s)", fontsize=9)
    ax[1].set_title("peak contact load over the drop")
    fig.suptitle(f"drop outcome over T_b0 and k_b ({res['drop_time_s']:g} s drops; "
                 "star: the page's drop)")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main() -> None:
    """Run the drops (and the map with --map), write the images and the JSON summaries."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="0.05 s drops, 3 x 3 map of 0.05 s")
    ap.add_argument("--map", action="store_true", help="also the T_b0 x k_b map")
    ap.add_argument("--no-drops", action="store_true", help="skip the drops (with --map)")
    ap.add_argument("--n-tb", type=int, default=7, help="map cells along T_b0")
    ap.add_argument("--n-kb", type=int, default=7, help="map cells along k_b")
    ap.add_argument("--map-time", type=float, default=0.3, help="s, each map drop")
    ap.add_argument("--workers", type=int, default=1, help="map processes (at most 1)")
    ap.add_argument("--out", type=Path, default=ROOT / "docs",
                    help="directory of the JSON files; images go to its img/")
    args = ap.parse_args()
    T = 0.05 if args.quick else 0.3
    img = args.out / "img"
    img.mkdir(parents=True, exist_ok=True)
    if not args.no_drops:
        traces = {name: run_drop(T, ov) for name, ov in VARIANTS.items()}
        window = min(0.1, T / 2)
        out = {name: summary(tr, window) for name, tr in traces.items()}
        for name, s in out.items():
            print(f"{name:28s} " + ", ".join(
                f"{k} {v:.6g}" if isinstance(v, float) else f"{k} {v}" for k, v in s.items()))
        plot_drop(traces["drop"], img / "bearing_drop.png")
        plot_variants(traces, img / "bearing_variants.png")
        (args.out / "bearing_page.json").write_text(json.dumps(
            {"drop_time_s": T, "step_s": H, "bearing": DROP_BEARING, "variants": VARIANTS,
             "results": out}, indent=1) + "\n")
    if args.map:
        n_tb, n_kb, Tm = (3, 3, 0.05) if args.quick else (args.n_tb, args.n_kb,
                                                           args.map_time)
        res = run_map(n_tb, n_kb, Tm, args.workers)
        for r in res["cells"]:
            print(f"T_b0 {r['T_b0']:.3g} k_b {r['k_b']:.3g}: whirl {r['whirl_mean']:.1f} "
                  f"neg {r['neg_share']:.2f} backward {r['backward']} (early "
                  f"{r['whirl_mean_early']:.1f} {r['backward_early']}) "
                  f"peak {r['F_n_peak_max']:.4g} N "
                  f"Omega {r['Omega_end']:.2f} cpu {r['cpu_s']:.1f} s")
        print(f"map: {n_tb} x {n_kb}, wall {res['wall_s']:.1f} s")
        plot_map(res, img / "bearing_map.png")
        (args.out / "bearing_map.json").write_text(json.dumps(res, indent=1) + "\n")


if __name__ == "__main__":
    main()
