"""Bifurcation diagrams and regime maps from a sweep's Parquet output.

Units as in ``rotortd_tools.sweep``: r in c_r, impact normal speeds in c_r Omega, angles in rad,
parameters scaled (Omega in rad/s). Analytic markers:

- the boundary equilibrium bifurcation (BEB), where the regular equilibrium
  U* = rho e^{i phi}/(omega^2 - 1 + i gamma) reaches |U*| = 1; for a gamma sweep this is
  gamma_BEB = sqrt(rho^2 - (1 - omega^2)^2), for any other parameter the crossing is
  located on a fine grid of the swept parameter (other parameters as in the sweep);
- events of the period-one cycles (fold, period doubling, grazing, torus) read from a JSON
  file (``docs/chapter_results.json`` by default, when it exists): any object with a
  numeric ``gamma`` and a string ``event``/``type``/``kind``/``name``, or any key that
  names an event (``fold``, ``period_doubling``/``pd``, ``grazing``, ``torus``) and
  contains ``gamma`` (or is the bare word), with a number or a list of numbers; events
  under a ``rub`` key are labelled "rub ..."; used for gamma sweeps only.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from rotortd import scaled
from rotortd.scaled import regular_equilibrium

from rotortd_tools.sweep import (
    DROP_REGIMES,
    PARAM_NAMES,
    REGIMES,
    SweepError,
    point_params,
    read_meta,
    read_sweep,
    regime_group,
)

COLOURS = {
    "free": "tab:green",
    "period-1": "tab:blue",
    "period-2": "tab:cyan",
    "period-n": "tab:purple",
    "irregular": "tab:orange",
    "rub": "tab:red",
    "dry-whirl": "black",
    "no-start": "0.85",
    "failed": "magenta",
}
DROP_COLOURS = {
    "no-contact": "tab:green",
    "impacting": "tab:blue",
    "settled": "0.6",
    "forward-rub": "tab:red",
    "dry-whip": "tab:orange",
    "dry-whirl": "black",
    "no-start": "0.9",
    "failed": "magenta",
}
"""Colours of the drop outcomes (``classify_drop``) in ``drop_map``."""
EVENT_WORDS = {
    "fold": "fold",
    "period_doubling": "period doubling",
    "period-doubling": "period doubling",
    "pd": "period doubling",
    "grazing": "grazing",
    "torus": "torus",
}
DEFAULT_RESULTS = Path("docs/chapter_results.json")


# --------------------------------------------------------------------------- data


def load(path: Path | str) -> tuple[dict[str, np.ndarray], list[str], dict[str, Any]]:
    """Rows as arrays, the swept parameter names and the fixed values of a sweep."""
    data = read_sweep(path)
    if not data:
        raise SweepError(f"{path}: no rows (is it a sweep output directory?)")
    cols = {k: np.asarray(v, dtype=object if k.startswith("sec_") else None)
            for k, v in data.items()}
    meta = read_meta(path) or {}
    names = [a["name"] for a in meta.get("axes", [])]
    if not names:
        names = [n for n in PARAM_NAMES if len(np.unique(cols[n])) > 1][:2]
    return cols, names, dict(meta.get("fixed", {}))


def regime_colours(regimes: Sequence[str]) -> list[str]:
    """Marker colour of each regime."""
    return [COLOURS.get(regime_group(str(r)), "magenta") for r in regimes]


# --------------------------------------------------------------------------- markers


def beb_values(name: str, lo: float, hi: float, fixed: dict[str, float],
               other: dict[str, float] | None = None, n: int = 4001) -> list[float]:
    """Values of parameter ``name`` in [lo, hi] where |U*| = 1 (located on a fine grid)."""
    xs = np.linspace(lo, hi, n)
    f = np.array([_u_star_excess({**fixed, **(other or {}), name: float(x)}) for x in xs])
    out = []
    for i in np.nonzero(np.sign(f[:-1]) * np.sign(f[1:]) < 0)[0]:
        x0, x1, f0, f1 = xs[i], xs[i + 1], f[i], f[i + 1]
        out.append(float(x0 - f0 * (x1 - x0) / (f1 - f0)))
    return out


def _u_star_excess(values: dict[str, float]) -> float:
    """|U*| - 1 at a point (positive: the free whirl leaves the clearance)."""
    _, _, sp = point_params(values)
    try:
        return abs(regular_equilibrium(sp)) - 1.0
    except ZeroDivisionError:  # undamped resonance: no steady whirl
        return math.inf


def gamma_beb(fixed: dict[str, float]) -> float:
    """gamma_BEB = sqrt(rho^2 - (1 - omega^2)^2) for the sweep's other parameters (or NaN)."""
    return scaled.gamma_beb(point_params(fixed)[2])


def chapter_events(path: Path | None) -> list[tuple[str, float]]:
    """(label, gamma) events from a chapter-results JSON (see the module docstring)."""
    if path is None or not Path(path).exists():
        return []
    try:
        doc = json.loads(Path(path).read_text())
    except (OSError, ValueError):
        return []
    seen = {(lab, round(g, 12)): (lab, g) for lab, g in _walk_events(doc, "")}
    return sorted(seen.values(), key=lambda e: e[1])


def _walk_events(node: Any, path: str) -> Iterator[tuple[str, float]]:
    key = path.rsplit("/", 1)[-1].lower()
    prefix = "rub " if "rub" in path.lower() else ""
    label = _event_label(key) if ("gamma" in key or key in EVENT_WORDS) else ""
    if isinstance(node, dict):
        tag = next((node[k] for k in ("event", "type", "kind", "name")
                    if isinstance(node.get(k), str)), None)
        if tag and _event_label(tag) and _is_number(node.get("gamma")):
            yield prefix + _event_label(tag), float(node["gamma"])
        for k, v in node.items():
            yield from _walk_events(v, f"{path}/{k}")
    elif isinstance(node, list):
        for v in node:
            yield from _walk_events(v, path)
    elif label and _is_number(node):
        yield prefix + label, float(node)


def _event_label(text: str) -> str:
    low = str(text).lower()
    for word, label in EVENT_WORDS.items():
        if word == "pd":
            if low in ("pd", "gamma_pd") or low.endswith("_pd"):
                return label
        elif word in low:
            return label
    return ""


def _is_number(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


# --------------------------------------------------------------------------- figures


def plot_sweep(path: Path | str, out: Path | str, results: Path | None = DEFAULT_RESULTS,
               title: str = "") -> Path:
    """Draw a sweep: bifurcation diagram (one swept parameter) or regime maps (two)."""
    import matplotlib

    matplotlib.use("Agg")
    cols, names, fixed = load(path)
    meta = read_meta(path) or {}
    if len(names) == 2 and set(cols["start"]) == {"drop"}:
        logs = {a["name"]: bool(a.get("log")) for a in meta.get("axes", [])}
        fig = drop_map(cols, names, fixed, logs)
    elif len(names) == 2:
        fig = regime_map(cols, names, fixed)
    else:
        name = names[0] if names else "gamma"
        fig = bifurcation_diagram(cols, name, fixed, chapter_events(results) if
                                  name == "gamma" else [])
    if title:
        fig.suptitle(title)
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=130)
    import matplotlib.pyplot as plt

    plt.close(fig)
    return out


def bifurcation_diagram(cols: dict[str, np.ndarray], name: str, fixed: dict[str, float],
                        events: list[tuple[str, float]]):
    """Three panels vs the parameter: r_max/r_min, impact speeds, regime per start."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 1, figsize=(11, 10), sharex=True, layout="constrained",
                             gridspec_kw={"height_ratios": (1.2, 1.2, 0.8)})
    x = cols[name].astype(float)
    ok = cols["status"] == "ok"
    col = np.array(regime_colours(cols["regime"]))
    _panel_radius(axes[0], x, cols, ok, col)
    _panel_impacts(axes[1], x, cols, ok)
    starts = _panel_starts(axes[2], x, cols, col)
    axes[2].set_xlabel(_label(name))
    lo, hi = float(np.min(x)), float(np.max(x))
    _draw_markers(axes, name, lo, hi, fixed, events)
    _regime_legend(axes[0], [str(r) for r in cols["regime"]])
    fig.suptitle(f"{len(x)} runs, {len(starts)} starts; fixed: {_fixed_text(fixed)}")
    return fig


def _panel_radius(ax, x, cols, ok, col) -> None:
    ax.scatter(x[ok], cols["r_max"][ok], s=6, c=col[ok], marker="o", lw=0)
    ax.scatter(x[ok], cols["r_min"][ok], s=7, facecolors="none", edgecolors=col[ok],
               marker="v", lw=0.5)
    ax.set_ylabel("r / c_r: max (dots), min (triangles)")
    ax.set_ylim(-0.02, 1.05)
    ax.grid(True, alpha=0.3)


def _panel_impacts(ax, x, cols, ok) -> None:
    xs, vs, cs = [], [], []
    for i in np.nonzero(ok)[0]:
        speeds = cols["sec_speed"][i]
        if speeds is None or len(speeds) == 0:
            continue
        xs.append(np.full(len(speeds), x[i]))
        vs.append(np.asarray(speeds, float))
        cs += [COLOURS.get(regime_group(str(cols["regime"][i])), "magenta")] * len(speeds)
    if xs:
        ax.scatter(np.concatenate(xs), np.concatenate(vs), s=1.5, c=cs, lw=0)
    ax.set_ylabel("impact speed ṙ⁻ / (c_r Ω)\n(Poincaré section points)")
    ax.grid(True, alpha=0.3)


def _panel_starts(ax, x, cols, col) -> list[str]:
    starts = list(dict.fromkeys(str(s) for s in cols["start"]))
    ypos = {s: k for k, s in enumerate(starts)}
    y = np.array([ypos[str(s)] for s in cols["start"]])
    ax.scatter(x, y, c=col, s=12, marker="s", lw=0)
    ax.set_yticks(range(len(starts)), starts)
    ax.set_ylim(-0.6, len(starts) - 0.4)
    ax.set_ylabel("start")
    ax.grid(True, axis="x", alpha=0.3)
    return starts


def _draw_markers(axes, name, lo, hi, fixed, events) -> None:
    marks = [("BEB", v) for v in beb_values(name, lo, hi, fixed)]
    marks += [(lab, g) for lab, g in events if lo <= g <= hi]
    styles = {"BEB": "k--", "fold": "g:", "period doubling": "b-.", "grazing": "r:",
              "torus": "m:", "rub fold": "y:"}
    for lab, v in marks:
        for ax in axes:
            ax.axvline(v, color=styles.get(lab, "k:")[0], ls=styles.get(lab, "k:")[1:], lw=1)
        text = f"{lab} {v:.4g}"
        axes[0].text(v, 0.5, text, rotation=90, va="center", ha="right", fontsize=7)


def _regime_legend(ax, regimes: Sequence[str]) -> None:
    from matplotlib.lines import Line2D

    present = {regime_group(r) for r in regimes}
    handles = [Line2D([], [], ls="", marker="o", color=COLOURS[g], label=g)
               for g in REGIMES if g in present]
    ax.legend(handles=handles, loc="lower left", bbox_to_anchor=(0.0, 1.0), fontsize="small",
              ncol=len(handles), frameon=False)


def regime_map(cols: dict[str, np.ndarray], names: list[str], fixed: dict[str, float]):
    """One regime map per start over the two swept parameters, BEB curve overlaid."""
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    starts = list(dict.fromkeys(str(s) for s in cols["start"]))
    ncol = 2 if len(starts) == 4 else min(3, len(starts))
    nrow = math.ceil(len(starts) / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(5.0 * ncol, 4.2 * nrow + 0.6),
                             squeeze=False, layout="constrained", sharex=True, sharey=True)
    x, y = cols[names[0]].astype(float), cols[names[1]].astype(float)
    groups = np.array([regime_group(str(r)) for r in cols["regime"]])
    beb = _beb_curve(names, x, y, fixed)
    for ax, start in zip(axes.flat, starts):
        sel = cols["start"] == start
        _draw_cells(ax, x[sel], y[sel], groups[sel])
        if beb is not None:
            ax.contour(*beb, levels=[0.0], colors="k", linestyles="--", linewidths=1)
        ax.set_title(f"start: {start}")
        ax.set_xlabel(_label(names[0]))
        ax.set_ylabel(_label(names[1]))
    for ax in list(axes.flat)[len(starts):]:
        ax.set_visible(False)
    present = set(groups)
    handles = [Line2D([], [], ls="", marker="s", color=COLOURS[g], label=g)
               for g in REGIMES if g in present]
    fig.legend(handles=handles, loc="outside lower center", ncol=len(handles))
    fig.suptitle(f"regimes; dashed: BEB |U*| = 1; fixed: {_fixed_text(fixed)}")
    return fig


def _draw_cells(ax, x: np.ndarray, y: np.ndarray, groups: np.ndarray) -> None:
    """Regime cells: a mesh when the points form a full grid, else square markers."""
    from matplotlib.colors import ListedColormap

    xs, ys = np.unique(x), np.unique(y)
    if len(x) == len(xs) * len(ys) and len(xs) > 1 and len(ys) > 1:
        code = {g: k for k, g in enumerate(REGIMES)}
        Z = np.full((len(ys), len(xs)), np.nan)
        Z[np.searchsorted(ys, y), np.searchsorted(xs, x)] = [code[g] for g in groups]
        cmap = ListedColormap([COLOURS[g] for g in REGIMES])
        ax.pcolormesh(_edges(xs), _edges(ys), Z, cmap=cmap, vmin=-0.5,
                      vmax=len(REGIMES) - 0.5)
    else:
        ax.scatter(x, y, c=[COLOURS.get(g, "magenta") for g in groups],
                   s=_marker_size(x, y), marker="s", lw=0)


def drop_map(cols: dict[str, np.ndarray], names: list[str], fixed: dict[str, float],
             logs: dict[str, bool] | None = None):
    """Three maps of a two-parameter drop sweep (``--starts drop``): the outcome
    (``classify_drop``), the mean whirl rate over the window |theta'| / 2 pi (Hz; the whip
    speed where the outcome is a backward whirl or dry whirl), and the spin kept,
    Omega_mean / Omega (the initial spin). With J an axis, the well-posedness bound
    J = m mu e_c (R + e_c) (kg m^2) is drawn dashed when mu is the other axis."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap, LogNorm
    from matplotlib.patches import Patch

    logs = logs or {}
    x, y = cols[names[0]].astype(float), cols[names[1]].astype(float)
    xs, ys = np.unique(x), np.unique(y)
    ix, iy = np.searchsorted(xs, x), np.searchsorted(ys, y)
    ex = _edges_log(xs) if logs.get(names[0]) else _edges(xs)
    ey = _edges_log(ys) if logs.get(names[1]) else _edges(ys)

    def grid(values) -> np.ndarray:
        Z = np.full((len(ys), len(xs)), np.nan)
        Z[iy, ix] = values
        return Z

    regimes = [str(r) for r in cols["regime"]]
    code = {g: k for k, g in enumerate(DROP_REGIMES)}
    outcome = grid([code.get(r, code["failed"]) for r in regimes])
    whirl = np.abs(cols["whirl_mean"].astype(float)) / (2.0 * np.pi)
    whip = np.array([r in ("dry-whirl", "dry-whip") for r in regimes])
    kept = cols["Omega_mean"].astype(float) / cols["Omega"].astype(float)
    fig, axes = plt.subplots(1, 3, figsize=(17, 5.6), layout="constrained", sharey=True)
    ax = axes[0]
    ax.pcolormesh(ex, ey, outcome, vmin=-0.5, vmax=len(DROP_REGIMES) - 0.5,
                  cmap=ListedColormap([DROP_COLOURS[g] for g in DROP_REGIMES]))
    present = [g for g in DROP_REGIMES if g in set(regimes)]
    ax.legend(handles=[Patch(color=DROP_COLOURS[g], label=g) for g in present],
              loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=3, fontsize="small",
              frameon=False)
    ax.set_title("drop outcome (last window)", pad=34)
    ax = axes[1]
    Zw = grid(np.where(np.isfinite(whirl) & (whirl > 0), whirl, np.nan))
    pos = Zw[np.isfinite(Zw)]
    norm = LogNorm(max(float(pos.min()), 1e-3), float(pos.max())) if pos.size else None
    m = ax.pcolormesh(ex, ey, Zw, cmap="viridis", norm=norm)
    fig.colorbar(m, ax=ax, label="|mean whirl rate| / 2π [Hz]")
    Zm = grid(np.where(whip, 1.0, 0.0))
    ax.contour(xs, ys, Zm, levels=[0.5], colors="w", linewidths=1.5)
    if np.isfinite(Zw).sum() > 3:
        cs = ax.contour(xs, ys, Zw, levels=[30, 100, 300, 1000], colors="w",
                        linewidths=0.6, linestyles=":")
        ax.clabel(cs, fmt="%g Hz", fontsize=7)
    ax.set_title("whirl speed (white line: backward whirl / dry whirl inside)")
    ax = axes[2]
    m = ax.pcolormesh(ex, ey, grid(kept), cmap="magma", vmin=min(0.0, np.nanmin(kept)),
                      vmax=1.0)
    fig.colorbar(m, ax=ax, label="mean Ω over the window / initial Ω")
    cs = ax.contour(xs, ys, grid(kept), levels=[0.1, 0.25, 0.5, 0.75, 0.9], colors="w",
                    linewidths=0.6)
    ax.clabel(cs, fmt="%g", fontsize=7)
    ax.set_title("spin kept")
    for ax in axes:
        _drop_axes(ax, names, logs, xs, fixed)
    fig.suptitle(f"drop with the spin as a state: {len(x)} points; fixed: "
                 f"{_fixed_text(fixed)}")
    return fig


def _drop_axes(ax, names: list[str], logs: dict[str, bool], xs: np.ndarray,
               fixed: dict[str, float]) -> None:
    from matplotlib.ticker import FormatStrFormatter, NullFormatter

    ax.set_xscale("log" if logs.get(names[0]) else "linear")
    ax.set_yscale("log" if logs.get(names[1]) else "linear")
    for axis, name in ((ax.xaxis, names[0]), (ax.yaxis, names[1])):
        if logs.get(name):
            axis.set_minor_formatter(NullFormatter())
            if name == "mu":
                axis.set_ticks([0.02, 0.05, 0.1, 0.2, 0.5])
                axis.set_major_formatter(FormatStrFormatter("%g"))
    ax.set_xlabel(_label(names[0]))
    ax.set_ylabel(_label(names[1]))
    if names == ["mu", "J"]:
        bound = [_j_bound({**fixed, "mu": float(v)}) for v in xs]
        lo, hi = ax.get_ylim()
        ax.plot(xs, bound, "w--", lw=1)
        mR2 = _m_R2(fixed)
        for frac, text in ((0.5, "½ m R² (solid disc)"), (1.0, "m R²")):
            ax.axhline(frac * mR2, color="c", ls=":", lw=0.8)
            ax.text(xs[0], frac * mR2, text, color="c", fontsize=7, va="bottom")
        ax.set_ylim(lo, hi)


def _j_bound(values: dict[str, float]) -> float:
    """Well-posedness bound m mu e_c (R + e_c) (kg m^2) at a point."""
    p = point_params(values)[0]
    return p.m * p.mu * p.e_c * (p.R + p.e_c)


def _m_R2(values: dict[str, float]) -> float:
    """m R^2 (kg m^2) at a point."""
    p = point_params(values)[0]
    return p.m * p.R * p.R


def _edges_log(v: np.ndarray) -> np.ndarray:
    """Cell edges around sorted positive centres v, geometric midpoints."""
    return np.exp(_edges(np.log(v)))


def _edges(v: np.ndarray) -> np.ndarray:
    """Cell edges around sorted centres v."""
    mid = (v[1:] + v[:-1]) / 2.0
    return np.concatenate([[2 * v[0] - mid[0]], mid, [2 * v[-1] - mid[-1]]])


def _marker_size(x: np.ndarray, y: np.ndarray) -> float:
    n = max(len(np.unique(x)), len(np.unique(y)), 1)
    return float(np.clip(9000.0 / n**2, 2.0, 120.0))


def _beb_curve(names, x, y, fixed, n: int = 120):
    """(X, Y, |U*| - 1) on a grid for the BEB contour (None if it cannot be computed)."""
    xs = np.linspace(x.min(), x.max(), n)
    ys = np.linspace(y.min(), y.max(), n)
    Z = np.empty((n, n))
    try:
        for j, yv in enumerate(ys):
            for i, xv in enumerate(xs):
                Z[j, i] = _u_star_excess({**fixed, names[0]: float(xv), names[1]: float(yv)})
    except ValueError:
        return None
    X, Y = np.meshgrid(xs, ys)
    return X, Y, Z


def _label(name: str) -> str:
    return {"gamma": "γ = c/(mΩ)", "omega": "ω = √(k/m)/Ω", "rho": "ρ = e_c/c_r",
            "phi": "φ [rad]", "mu": "μ", "d": "d (restitution)", "R_over_cr": "R/c_r",
            "Omega": "Ω [rad/s]", "J": "J [kg m²]",
            "T_drive": "T_drive [N m]"}.get(name, name)


def _fixed_text(fixed: dict[str, float]) -> str:
    extra = ", ".join(f"{k}={v:g}" for k, v in fixed.items())
    return "chapter set" + (f" with {extra}" if extra else "")
