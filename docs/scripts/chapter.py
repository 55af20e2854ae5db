"""Reproduce the chapter (docs/validation.md §4): equilibria, forward rub, impacting cycles,
Fig. 5-2.

    python docs/scripts/chapter.py

Writes docs/img/chapter_*.png, docs/chapter_results.json and docs/chapter_results.md.
Scaled co-rotating frame and units throughout (docs/model.md §1), chapter parameter set with
gamma varied; the SI realisation is Omega = 184.2 rad/s, m = 50 kg, c_r = 0.7 mm.
"""

from __future__ import annotations

import itertools
import json
import time
from pathlib import Path

import matplotlib
from rotortd.scaled import wrap_angle

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import scipy.optimize
from rotortd_tools import cycles as C

DOCS = Path(__file__).resolve().parents[1]
IMG = DOCS / "img"
GAMMAS = np.linspace(0.05, 0.3, 51)
BRUTE_GAMMAS = np.linspace(0.05, 0.3, 40)
COLORS = {
    "free whirl": "tab:green",
    "impacting": "tab:blue",
    "rub/sliding": "tab:orange",
    "dry whirl/rolling": "tab:red",
}
MARKERS = {"rest": "o", "near U*": "s", "cycle": "^", "large orbit": "D"}


# --------------------------------------------------------------------------- numbers


def beb_numbers() -> dict:
    """gamma_BEB from the formula and from root finding on |U*(gamma)| = 1."""
    sp = C.chapter_params()
    g_formula = C.gamma_beb(sp)
    g_root = scipy.optimize.brentq(
        lambda g: abs(C.regular_equilibrium(C.chapter_params(gamma=g))) - 1.0,
        0.01,
        0.3,
        xtol=1e-15,
    )
    return {"gamma_beb_formula": g_formula, "gamma_beb_root": g_root}


def rub_numbers() -> dict:
    """Range and stability of the forward-rub pseudo-equilibria (core function)."""
    sp = C.chapter_params()
    g_fold = C.rub_fold_gamma(sp)
    g_beb = C.gamma_beb(sp)
    near = [C.rub_equilibria(C.chapter_params(gamma=g_beb + e)) for e in (1e-4, 1e-6, 1e-8)]
    saddle_N = [min(e.N for e in eqs if not e.stable) for eqs in near]
    Us = C.regular_equilibrium(C.chapter_params(gamma=g_beb + 1e-8))
    saddle_alpha = next(e.alpha for e in near[-1] if not e.stable)
    return {
        "gamma_fold_smooth": g_fold,
        "stable_branch": f"0 < gamma <= {g_fold:.6f} (stable node/focus of the sliding motion)",
        "saddle_branch": f"{g_beb:.6f} < gamma <= {g_fold:.6f} (saddle), born at the BEB with N=0",
        "saddle_N_at_gamma_beb_plus_1e-4_1e-6_1e-8": saddle_N,
        "saddle_alpha_minus_arg_Ustar_at_beb_plus_1e-8": wrap_angle(saddle_alpha - np.angle(Us)),
        "examples": {
            f"{g}": [
                {"alpha": e.alpha, "N": e.N, "stable": e.stable, "eig": [str(v) for v in e.eig]}
                for e in C.rub_equilibria(C.chapter_params(gamma=g))
            ]
            for g in (0.065, 0.1, 0.152009, 0.3)
        },
    }


def cycle_dict(c: C.Cycle) -> dict:
    """JSON-able summary of a cycle (scaled co-rotating; SI where named)."""
    return {
        "gamma": c.gamma,
        "branch": c.branch,
        "period_T": c.T,
        "period_si_s": c.T_si,
        "impact_angle_alpha": c.alpha,
        "impact_speed_rdot": c.rdot,
        "impact_speed_si_m_per_s": c.rdot_si,
        "post_impact_x": list(map(float, c.x)),
        "multipliers": [[float(v.real), float(v.imag)] for v in c.multipliers],
        "multiplier_moduli": [float(abs(v)) for v in c.multipliers],
        "stable": c.stable,
        "max_radius_in_flight": c.max_radius,
        "grazing_margin": c.grazing_margin,
        "newton_residual": c.residual,
    }


def core_return_error(c: C.Cycle) -> float:
    """Scaled distance between the cycle's impact and the first impact of a core run."""
    core = c.core()
    rep = core.step(1.5 * c.T_si, C.OMEGA)
    imp = rep.impacts[0]
    E = np.exp(1j * C.OMEGA * imp.t)
    U = imp.z / (C.C_R * E)
    dU = (imp.v_plus - 1j * C.OMEGA * imp.z) / (C.C_R * C.OMEGA * E)
    return float(max(abs(U - c.U0), abs(dU - c.dU0), abs(imp.t * C.OMEGA - c.T)))


# --------------------------------------------------------------------------- figures


def orbit_of_cycle(c: C.Cycle, periods: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """(t, U(t)) over several periods of a cycle (closed-form flight, repeated)."""
    flow = C.ScaledFlow(c.sp)
    ts = np.linspace(0.0, c.T, 400)
    U = flow.states(np.array([c.U0, c.dU0]), ts)[:, 0]
    t_all = np.concatenate([ts + k * c.T for k in range(periods)])
    return t_all, np.tile(U, periods)


def core_samples(c: C.Cycle, t_end: float, dt: float = 0.05) -> tuple[np.ndarray, np.ndarray]:
    """(t, z/c_r) sampled from a TouchdownCore run started on the cycle (cross-check)."""
    core = c.core()
    ts, zs = [], []
    for k in range(round(t_end / dt)):
        core.step(dt / C.OMEGA, C.OMEGA)
        ts.append((k + 1) * dt)
        zs.append(core.z / C.C_R)
    return np.array(ts), np.array(zs)


def fig_orbits(c065: C.Cycle, c01: C.Cycle) -> None:
    """Fig. 5-2: inertial orbit, co-rotating orbit, r(t) for gamma = 0.3, 0.065, 0.1."""
    fig, axs = plt.subplots(3, 3, figsize=(11, 10))
    circ = np.exp(1j * np.linspace(0, 2 * np.pi, 400))
    sp3 = C.chapter_params(gamma=0.3)
    Us = C.regular_equilibrium(sp3)
    t = np.linspace(0, 30, 1500)
    rows = [
        ("(a) regular equilibrium, $\\gamma$ = 0.3", t, np.full_like(t, Us, dtype=complex), None),
        (
            f"(b) cycle near grazing, $\\gamma$ = 0.065 (T = {c065.T:.3f})",
            *orbit_of_cycle(c065),
            c065,
        ),
        (
            f"(c) small cycle near the BEB, $\\gamma$ = 0.1 (T = {c01.T:.3f})",
            *orbit_of_cycle(c01),
            c01,
        ),
    ]
    for i, (title, tt, U, cyc) in enumerate(rows):
        Z = U * np.exp(1j * tt)
        ax = axs[i, 0]
        ax.plot(circ.real, circ.imag, color="0.7", lw=3)
        ax.plot(Z.real, Z.imag, "k", lw=0.8)
        if cyc is not None:
            _, zc = core_samples(cyc, tt[-1] / 2)
            ax.plot(zc.real, zc.imag, ".", ms=2, color="tab:red", label="TouchdownCore")
            ax.legend(loc="lower left", fontsize=7)
        ax.set_title(title + "\ninertial", fontsize=9)
        ax = axs[i, 1]
        ax.plot(circ.real, circ.imag, color="0.7", lw=3)
        ax.plot(U.real, U.imag, "k", lw=1.2)
        ax.plot(
            [Us.real if cyc is None else C.regular_equilibrium(cyc.sp).real],
            [Us.imag if cyc is None else C.regular_equilibrium(cyc.sp).imag],
            "x",
            color="tab:blue",
        )
        ax.set_title("co-rotating (x: U*)", fontsize=9)
        for ax in axs[i, :2]:
            ax.set_aspect("equal")
            ax.set_xlim(-1.15, 1.15)
            ax.set_ylim(-1.15, 1.15)
        ax = axs[i, 2]
        ax.plot(tt, np.abs(U), "k", lw=1)
        ax.axhline(1.0, color="0.7", lw=2)
        ax.set_xlabel("t (scaled)")
        ax.set_ylabel("r")
        r_lo = float(np.abs(U).min())
        ax.set_ylim(r_lo - 0.2 * (1.0 - r_lo) - 0.002, 1.0 + 0.05 * (1.0 - r_lo) + 0.001)
        ax.set_title("r(t)", fontsize=9)
    fig.tight_layout()
    fig.savefig(IMG / "chapter_fig5_2.png", dpi=110)
    plt.close(fig)


def virtual_branch(key: str, g_lo: float, g_hi: float) -> tuple[np.ndarray, np.ndarray]:
    """Closed-form cycle branch ``key`` past grazing (virtual): (gamma, rdot)."""
    gs, rs = [], []
    for g in np.linspace(g_lo, g_hi, 40):
        cyc = C.labelled_cycles(C.chapter_params(gamma=g)).get(key)
        if cyc is not None:
            gs.append(g)
            rs.append(cyc.rdot)
    return np.array(gs), np.array(rs)


def fig_bifurcation(pts: list[C.BranchPoint], attractors: list[C.Attractor], g_graze: float):
    """Bifurcation diagram over gamma in [0.05, 0.3]."""
    fig, axs = plt.subplots(4, 1, figsize=(9, 13), sharex=True)
    sp0 = C.chapter_params()
    g_beb = C.gamma_beb(sp0)
    # (a) cycles
    ax = axs[0]
    for name, col in (("large", "k"), ("small", "tab:purple")):
        bp = [p for p in pts if p.branch == name and p.event is None]
        for a, b in itertools.pairwise(bp):
            ls = "-" if (a.stable and b.stable) else "--"
            ax.plot([a.gamma, b.gamma], [a.rdot, b.rdot], ls, color=col, lw=1.5)
    gv, rv = virtual_branch("long-large", 0.05, g_graze)
    ax.plot(gv, rv, ":", color="0.6", label="virtual (past grazing)")
    marks = {"fold": "^", "period_doubling": "s", "grazing": "o", "beb_birth": "*", "torus": "D"}
    for p in pts:
        if p.event:
            ax.plot(p.gamma, p.rdot, marks[p.event], color="tab:red", ms=8, label=p.event)
    h, lab = ax.get_legend_handles_labels()
    uniq = dict(zip(lab, h))
    ax.legend(uniq.values(), uniq.keys(), fontsize=8)
    ax.set_ylabel("impact speed $\\dot r^-$")
    ax.set_title("period-one impacting cycles (solid stable, dashed unstable)", fontsize=10)
    # (b) U*
    ax = axs[1]
    g = np.linspace(0.05, 0.3, 300)
    u = np.array([abs(C.regular_equilibrium(C.chapter_params(gamma=x))) for x in g])
    ax.plot(g[u < 1], u[u < 1], "k-", label="U* admissible")
    ax.plot(g[u >= 1], u[u >= 1], "k--", label="U* virtual")
    ax.axhline(1.0, color="0.7")
    ax.set_ylabel("|U*|")
    ax.legend(fontsize=8)
    # (c) rub
    ax = axs[2]
    for stable, ls in ((True, "-"), (False, "--")):
        gg, nn = [], []
        for x in g:
            for e in C.rub_equilibria(C.chapter_params(gamma=x)):
                if e.stable == stable:
                    gg.append(x)
                    nn.append(e.N)
        ax.plot(gg, nn, ls, color="tab:orange", label=("stable" if stable else "saddle") + " rub")
    ax.set_ylabel("rub normal force N/(m c_r Ω²)")
    ax.legend(fontsize=8)
    # (d) brute force
    ax = axs[3]
    for a in attractors:
        ax.plot(a.gamma, a.max_r, MARKERS[a.start], color=COLORS[a.regime], ms=5, alpha=0.8)
    for reg, col in COLORS.items():
        ax.plot([], [], "o", color=col, label=reg)
    for st, mk in MARKERS.items():
        ax.plot([], [], mk, color="0.4", label=f"start: {st}", ms=5)
    ax.legend(fontsize=7, ncol=2)
    ax.set_ylabel("max r after transient")
    ax.set_xlabel("$\\gamma$")
    for ax in axs:
        ax.axvline(g_beb, color="0.5", lw=0.8, ls=":")
    fig.tight_layout()
    fig.savefig(IMG / "chapter_bifurcation.png", dpi=110)
    plt.close(fig)


# --------------------------------------------------------------------------- main


def _maxr(r: float) -> str:
    """Max interior |U| in flight; 0 means r has no interior maximum (no approach)."""
    return f"{r:.5f}" if r > 0.0 else "none"


def markdown(res: dict) -> str:
    """The results as a markdown page."""
    L = [
        "# Chapter reproduction: numbers",
        "",
        "Generated by `python docs/scripts/chapter.py` (scaled co-rotating frame, "
        "docs/model.md §1;",
        "chapter set with γ varied). Figures: `img/chapter_bifurcation.png`,",
        "`img/chapter_fig5_2.png`.",
        "",
        "## Equilibria",
        "",
        "| quantity | value |",
        "|---|---|",
    ]
    b, r = res["beb"], res["rub"]
    L += [
        f"| γ_BEB (formula) | {b['gamma_beb_formula']:.10f} |",
        f"| γ_BEB (root of \\|U*\\| = 1) | {b['gamma_beb_root']:.10f} |",
        f"| forward rub, stable branch | {r['stable_branch']} |",
        f"| forward rub, saddle branch | {r['saddle_branch']} |",
        "| saddle N at γ_BEB + 1e-4, 1e-6, 1e-8 | "
        + ", ".join(f"{x:.3e}" for x in r["saddle_N_at_gamma_beb_plus_1e-4_1e-6_1e-8"])
        + " |",
        "",
        "## Period-one cycles",
        "",
        "| γ | branch | T | α | ṙ⁻ | multipliers | stable | max r in flight | residual "
        "| core return err |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for c in res["cycles"]:
        mult = ", ".join(f"{complex(*m):.4f}".replace("j", "i") for m in c["multipliers"])
        L.append(
            f"| {c['gamma']} | {c['branch']} | {c['period_T']:.6f} "
            f"| {c['impact_angle_alpha']:.6f} | {c['impact_speed_rdot']:.6f} | {mult} "
            f"| {c['stable']} | {_maxr(c['max_radius_in_flight'])} | "
            f"{c['newton_residual']:.1e} | {c['core_return_error']:.1e} |"
        )
    L += [
        "",
        "## Branch events (continuation in γ ∈ [0.05, 0.3])",
        "",
        "| branch | event | γ | T | ṙ⁻ | multipliers |",
        "|---|---|---|---|---|---|",
    ]
    for e in res["events"]:
        mult = ", ".join(f"{complex(*m):.3f}".replace("j", "i") for m in e["multipliers"])
        L.append(
            f"| {e['branch']} | {e['event']} | {e['gamma']:.7f} | {e['T']:.5f} "
            f"| {e['rdot']:.5f} | {mult} |"
        )
    L += [
        "",
        "## Brute-force attractors (TouchdownCore, 300 scaled time units, last 100 recorded)",
        "",
        "| regime | count |",
        "|---|---|",
    ]
    for k, v in res["brute_force_counts"].items():
        L.append(f"| {k} | {v} |")
    L += ["", f"Run time: {res['run_time_s']:.0f} s.", ""]
    return "\n".join(L)


def main() -> None:
    t0 = time.time()
    IMG.mkdir(exist_ok=True)
    res: dict = {"beb": beb_numbers(), "rub": rub_numbers()}
    cycles = []
    for g in (0.065, 0.1):
        for key in sorted(C.labelled_cycles(C.chapter_params(gamma=g))):
            c = C.find_period_one_cycle(g, branch=key)
            d = cycle_dict(c)
            d["core_return_error"] = core_return_error(c)
            cycles.append((c, d))
    res["cycles"] = [d for _, d in cycles]
    pts = C.continue_cycles(GAMMAS)
    events = [p for p in pts if p.event]
    res["events"] = [
        {
            "branch": p.branch,
            "event": p.event,
            "gamma": p.gamma,
            "T": p.T,
            "rdot": p.rdot,
            "multipliers": [[v.real, v.imag] for v in p.multipliers],
        }
        for p in events
    ]
    g_graze = next(p.gamma for p in events if p.event == "grazing")
    attractors = []
    for g in BRUTE_GAMMAS:
        for name, (U0, dU0) in C.standard_starts(float(g)).items():
            attractors.append(C.run_attractor(float(g), U0, dU0, name))
    res["brute_force"] = [a.__dict__ for a in attractors]
    res["brute_force_counts"] = {reg: sum(a.regime == reg for a in attractors) for reg in C.REGIMES}
    pick = {(d["gamma"], d["branch"]): c for c, d in cycles}
    fig_orbits(pick[(0.065, "long-large")], pick[(0.1, "long-small")])
    fig_bifurcation(pts, attractors, g_graze)
    res["run_time_s"] = time.time() - t0
    (DOCS / "chapter_results.json").write_text(json.dumps(res, indent=1, default=str) + "\n")
    (DOCS / "chapter_results.md").write_text(markdown(res))
    print(f"done in {res['run_time_s']:.1f} s")


if __name__ == "__main__":
    main()
