"""Count the lines of a source tree: physical, and logical (no blanks, comments or docstrings).

    python docs/scripts/loc.py [DIR ...]            (default: fmu_src/rotortd)
    python docs/scripts/loc.py --base COMMIT [DIR]  (also the same folder at COMMIT, via git)

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
    docs = docstring_lines(source)
    code: set[int] = set()
    skip = {tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT,
            tokenize.ENCODING, tokenize.ENDMARKER}
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type in skip or (tok.type == tokenize.STRING and tok.start[0] in docs):
            continue
        code.update(range(tok.start[0], tok.end[0] + 1))
    return len(source.splitlines()), len(code)


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
    args = ap.parse_args(argv)
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
