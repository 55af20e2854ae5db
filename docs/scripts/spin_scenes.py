"""Regenerate the figures and numbers of docs/spin.md (about 1.5 minutes on 2 cores).

    python docs/scripts/spin_scenes.py

Runs the scenes of the spin as a state (docs/model.md §8) with ``rotortd.SpinCore`` and the
independent reference (``tests/reference/spin_reference.py``, scipy DOP853 at rtol 1e-12):
the drop from the levitated whirl into dry whirl (J = m R^2/2 and 5 m R^2), the run-down with
the drive through impacts and a forward rub, the run-up through the critical speed (1 N m
passes, 0.1 N m is held below), and the balances of tests/test_spin_core.py. Writes
docs/img/spin_*.png and docs/spin_scenes.json (the figures' key numbers).
"""

from __future__ import annotations

import argparse
import cmath
import json
import math
import pickle
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path[:0] = [str(ROOT / "fmu_src"), str(ROOT)]

from rotortd import RotorParams, SpinCore, TouchdownCore  # noqa: E402

from tests.reference.spin_reference import simulate, steady_whirl_start  # noqa: E402
from tests.reference.spin_scenes import CHAPTER_G, OMEGA0  # noqa: E402

IMG = ROOT / "docs" / "img"
OUT_JSON = ROOT / "docs" / "spin_scenes.json"
P_G = RotorParams(g=9.81)
J_HALF = 0.5 * P_G.m * P_G.R ** 2  # 0.04 kg m^2
DROP_END, DROP_H, DENSE_H = 0.3, 1e-4, 1e-5
RUNDOWN = {"J": 0.04, "W0": 220.0, "h": 1e-3, "n": 900, "T_drive": -4.0}
RUNUP_P = {"g": 0.0, "c": 5000.0}
RUNUPS = ((1.0, 5.0), (0.1, 60.0))  # (T_drive [N m], t_end [s])
MODE_LABELS = ("free", "sliding", "rolling")


# ------------------------------------------------------------------------------ runs


def _core_run(core: SpinCore, h: float, n: int, **ins: float) -> dict[str, Any]:
    """Omega, mode and r/c_r at every communication point, transitions, counters."""
    om, modes, r = [core.Omega], [core.mode], [core.kinematics().r_rel]
    counts = [core.n_impacts]
    trans: list[tuple[float, str]] = []
    for _ in range(n):
        rep = core.step(h, **ins)
        if rep.status != 0:
            raise RuntimeError(rep.message)
        om.append(core.Omega)
        modes.append(core.mode)
        r.append(core.kinematics().r_rel)
        counts.append(core.n_impacts)
        trans += rep.transitions
    return {"Omega": np.array(om), "mode": np.array(modes), "r": np.array(r),
            "impacts_so_far": np.array(counts),
            "transitions": trans, "n_impacts": core.n_impacts, "E_diss": core.E_diss}


def _drop_core(J: float, h: float, dz: float = 0.0) -> dict[str, Any]:
    held = TouchdownCore.on_steady_whirl(P_G, OMEGA0)
    core = SpinCore(P_G, J, z0=held.z + dz * P_G.c_r, v0=held.v, psi0=0.0, Omega0=OMEGA0)
    return _core_run(core, h, round(DROP_END / h), amb_on=0.0)


def _ref_summary(res: Any, c_r: float) -> dict[str, Any]:
    s = res.samples
    return {"t": s["t"], "Omega": s["Omega"], "mode": s["mode"], "r": np.abs(s["z"]) / c_r,
            "theta_dot": s["theta_dot"], "transitions": list(res.transitions),
            "n_impacts": len(res.impacts), "status": res.status,
            "impact_times": np.array([i["t"] for i in res.impacts]),
            "E_impacts": res.E_impacts, "E_friction": res.E_friction}


def task(name: str, *args: float) -> tuple[str, tuple, Any]:
    """One independent run (core or reference), for the process pool."""
    t0 = time.perf_counter()
    out: Any
    if name == "drop_core":  # (J, h, dz)
        out = _drop_core(*args)
    elif name == "drop_ref":  # (J,) on the dense grid
        z0, v0 = steady_whirl_start(CHAPTER_G, OMEGA0, a=1.0)
        grid = np.linspace(0.0, DROP_END, round(DROP_END / DENSE_H) + 1)
        res = simulate(CHAPTER_G, args[0], OMEGA0, z0, v0, 0.0, DROP_END, grid, a=0.0)
        out = _ref_summary(res, CHAPTER_G["c_r"])
    elif name == "rundown_core":
        held = TouchdownCore.on_steady_whirl(P_G, RUNDOWN["W0"])
        core = SpinCore(P_G, RUNDOWN["J"], z0=held.z, v0=held.v, psi0=0.0, Omega0=RUNDOWN["W0"])
        out = _core_run(core, RUNDOWN["h"], RUNDOWN["n"], amb_on=1.0,
                        T_drive=RUNDOWN["T_drive"])
    elif name == "rundown_ref":  # (rtol,)
        z0, v0 = steady_whirl_start(CHAPTER_G, RUNDOWN["W0"], a=1.0)
        grid = np.arange(RUNDOWN["n"] + 1) * RUNDOWN["h"]
        res = simulate(CHAPTER_G, RUNDOWN["J"], RUNDOWN["W0"], z0, v0, 0.0,
                       RUNDOWN["n"] * RUNDOWN["h"], grid, a=1.0, T_drive=RUNDOWN["T_drive"],
                       rtol=args[0])
        out = _ref_summary(res, CHAPTER_G["c_r"])
    elif name == "runup_core":  # (T_drive, t_end)
        core = SpinCore.on_steady_whirl(RotorParams(**RUNUP_P), 60.0, J=J_HALF)
        out = _core_run(core, 1e-3, round(args[1] / 1e-3), amb_on=1.0, T_drive=args[0])
    elif name == "runup_ref":  # (T_drive, t_end, rtol)
        params = dict(CHAPTER_G, **RUNUP_P)
        z0, v0 = steady_whirl_start(params, 60.0, a=1.0)
        grid = np.arange(round(args[1] / 1e-3) + 1) * 1e-3
        res = simulate(params, J_HALF, 60.0, z0, v0, 0.0, args[1], grid, a=1.0,
                       T_drive=args[0], rtol=args[2])
        out = _ref_summary(res, params["c_r"])
    elif name == "balances":
        out = balances()
    else:
        raise ValueError(name)
    return name, args, (out, time.perf_counter() - t0)


# ------------------------------------------------------------------------------ balances


def _body(core: SpinCore) -> dict[str, float]:
    """T, L about the bearing centre, V and psi from the public state (as the tests)."""
    p = core.params
    E = cmath.exp(1j * (core.psi + p.phi))
    zG, vG = core.z + p.e_c * E, core.v + 1j * core.Omega * p.e_c * E
    return {"T": 0.5 * p.m * abs(vG) ** 2 + 0.5 * core.J * core.Omega ** 2,
            "L": p.m * (zG.conjugate() * vG).imag + core.J * core.Omega,
            "V": p.m * p.g * zG.imag, "psi": core.psi}


def balances() -> dict[str, Any]:
    """The conservation scenes and the energy balance of tests/test_spin_core.py."""
    out: dict[str, Any] = {}
    for d in (1.0, 0.8):
        core = SpinCore(RotorParams(mu=0.0, g=0.0, d=d), J_HALF, z0=0.3e-3 + 0.1e-3j,
                        v0=0.08 - 0.05j, psi0=0.4, Omega0=184.2)
        b0 = _body(core)
        for _ in range(1000):
            core.step(1e-3, amb_on=0.0)
        b1 = _body(core)
        out[f"conservation_d={d}"] = {
            "impacts": core.n_impacts,
            "L_rel_change": abs(b1["L"] - b0["L"]) / abs(b0["L"]),
            "T_rel_change": abs(b1["T"] - b0["T"]) / b0["T"],
            "E_diss_rel": core.E_diss / b0["T"],
            "energy_residual_rel": abs(b1["T"] - b0["T"] + core.E_diss) / b0["T"]}
    for T in (0.0, 5.0):
        core = SpinCore.on_steady_whirl(P_G, 184.2, J=J_HALF)
        b0 = _body(core)
        for _ in range(3000):
            core.step(1e-4, amb_on=0.0, T_drive=T)
        b1 = _body(core)
        terms = {"dT": b1["T"] - b0["T"], "dV": b1["V"] - b0["V"],
                 "-W_drive": -T * (b1["psi"] - b0["psi"]), "E_diss": core.E_diss}
        res = sum(terms.values())
        out[f"energy_T_drive={T}"] = {
            "impacts": core.n_impacts, "terms_J": terms, "residual_J": res,
            "residual_rel": abs(res) / sum(abs(x) for x in terms.values())}
    return out


# ------------------------------------------------------------------------------ helpers


def _first(trans: list, name: str) -> float | None:
    return next((t for t, m in trans if m == name), None)


def _oscillation(t: np.ndarray, om: np.ndarray, t0: float) -> dict[str, float]:
    """Frequency (FFT peak, Hz) and half peak-to-peak of Omega on [t0, end]."""
    sel = t >= t0
    x, tt = om[sel], t[sel]
    trend = np.polyval(np.polyfit(tt, x, 2), tt)
    y = (x - trend) * np.hanning(len(x))
    f = np.fft.rfftfreq(len(y), tt[1] - tt[0])
    k = int(np.argmax(np.abs(np.fft.rfft(y))[1:])) + 1
    return {"f_Hz": float(f[k]), "half_p2p_rel": float(np.ptp(x - trend) / 2 / x.mean()),
            "Omega_mean": float(x.mean())}


def _drag(W: float, p: RotorParams) -> float:
    """c Omega |Z1|^2 of the steady whirl at W (N m)."""
    Z1 = p.m * p.e_c * W * W / abs(p.k - p.m * W * W + 1j * p.c * W)
    return p.c * W * Z1 * Z1


def _equilibrium(T: float, p: RotorParams, lo: float, hi: float) -> float | None:
    if _drag(hi, p) < T:
        return None
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _drag(mid, p) < T else (lo, mid)
    return lo


def _g(x: Any) -> Any:
    """Round floats for the JSON (4 significant digits)."""
    if isinstance(x, dict):
        return {k: _g(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_g(v) for v in x]
    if isinstance(x, (float, np.floating)):
        return float(f"{float(x):.4g}")
    if isinstance(x, np.integer):
        return int(x)
    return x


def _mark(ax: Any, t_s: float | None, t_r: float | None, label: bool = True) -> None:
    for tt, col, lab in ((t_s, "tab:orange", "enters sliding"),
                         (t_r, "tab:green", "enters rolling")):
        if tt is not None:
            ax.axvline(tt, color=col, ls=":", lw=1.2,
                       label=f"{lab} ({tt * 1e3:.2f} ms)" if label else None)


# ------------------------------------------------------------------------------ scenes


def drop_scene(r: dict) -> dict[str, Any]:
    """Figures spin_drop.png and spin_drop_zoom.png, and the drop's numbers."""
    out: dict[str, Any] = {}
    fig, ax = plt.subplots(3, 2, figsize=(12, 9.5), sharex=True,
                           gridspec_kw={"height_ratios": [3, 1, 2]})
    figz, axz = plt.subplots(1, 2, figsize=(12, 4.2))
    for col, J in enumerate((J_HALF, 10 * J_HALF)):
        core, dense = r[("drop_core", (J, DROP_H, 0.0))], r[("drop_ref", (J,))]
        pert, coarse = r[("drop_core", (J, DROP_H, 1e-12))], r[("drop_core", (J, 1e-3, 0.0))]
        t = np.arange(len(core["Omega"])) * DROP_H
        ref_om, ref_mode = dense["Omega"][::10], dense["mode"][::10]
        diff = core["Omega"] - ref_om
        amp = float(np.max(np.abs(pert["Omega"] - core["Omega"])) / OMEGA0 / 1e-12)
        tol = 3.0 * amp * 1e-12 * OMEGA0
        ts, tr = _first(core["transitions"], "sliding"), _first(core["transitions"], "rolling")
        rs, rr = _first(dense["transitions"], "sliding"), _first(dense["transitions"], "rolling")
        last = t >= DROP_END - 0.1 - 1e-12
        osc = _oscillation(dense["t"], dense["Omega"], rr + 0.02)
        i1, i3 = round(0.1 / DROP_H), round(0.3 / DROP_H)
        key = "J=m R^2/2" if col == 0 else "J=5 m R^2"
        out[key] = {
            "J": J, "impacts_core": core["n_impacts"], "impacts_ref": dense["n_impacts"],
            "t_sliding_core": ts, "t_sliding_ref": rs, "dt_sliding": ts - rs,
            "t_rolling_core": tr, "t_rolling_ref": rr, "dt_rolling": tr - rr,
            "max_abs_dOmega": float(np.max(np.abs(diff))),
            "max_rel_dOmega": float(np.max(np.abs(diff)) / OMEGA0),
            "rel_dOmega_at_0.1": float(abs(diff[i1]) / abs(ref_om[i1])),
            "rel_dOmega_at_0.3": float(abs(diff[i3]) / abs(ref_om[i3])),
            "amplification_A": amp, "test_tolerance_rad_s": tol,
            "mean_Omega_last_0.1_core": float(core["Omega"][last].mean()),
            "mean_Omega_last_0.1_ref": float(ref_om[last].mean()),
            "d_mean_Omega_last_0.1": float(core["Omega"][last].mean() - ref_om[last].mean()),
            "t_of_max_dOmega": float(t[int(np.argmax(np.abs(diff)))]),
            "max_abs_dOmega_rolling_from_0.1": float(np.max(np.abs(diff[t >= 0.1]))),
            "max_abs_Omega_1e-3_vs_1e-4": float(np.max(np.abs(coarse["Omega"]
                                                               - core["Omega"][::10]))),
            "rolling_oscillation_ref": osc,
            "f_beta_Hz": osc["Omega_mean"] * (1 + P_G.R / P_G.c_r) / (2 * math.pi),
        }
        # Omega: reference line, core markers (every 25th communication point)
        a = ax[0, col]
        a.plot(dense["t"], dense["Omega"], "k", lw=0.8, label="reference (DOP853, 1e-12)")
        a.plot(t[::25], core["Omega"][::25], "o", ms=3, mfc="none", color="tab:blue",
               label="SpinCore, every 25th 1e-4 s point")
        _mark(a, ts, tr)
        a.set(ylabel="Omega [rad/s]",
              title=f"drop into dry whirl, J = {J:g} kg m^2 ({J / (P_G.m * P_G.R**2):g} m R^2)")
        a.legend(fontsize=8, loc="upper right")
        a = ax[1, col]
        a.plot(t, core["mode"], drawstyle="steps-post", color="tab:blue", label="SpinCore")
        a.plot(t, ref_mode, drawstyle="steps-post", color="k", ls="--", lw=0.8,
               label="reference")
        _mark(a, ts, tr, label=False)
        a.set(ylabel="mode", yticks=[0, 1, 2], ylim=(-0.3, 2.3))
        a.set_yticklabels(MODE_LABELS, fontsize=8)
        a = ax[2, col]
        a.semilogy(t, np.maximum(np.abs(diff), 1e-16), lw=0.7, color="tab:blue",
                   label="|Omega core - Omega ref|")
        a.axhline(tol, color="tab:red", ls="--", lw=1,
                  label=f"test tolerance 3 A 1e-12 Omega0 (A = {amp:.0f})")
        _mark(a, ts, tr, label=False)
        a.set(xlabel="t [s]", ylabel="rad/s", ylim=(1e-14, 1e-5))
        a.legend(fontsize=8, loc="upper left")
        # zoom on the rolling phase: 4 ms near the end
        az = axz[col]
        w0, w1 = 0.290, 0.294
        sd = (dense["t"] >= w0) & (dense["t"] <= w1)
        sc = (t >= w0 - 1e-9) & (t <= w1 + 1e-9)
        az.plot(dense["t"][sd] * 1e3, dense["Omega"][sd], "k", lw=0.9,
                label="reference, sampled every 1e-5 s")
        az.plot(t[sc] * 1e3, core["Omega"][sc], "o", ms=5, mfc="none", color="tab:blue",
                label="SpinCore, every 1e-4 s")
        lo, hi = dense["Omega"][sd].min(), dense["Omega"][sd].max()
        az.set(xlabel="t [ms]", ylabel="Omega [rad/s]", ylim=(lo - 0.1 * (hi - lo),
                                                              hi + 0.45 * (hi - lo)),
               title=f"rolling, J = {J:g} kg m^2: {osc['f_Hz']:.0f} Hz, "
                     f"+-{100 * osc['half_p2p_rel']:.2f} %\n"
                     f"(beta' = Omega (1 + R/c_r): "
                     f"{out[key]['f_beta_Hz']:.0f} Hz at the mean Omega)")
        az.legend(fontsize=8, loc="upper center", ncol=2)
    fig.tight_layout()
    fig.savefig(IMG / "spin_drop.png", dpi=110)
    figz.tight_layout()
    figz.savefig(IMG / "spin_drop_zoom.png", dpi=110)
    plt.close("all")
    return out


def _diff_panel(a: Any, t: np.ndarray, diff: np.ndarray, spread: np.ndarray) -> None:
    a.semilogy(t, np.maximum(np.abs(diff), 1e-16), lw=0.7, color="tab:blue",
               label="|Omega core - Omega ref|")
    a.semilogy(t, np.maximum(3 * spread, 1e-16), lw=0.7, color="tab:red", alpha=0.7,
               label="3 |ref(rtol 1e-11) - ref(1e-12)|")
    a.set(ylabel="rad/s", ylim=(1e-15, 1e-5))
    a.legend(fontsize=8, loc="upper left")


def rundown_scene(r: dict) -> dict[str, Any]:
    core, ref = r[("rundown_core", ())], r[("rundown_ref", (1e-12,))]
    ref11 = r[("rundown_ref", (1e-11,))]
    h, W0 = RUNDOWN["h"], RUNDOWN["W0"]
    t = np.arange(len(core["Omega"])) * h
    diff, spread = core["Omega"] - ref["Omega"], np.abs(ref11["Omega"] - ref["Omega"])
    (t_rub, n1), (t_off, n2) = core["transitions"][:2]
    w_crit = math.sqrt(P_G.k / P_G.m)
    k_mid = int(np.searchsorted(t, 0.5 * (t_rub + t_off)))
    imp = np.flatnonzero(np.diff(core["mode"]) != 0)
    out = {
        "impacts_core": core["n_impacts"], "impacts_ref": ref["n_impacts"],
        "transitions_core": core["transitions"], "transitions_ref": ref["transitions"],
        "dt_rub_entry": t_rub - _first(ref["transitions"], "sliding"),
        "dt_lift_off": t_off - _first(ref["transitions"], "free"),
        "Omega_at_lift_off": float(np.interp(t_off, t, core["Omega"])),
        "rub_whirl_rate_mid_ref": float(ref["theta_dot"][k_mid]),
        "max_abs_dOmega": float(np.max(np.abs(diff))),
        "max_rel_dOmega": float(np.max(np.abs(diff)) / W0),
        "max_excess_over_3_spread": float(np.max(np.abs(diff) - 3 * spread)),
        "max_spread": float(np.max(spread)), "Omega_end_core": float(core["Omega"][-1]),
        "max_r_over_c_r": float(np.max(core["r"])), "n_mode_changes_on_grid": len(imp),
    }
    fig, ax = plt.subplots(4, 1, figsize=(10, 10), sharex=True,
                           gridspec_kw={"height_ratios": [3, 2, 1, 2]})
    ax[0].plot(t, ref["Omega"], "k", lw=0.8, label="reference")
    ax[0].plot(t[::20], core["Omega"][::20], "o", ms=3, mfc="none", color="tab:blue",
               label="SpinCore, every 20th 1 ms point")
    ax[0].axhline(w_crit, color="gray", ls="--", lw=0.8, label="sqrt(k/m) = 140 rad/s")
    ax[0].set(ylabel="Omega [rad/s]",
              title="run-down: T_drive = -4 N m from 220 rad/s, bearing on, g = 9.81, "
                    "J = 0.04 kg m^2")
    ax[1].plot(t, ref["r"], "k", lw=0.6, label="reference")
    ax[1].plot(t, core["r"], ".", ms=1.5, color="tab:blue", label="SpinCore (1 ms points)")
    ax[1].axhline(1.0, color="gray", lw=0.8)
    ax[1].set(ylabel="r / c_r", ylim=(0.6, 1.03))
    ax1b = ax[1].twinx()
    ax1b.plot(t, core["impacts_so_far"], color="tab:purple", lw=1.2,
              label="impacts so far, SpinCore")
    ti = ref["impact_times"]
    ax1b.plot(ti, np.arange(1, len(ti) + 1), color="k", ls="--", lw=0.8,
              label="impacts so far, reference")
    ax1b.set(ylabel="impacts")
    ax1b.legend(fontsize=8, loc="center left")
    ax[2].plot(t, core["mode"], drawstyle="steps-post", color="tab:blue", label="SpinCore")
    ax[2].plot(t, ref["mode"], drawstyle="steps-post", color="k", ls="--", lw=0.8,
               label="reference")
    ax[2].set(ylabel="mode", yticks=[0, 1, 2], ylim=(-0.3, 2.3))
    ax[2].set_yticklabels(MODE_LABELS, fontsize=8)
    _diff_panel(ax[3], t, diff, spread)
    ax[3].set(xlabel="t [s]")
    for a in ax[:3]:
        a.axvspan(t_rub, t_off, color="tab:orange", alpha=0.15,
                  label="forward rub" if a is ax[0] else None)
        a.legend(fontsize=8, loc="upper left" if a is ax[1] else "upper right")
    fig.tight_layout()
    fig.savefig(IMG / "spin_rundown.png", dpi=110)
    plt.close(fig)
    assert n1 == "sliding" and n2 == "lift_off", (n1, n2)
    return out


def runup_scene(r: dict) -> dict[str, Any]:
    p = RotorParams(**RUNUP_P)
    w_crit = math.sqrt(p.k / p.m)
    ws = np.linspace(60.0, 300.0, 2401)
    rising = bool(np.all(np.diff([_drag(w, p) for w in ws]) > 0))
    out: dict[str, Any] = {"w_crit": w_crit, "drag_at_w_crit_N_m": _drag(w_crit, p),
                           "drag_rises_60_to_300": rising}
    fig, ax = plt.subplots(3, 2, figsize=(12, 9), sharex="col",
                           gridspec_kw={"height_ratios": [3, 2, 2]})
    for col, (T, t_end) in enumerate(RUNUPS):
        core, ref = r[("runup_core", (T, t_end))], r[("runup_ref", (T, t_end, 1e-12))]
        ref11 = r[("runup_ref", (T, t_end, 1e-11))]
        t = np.arange(len(core["Omega"])) * 1e-3
        diff, spread = core["Omega"] - ref["Omega"], np.abs(ref11["Omega"] - ref["Omega"])
        W_eq = _equilibrium(T, p, 60.0, w_crit)
        om = core["Omega"]
        k_cross = int(np.argmax(om > w_crit)) if om[-1] > w_crit else None
        out[f"T_drive={T}"] = {
            "t_end": t_end, "impacts_core": core["n_impacts"], "impacts_ref": ref["n_impacts"],
            "Omega_end_core": float(om[-1]), "Omega_end_ref": float(ref["Omega"][-1]),
            "W_equilibrium": W_eq, "t_cross_w_crit": None if k_cross is None else t[k_cross],
            "max_abs_dOmega": float(np.max(np.abs(diff))),
            "max_rel_dOmega": float(np.max(np.abs(diff) / np.abs(ref["Omega"]))),
            "max_excess_over_3_spread": float(np.max(np.abs(diff) - 3 * spread)),
            "max_spread": float(np.max(spread)), "max_r_over_c_r": float(np.max(core["r"])),
            "monotone": bool(np.all(np.diff(om) > 0)),
            "last_s_gain": float(om[-1] - om[-1001]),
        }
        thin = 100 if t_end < 10 else 1000
        a = ax[0, col]
        a.plot(t, ref["Omega"], "k", lw=0.9, label="reference")
        a.plot(t[::thin], om[::thin], "o", ms=4, mfc="none", color="tab:blue",
               label=f"SpinCore, every {thin}th 1 ms point")
        a.axhline(w_crit, color="gray", ls="--", lw=0.9, label="sqrt(k/m) = 140 rad/s")
        if W_eq is not None:
            a.axhline(W_eq, color="tab:red", ls=":", lw=1.2,
                      label=f"quasi-steady speed c W |Z1|^2 = T: {W_eq:.2f} rad/s")
        a.set(ylabel="Omega [rad/s]", title=f"run-up, T_drive = {T:g} N m")
        a.legend(fontsize=8, loc="lower right")
        a = ax[1, col]
        a.plot(t, core["r"], color="tab:blue", lw=1.0, label="SpinCore |z|/c_r")
        z1 = [p.m * p.e_c * w * w / abs(p.k - p.m * w * w + 1j * p.c * w) / p.c_r for w in om]
        a.plot(t, z1, color="k", ls="--", lw=0.8, label="steady whirl |Z1(Omega)|/c_r")
        a.set(ylabel="r / c_r", ylim=(0, None))
        a.legend(fontsize=8)
        _diff_panel(ax[2, col], t, diff, spread)
        ax[2, col].set(xlabel="t [s]", ylim=(1e-15, 1e-8))
    fig.suptitle("run-up from 60 rad/s through the critical speed: bearing on, g = 0, "
                 "c = 5000 N s/m, J = 0.04 kg m^2, 1 ms steps", fontsize=11)
    fig.tight_layout()
    fig.savefig(IMG / "spin_runup.png", dpi=110)
    plt.close(fig)
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cache", type=Path, default=None,
                    help="pickle of the runs: read if it exists, else written (for replotting)")
    cache = ap.parse_args(argv).cache
    t_start = time.perf_counter()
    jobs: list[tuple] = [("runup_core", 0.1, 60.0), ("runup_ref", 0.1, 60.0, 1e-12),
                         ("runup_ref", 0.1, 60.0, 1e-11)]
    for J in (J_HALF, 10 * J_HALF):
        jobs += [("drop_ref", J), ("drop_core", J, DROP_H, 0.0),
                 ("drop_core", J, DROP_H, 1e-12), ("drop_core", J, 1e-3, 0.0)]
    jobs += [("rundown_core",), ("rundown_ref", 1e-12), ("rundown_ref", 1e-11)]
    jobs += [("runup_core", 1.0, 5.0), ("runup_ref", 1.0, 5.0, 1e-12),
             ("runup_ref", 1.0, 5.0, 1e-11), ("balances",)]
    results: dict[tuple, Any] = {}
    cpu: dict[str, float] = {}
    if cache is not None and cache.exists():
        results, cpu = pickle.loads(cache.read_bytes())
    else:
        with ProcessPoolExecutor(max_workers=2) as pool:
            futures = [pool.submit(task, *job) for job in jobs]
            for fut in futures:
                name, args, (out, dt) = fut.result()
                results[(name, args)] = out
                cpu[f"{name}{list(args)}"] = round(dt, 1)
        if cache is not None:
            cache.write_bytes(pickle.dumps((results, cpu)))
    IMG.mkdir(parents=True, exist_ok=True)
    summary = {
        "regenerate": "python docs/scripts/spin_scenes.py",
        "drop": drop_scene(results), "rundown": rundown_scene(results),
        "runup": runup_scene(results), "balances": results[("balances", ())],
        "run_seconds": {"wall": round(time.perf_counter() - t_start, 1), "per_job": cpu},
    }
    OUT_JSON.write_text(json.dumps(_g(summary), indent=1) + "\n")
    print(json.dumps(_g(summary), indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
