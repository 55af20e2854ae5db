"""Regenerate the validation tables and figures (docs/validation.md, docs/img/validation_*).

    python docs/scripts/validation.py [--skip-chapter] [--jobs 2]

Builds the FMU from the current sources into a temporary directory, runs every scene of
models/scenes/ through FMPy (CLI and API) at every communication step of
``STEPS`` (tests/validation_lib.py), compares impact by impact with the mpmath reference and the
direct integrator, and writes:

* the generated block of docs/validation.md (between the BEGIN/END markers);
* docs/validation_results.json (every number of the tables);
* docs/img/validation_error_vs_step.png, validation_impacts.png, validation_orbits.png;
* unless --skip-chapter: the chapter reproduction (docs/scripts/chapter.py: chapter_*.png,
  chapter_results.md/json).

Errors are scaled: positions in c_r, velocities in c_r Omega, times in 1/Omega. The
references themselves are regenerated separately (tests/reference/make_references.py,
about 3 minutes). Run time of this script: about 2 minutes plus about 1 minute for the chapter.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from mdblock import replace_block  # noqa: E402 (docs/scripts/mdblock.py)

from tests import validation_lib as V  # noqa: E402

DOCS = ROOT / "docs"
IMG = DOCS / "img"
APIS = ("api", "cli")
ORBIT_SCENES = ("Cycle_g0065", "Chatter_to_rub", "Dry_whirl_rolling", "AMB_drop")


def build_fmu(dest: Path) -> Path:
    """Build the FMU from the current sources with build.py's own function."""
    import build

    spec = next(s for s in build.FMU_SPECS if s.name == "RotorTouchdown")
    return build.build_fmu(spec, dest)


def run_matrix(fmu: Path, workdir: Path, jobs: int) -> dict[tuple[str, float, str], Any]:
    """Every scene x step x interface: (Comparison, FmuRun) keyed by (scene, h, api)."""
    scenes = {n: V.load_scene(n) for n in V.scene_names()}
    keys = [(n, h, a) for n in scenes for h in V.STEPS for a in APIS]

    def job(key: tuple[str, float, str]) -> tuple[Any, Any]:
        name, h, api = key
        run = V.run_fmu(fmu, scenes[name], h, api, workdir)
        return V.compare(scenes[name], run, h, api), run

    with ThreadPoolExecutor(jobs) as ex:
        return dict(zip(keys, ex.map(job, keys)))


def _e(x: float) -> str:
    """Short scientific notation."""
    return "0" if x == 0 else f"{x:.1e}"


def scene_table() -> list[str]:
    """Markdown table of the scenes: description, horizon, impacts, contact, amplification."""
    rows = ["| scene | what | stop (s) | ref. impacts | contact events (s) | max amplification |"
            " count change under 1e-12 |", "|---|---|---|---|---|---|---|"]
    for name in V.scene_names():
        sc = V.load_scene(name)
        ev = ", ".join(f"{k} {t:.5f}" for t, k in sc.meta["reference"]["contact_events"])
        rows.append(f"| {name} | {sc.meta['description']} | {sc.stop:g} | {len(sc.impacts)} | "
                    f"{ev or '-'} | {_e(sc.sens['max'])} | {V.count_slack(sc)} |")
    return rows


def error_table(res: dict) -> list[str]:
    """Markdown table scene x step: max errors, end error, tolerance, pass (API and CLI)."""
    rows = ["| scene | h (s) | impacts FMU/ref | max Δt | max Δz | max Δv | max grid | end |"
            " end tol | worst err/tol | CLI = API | pass |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for name in V.scene_names():
        for h in V.STEPS:
            a, c = res[(name, h, "api")][0], res[(name, h, "cli")][0]
            s = a.summary()
            same = _same(a, c)
            ok = "yes" if not a.failures and not c.failures else "**no**"
            rows.append(f"| {name} | {h:g} | {s['n_fmu']}/{s['n_ref']} | {_e(s['max_dt'])} | "
                        f"{_e(s['max_dz'])} | {_e(s['max_dv'])} | {_e(s['max_grid'])} | "
                        f"{_e(s['end'])} | {_e(s['end_tol'])} | {s['worst_ratio']:.2f} | "
                        f"{'yes' if same else 'no'} | {ok} |")
    return rows


def _same(a: Any, c: Any) -> bool:
    """CLI and API gave identical errors (the same FMU, the same steps)."""
    return (a.n_fmu == c.n_fmu and np.array_equal(a.imp_t, c.imp_t)
            and np.array_equal(a.grid, c.grid))


def direct_table() -> list[str]:
    """Markdown table: direct integrator vs mpmath (impacts by index, grid, end)."""
    rows = ["| scene | impacts direct/mp | max Δt | max Δz | max Δv | max grid | end |",
            "|---|---|---|---|---|---|---|"]
    for name in V.scene_names():
        d = V.direct_errors(V.load_scene(name))
        rows.append(f"| {name} | {d['n_direct']}/{d['n_ref']} | {_e(d['max_dt'])} | "
                    f"{_e(d['max_dz'])} | {_e(d['max_dv'])} | {_e(d['max_grid'])} | "
                    f"{_e(d['end'])} |")
    return rows


def fmu_vs_direct_table(res: dict) -> list[str]:
    """FMU (API, h = 1e-4) against the direct integrator, impacts matched by index."""
    rows = ["| scene | max Δt | max Δz | max Δv | end |", "|---|---|---|---|---|"]
    for name in V.scene_names():
        sc = V.load_scene(name)
        run = res[(name, 1e-4, "api")][1]
        e = V.impact_errors(sc, run.impacts, sc.direct_impacts)
        d = {"time": sc.direct["time"], "x": sc.direct["x"], "y": sc.direct["y"],
             "vx": sc.direct["vx"], "vy": sc.direct["vy"]}
        r = run.result
        k = int(np.argmin(np.abs(r["time"] - d["time"][-1])))
        end = max(np.hypot(r["x"][k] - d["x"][-1], r["y"][k] - d["y"][-1]) / sc.c_r,
                  np.hypot(r["vx"][k] - d["vx"][-1], r["vy"][k] - d["vy"][-1])
                  / (sc.c_r * sc.omega))
        dv = np.maximum(e["vm"], e["vp"])
        rows.append(f"| {name} | {_e(V._max(e['t']))} | {_e(V._max(e['z']))} | "
                    f"{_e(V._max(dv))} | {_e(float(end))} |")
    return rows


def plot_error_vs_step(res: dict) -> None:
    """Max end-state and impact-time error vs communication step, one line per scene."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharex=True)
    for name in V.scene_names():
        hs = np.array(V.STEPS)
        end = [res[(name, h, "api")][0].end for h in hs]
        ratio = [res[(name, h, "api")][0].worst_ratio() for h in hs]
        axes[0].loglog(hs, np.maximum(end, 1e-17), "o-", label=name)
        axes[1].loglog(hs, np.maximum(ratio, 1e-6), "o-", label=name)
    axes[0].set_ylabel("end-state error (scaled: c_r, c_r Ω)")
    axes[1].set_ylabel("worst error / tolerance (all quantities)")
    axes[1].axhline(1.0, color="k", lw=1)
    for ax in axes:
        ax.set_xlabel("communication step h (s)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.suptitle("FMU (fmpy.simulate_fmu) vs mpmath reference")
    fig.tight_layout()
    fig.savefig(IMG / "validation_error_vs_step.png", dpi=110)
    plt.close(fig)


def plot_impacts(res: dict) -> None:
    """Impact-by-impact time error and tolerance for two scenes at h = 1e-4 s."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for ax, name in zip(axes, ("Cycle_g0065", "Chatter_to_rub")):
        sc = V.load_scene(name)
        cmp = res[(name, 1e-4, "api")][0]
        i = np.arange(len(cmp.imp_t))
        ax.semilogy(i, np.maximum(cmp.imp_t, 1e-17), ".", label="|Δt| FMU vs mp (1/Ω)")
        ax.semilogy(i, np.maximum(cmp.imp_v, 1e-17), "x", ms=3, label="|Δv| (c_r Ω)")
        ax.semilogy(i, cmp.imp_t_tol, "-", lw=1, label="tolerance Δt")
        rd = sc.impacts[: len(i), 7] / (sc.c_r * sc.omega)
        ax.semilogy(i, rd, "--", lw=1, color="gray", label="ṙ⁻ (c_r Ω)")
        ax.set_title(f"{name}, h = 1e-4 s")
        ax.set_xlabel("impact number")
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(IMG / "validation_impacts.png", dpi=110)
    plt.close(fig)


def plot_orbits(res: dict) -> None:
    """Orbits (x/c_r, y/c_r) of a few scenes: FMU at h = 1e-4 s vs reference grid + impacts."""
    fig, axes = plt.subplots(1, len(ORBIT_SCENES), figsize=(4 * len(ORBIT_SCENES), 4.2))
    th = np.linspace(0, 2 * np.pi, 400)
    for ax, name in zip(axes, ORBIT_SCENES):
        sc = V.load_scene(name)
        r = res[(name, 1e-4, "api")][1].result
        ax.plot(np.cos(th), np.sin(th), "k-", lw=0.8)
        ax.plot(r["x"] / sc.c_r, r["y"] / sc.c_r, "-", lw=0.7, label="FMU, h = 1e-4 s")
        ax.plot(sc.ref["x"] / sc.c_r, sc.ref["y"] / sc.c_r, ".", ms=3, label="mp grid (1 ms)")
        if len(sc.impacts):
            ax.plot(sc.impacts[:, 1] / sc.c_r, sc.impacts[:, 2] / sc.c_r, "r+", ms=6,
                    label="mp impacts")
        ax.set_aspect("equal")
        ax.set_title(name, fontsize=9)
        ax.set_xlabel("x / c_r")
    axes[0].set_ylabel("y / c_r")
    axes[0].legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    fig.savefig(IMG / "validation_orbits.png", dpi=110)
    plt.close(fig)


def write_results(res: dict, secs: float) -> dict[str, Any]:
    """docs/validation_results.json: every summary plus timing."""
    out = {"seconds_matrix": round(secs, 1),
           "runs": [res[k][0].summary() for k in sorted(res)],
           "direct": {n: V.direct_errors(V.load_scene(n)) for n in V.scene_names()}}
    (DOCS / "validation_results.json").write_text(json.dumps(out, indent=1, default=float))
    return out


def update_markdown(res: dict, secs: float) -> None:
    """Replace the generated block of docs/validation.md."""
    n_fail = sum(1 for c, _ in res.values() if c.failures)
    worst = max(c.worst_ratio() for c, _ in res.values())
    lines = ["", f"Generated by `python docs/scripts/validation.py` ({len(res)} FMU runs "
             f"in {secs:.0f} s on 2 workers; {n_fail} failing; worst error/tolerance "
             f"{worst:.2f}).", "", "### Scenes", "", *scene_table(), "",
             "### FMU vs mpmath, per scene and communication step", "",
             "Max over all impacts (Δt in 1/Ω, Δz in c_r, Δv = max of before/after in c_r Ω), "
             "over the reference grid points (state), and at the end; `end tol` from the rule "
             "above; `worst err/tol` over every compared quantity (API run; the CLI run is "
             "compared separately).", "", *error_table(res), "",
             "### The two references: direct integrator vs mpmath", "", *direct_table(), "",
             "### FMU (API, h = 1e-4 s) vs direct integrator", "", *fmu_vs_direct_table(res),
             ""]
    replace_block(DOCS / "validation.md", "validation_tables", "\n".join(lines))


def main(argv: list[str] | None = None) -> None:
    """Command line entry point."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--skip-chapter", action="store_true")
    ap.add_argument("--jobs", type=int, default=2)
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="rotortd_val_") as tmp:
        fmu = build_fmu(Path(tmp))
        res = run_matrix(fmu, Path(tmp), args.jobs)
        secs = time.perf_counter() - t0
        write_results(res, secs)
        plot_error_vs_step(res)
        plot_impacts(res)
        plot_orbits(res)
        update_markdown(res, secs)
    print(f"validation: {len(res)} runs, {time.perf_counter() - t0:.0f} s", flush=True)
    if not args.skip_chapter:
        subprocess.run([sys.executable, str(DOCS / "scripts" / "chapter.py")], check=True,
                       cwd=str(ROOT))
    print(f"total {time.perf_counter() - t0:.0f} s", flush=True)


if __name__ == "__main__":
    main()
