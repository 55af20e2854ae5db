"""Replace a generated block of a Markdown page: the text between ``<!-- BEGIN name -->``
and ``<!-- END name -->``. Shared by the docs scripts (benchmarks, validation, fmu_table)."""

from __future__ import annotations

from pathlib import Path


def replace_block(doc: Path, name: str, body: str) -> None:
    """Put ``body`` between the BEGIN/END markers ``name`` of ``doc`` (one newline each side)."""
    text = doc.read_text(encoding="utf-8")
    begin, end = f"<!-- BEGIN {name} -->", f"<!-- END {name} -->"
    i, j = text.index(begin) + len(begin), text.index(end)
    doc.write_text(text[:i] + "\n" + body + "\n" + text[j:], encoding="utf-8")
