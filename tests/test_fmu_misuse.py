"""Misuse of the FMU and its declared ranges, through FMPy in a subprocess.

- The misuse table (tests/fmu_misuse.py): each invalid parameter and input, each forbidden
  call order, each corrupt state gets the status and the message pinned in ``CASES``, and
  docs/fmu.md shows exactly that table.
- The ranges: for every Real parameter and input, a value inside its declared [min, max] is
  accepted and one clearly outside is refused, naming the variable, its unit and range.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from rotortd.limits import LIMITS

sys.path.insert(0, str(Path(__file__).resolve().parent))
import fmu_misuse

ROOT = Path(__file__).resolve().parent.parent
HERE = Path(__file__).resolve().parent


def _run(args: list[str], timeout: float = 300.0) -> tuple[object, str]:
    proc = subprocess.run([sys.executable, *args], capture_output=True, text=True,
                          timeout=timeout, cwd=str(ROOT))
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("RESULT:")]
    assert lines, f"rc={proc.returncode}\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
    return json.loads(lines[-1][len("RESULT:"):]), proc.stderr


@pytest.fixture(scope="module")
def misuse_rows(fmu_path: Path) -> tuple[list[dict], str]:
    rows, stderr = _run([str(HERE / "fmu_misuse.py"), str(fmu_path)])
    return rows, stderr


def test_misuse_table_statuses_and_messages(misuse_rows: tuple[list[dict], str]) -> None:
    rows, _stderr = misuse_rows
    assert [r["id"] for r in rows] == list(fmu_misuse.CASES)
    for row in rows:
        _what, _fn, (call, nxt), words, _fmi = fmu_misuse.CASES[row["id"]]
        assert (row["call"], row["next"]) == (call, nxt), row
        assert words in row["message"], row
    projected = next(r for r in rows if r["id"] == "start_ulps_outside")
    assert projected["message"] == "", projected


def test_failures_reach_stderr_without_logging(misuse_rows: tuple[list[dict], str]) -> None:
    """The first failure of each instance is one line on stderr (PythonFMU forwards log
    messages only with logging on)."""
    _rows, stderr = misuse_rows
    assert "inst: error: initialisation failed: m = -1.0 kg is out of range" in stderr
    assert "inst: error: output 'x' cannot be set by the host" in stderr


def test_docs_show_the_misuse_table(misuse_rows: tuple[list[dict], str]) -> None:
    rows, _stderr = misuse_rows
    doc = (ROOT / "docs" / "fmu.md").read_text(encoding="utf-8")
    assert fmu_misuse.render(rows) in doc, (
        "docs/fmu.md is stale: python tests/fmu_misuse.py models/RotorTouchdown.fmu --docs")


INSIDE_AND_OUTSIDE = {name: (lim.lo + 0.25 * (lim.hi - lim.lo),
                             lim.hi + max(1.0, abs(lim.hi)) if name != "d" else 1.5)
                      for name, lim in LIMITS.items()}


def test_every_range_accepts_inside_and_refuses_outside(fmu_path: Path) -> None:
    """Each Real parameter and input with a declared range: a value inside is accepted
    (init and one step OK) and one outside is refused with its name, unit and range."""
    cases = {}
    for name, (inside, outside) in INSIDE_AND_OUTSIDE.items():
        if name in ("x0", "y0"):  # inside the range but also inside the clearance
            inside = 0.5 * LIMITS["c_r"].lo
        cases[name] = (inside, outside)
    rows, _stderr = _run([str(HERE / "fmu_scenarios.py"), "ranges", str(fmu_path),
                          json.dumps({"cases": cases})])
    assert rows["ok"], rows
    for name, (inside_ok, outside_msgs) in rows["results"].items():
        # h_spin is deprecated (no effect): setting it draws one warning (fmi2Warning)
        assert inside_ok == ([1, 0] if name == "h_spin" else [0, 0]), (name, inside_ok)
        lim = LIMITS[name]
        want = f"{name} = "
        assert any(want in m and f"[{lim.lo:g}, {lim.hi:g}]" in m for m in outside_msgs), (
            name, outside_msgs)
