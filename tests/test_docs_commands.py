"""Every command block of README.md and docs/*.md works as written (issue 25, item 4).

Each ```bash, ```sh and ```python block carries a marker on the line just before it:

- ``<!-- run -->``: run as written;
- ``<!-- smoke: RULE ;; RULE ... -->``: run after the documented reductions, each RULE one of
  ``replace OLD => NEW`` (OLD must occur in the block) and ``prepend TEXT`` (a line put
  before the block, e.g. the values an API synopsis leaves as names);
- ``<!-- illustrative: REASON -->``: listed, not run (``python tests/test_docs_commands.py``
  prints every block with its marker).

Quick group: every block has a valid marker, the smoke rules still apply, and the extractor
rejects a planted unmarked block. Slow group: each "run" and "smoke" block runs with bash
(``-euo pipefail``; a python block with the environment's python) in a temporary copy of the
repository (``git ls-files`` plus untracked, not ignored files; the FMUs and SSP files that
the test builds once in its own copy are added when the block uses ``models/`` without
running ``build.py``), with the environment's python first on PATH and the copy's
``fmu_src`` on PYTHONPATH. A failure names the block's file, line and output.

Budget: the slow group takes about 2 minutes on this 2-core machine (126 s measured for
its 13 blocks with another job loading it: the spin scenes 34 s, the co-simulation engines
25 s, the fuzz smoke 24 s, the four sweep smokes 32 s, the rest 15 s); the quick tests
take under a second.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LANGS = ("bash", "sh", "python")
KINDS = ("run", "smoke", "illustrative")
MARKER = re.compile(r"^<!--\s*(?P<kind>[a-z]+)\s*(?::(?P<note>.*?))?\s*-->\s*$")
FENCE = re.compile(r"^```\s*(?P<lang>[\w+-]*)\s*$")
RULE_SEP = " ;; "
BLOCK_TIMEOUT = 900.0   # s, one block
MARKER_HELP = ("<!-- run -->, <!-- smoke: replace OLD => NEW ;; prepend TEXT -->, or "
               "<!-- illustrative: REASON -->")


class DocBlockError(ValueError):
    """A command block without a valid marker, or a smoke rule that no longer applies."""


@dataclass(frozen=True)
class Block:
    """A fenced command block of a Markdown page; ``line`` is its opening fence (1-based)."""

    path: str
    line: int
    lang: str
    code: str
    kind: str
    note: str

    @property
    def where(self) -> str:
        return f"{self.path}:{self.line}"


def _marker(prev: str, where: str, lang: str) -> tuple[str, str]:
    """(kind, note) of the marker line before a block; DocBlockError if it is not one."""
    m = MARKER.match(prev.strip())
    if m is None or m["kind"] not in KINDS:
        raise DocBlockError(f"{where}: ```{lang} block without a marker on the line just "
                            f"before it ({MARKER_HELP})")
    kind, note = m["kind"], (m["note"] or "").strip()
    if kind != "run" and not note:
        what = "its rules" if kind == "smoke" else "a reason"
        raise DocBlockError(f"{where}: the {kind} marker needs {what} ({MARKER_HELP})")
    if kind == "run" and note:
        raise DocBlockError(f"{where}: a run marker takes nothing after it: {prev.strip()!r}")
    return kind, note


def extract_blocks(text: str, path: str) -> list[Block]:
    """The bash/sh/python blocks of a page with their markers. Raises DocBlockError
    naming every block (file:line) whose marker is missing or malformed."""
    lines = text.splitlines()
    blocks, problems = [], []
    i = 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if m is None:
            i += 1
            continue
        j = i + 1
        while j < len(lines) and not lines[j].startswith("```"):
            j += 1
        lang = m["lang"]
        if lang in LANGS:
            where = f"{path}:{i + 1}"
            try:
                kind, note = _marker(lines[i - 1] if i else "", where, lang)
            except DocBlockError as exc:
                problems.append(str(exc))
            else:
                blocks.append(Block(path, i + 1, lang, "\n".join(lines[i + 1:j]) + "\n",
                                    kind, note))
        i = j + 1
    if problems:
        raise DocBlockError("\n".join(problems))
    return blocks


def doc_pages() -> list[Path]:
    return [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


def all_blocks(strict: bool = True) -> list[Block]:
    """The blocks of every page; with ``strict`` False a page that fails to parse is
    skipped (its error is the quick test's to report)."""
    found = []
    for page in doc_pages():
        try:
            found += extract_blocks(page.read_text(encoding="utf-8"),
                                    page.relative_to(ROOT).as_posix())
        except DocBlockError:
            if strict:
                raise
    return found


def apply_smoke(block: Block) -> str:
    """The block's code after its smoke rules; DocBlockError if a rule is malformed or its
    OLD text no longer occurs (the reduction would silently not apply)."""
    code = block.code
    for rule in block.note.split(RULE_SEP):
        verb, _, arg = rule.strip().partition(" ")
        if verb == "replace" and " => " in arg:
            old, new = arg.split(" => ", 1)
            if old not in code:
                raise DocBlockError(f"{block.where}: smoke rule {rule!r}: {old!r} is not in "
                                    f"the block")
            code = code.replace(old, new)
        elif verb == "prepend" and arg:
            code = arg + "\n" + code
        else:
            raise DocBlockError(f"{block.where}: smoke rule {rule!r} is neither "
                                f"'replace OLD => NEW' nor 'prepend TEXT'")
    return code


def runnable_code(block: Block) -> str:
    return apply_smoke(block) if block.kind == "smoke" else block.code


# ---------------------------------------------------------------------------- quick group
def test_every_block_has_a_marker() -> None:
    """Every bash/sh/python block of README.md and docs/*.md is marked run, smoke (with
    rules) or illustrative (with a reason), and there are blocks of each kind."""
    blocks = all_blocks()
    kinds = {b.kind for b in blocks}
    assert kinds == set(KINDS), kinds


def test_smoke_rules_apply() -> None:
    """Each smoke block's rules apply (their OLD text is still in the block) and change
    it; a rule whose text is gone is an error, not a silent full-length run."""
    for block in all_blocks():
        if block.kind == "smoke":
            assert apply_smoke(block) != block.code, block.where
    stale = Block("x.md", 3, "bash", "rotortd sweep gamma=0.05:0.3:1000\n", "smoke",
                  "replace gamma=0.1:0.2:500 => gamma=0.1:0.2:3")
    with pytest.raises(DocBlockError, match=r"x\.md:3: smoke rule"):
        apply_smoke(stale)


PLANTED = """# page

<!-- run -->
```bash
echo marked
```

```bash
echo unmarked
```

<!-- illustrative: a reason -->

```python
print("marker not on the line just before")
```

<!-- illustrative -->
```sh
echo no reason
```

```
plain text, not a command block
```
"""


def test_extractor_rejects_unmarked_blocks() -> None:
    """A planted page: the block without a marker, the one whose marker is separated by a
    blank line and the illustrative one without a reason are each named by file:line; the
    marked block and the plain text block pass."""
    with pytest.raises(DocBlockError) as info:
        extract_blocks(PLANTED, "planted.md")
    msg = str(info.value)
    assert "planted.md:8: ```bash block without a marker" in msg
    assert "planted.md:14: ```python block without a marker" in msg
    assert "planted.md:19: the illustrative marker needs a reason" in msg
    assert "planted.md:4" not in msg and "planted.md:23" not in msg
    good = extract_blocks(PLANTED.split("```bash\necho unmarked")[0], "planted.md")
    assert [(b.line, b.kind, b.code) for b in good] == [(4, "run", "echo marked\n")]


# ---------------------------------------------------------------------------- slow group
def _repo_files() -> list[str]:
    """The checkout's files: tracked, plus untracked ones that are not ignored."""
    out = subprocess.run(["git", "ls-files", "-z", "--cached", "--others",
                          "--exclude-standard"], cwd=ROOT, capture_output=True, check=True)
    return [f for f in out.stdout.decode().split("\0") if f and (ROOT / f).is_file()]


def _copy_repo(dest: Path) -> Path:
    for name in _repo_files():
        target = dest / name
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / name, target)
    return dest


def _env(copy: Path) -> dict[str, str]:
    env = dict(os.environ, PYTHONPATH=str(copy / "fmu_src"))
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "")])
    return env


def _run(cmd: list[str], cwd: Path, timeout: float = BLOCK_TIMEOUT
         ) -> subprocess.CompletedProcess[str]:
    return subprocess.run(cmd, cwd=cwd, env=_env(cwd), stdin=subprocess.DEVNULL,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          timeout=timeout)


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A copy of the repository with its FMUs built and the SSP files written."""
    copy = _copy_repo(tmp_path_factory.mktemp("docs_built"))
    for cmd in (["python", "build.py"], ["python", "-m", "rotortd_cosim.ssp"]):
        proc = _run([sys.executable, *cmd[1:]], copy)
        assert proc.returncode == 0, f"{' '.join(cmd)} in the copy:\n{proc.stdout[-4000:]}"
    return copy


def _needs_models(code: str) -> bool:
    return "models/" in code and "build.py" not in code


RUNNABLE = [b for b in all_blocks(strict=False) if b.kind in ("run", "smoke")]


@pytest.mark.slow
@pytest.mark.parametrize("block", RUNNABLE, ids=[b.where for b in RUNNABLE])
def test_doc_block_runs(block: Block, built: Path, tmp_path: Path) -> None:
    """The block exits 0 in a fresh copy of the repository (smoke blocks after their
    documented reductions)."""
    copy = _copy_repo(tmp_path / "repo")
    if _needs_models(block.code):
        for built_file in [*built.glob("models/*.fmu"), *built.glob("models/systems/*.ssp")]:
            shutil.copy2(built_file, copy / built_file.relative_to(built))
    code = runnable_code(block)
    cmd = [sys.executable, "-c", code] if block.lang == "python" else \
        ["bash", "-euo", "pipefail", "-c", code]
    try:
        proc = _run(cmd, copy)
    except subprocess.TimeoutExpired as exc:
        out = exc.stdout.decode(errors="replace") if isinstance(exc.stdout, bytes) else \
            exc.stdout or ""
        pytest.fail(f"{block.where} ({block.kind}) did not finish in {BLOCK_TIMEOUT:.0f} s:"
                    f"\n{code}--- output (end) ---\n{out[-6000:]}")
    assert proc.returncode == 0, (
        f"{block.where} ({block.kind}) exited {proc.returncode}\n--- command ---\n{code}"
        f"--- output (end) ---\n{proc.stdout[-6000:]}")
    shutil.rmtree(copy)   # kept only when the block failed


if __name__ == "__main__":
    for b in all_blocks():
        print(f"{b.where:28} {b.lang:7} {b.kind:13} {b.note}")
