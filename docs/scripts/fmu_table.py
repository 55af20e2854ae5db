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

from mdblock import replace_block  # noqa: E402 (docs/scripts/mdblock.py)

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


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("fmu", nargs="?", type=Path,
                        default=ROOT / "models" / "RotorTouchdown.fmu")
    parser.add_argument("--update", type=Path, help="Markdown file with fmu_table markers")
    args = parser.parse_args(argv)
    table = markdown_table(args.fmu)
    if args.update:
        replace_block(args.update, "fmu_table", table)
        print(f"fmu_table: updated {args.update}")
    else:
        print(table)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
