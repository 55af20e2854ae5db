"""Every citation in docs/ and in docstrings points at something in the repository.

Three forms are checked (issue 23, item 4):

* ``docs/<page>.md §N``: the page exists and has a heading numbered ``N.``;
* repository paths (``fmu_src/...``, ``docs/...``, ``tests/...``, ``models/...``,
  ``build.py``, ...): the file or folder exists (build outputs and placeholders excepted);
* dotted module names (``rotortd.scaled.to_scaled``, ``rotortd_cosim.run``): the module's
  file exists under ``fmu_src/`` and each further name is defined in it (a top-level or class
  level ``def``, ``class`` or assignment, found by ``ast``, without importing anything).

Citations of documents outside the repository (the shared model statement, its section
numbers, a "SPEC") are refused outright. The test reports how many citations it checked
and needs at least ``MIN_CHECKED`` of them, so that a broken extractor cannot pass by
finding nothing.
"""

from __future__ import annotations

import ast
import re
import subprocess
from dataclasses import dataclass
from functools import cache
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MIN_CHECKED = 600  # the count at this test's first commit; fewer means lost checks

SECTION = re.compile(r"`?(docs/[\w./-]+\.md)`?\s*§\s*(\d+)")
PATH = re.compile(r"(?<![\w./-])((?:fmu_src|docs|tests|models|\.ci)/[\w./-]*[\w/]"
                  r"|build\.py|pyproject\.toml|README\.md)(?![\w*<{…-])")
DOTTED = re.compile(r"(?<![\w./-])(rotortd(?:_[a-z]+)?(?:\.[A-Za-z_]\w*)+)")
FOREIGN = re.compile(r"\.\./shared|MODEL\.md|MODEL §|spin-SPEC|\bthe SPEC\b|SPEC's")
# Paths that the build or a run writes (not tracked), and sample names in examples.
GENERATED = re.compile(r"^models/[^/]*\.(fmu|ssp)$|^models/systems/[^/]*\.ssp$|^out/"
                       r"|\.(npz|parquet|csv|png)$")
NUMBERED_HEADING = re.compile(r"^#{2,4}\s+(\d+)\.", re.MULTILINE)


@dataclass(frozen=True)
class Citation:
    where: str  # file:line
    text: str
    kind: str  # "section", "path", "module" or "foreign"


def _tracked() -> list[Path]:
    out = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True,
                         check=True).stdout.split()
    return [ROOT / p for p in out]


def _docstrings(path: Path) -> list[tuple[int, str]]:
    """(line, text) of the module's, classes' and functions' docstrings."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value,
                                                                       ast.Constant):
                value = body[0].value.value
                if isinstance(value, str):
                    found.append((body[0].lineno, value))
    return found


def _texts() -> list[tuple[str, int, str]]:
    """(file, first line, text) of every markdown page in docs/ and every docstring."""
    texts = []
    for path in _tracked():
        rel = path.relative_to(ROOT).as_posix()
        if rel.startswith("docs/") and path.suffix == ".md":
            texts.append((rel, 1, path.read_text(encoding="utf-8")))
        elif path.suffix == ".py" and rel != "tests/test_citations.py":
            texts += [(rel, line, text) for line, text in _docstrings(path)]
    return texts


def find_citations(rel: str, first_line: int, text: str) -> list[Citation]:
    """Every citation of the three forms (and every foreign one) in one text."""
    cites = []
    for lineno, line in enumerate(text.splitlines(), start=first_line):
        where = f"{rel}:{lineno}"
        cites += [Citation(where, f"{m[1]} §{m[2]}", "section") for m in SECTION.finditer(line)]
        cites += [Citation(where, m[1].rstrip("/."), "path") for m in PATH.finditer(line)]
        cites += [Citation(where, m[1], "module") for m in DOTTED.finditer(line)]
        cites += [Citation(where, m[0], "foreign") for m in FOREIGN.finditer(line)]
    return cites


@cache
def _headings(page: str) -> frozenset[str]:
    path = ROOT / page
    if not path.is_file():
        return frozenset()
    return frozenset(NUMBERED_HEADING.findall(path.read_text(encoding="utf-8")))


@cache
def _names(module_file: Path) -> dict[str, frozenset[str]]:
    """Top-level names of a module, and for each class its own names ("" key: the module)."""
    tree = ast.parse(module_file.read_text(encoding="utf-8"))
    names: dict[str, frozenset[str]] = {"": frozenset(_defined(tree.body))}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            names[node.name] = frozenset(_defined(node.body))
    return names


def _defined(body: list[ast.stmt]) -> list[str]:
    names = []
    for node in body:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            names.append(node.name)
        elif isinstance(node, ast.Assign):
            names += [t.id for t in node.targets if isinstance(t, ast.Name)]
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.append(node.target.id)
        elif isinstance(node, ast.ImportFrom | ast.Import):
            names += [(a.asname or a.name).split(".")[0] for a in node.names]
        elif isinstance(node, ast.If | ast.Try):
            names += _defined(node.body)
    return names


def _module_ok(dotted: str) -> bool:
    parts = dotted.split(".")
    base = ROOT / "fmu_src"
    for i in range(len(parts), 0, -1):
        stem = base.joinpath(*parts[:i])
        module = stem.with_suffix(".py") if stem.with_suffix(".py").is_file() else (
            stem / "__init__.py")
        if module.is_file():
            return _attributes_ok(module, parts[i:])
    return False


def _attributes_ok(module: Path, rest: list[str]) -> bool:
    if not rest:
        return True
    names = _names(module)
    if rest[0] not in names[""]:
        sub = module.parent / rest[0]
        return module.name == "__init__.py" and (sub.with_suffix(".py").is_file()
                                                 or sub.is_dir())
    if len(rest) == 1:
        return True
    if rest[0] in names:
        return rest[1] in names[rest[0]]
    source = _imported_from(module, rest[0])  # a name a package re-exports
    return source is not None and _attributes_ok(source, rest)


def _imported_from(module: Path, name: str) -> Path | None:
    """The file of the sibling module that ``module`` imports ``name`` from, if any."""
    for node in ast.parse(module.read_text(encoding="utf-8")).body:
        if (isinstance(node, ast.ImportFrom) and node.level == 1 and node.module
                and any(a.name == name for a in node.names)):
            path = module.parent / (node.module.replace(".", "/") + ".py")
            return path if path.is_file() else None
    return None


def check(cite: Citation) -> str:
    """'' if the citation's target exists, else why not."""
    if cite.kind == "foreign":
        return "cites a document outside the repository"
    if cite.kind == "section":
        page, number = cite.text.split(" §")
        if not (ROOT / page).is_file():
            return f"no page {page}"
        return "" if number in _headings(page) else f"{page} has no section {number}"
    if cite.kind == "path":
        if GENERATED.search(cite.text) or (ROOT / cite.text).exists():
            return ""
        return "no such file or folder"
    return "" if _module_ok(cite.text) else "no such module or name"


def all_citations() -> list[Citation]:
    return [c for rel, line, text in _texts() for c in find_citations(rel, line, text)]


def test_every_citation_has_a_target() -> None:
    cites = all_citations()
    bad = [f"{c.where}: {c.text!r} ({c.kind}): {why}" for c in cites if (why := check(c))]
    kinds = {k: sum(c.kind == k for c in cites) for k in ("section", "path", "module")}
    print(f"checked {len(cites)} citations: {kinds}")
    assert not bad, f"{len(bad)} of {len(cites)} citations have no target:\n" + "\n".join(bad)
    assert len(cites) >= MIN_CHECKED, f"only {len(cites)} citations found (>= {MIN_CHECKED})"
    assert all(kinds.values()), kinds


def test_planted_bad_citations_are_caught() -> None:
    text = ("See docs/model.md §99, `fmu_src/rotortd/no_such.py`, `rotortd.scaled.nope`,\n"
            "`rotortd.no_module`, docs/nowhere.md §1 and ../shared/MODEL.md §6.\n"
            "Good: docs/model.md §1, `fmu_src/rotortd/scaled.py`, `rotortd.scaled.to_scaled`,"
            " `rotortd.step.simulator.TouchdownCore.step`.")
    cites = find_citations("planted.md", 1, text)
    verdicts = {c.text: bool(check(c)) for c in cites}
    assert verdicts == {
        "docs/model.md §99": True, "docs/model.md": False, "docs/nowhere.md": True,
        "fmu_src/rotortd/no_such.py": True,
        "rotortd.scaled.nope": True, "rotortd.no_module": True, "docs/nowhere.md §1": True,
        "../shared": True, "MODEL.md": True,
        "docs/model.md §1": False, "fmu_src/rotortd/scaled.py": False,
        "rotortd.scaled.to_scaled": False, "rotortd.step.simulator.TouchdownCore.step": False,
    }, verdicts
