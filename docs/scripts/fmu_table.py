"""Print the variable table of a built FMU as Markdown (pasted into docs/fmu.md).

    python docs/scripts/fmu_table.py [models/RotorTouchdown.fmu] [--update docs/fmu.md]

With --update, the table replaces the text between the BEGIN/END fmu_table markers.
"""

from __future__ import annotations

import argparse
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from build import variable_rows  # noqa: E402

COLUMNS = ("name", "type", "causality", "variability", "start", "unit", "min", "max",
           "description")


def markdown_table(fmu: Path) -> str:
    with zipfile.ZipFile(fmu) as zf:
        rows = variable_rows(zf.read("modelDescription.xml"))
    lines = ["| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    for row in rows:
        cells = [row[c].replace("|", "\\|") for c in COLUMNS]
        cells[0] = f"`{cells[0]}`"
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


BEGIN, END = "<!-- BEGIN fmu_table -->", "<!-- END fmu_table -->"


def update_markdown(doc: Path, table: str) -> None:
    text = doc.read_text(encoding="utf-8")
    start, end = text.index(BEGIN) + len(BEGIN), text.index(END)
    doc.write_text(text[:start] + "\n" + table + "\n" + text[end:], encoding="utf-8")


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("fmu", nargs="?", type=Path,
                        default=ROOT / "models" / "RotorTouchdown.fmu")
    parser.add_argument("--update", type=Path, help="Markdown file with fmu_table markers")
    args = parser.parse_args(argv)
    table = markdown_table(args.fmu)
    if args.update:
        update_markdown(args.update, table)
        print(f"fmu_table: updated {args.update}")
    else:
        print(table)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
