"""Count the lines of a source tree: physical, and logical (no blanks, comments or docstrings).

    python docs/scripts/loc.py [DIR ...]            (default: fmu_src/rotortd)
    python docs/scripts/loc.py --base COMMIT [DIR]  (also the same folder at COMMIT, via git)
    python docs/scripts/loc.py --groups             (fmu_src/rotortd by what the code is for)

A logical line is a physical line that holds code: the tokenizer's comment, newline and
indentation tokens are dropped, and so are the string tokens that are docstrings (the first
statement of a module, class or function). Issue 23 asks for fewer logical lines in
``fmu_src/rotortd/`` than at its first commit; this script is the one way the project counts.
"""

from __future__ import annotations

import argparse
import ast
import io
import subprocess
import sys
import tokenize
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def docstring_lines(source: str) -> set[int]:
    """The line numbers covered by docstrings in ``source``."""
    lines: set[int] = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            body = node.body
            if (body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant)
                    and isinstance(body[0].value.value, str)):
                end = body[0].end_lineno or body[0].lineno
                lines.update(range(body[0].lineno, end + 1))
    return lines


def count(source: str) -> tuple[int, int]:
    """(physical lines, logical lines) of one Python source."""
    return len(source.splitlines()), len(code_lines(source))


GROUPS: dict[str, tuple[str, ...]] = {
    "issue 24, the real bearing (none of it at e272741)": (
        "bodies/race.py", "contact/laws.py", "segments/bearing_contact.py",
        "step/bearing_step.py"),
    "issue 26, the speed accelerators (none of them at e272741)": (
        "segments/dry_whirl_orbit.py", "segments/dry_whirl_driven.py",
        "segments/rolling_spin_fast.py",
        "step/flight_step.py::quiet_step", "step/flight_step.py::quiet_lane",
        "step/flight_step.py::QuietLane", "step/flight_step.py::make_quiet_lane",
        "segments/spin_flight.py::_run_quiet", "segments/spin_flight.py::short_taylor",
        "step/spin_step.py::_spin_quiet_step", "segments/spin_quiet.py",
        "step/spin_step.py::_spin_quiet_lane", "step/spin_step.py::SpinQuietLane",
        "step/spin_step.py::make_spin_quiet_lane", "step/spin_step.py::_whole_report",
        "step/spin_step.py::_spin_roll_step"),
    "the held spin's declared accelerators (docs/architecture.md)": (
        "segments/flight.py", "segments/rolling.py", "segments/rub.py",
        "segments/sliding.py", "contact/search.py", "contact/impact.py"),
}
"""Issue 23's less-code accounting (``--groups``): the code of fmu_src/rotortd by what it is
for. An entry is a file under fmu_src/rotortd or ``file::name``, a top-level or class-level
definition in it; what no entry names is "the rest". contact/search.py also holds the
search helpers both rotors use (safe_step, the cubic's tests), so its group is an upper
bound."""


def definition_lines(source: str, name: str) -> set[int]:
    """The lines of the definitions called ``name`` (functions or classes, top level or in a
    class), decorators included."""
    lines: set[int] = set()
    tree = ast.parse(source)
    nodes = list(tree.body) + [n for c in tree.body if isinstance(c, ast.ClassDef)
                               for n in c.body]
    for node in nodes:
        if (isinstance(node, ast.FunctionDef | ast.ClassDef | ast.AsyncFunctionDef)
                and node.name == name):
            start = min([node.lineno] + [d.lineno for d in node.decorator_list])
            lines.update(range(start, (node.end_lineno or node.lineno) + 1))
    if not lines:
        raise SystemExit(f"loc.py: no definition {name!r} (GROUPS is out of date)")
    return lines


def code_lines(source: str) -> set[int]:
    """The logical lines of ``source`` (as ``count``), as a set of line numbers."""
    docs = docstring_lines(source)
    code: set[int] = set()
    skip = {tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT,
            tokenize.ENCODING, tokenize.ENDMARKER}
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type in skip or (tok.type == tokenize.STRING and tok.start[0] in docs):
            continue
        code.update(range(tok.start[0], tok.end[0] + 1))
    return code


def group_counts(folder: Path) -> dict[str, int]:
    """Logical lines of ``folder`` per GROUPS entry, and "the rest"."""
    code = {p.relative_to(folder).as_posix(): code_lines(p.read_text(encoding="utf-8"))
            for p in sorted(folder.rglob("*.py"))}
    out: dict[str, int] = {}
    for group, entries in GROUPS.items():
        n = 0
        for entry in entries:
            path, _, name = entry.partition("::")
            if path not in code:
                raise SystemExit(f"loc.py: no file {path} (GROUPS is out of date)")
            src = (folder / path).read_text(encoding="utf-8")
            taken = definition_lines(src, name) & code[path] if name else set(code[path])
            code[path] = code[path] - taken
            n += len(taken)
        out[group] = n
    out["the rest"] = sum(len(c) for c in code.values())
    return out


def tree_counts(files: dict[str, str]) -> tuple[int, int, int]:
    """(files, physical, logical) over {path: source}."""
    phys = logic = 0
    for source in files.values():
        p, lg = count(source)
        phys, logic = phys + p, logic + lg
    return len(files), phys, logic


def worktree_files(folder: Path) -> dict[str, str]:
    return {str(p): p.read_text(encoding="utf-8") for p in sorted(folder.rglob("*.py"))}


def commit_files(commit: str, folder: str) -> dict[str, str]:
    names = subprocess.run(["git", "ls-tree", "-r", "--name-only", commit, folder], cwd=ROOT,
                           capture_output=True, text=True, check=True).stdout.split()
    return {n: subprocess.run(["git", "show", f"{commit}:{n}"], cwd=ROOT, capture_output=True,
                              text=True, check=True).stdout
            for n in names if n.endswith(".py")}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dirs", nargs="*", default=["fmu_src/rotortd"])
    ap.add_argument("--base", help="also count each folder at this commit")
    ap.add_argument("--groups", action="store_true",
                    help="fmu_src/rotortd's logical lines by what the code is for (GROUPS)")
    args = ap.parse_args(argv)
    if args.groups:
        for group, n in group_counts(ROOT / "fmu_src" / "rotortd").items():
            print(f"{n:6d}  {group}")
        return 0
    for folder in args.dirs:
        n, phys, logic = tree_counts(worktree_files(ROOT / folder))
        print(f"{folder}: {n} files, {phys} physical lines, {logic} logical lines")
        if args.base:
            bn, bphys, blogic = tree_counts(commit_files(args.base, folder))
            print(f"{folder} at {args.base}: {bn} files, {bphys} physical lines, "
                  f"{blogic} logical lines (now {logic - blogic:+d} logical, "
                  f"{phys - bphys:+d} physical)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
