"""What each package may import (docs/architecture.md, "Packages and what each may import").

Read from the source with ``ast`` (every import statement, nested ones included), so a
lazily imported module counts too.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "fmu_src"

# The standard-library modules the physics core may use: docs/architecture.md lists the same.
CORE_ALLOWED = {"__future__", "math", "cmath", "dataclasses", "typing", "collections",
                "bisect", "operator", "enum"}
ALLOWED = {
    "rotortd": CORE_ALLOWED,
    "rotortd_drive": CORE_ALLOWED,
}


def _imports(package: str) -> dict[str, set[str]]:
    """{top-level module imported from outside the package: {files}}."""
    found: dict[str, set[str]] = {}
    for path in sorted((SRC / package).rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0:
                names = [node.module or ""]
            else:
                continue
            for name in names:
                found.setdefault(name.split(".")[0], set()).add(path.name)
    return found


@pytest.mark.parametrize("package", sorted(ALLOWED))
def test_package_imports_only_what_it_may(package: str) -> None:
    imported = _imports(package)
    assert imported, f"no imports found in {package}: the scan is broken"
    extra = {name: sorted(files) for name, files in imported.items()
             if name not in ALLOWED[package]}
    assert not extra, f"{package} imports {extra}; allowed: {sorted(ALLOWED[package])}"


def test_the_allowed_list_is_the_documented_one() -> None:
    doc = (SRC.parent / "docs" / "architecture.md").read_text(encoding="utf-8")
    row = next(line for line in doc.splitlines() if line.startswith("| `rotortd` |"))
    documented = {name for name in CORE_ALLOWED - {"__future__"} if f"`{name}`" in row}
    assert documented == CORE_ALLOWED - {"__future__"}, row


def test_loc_counts_logical_lines() -> None:
    """docs/scripts/loc.py: blanks, comments and docstrings are not logical lines; a
    multi-line statement counts each of its lines, a string that is not a docstring too."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("loc", SRC.parent / "docs/scripts/loc.py")
    assert spec and spec.loader
    loc = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(loc)
    source = ('"""Module\ndocstring."""\n\n# a comment\nimport math\n\n\n'
              'def f(x: float) -> float:\n    """Doc."""\n    s = """not a\n    docstring"""\n'
              '    return (math.sin(x)  # trailing comment\n            + len(s))\n')
    assert loc.count(source) == (13, 6)


def test_loc_groups_partition_the_core() -> None:
    """docs/scripts/loc.py --groups: every entry of its GROUPS names a file or definition
    that exists (else it exits), and the groups with "the rest" add up to the whole count."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("loc", SRC.parent / "docs/scripts/loc.py")
    assert spec and spec.loader
    loc = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(loc)
    groups = loc.group_counts(SRC / "rotortd")
    _, _, total = loc.tree_counts(loc.worktree_files(SRC / "rotortd"))
    assert sum(groups.values()) == total
    assert all(n > 0 for n in groups.values()), groups
    assert loc.definition_lines("class A:\n    def f(self):\n        pass\n", "f") == {2, 3}
