"""What is installed where: the OpenCL sources (installed or in a source checkout), the
cache folder, and whether an optional extra's module is there."""
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


def data_dir() -> Path:
    """The folder of the files pyjulia4d ships (the path tracer's sky, pyjulia4d/data)."""
    return Path(__file__).resolve().parent / "data"


def cache_dir() -> Path:
    """pyjulia4d's cache folder: $PYJULIA4D_CACHE, else ~/.cache/pyjulia4d."""
    root = os.environ.get("PYJULIA4D_CACHE") or os.path.join(os.path.expanduser("~"), ".cache", "pyjulia4d")
    return Path(root)


def module_installed(name: str) -> bool:
    """Whether the module ``name`` can be imported, without importing it (an extra's: the
    cluster's ``distributed``, the video's ``imageio_ffmpeg``)."""
    import importlib.util

    try:
        return importlib.util.find_spec(name) is not None
    except ValueError:   # sys.modules[name] is None (blocked)
        return False
