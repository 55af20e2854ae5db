"""Parameter sweeps: specification errors, signatures, Dask = serial, resume after a kill."""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from rotortd import MODE_ROLLING, MODE_SLIDING
from rotortd.scaled import regular_equilibrium
from rotortd_tools import sweep as sw
from rotortd_tools.cli import main
from rotortd_tools.sweep import spec as sweep_spec

SHORT = sw.Settings(transient=60.0, record=30.0)


def _rows_by_key(path: Path) -> dict[str, dict]:
    data = sw.read_sweep(path)
    keys = data["key"]
    assert len(keys) == len(set(keys)), "a point is present more than once"
    return {k: {c: data[c][i] for c in data} for i, k in enumerate(keys)}


def _same(a: object, b: object) -> bool:
    if isinstance(a, float) and isinstance(b, float):
        return (math.isnan(a) and math.isnan(b)) or a == b
    return a == b


def _assert_identical(ra: dict[str, dict], rb: dict[str, dict]) -> None:
    assert set(ra) == set(rb)
    for key in ra:
        for col, va in ra[key].items():
            if col == "cpu_s":
                continue
            assert _same(va, rb[key][col]), (key, col, va, rb[key][col])


def _cycles_available() -> bool:
    try:
        sw.cycle_finder()
    except ImportError:
        return False
    return True


# --------------------------------------------------------------------------- specification


@pytest.mark.parametrize(
    ("tokens", "starts", "fragment"),
    [
        (["gama=0.1:0.2:3"], "rest", "unknown parameter 'gama'"),
        (["gamma=0.2:0.1:3"], "rest", "lower end must be below"),
        (["gamma=0.1:0.2"], "rest", "bad range"),
        (["gamma=0.1:0.2:0"], "rest", "n = 0 must be > 0"),
        (["gamma=0.1:0.2:-4"], "rest", "must be > 0"),
        (["gamma=0.1:0.2:x"], "rest", "not an integer"),
        (["gamma=0.1:0.2:3", "gamma=0.3"], "rest", "gamma is given twice"),
        (["mu=0.1:0.2:3", "mu=0.1:0.3:3"], "rest", "mu is given twice"),
        (["d=0.5:1.2:3"], "rest", "d: upper end 1.2 is out of range [0, 1]"),
        (["d=1.5"], "rest", "d: value 1.5 is out of range"),
        (["gamma=-0.1:0.2:3"], "rest", "gamma: lower end -0.1 is out of range"),
        (["Omega=0:100:3"], "rest", "Omega: lower end 0.0 is out of range (0"),
        (["gamma=abc"], "rest", "'abc' is not a number"),
        (["gamma"], "rest", "bad token 'gamma'"),
        (["gamma=0.1:0.2:3", "mu=0:1:3", "d=0:1:3"], "rest", "at most two parameters"),
        (["gamma=0.1:0.2:3"], "rest,sideways", "unknown start 'sideways'"),
        (["gamma=0.1:0.2:3"], "cycle:medium", "unknown cycle branch 'medium'"),
        (["gamma=0.1:0.2:3"], "rest,rest", "given twice"),
        (["gamma=0.1:0.2:3"], "up:down", "seed cannot be up/down"),
    ],
)
def test_bad_specifications_raise_named_errors(tokens, starts, fragment):
    with pytest.raises(sw.SweepError, match=None) as err:
        sw.parse_spec(tokens, starts)
    assert fragment in str(err.value)


def test_cli_bad_specification_exits_2(capsys, tmp_path):
    rc = main(["sweep", "gamma=0.1:0.2:3", "d=2", "--out", str(tmp_path / "o")])
    assert rc == 2
    err = capsys.readouterr().err
    assert "rotortd sweep: error:" in err and "d: value 2.0 is out of range [0, 1]" in err
    rc = main(["sweep", "gamma=0.1:0.2:3", "--transient", "-1", "--out", str(tmp_path / "o")])
    assert rc == 2 and "transient" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_missing_cycles_module_gives_clear_error(monkeypatch):
    def broken():
        raise ImportError("No module named 'rotortd_tools.cycles'")

    monkeypatch.setattr(sweep_spec, "cycle_finder", broken)
    with pytest.raises(sw.SweepError, match=r"'cycle' start needs rotortd_tools\.cycles"):
        sw.parse_spec(["gamma=0.1:0.2:3"], "rest,cycle")
    sw.parse_spec(["gamma=0.1:0.2:3"], "rest,steady,large,up,down:steady")


def test_grid_random_aliases_and_point_order():
    spec = sw.parse_spec(["gamma=0.1:0.3:5", "R/c_r=40:60:~3", "mu=0.2"], "rest", seed=7)
    assert spec.axes[0].values == tuple(np.linspace(0.1, 0.3, 5))
    r = spec.axes[1].values
    assert spec.axes[1].name == "R_over_cr" and list(r) == sorted(r)
    assert all(40 <= v <= 60 for v in r)
    assert sw.parse_spec(["R/c_r=40:60:~3"], "rest", seed=7).axes[0].values != r
    assert sw.parse_spec(["gamma=0.1:0.2:2", "R/c_r=40:60:~3"], "rest", seed=7
                         ).axes[1].values == r
    pts = spec.points()
    assert len(pts) == 15 and pts[1] == {"gamma": spec.axes[0].values[1], "R_over_cr": r[0]}
    _, Omega, sp = sw.point_params(spec.values_of(pts[0]))
    assert (sp.gamma, sp.mu, sp.R_over_cr, Omega) == (0.1, 0.2, r[0], 184.2)
    _, _, sp2 = sw.point_params({"Omega": 368.4})
    assert sp2.gamma == pytest.approx(0.152009 / 2, rel=1e-5)


# --------------------------------------------------------------------------- signatures


def test_detect_period_and_classify():
    a = [0.1, 0.5] * 20
    v = [0.7, 0.3] * 20
    assert sw.detect_period(a, v, 1e-6, 8) == 2
    assert sw.detect_period([0.2] * 10, [0.5] * 10, 1e-6, 8) == 1
    rng = np.random.default_rng(1)
    assert sw.detect_period(list(rng.uniform(size=60)), list(rng.uniform(size=60)), 1e-6, 8) == 0
    assert sw.detect_period([math.pi - 1e-9, -math.pi + 1e-9] * 2, [1.0] * 4, 1e-6, 4) == 1
    assert sw.classify(0, 0.0, 0.0, 0) == "free"
    assert sw.classify(10, 0.0, 0.0, 3) == "period-3"
    assert sw.classify(10, 0.1, 0.0, 0) == "irregular"
    assert sw.classify(0, 0.9, 0.1, 0) == "rub"
    assert sw.classify(0, 0.0, 1.0, 0) == "dry-whirl"
    assert sw.regime_group("period-7") == "period-n"


def _run(gamma: float, start: str, settings: sw.Settings | None = None) -> dict:
    settings = settings or sw.Settings()
    job = sw.Job(0, (("gamma", gamma),), (("gamma", gamma),), start)
    return sw.run_job(job, settings)[0]


def test_chapter_regimes_from_named_starts():
    """Free whirl at |U*| from 'steady' above the BEB; rub from rest at 0.3; whip at 0.065."""
    sp = sw.point_params({"gamma": 0.3})[2]
    u_star = abs(regular_equilibrium(sp))
    free = _run(0.3, "steady")
    assert free["regime"] == "free" and free["n_impacts"] == 0
    assert free["r_max"] == pytest.approx(u_star, abs=1e-9)
    rub = _run(0.3, "rest")
    assert rub["regime"] == "rub" and rub["final_mode"] == MODE_SLIDING
    assert rub["contact_frac"] == pytest.approx(1.0) and rub["r_min"] == pytest.approx(1.0)
    whip = _run(0.065, "rest")
    assert whip["regime"] == "dry-whirl" and whip["final_mode"] == MODE_ROLLING
    below = _run(0.065, "steady")
    assert below["regime"] == "no-start" and "not admissible" in below["message"]


def test_impacting_signature_is_consistent():
    row = _run(0.1, "rest")
    assert row["regime"] == "period-1" and row["status"] == "ok"
    n = row["n_impacts"]
    assert n > 5 and row["r_max"] == 1.0 and row["contact_frac"] == 0.0
    assert row["impacts_per_rev"] == pytest.approx(n * 2 * math.pi / 100.0, rel=1e-2)
    assert row["period_time"] == pytest.approx(2 * math.pi / row["impacts_per_rev"], rel=0.05)
    sec_v, sec_a = row["sec_speed"], row["sec_angle"]
    assert len(sec_v) == min(n, 64) and max(sec_v) == row["v_max"]
    assert max(sec_v) - min(sec_v) < 1e-4 and max(sec_a) - min(sec_a) < 1e-4
    assert all(-math.pi < a <= math.pi for a in sec_a)


@pytest.mark.skipif(not _cycles_available(), reason="rotortd_tools.cycles not available")
def test_cycle_start_stays_on_stable_cycle():
    row = _run(0.12, "cycle", SHORT)
    assert row["status"] == "ok" and row["regime"] == "period-1", row["message"]
    assert _run(0.29, "cycle", SHORT)["regime"] == "no-start"


# --------------------------------------------------------------------------- execution


def test_continuation_chain_splitting_is_exact(tmp_path):
    """A continuation pass gives the same rows whatever the segment size and resume point."""
    spec = sw.parse_spec(["gamma=0.09:0.2:6"], "down:steady,up")
    plan = sw.make_plan(spec, set(), {})
    rows: list[dict] = []
    sw.run_serial(plan, SHORT, rows.extend)
    ref = {r["key"]: r for r in rows}
    seg_rows: list[dict] = []
    for chain, state in plan.chains:
        prev = ([], state)
        for seg in sw.batches(chain, 4):
            prev = sw.run_segment(seg, SHORT, prev)
            seg_rows += prev[0]
    _assert_identical(ref, {r["key"]: r for r in seg_rows})
    done = {r["key"] for r in rows if r["index"] < 3}
    states = {r["key"]: r["final_state"] for r in rows}
    rest = sw.make_plan(spec, done, states)
    assert rest.n_todo == 3 + 6  # "up" resumes at index 3; "down" has no finished prefix
    more: list[dict] = []
    sw.run_serial(rest, SHORT, more.extend)
    for r in more:
        _assert_identical({r["key"]: ref[r["key"]]}, {r["key"]: r})


def test_dask_local_cluster_equals_serial(tmp_path):
    """Two worker processes give the same numbers, point for point, as a serial run."""
    starts = "rest,steady,large,up,down:steady" + (",cycle" if _cycles_available() else "")
    spec = sw.parse_spec(["gamma=0.06:0.3:7", "mu=0.15"], starts)
    sw.run_sweep(spec, SHORT, tmp_path / "serial", serial=True)
    counts = sw.run_sweep(spec, SHORT, tmp_path / "dask", workers=2, batch=2, chunk=3,
                          progress=False)
    assert counts == {"total": 7 * len(spec.starts), "resumed": 0,
                      "computed": 7 * len(spec.starts)}
    a, b = _rows_by_key(tmp_path / "serial"), _rows_by_key(tmp_path / "dask")
    assert len(a) == 7 * len(spec.starts)
    _assert_identical(a, b)
    regimes = {r["regime"] for r in a.values()}
    assert {"free", "rub", "dry-whirl"} <= regimes


def test_resume_refuses_a_different_sweep(tmp_path):
    spec = sw.parse_spec(["gamma=0.1:0.2:2"], "steady")
    sw.run_sweep(spec, SHORT, tmp_path / "o", serial=True)
    with pytest.raises(sw.SweepError, match="holds a different sweep"):
        sw.run_sweep(spec, sw.Settings(transient=61.0, record=30.0), tmp_path / "o",
                     serial=True)
    counts = sw.run_sweep(sw.parse_spec(["gamma=0.1:0.2:2"], "steady,rest"), SHORT,
                          tmp_path / "o", serial=True)
    assert counts == {"total": 4, "resumed": 2, "computed": 2}


def test_resume_after_killed_cli_run(tmp_path):
    """Kill the CLI (and its worker processes) after some rows, rerun: all rows, once, exact."""
    out = tmp_path / "killed.parquet"
    args = ["gamma=0.06:0.3:40", "--starts", "rest,up,down:steady", "--transient", "150",
            "--record", "50", "--out", str(out)]
    cmd = [sys.executable, "-m", "rotortd_tools.cli", "sweep", *args, "--workers", "2",
           "--batch", "1", "--chunk", "2", "--flush-seconds", "0.3", "--no-progress"]
    proc = subprocess.Popen(cmd, start_new_session=True, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and proc.poll() is None:
            if len(sw.part_files(out)) >= 2:
                break
            time.sleep(0.05)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait(timeout=30)
    n_before = len(sw.read_sweep(out).get("key", []))
    assert 0 < n_before < 120, "the run was not interrupted part way"
    res = subprocess.run([sys.executable, "-m", "rotortd_tools.cli", "sweep", *args,
                          "--workers", "2", "--no-progress"],
                         capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    assert f"{n_before} already present" in res.stdout
    spec = sw.parse_spec(["gamma=0.06:0.3:40"], "rest,up,down:steady")
    settings = sw.Settings(transient=150.0, record=50.0)
    sw.run_sweep(spec, settings, tmp_path / "ref", serial=True)
    _assert_identical(_rows_by_key(tmp_path / "ref"), _rows_by_key(out))


# --------------------------------------------------------------------------- plots


def test_sweep_plot_1d_2d_and_chapter_events(tmp_path):
    from rotortd_tools.sweep_plot import beb_values, chapter_events, gamma_beb

    sw.run_sweep(sw.parse_spec(["gamma=0.06:0.2:4"], "rest,steady"), SHORT,
                 tmp_path / "a", serial=True)
    sw.run_sweep(sw.parse_spec(["gamma=0.06:0.2:3", "mu=0.1:0.3:2"], "rest"), SHORT,
                 tmp_path / "b", serial=True)
    res = tmp_path / "chapter_results.json"
    res.write_text(json.dumps({"events": [{"event": "fold", "gamma": 0.15}],
                               "gamma_grazing": 0.0651, "pd": [0.11], "other": 3}))
    assert chapter_events(res) == [("grazing", 0.0651), ("period doubling", 0.11),
                                   ("fold", 0.15)]
    assert chapter_events(tmp_path / "missing.json") == []
    g = gamma_beb({})
    assert beb_values("gamma", 0.05, 0.3, {}) == pytest.approx([g], abs=1e-6)
    assert g == pytest.approx(0.07285, abs=1e-5)
    assert main(["sweep-plot", str(tmp_path / "a"), "-o", str(tmp_path / "a.png"),
                 "--results", str(res)]) == 0
    assert main(["sweep-plot", str(tmp_path / "b"), "-o", str(tmp_path / "b.png")]) == 0
    assert (tmp_path / "a.png").stat().st_size > 10_000
    assert (tmp_path / "b.png").stat().st_size > 10_000
    assert main(["sweep-plot", str(tmp_path / "none"), "-o", str(tmp_path / "c.png")]) == 2


# --------------------------------------------------------------------------- spin as a state


def test_grammar_accepts_J_T_drive_and_geometric_grids():
    spec = sw.parse_spec(["mu=0.02:0.5:log3", "J=3.2e-4:1.6:log4", "T_drive=0.5"], "drop")
    assert spec.names == ("mu", "J") and dict(spec.fixed) == {"T_drive": 0.5}
    assert spec.axes[0].log and spec.axes[1].log and not spec.axes[0].random
    assert spec.axes[0].values == pytest.approx((0.02, 0.1, 0.5))
    assert spec.axes[1].values[0] == 3.2e-4 and spec.axes[1].values[-1] == 1.6
    assert sw.spin_inputs(spec.values_of(spec.points()[1])) == (3.2e-4, 0.5)
    assert sw.spin_inputs({"gamma": 0.1}) == (None, 0.0)
    assert sw.parse_spec(["J=0.04"], "rest,steady,large,up").fixed == (("J", 0.04),)
    assert sw.parse_spec(["J=0.04", "T_drive=-2:2:3"], "rest").names == ("T_drive",)


@pytest.mark.parametrize(
    ("tokens", "starts", "fragment"),
    [
        (["T_drive=1"], "rest", "T_drive needs J"),
        (["J=0"], "rest", "J: value 0.0 is out of range (0, inf)"),
        (["J=-1:1:3"], "rest", "J: lower end -1.0 is out of range"),
        (["mu=0.5", "J=1e-4:1:log3"], "drop", "too small"),  # bound 3.02e-4 at mu = 0.5
        (["mu=0:0.5:log3"], "rest", "geometric grid '0:0.5:log3' needs a lower end > 0"),
        (["J=0.01:1:logx"], "rest", "not an integer"),
        (["J=0.04"], "up:drop", "a drop cannot seed a continuation"),
    ],
)
def test_grammar_refuses_bad_spin_specifications(tokens, starts, fragment):
    with pytest.raises(sw.SweepError) as err:
        sw.parse_spec(tokens, starts)
    assert fragment in str(err.value)


def test_drop_settings_are_validated(capsys, tmp_path):
    sw.Settings(drop_time=0.3, drop_window=0.3, drop_step=1e-4).validate()
    for bad in ({"drop_time": 0.0}, {"drop_window": 0.5}, {"drop_step": 0.2}):
        with pytest.raises(sw.SweepError, match=next(iter(bad))):
            sw.Settings(**bad).validate()
    rc = main(["sweep", "J=0.04", "--starts", "drop", "--drop-window", "1",
               "--out", str(tmp_path / "o")])
    assert rc == 2 and "drop_window" in capsys.readouterr().err


DROP = sw.Settings(drop_time=0.15, drop_window=0.03, drop_step=1e-4)


def test_two_point_drop_sweep_with_J_records_outcomes(tmp_path):
    """mu = 0.15, J = 0.04 and 1.6 kg m^2: both drops end in dry whirl; the whip speed is
    the rolling relation theta' = -R Omega / c_r, and the heavier spin keeps more speed."""
    spec = sw.parse_spec(["J=0.04:1.6:log2", "mu=0.15"], "drop")
    counts = sw.run_sweep(spec, DROP, tmp_path / "d", serial=True)
    assert counts == {"total": 2, "resumed": 0, "computed": 2}
    rows = sorted(_rows_by_key(tmp_path / "d").values(), key=lambda r: r["J"])
    assert [r["J"] for r in rows] == [0.04, 1.6] and [r["T_drive"] for r in rows] == [0, 0]
    p = sw.point_params({})[0]
    for r in rows:
        assert r["status"] == "ok" and r["regime"] == "dry-whirl", r
        assert r["regime"] in sw.DROP_OUTCOMES and r["final_mode"] == MODE_ROLLING
        assert r["roll_frac"] == pytest.approx(1.0) and r["slip_ratio"] < 1e-9
        assert r["whirl_mean"] == pytest.approx(-p.R * r["Omega_mean"] / p.c_r, rel=1e-3)
        assert 0.0 < r["Omega_mean"] < r["Omega"] and r["Omega_end"] > 0.0
    assert rows[1]["Omega_mean"] > 2.0 * rows[0]["Omega_mean"]
    meta = sw.read_meta(tmp_path / "d")
    assert meta["format"] == sw.FORMAT_VERSION == 4 and meta["axes"][0]["log"] is True


def test_spin_state_runs_without_drop_and_held_rows_have_no_J():
    """J with a named start runs a SpinCore: the drive torque moves the spin; without J
    the parameters J and T_drive are NaN and the spin stays held."""
    short = sw.Settings(transient=20.0, record=10.0)
    vals = (("J", 0.04), ("T_drive", 5.0))
    neg = (("J", 0.04), ("T_drive", -5.0))
    up = sw.run_job(sw.Job(0, vals, vals, "steady"), short)[0]
    down = sw.run_job(sw.Job(0, neg, neg, "steady"), short)[0]
    assert up["status"] == down["status"] == "ok" and up["regime"] == "free"
    assert up["Omega_end"] > up["Omega"] > down["Omega_end"]
    assert math.isnan(up["Omega_mean"]) and json.loads(up["final_state"])["rotor"]["J"] == 0.04
    held = _run(0.3, "steady", short)
    assert math.isnan(held["J"]) and math.isnan(held["T_drive"])
    assert held["Omega_end"] == held["Omega"]


def test_old_store_format_is_read_but_not_resumed(tmp_path):
    spec = sw.parse_spec(["gamma=0.1:0.2:2"], "steady")
    sw.run_sweep(spec, SHORT, tmp_path / "o", serial=True)
    meta = sw.read_meta(tmp_path / "o")
    meta["format"] = 1
    (tmp_path / "o" / sw.META_FILE).write_text(json.dumps(meta))
    assert len(sw.read_sweep(tmp_path / "o")["key"]) == 2
    with pytest.raises(sw.SweepError, match=r"store format 1.*read .*not resumed"):
        sw.run_sweep(spec, SHORT, tmp_path / "o", serial=True)


def _drop(n=0, slide=0.0, roll=0.0, W=100.0, whirl=-5000.0, ratio=0.0, tw=0.1):
    return sw.classify_drop(n, slide, roll, W, whirl, ratio, tw)


def test_classify_drop_classes_and_threshold_boundaries():
    from rotortd_tools.attractor import SLIP_ROLL, WHIRL_TURNS

    turn = 2.0 * math.pi * WHIRL_TURNS / 0.1  # whirl rate of one turn in the 0.1 s window
    assert _drop(0, 0.0, 0.0) == "no-contact"
    assert _drop(1, 0.0, 0.0) == "impacting"
    assert _drop(0, 0.01, 0.0) == "impacting"  # touched without impact: not no-contact
    assert _drop(30, 0.2, 0.2999) == "impacting"  # contact just below half the window
    assert _drop(30, 0.2, 0.3) == "dry-whirl"  # contact at half the window: sustained
    assert _drop(0, 1.0, 0.0, whirl=150.0, ratio=0.9) == "forward-rub"
    assert _drop(0, 1.0, 0.0, whirl=-3000.0, ratio=0.2) == "dry-whip"
    assert _drop(0, 0.0, 1.0, whirl=-3000.0, ratio=0.0) == "dry-whirl"
    assert _drop(0, 0.5, 0.5, whirl=-3000.0, ratio=SLIP_ROLL) == "dry-whirl"
    assert _drop(0, 0.5, 0.5, whirl=-3000.0, ratio=SLIP_ROLL * 1.001) == "dry-whip"
    assert _drop(0, 0.0, 1.0, whirl=-turn * 0.999) == "settled"  # rocking at the bottom
    assert _drop(0, 0.0, 1.0, whirl=turn * 0.999, ratio=0.5) == "settled"
    assert _drop(0, 0.0, 1.0, whirl=-turn * 1.001) == "dry-whirl"
    assert _drop(0, 1.0, 0.0, whirl=turn * 1.001, ratio=0.5) == "forward-rub"
    # the whirl's sense is taken against the spin: a reversed spin rolling forward whips
    assert _drop(0, 0.0, 1.0, W=-4.0, whirl=230.0) == "dry-whirl"
    assert _drop(0, 1.0, 0.0, W=-4.0, whirl=-230.0, ratio=0.5) == "forward-rub"
    assert _drop(0, 1.0, 0.0, W=0.0, whirl=230.0, ratio=0.5) == "forward-rub"


def test_drop_recorder_summary_normalises_the_slip():
    rec = sw.DropRecorder(t_window=0.1, n_impacts=0, t_slide=0.1, n=4, sum_Omega=400.0,
                          sum_whirl=-4 * 2000.0, sum_slip=4 * 0.05)
    s = rec.summary(R=0.04, c_r=7e-4)
    assert s["Omega_mean"] == 100.0 and s["whirl_mean"] == -2000.0
    assert s["slip_ratio"] == pytest.approx(0.05 / 4.0)  # R Omega = 4 > c_r theta' = 1.4
    assert s["contact_frac"] == pytest.approx(1.0) and s["regime"] == "dry-whip"


def test_drop_map_draws_from_a_drop_store(tmp_path):
    """sweep-plot of a two-parameter drop sweep draws the outcome map (no simulation: the
    rows are hand-made; two outcomes, a whip speed, a spin kept)."""
    from rotortd_tools.sweep_plot import drop_map

    mu, J = np.array([0.05, 0.5, 0.05, 0.5]), np.array([1e-3, 1e-3, 1.0, 1.0])
    cols = {"mu": mu, "J": J, "Omega": np.full(4, 184.2), "start": np.array(["drop"] * 4),
            "regime": np.array(["impacting", "settled", "impacting", "dry-whirl"]),
            "whirl_mean": np.array([10.0, 0.5, 100.0, -9000.0]),
            "Omega_mean": np.array([10.0, 0.1, 180.0, 170.0])}
    fig = drop_map(cols, ["mu", "J"], {}, {"mu": True, "J": True})
    assert [ax.get_xscale() for ax in fig.axes[:3]] == ["log"] * 3
    texts = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert texts == ["impacting", "settled", "dry-whirl"]
    fig.savefig(tmp_path / "m.png")
    assert (tmp_path / "m.png").stat().st_size > 10_000


def test_sweep_without_its_extra_says_what_to_install() -> None:
    """Without dask/pyarrow/tqdm (the [sweep] extra) the CLI exits 2 with one message."""
    code = ("import sys; sys.modules['dask'] = None; sys.modules['pyarrow'] = None; "
            "from rotortd_tools.cli import main; sys.exit(main(['sweep', 'mu=0.1', "
            "'--out', 'x.parquet']))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 2, proc.stderr
    assert "dask.distributed, pyarrow" in proc.stderr and '".[sweep]"' in proc.stderr


# --------------------------------------------------------------------------- real bearing

BEARING_ON = ["J=0.04", "race_turns=1", "support_compliant=1", "contact_compliant=1"]


def test_drop_sweep_over_k_b_with_the_real_bearing(tmp_path, capsys):
    """rotortd sweep k_b (docs/model.md §10, all three options on): two short drops through
    the CLI; the rows carry the bearing's parameters, the turning race keeps the spin."""
    out = tmp_path / "kb"
    rc = main(["sweep", "k_b=1e7:1e8:log2", *BEARING_ON, "--starts", "drop", "--serial",
               "--drop-time", "0.02", "--drop-window", "0.01", "--no-progress",
               "--out", str(out)])
    assert rc == 0, capsys.readouterr().err
    rows = sorted(_rows_by_key(out).values(), key=lambda r: r["k_b"])
    assert [r["k_b"] for r in rows] == [1e7, 1e8]
    for r in rows:
        assert r["status"] == "ok" and r["regime"] in sw.DROP_OUTCOMES, r
        assert (r["race_turns"], r["support_compliant"], r["contact_compliant"]) == (1, 1, 1)
        assert (r["J_b"], r["k_c"], r["p_c"]) == (2e-4, 1e9, 1.0)  # BearingParams' defaults
        assert 0.95 * r["Omega"] < r["Omega_end"] < r["Omega"]
        state = json.loads(r["final_state"])
        assert state["bearing"]["kind"] != "fixed-rigid"
    held = sw.run_job(sw.Job(0, (), (("J", 0.04),), "drop"),
                      sw.Settings(drop_time=0.02, drop_window=0.01))[0]
    assert math.isnan(held["k_b"]) and math.isnan(held["race_turns"])


@pytest.mark.parametrize(
    ("tokens", "starts", "fragment"),
    [
        (["k_b=1e7:1e8:2", "support_compliant=1"], "drop", "needs the spin as a state"),
        (["J=0.04", "k_b=1e7:1e8:2"], "drop", "k_b has no effect with support_compliant off"),
        (["J=0.04", "race_turns=0", "T_b0=0.1"], "drop", "T_b0 has no effect"),
        (["J=0.04", "race_turns=0.5"], "drop", "race_turns: value 0.5 is not 0 or 1"),
        (["J=0.04", "contact_compliant=1", "p_c=1.6"], "drop", "p_c: value 1.6 is out of range"),
        (["J=0.04", "support_compliant=1", "k_b=1e2"], "drop", "k_b: value 100.0 is out"),
        (["J=0.04", "contact_compliant=1", "d=0"], "drop", "d = 0.0 is refused"),
        (["J=0.04", "race_turns=1"], "rest,up", "not continued"),
    ],
)
def test_grammar_refuses_bad_bearing_specifications(tokens, starts, fragment):
    with pytest.raises(sw.SweepError) as err:
        sw.parse_spec(tokens, starts)
    assert fragment in str(err.value)
