"""The Parquet store of a sweep: part files appended as rows arrive, its description, resume."""

from __future__ import annotations

import json
import os
import time
import uuid
from collections.abc import Iterable, Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

from rotortd_tools.sweep.schema import arrow_schema
from rotortd_tools.sweep.spec import Settings, SweepError, SweepSpec

META_FILE = "_sweep.json"
FORMAT_VERSION = 4  # 4: the real bearing's twelve parameter columns (docs/model.md §10)
"""Store format: 4 added the real bearing's twelve parameters (race_turns ... p_c, NaN when
no bearing name is given); 3 named the drop outcomes as the literature does (dry-whirl,
dry-whip); 2 added the columns J, T_drive, Omega_end, Omega_mean, whirl_mean,
slip_mean, slip_ratio and the drop settings. A format-1 store is still read (``read_sweep``,
``rotortd sweep-plot``) but is not resumed."""


class ParquetSink:
    """A directory of Parquet part files, appended as rows arrive; resumable.

    Rows are buffered and written as a new part file (via a temporary name and an atomic
    rename, so a killed run never leaves a partial file) every ``flush_rows`` rows or
    ``flush_s`` seconds. ``done`` holds the keys already in the directory.
    """

    def __init__(self, path: Path, flush_rows: int = 64, flush_s: float = 2.0) -> None:
        self.path = Path(path)
        self.flush_rows, self.flush_s = flush_rows, flush_s
        self.buffer: list[dict[str, Any]] = []
        self.run_id = f"{time.strftime('%Y%m%dT%H%M%S')}-{uuid.uuid4().hex[:8]}"
        self.seq = 0
        self.last = time.monotonic()
        self.path.mkdir(parents=True, exist_ok=True)
        self.existing = read_sweep(self.path, columns=["key", "start", "index", "final_state"])
        self.done: set[str] = set(self.existing["key"]) if self.existing else set()

    def add(self, rows: Iterable[dict[str, Any]]) -> int:
        """Buffer new rows (keys already written are dropped); flush when due."""
        n = 0
        for row in rows:
            if row["key"] in self.done:
                continue
            self.done.add(row["key"])
            self.buffer.append(row)
            n += 1
        if len(self.buffer) >= self.flush_rows or time.monotonic() - self.last >= self.flush_s:
            self.flush()
        return n

    def flush(self) -> None:
        """Write the buffer as one part file."""
        self.last = time.monotonic()
        if not self.buffer:
            return
        import pyarrow as pa
        import pyarrow.parquet as pq

        table = pa.Table.from_pylist(self.buffer, schema=arrow_schema())
        name = f"part-{self.run_id}-{self.seq:05d}.parquet"
        tmp = self.path / f".{name}.tmp"
        pq.write_table(table, tmp)
        os.replace(tmp, self.path / name)
        self.seq += 1
        self.buffer = []


def part_files(path: Path) -> list[Path]:
    """The finished part files of an output directory (sorted)."""
    return sorted(Path(path).glob("part-*.parquet"))


def read_sweep(path: Path | str, columns: Sequence[str] | None = None) -> dict[str, list]:
    """Read an output directory as {column: list} (empty dict when there are no rows)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    files = part_files(Path(path))
    if not files:
        return {}
    tables = [pq.read_table(f, columns=list(columns) if columns else None) for f in files]
    return pa.concat_tables(tables, promote_options="default").to_pydict()


def read_meta(path: Path | str) -> dict[str, Any] | None:
    """The sweep's description (``_sweep.json``), or None."""
    f = Path(path) / META_FILE
    return json.loads(f.read_text()) if f.exists() else None


def spec_meta(spec: SweepSpec, settings: Settings) -> dict[str, Any]:
    """JSON description of a sweep: what a resume must match."""
    return {
        "format": FORMAT_VERSION,
        "axes": [{"name": a.name, "lo": a.lo, "hi": a.hi, "n": a.n, "random": a.random,
                  "log": a.log} for a in spec.axes],
        "fixed": dict(spec.fixed),
        "seed": spec.seed,
        "settings": asdict(settings),
        "starts": list(spec.starts),
    }


def prepare_output(path: Path, spec: SweepSpec, settings: Settings, overwrite: bool) -> None:
    """Create or check the output directory; SweepError when it holds another sweep."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise SweepError(f"output {path} exists and is not a directory of part files")
    if overwrite and path.exists():
        for f in [*part_files(path), path / META_FILE]:
            f.unlink(missing_ok=True)
    new = spec_meta(spec, settings)
    old = read_meta(path)
    if old is not None and old.get("format") != FORMAT_VERSION:
        raise SweepError(
            f"output {path} holds a sweep in store format {old.get('format')!r}, this is "
            f"format {FORMAT_VERSION} (format 2 added the columns J, T_drive, Omega_end, "
            "Omega_mean, whirl_mean, slip_mean, slip_ratio; format 3 renamed the regime "
            "whip and the drop outcome dry-whip (both rolling) to dry-whirl and the drop "
            "outcome backward-whirl (sliding) to dry-whip, as the rotordynamics literature "
            "names them; format 4 added the real bearing's parameters race_turns ... p_c): "
            "it can still be read "
            "(read_sweep, sweep-plot) but not resumed; use --overwrite or another --out"
        )
    if old is not None:
        same = {k: v for k, v in old.items() if k != "starts"}
        if same != {k: v for k, v in new.items() if k != "starts"}:
            raise SweepError(
                f"output {path} holds a different sweep (axes, fixed values, seed or "
                "settings differ); use --overwrite or another --out"
            )
        new["starts"] = list(dict.fromkeys([*old["starts"], *new["starts"]]))
    elif part_files(path):
        raise SweepError(f"output {path} has part files but no {META_FILE}; use --overwrite")
    path.mkdir(parents=True, exist_ok=True)
    (path / META_FILE).write_text(json.dumps(new, indent=1))


