"""Child processes for the tests: the package from this checkout on PYTHONPATH, the OpenCL
registration left to each child (as any process does it), a Python snippet or the command
line run with a timeout."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pyjulia4d

PKG_ROOT = str(Path(pyjulia4d.__file__).resolve().parent.parent)


def subprocess_env(**extra: str) -> dict[str, str]:
    """This environment with the checkout's package first on PYTHONPATH, without the
    OCL_ICD_VENDORS this process's own registration set, plus ``extra``."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [PKG_ROOT, env.get("PYTHONPATH")]))
    env.pop("OCL_ICD_VENDORS", None)   # set by this process's own registration
    env.update(extra)
    return env


def python_process(code: str, **extra: str) -> subprocess.CompletedProcess[str]:
    """``python -c code`` in a child, ``extra`` in its environment."""
    return subprocess.run([sys.executable, "-c", code], env=subprocess_env(**extra), capture_output=True, text=True,
                          timeout=300)


def cli_process(args: list[str], cwd: Path, prelude: str = "", **extra: str) -> subprocess.CompletedProcess[str]:
    """The command line with ``args`` in a child in ``cwd``, after ``prelude`` (Python run first)."""
    code = prelude + "import sys; from pyjulia4d.app.cli import main; sys.exit(main(sys.argv[1:]))"
    return subprocess.run([sys.executable, "-c", code, *args], cwd=cwd, env=subprocess_env(**extra),
                          capture_output=True, text=True, timeout=300)
