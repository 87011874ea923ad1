"""The benchmark scripts' command lines: bad input is one line naming it, exit status 2, no
traceback (as the package's own command line, app/cli.py)."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import NoReturn

SIZE_MAX = 100_000   # pixels a side: far past any size these scripts render


class Parser(argparse.ArgumentParser):
    """argparse's parser whose errors are one line (no usage block) with exit status 2."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: {message}\n")


def size_of(text: str, flag: str = "--size") -> tuple[int, int]:
    """WIDTHxHEIGHT as two ints, each 1 to SIZE_MAX; otherwise one line naming ``flag`` and exit 2."""
    try:
        w, h = (int(x) for x in text.lower().split("x"))
    except ValueError:
        w = h = 0
    if not (1 <= w <= SIZE_MAX and 1 <= h <= SIZE_MAX):
        print(f"{Path(sys.argv[0]).name}: {flag}: expected WIDTHxHEIGHT, each 1 to {SIZE_MAX}, got {text!r}",
              file=sys.stderr)
        raise SystemExit(2)
    return w, h


def add_look(ap: argparse.ArgumentParser, more: str) -> None:
    """--look, as the scripts that set pyjulia4d beside POV-Ray take it (peers.py, peer_error.py);
    ``more`` ends its help: what else the choice changes in that script."""
    ap.add_argument("--look", choices=("matched", "default"), default="matched",
                    help="matched: a light at the eye, no shadows or occlusion; default: pyjulia4d's own look "
                         "(soft shadows, occlusion) against POV-Ray with its shadows on, from the same point light"
                         + more)
