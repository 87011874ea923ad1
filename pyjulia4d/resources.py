"""Where the OpenCL sources live, installed or in a source checkout."""
from __future__ import annotations

import os
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


def cache_dir() -> Path:
    """pyjulia4d's cache folder: $PYJULIA4D_CACHE, else ~/.cache/pyjulia4d."""
    root = os.environ.get("PYJULIA4D_CACHE") or os.path.join(os.path.expanduser("~"), ".cache", "pyjulia4d")
    return Path(root)
