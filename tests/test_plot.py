"""``rotortd plot``: c_r from the data, FMPy CSV and co-simulation .npz results, the spin and
impact panels, and the messages for bad input. The FMU runs in a subprocess (python -m fmpy
simulate), as a user runs it."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from rotortd_cosim.scenes import RECORDED
from rotortd_tools.cli import main
from rotortd_tools.plot import (
    PlotError,
    check_columns,
    clearance_from_data,
    co_rotating,
    load_result,
    make_figure,
)

C_R_WIDE = 1.2e-3   # m, a clearance other than the chapter's 0.7 mm


@pytest.fixture(scope="module")
def wide_csv(fmu_path: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """50 ms of a drop (bearing off, g = 9.81) with c_r = 1.2 mm: every output at 1e-4 s,
    impacts from 24 ms on."""
    out = tmp_path_factory.mktemp("plot") / "wide.csv"
    proc = subprocess.run(
        [sys.executable, "-m", "fmpy", "simulate", str(fmu_path), "--start-values", "c_r",
         repr(C_R_WIDE), "g", "9.81", "amb_on", "0", "--stop-time", "0.05",
         "--output-interval", "1e-4",
         "--output-file", str(out)], capture_output=True, text=True, timeout=120)
    assert out.is_file(), proc.stdout[-2000:] + proc.stderr[-2000:]
    return out


def _npz_like_cosim(columns: dict[str, np.ndarray], path: Path) -> Path:
    """A .npz in the layout of python -m rotortd_cosim.run: time and Component.variable
    for every recorded output (rotortd_cosim.scenes.RECORDED); the bearing's from
    ``columns``, the others zeros."""
    arrays = {"time": columns["time"]}
    for comp, var in RECORDED:
        src = columns[var] if comp == "RotorTouchdown" else np.zeros_like(columns["time"])
        arrays[f"{comp}.{var}"] = src
    np.savez(path, **arrays)
    return path


def test_csv_clearance_comes_from_the_data(wide_csv: Path, tmp_path: Path, capsys) -> None:
    cols = load_result(wide_csv)
    assert math.isclose(clearance_from_data(cols), C_R_WIDE, rel_tol=1e-12)
    png = tmp_path / "wide.png"
    assert main(["plot", str(wide_csv), "-o", str(png)]) == 0
    assert png.stat().st_size > 10_000
    out = capsys.readouterr().out
    assert "c_r = 0.0012 m (from |(x, y)|/r_rel in the data)" in out, out
    # the orbit stays in the clearance circle, which the old fixed 0.7 mm would break
    assert np.max(np.hypot(cols["x"], cols["y"])) / C_R_WIDE <= 1.0 + 1e-12
    assert np.max(np.hypot(cols["x"], cols["y"])) / 0.7e-3 > 1.0


def test_c_r_option_overrides_and_notes_the_data(wide_csv: Path, tmp_path: Path,
                                                  capsys) -> None:
    assert main(["plot", str(wide_csv), "-o", str(tmp_path / "a.png"), "--c-r", "7e-4"]) == 0
    out = capsys.readouterr().out
    assert "c_r = 0.0007 m (--c-r); note: the data gives 0.0012 m" in out, out


def test_figure_has_the_spin_and_impact_panels(wide_csv: Path) -> None:
    cols = load_result(wide_csv)
    assert check_columns(cols, "wide.csv") == []
    fig = make_figure(cols, C_R_WIDE)
    labels = [ax.get_ylabel() for ax in fig.axes]
    assert labels == ["y / c_r,  Im U", "r / c_r [1]", "F_n [N]", "T_f [N m]",
                      "spin Omega_out [rad/s]", "impacts (total)", "mode"]
    spin = fig.axes[4].lines[0].get_ydata()
    assert np.array_equal(spin, cols["Omega_out"])
    impacts = fig.axes[5].lines[0].get_ydata()
    assert impacts[-1] == cols["n_impacts"][-1] > 0


def test_npz_of_a_cosimulation(wide_csv: Path, tmp_path: Path, capsys) -> None:
    cols = load_result(wide_csv)
    npz = _npz_like_cosim(cols, tmp_path / "run.npz")
    got = load_result(npz)
    assert "u_re" not in got and "Drivetrain.Omega" not in got
    assert np.array_equal(got["Omega_out"], cols["Omega_out"])
    assert check_columns(got, "run.npz") == []
    # U from x, y and psi equals the FMU's own u_re + i u_im
    u = co_rotating(got, clearance_from_data(got))
    assert np.max(np.abs(u - (cols["u_re"] + 1j * cols["u_im"]))) <= 1e-12
    png = tmp_path / "run.png"
    assert main(["plot", str(npz), "-o", str(png)]) == 0 and png.stat().st_size > 10_000
    assert "c_r = 0.0012 m" in capsys.readouterr().out


def test_unknown_file_type_and_unreadable_files(tmp_path: Path, capsys) -> None:
    txt = tmp_path / "result.txt"
    txt.write_text("time,x\n0,0\n")
    assert main(["plot", str(txt), "-o", str(tmp_path / "x.png")]) == 2
    err = capsys.readouterr().err
    assert "unknown file type '.txt'" in err and ".csv" in err and ".npz" in err, err
    fake = tmp_path / "binary.csv"
    fake.write_bytes(b"PK\x03\x04\x14\x00\x00\x00\x08\x00\xff\xfe")
    assert main(["plot", str(fake), "-o", str(tmp_path / "x.png")]) == 2
    assert "not a text CSV" in capsys.readouterr().err
    assert main(["plot", str(tmp_path / "none.csv"), "-o", str(tmp_path / "x.png")]) == 2
    assert "no such file" in capsys.readouterr().err


def test_missing_columns_are_named(wide_csv: Path, tmp_path: Path, capsys) -> None:
    cols = load_result(wide_csv)
    with pytest.raises(PlotError, match=r"lacks column\(s\) r_rel, mode"):
        check_columns({k: v for k, v in cols.items() if k not in ("r_rel", "mode")}, "a.csv")
    lean = {k: v for k, v in cols.items()
            if k not in ("Omega_out", "n_impacts", "n_impacts_step", "u_re", "u_im", "psi")}
    notes = check_columns(lean, "b.csv")
    assert any("'Omega_out'" in n for n in notes)
    assert any("'n_impacts' or 'n_impacts_step'" in n for n in notes)
    assert any("co-rotating orbit U is left out" in n for n in notes)
    labels = [ax.get_ylabel() for ax in make_figure(lean, C_R_WIDE).axes]
    assert "spin Omega_out [rad/s]" not in labels and "impacts (total)" not in labels
    npz = _npz_like_cosim(cols, tmp_path / "run.npz")
    assert main(["plot", str(npz), "-o", str(tmp_path / "x.png"), "--component", "Rotor"]) == 2
    err = capsys.readouterr().err
    assert "no columns of component 'Rotor'" in err and "RotorTouchdown" in err, err


def test_clearance_that_varies_or_cannot_be_found(wide_csv: Path, tmp_path: Path,
                                                   capsys) -> None:
    cols = load_result(wide_csv)
    twice = {k: np.concatenate([v, v]) for k, v in cols.items()}
    twice["x"][len(cols["x"]):] *= 2.0
    twice["y"][len(cols["y"]):] *= 2.0
    with pytest.raises(PlotError, match=r"c_r varies in the data.*--c-r"):
        clearance_from_data(twice)
    still = {**cols, "r_rel": np.zeros_like(cols["r_rel"])}
    with pytest.raises(PlotError, match=r"cannot be determined.*--c-r"):
        clearance_from_data(still)
    assert main(["plot", str(wide_csv), "-o", str(tmp_path / "x.png"), "--c-r", "-1"]) == 2
    assert "--c-r -1.0 m: the radial clearance must be finite and > 0" in capsys.readouterr().err
