"""Compare the FMU recordings of a kept fingerprint run on the columns both trees have.

    python docs/scripts/fingerprint.py --base <commit> --keep      # prints: kept <dir>
    python docs/scripts/fingerprint_common.py <dir>

``fingerprint.py`` reports an FMU job as different when the recorded columns differ, which
is what adding an output does (T_imb). This script reads the kept recordings of both trees
(``<dir>/base``, ``<dir>/head``: ``fmu.json`` and the ``fmu__*.rows|imp|tr`` arrays) and
checks, per FMU job, every column of the base bit for bit (IEEE bits, NaN equal to NaN),
the impact and transition lists byte for byte, and the final FMU state with the head's new
variables removed. Exit 0 iff all of that is identical; it prints the new columns.
"""

from __future__ import annotations

import array
import json
import sys
from pathlib import Path
from typing import Any


def _rows(path: Path) -> array.array:
    out = array.array("d")
    out.frombytes(path.read_bytes())
    return out


def _without(value: Any, names: set[str]) -> Any:
    """value with every dict key in names removed, recursively."""
    if isinstance(value, dict):
        return {k: _without(v, names) for k, v in value.items() if k not in names}
    if isinstance(value, list):
        return [_without(v, names) for v in value]
    return value


def compare(kept: Path) -> bool:
    """Print one line per FMU job; True iff every job is identical on the base's columns."""
    base = json.loads((kept / "base" / "fmu.json").read_text())
    head = json.loads((kept / "head" / "fmu.json").read_text())
    all_same = True
    for job in sorted(base):
        cols_a, cols_b = base[job]["columns"][0], head[job]["columns"][0]
        new = [c for c in cols_b if c not in cols_a]
        a, b = _rows(kept / "base" / f"{job}.rows"), _rows(kept / "head" / f"{job}.rows")
        n = len(a) // len(cols_a)
        same = n == len(b) // len(cols_b) and set(cols_a) <= set(cols_b)
        if same:
            idx = [cols_b.index(c) for c in cols_a]
            same = all(a[r * len(cols_a) + i].hex() == b[r * len(cols_b) + j].hex()
                       for r in range(n) for i, j in enumerate(idx))
        for ext in ("imp", "tr"):
            same = same and ((kept / "base" / f"{job}.{ext}").read_bytes()
                             == (kept / "head" / f"{job}.{ext}").read_bytes())
        same = same and (_without(base[job]["state"], set(new))
                         == _without(head[job]["state"], set(new)))
        print(f"{job:32s} {n:6d} steps, {len(cols_a)} common columns, new {new}: "
              f"{'identical' if same else 'DIFFERENT'}")
        all_same = all_same and same
    return all_same


if __name__ == "__main__":
    sys.exit(0 if compare(Path(sys.argv[1])) else 1)
