"""What the benchmark scripts record about each run: the commit measured, and results
files that grow by one section per run, each rewritten atomically (a temp file renamed
over it, as pyjulia4d's own outputs are)."""
from __future__ import annotations

import contextlib
import datetime as _dt
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def git_commit() -> str:
    """The short commit of the checkout the benchmark runs in ("unknown" outside git)."""
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                              text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def utc_now() -> str:
    return f"{_dt.datetime.now(_dt.timezone.utc):%Y-%m-%d %H:%M} UTC"


def append_run(path: Path, title: str, section: str) -> None:
    """Append ``section`` to the results file ``path``, starting it with ``title``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    text = (path.read_text() if path.exists() else title) + section
    tmp = path.with_name(f".{path.name}.{os.getpid()}")
    tmp.write_text(text)
    os.replace(tmp, path)


def append_study(out: Path, script: str, heading: str, section: str) -> None:
    """Append ``section`` to ``out``/<the script's name>.md, a file that begins with ``heading``
    and names the script (benchmarks/<family>/<name>.py) that writes it."""
    name = Path(script).stem
    append_run(out / f"{name}.md", f"# {heading}\n\nWritten by {script}; a section per run.\n", section)


def short_commit(rev: str) -> str | None:
    """``rev``'s short commit in this repository, None where it names none."""
    got = subprocess.run(["git", "rev-parse", "--short", "--verify", "--quiet", f"{rev}^{{commit}}"], cwd=ROOT,
                         capture_output=True, text=True)
    return got.stdout.strip() if got.returncode == 0 else None


@contextlib.contextmanager
def earlier_tree(rev: str):
    """A git worktree of commit ``rev`` (short_commit's) in a temporary folder, removed after:
    the earlier side of a side-by-side run.  Its Python files and the checkout's are compiled
    to bytecode first: where PYTHONDONTWRITEBYTECODE is set, each command would otherwise
    compile again whatever has no fresh bytecode (0.03 CPU-s of a start-up for the whole
    package, 0.014 for three edited modules), biasing the side that lacks it."""
    with tempfile.TemporaryDirectory() as td:
        tree = Path(td) / "earlier"
        subprocess.run(["git", "worktree", "add", "--detach", str(tree), rev], cwd=ROOT, check=True,
                       capture_output=True)
        for side in (tree, ROOT):
            subprocess.run([sys.executable, "-m", "compileall", "-q", str(side / "pyjulia4d")], capture_output=True)
        try:
            yield tree
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", str(tree)], cwd=ROOT, capture_output=True)
