"""Where the OpenCL sources live, installed or in a source checkout."""
from __future__ import annotations

from pathlib import Path


def kernel_dir() -> Path:
    """The folder holding the ``*.cl`` kernel sources.

    An installed wheel ships them as the package ``pyjulia4d.kernels``; a source
    checkout keeps them in the top-level ``kernels/`` folder.
    """
    here = Path(__file__).resolve().parent
    installed = here / "kernels"
    if any(installed.glob("*.cl")):
        return installed
    return here.parent / "kernels"
