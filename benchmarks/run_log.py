"""What the benchmark scripts record about each run: the commit measured, and results
files that grow by one section per run, each rewritten atomically (a temp file renamed
over it, as pyjulia4d's own outputs are)."""
from __future__ import annotations

import datetime as _dt
import os
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


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
