"""README and docs/ stay true to the tree: every link points at a file that exists and, with
a #fragment, at a heading there (GitHub's anchor rule); every reference-style link is
defined; README stays a front door (at most about 250 lines); the user-facing text cites
papers, not the project's seed files, and names no issue numbers."""
from __future__ import annotations

import re
import unicodedata
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = [ROOT / "README.md"] + sorted((ROOT / "docs").glob("*.md"))
pytestmark = pytest.mark.skipif(not (ROOT / "docs").is_dir(), reason="docs/ is not beside the tests")


def _strip_code(text: str) -> str:
    return re.sub(r"`[^`\n]*`", "", re.sub(r"```.*?```", "", text, flags=re.S))


def anchors(path: Path) -> set[str]:
    """GitHub's heading anchors: lower case, punctuation dropped, spaces to '-', repeats -1, -2."""
    seen: dict[str, int] = {}
    out = set()
    for line in re.sub(r"```.*?```", "", path.read_text(encoding="utf-8"), flags=re.S).splitlines():
        m = re.match(r"^(#{1,6})\s+(.*?)\s*#*\s*$", line)
        if not m:
            continue
        h = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", m.group(2)).replace("`", "").lower()
        s = "".join(ch for ch in h if ch in " -_" or unicodedata.category(ch)[0] in "LN").replace(" ", "-")
        if s in seen:
            seen[s] += 1
            s = f"{s}-{seen[s]}"
        else:
            seen[s] = 0
        out.add(s)
    return out


@pytest.mark.parametrize("doc", DOCS, ids=lambda p: p.name)
def test_links_resolve(doc: Path) -> None:
    text = _strip_code(doc.read_text(encoding="utf-8"))
    targets = re.findall(r"\]\(([^)\s]+)\)", text)
    defs = dict(re.findall(r"^\[([^\]]+)\]:\s*(\S+)", text, flags=re.M))
    used = set(re.findall(r"\]\[([^\]]+)\]", text))
    assert used <= set(defs), used - set(defs)
    bad = []
    for tgt in targets + list(defs.values()):
        if tgt.startswith(("http://", "https://", "mailto:")):
            continue
        path, _, frag = tgt.partition("#")
        full = (doc.parent / path).resolve() if path else doc
        if not full.exists():
            bad.append(f"missing file {tgt}")
        elif frag and full.suffix == ".md" and frag not in anchors(full):
            bad.append(f"missing anchor {tgt}")
    assert bad == []


def test_readme_is_a_front_door() -> None:
    """Short, and no run log: figures come with the command that measures them, and the
    commits of runs belong in benchmarks/results/."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert len(text.splitlines()) <= 250
    hashes = [w for w in re.findall(r"\b[0-9a-f]{7,40}\b", _strip_code(text)) if re.search(r"[a-f]", w)
              and re.search(r"[0-9]", w)]
    assert hashes == []


def test_performance_page_keeps_to_todays_figures() -> None:
    """docs/performance.md holds today's figures and targets; the run-by-run record is
    benchmarks/results/history.md."""
    assert len((ROOT / "docs" / "performance.md").read_text(encoding="utf-8").splitlines()) <= 300


@pytest.mark.parametrize("doc", DOCS, ids=lambda p: p.name)
def test_user_text_cites_papers_not_seeds_nor_issues(doc: Path) -> None:
    text = doc.read_text(encoding="utf-8")
    if doc.name == "bibliography.md":   # its key from the source files' names to the papers
        text = re.sub(r"^\| `00\d_[0-9a-f]{16}\.txt` \|.*$", "", text, flags=re.M)
    assert not re.search(r"\bseed 00\d|\b00\d_[0-9a-f]{16}\.txt", text)
    assert not re.search(r"\bissue #?\d+|#\d{1,3}\b(?![0-9a-f])", _strip_code(text))


def python_blocks(path: Path) -> list[str]:
    return re.findall(r"```python\n(.*?)```", path.read_text(encoding="utf-8"), flags=re.S)


@pytest.mark.parametrize("doc", [d for d in DOCS if python_blocks(d)], ids=lambda p: p.name)
def test_python_examples_import_what_exists(doc: Path) -> None:
    """Each Python example's imports run, and every call on an imported name (a module's
    function, a class's constructor or method) names something that is there: an example
    a user copies must not stop at its first line."""
    for block in python_blocks(doc):
        names: dict = {}
        for line in block.splitlines():
            if re.match(r"^(from \S+ )?import ", line):
                exec(line.split("#")[0], names)   # noqa: S102 - the docs' own import lines
        for obj, attr in re.findall(r"\b([A-Za-z_]\w*)\.([A-Za-z_]\w*)\(", block):
            if obj in names and not obj.startswith("__"):
                assert hasattr(names[obj], attr), f"{doc.name}: {obj}.{attr} does not exist"
