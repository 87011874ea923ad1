"""OpenCL runtimes that come from PyPI: making Intel's CPU runtime visible to the ICD loader.

pyopencl's wheel loads OpenCL drivers ("ICDs") through its own ocl-icd, which reads the
``*.icd`` files in ``$OCL_ICD_VENDORS`` (default ``/etc/OpenCL/vendors``) and in its own
``pyopencl/.libs`` (PyPI's PoCL, from ``pyopencl[pocl]``).  PyPI's PoCL 3.0 (LLVM 14)
cannot compile for CPUs its LLVM does not know (AMD Zen 5: "unknown target CPU
'generic'"); Intel's CPU runtime (the ``intel-opencl-rt`` wheel, with
``intel-cmplr-lib-rt``) runs on any x86-64 CPU with SSE4.2, AMD's included.  Its wheel
installs an ``.icd`` file naming a path from its build (``/opt/anaconda1anaconda2anaconda3/
lib/libintelocl.so``) in a folder the loader never reads, so the loader never sees it.

``register()`` (called when pyjulia4d is imported, before any OpenCL call: ocl-icd reads
its vendors folder at the first one) writes a vendors folder of its own into pyjulia4d's
cache folder: one ``.icd`` file naming the wheel's real ``libintelocl.so``, plus a copy of
every system ``.icd`` file (``$OPENCL_VENDOR_PATH`` or ``/etc/OpenCL/vendors``), since
``OCL_ICD_VENDORS`` replaces that folder; then points ``OCL_ICD_VENDORS`` at it.  Nothing is
written outside the cache folder.  It does nothing when the user has set ``OCL_ICD_VENDORS``
(their choice stands), when ``PYJULIA4D_NO_BUNDLED_OPENCL`` is set, when the wheel is not
installed, or when a system ICD already is Intel's CPU runtime.
"""
from __future__ import annotations

import hashlib
import os
import sys
import tempfile
from pathlib import Path

from pyjulia4d.resources import cache_dir

SYSTEM_VENDORS = "/etc/OpenCL/vendors"   # ocl-icd's compiled-in default
_INTEL_LIB = "libintelocl.so"

# What register() did, for `devices` and the closing line: the library it registered
# ("" if none) and why not, when it did not; ``failed``: the why_not of a failure (not a
# choice, such as a user's OCL_ICD_VENDORS), "" if none.
registered: dict[str, str] = {"library": "", "folder": "", "why_not": "not yet run", "failed": ""}

# The remembered default device this process's loader was narrowed to (default_device.py):
# its record, empty where every runtime is loaded.
narrowed: dict[str, object] = {}


def user_vendors() -> bool:
    """Whether ``OCL_ICD_VENDORS`` was set by the user rather than by register()."""
    env = os.environ.get("OCL_ICD_VENDORS", "")
    return bool(env) and env != registered["folder"] and not narrowed


def intel_library() -> Path | None:
    """The ``libintelocl.so`` of the installed intel-opencl-rt wheel, or None.  The wheel puts
    it in ``<prefix>/lib`` (its RECORD names ``../../libintelocl.so`` from site-packages), so
    that is looked at first: importlib.metadata, the fallback, costs 40-100 ms of start-up."""
    for prefix in dict.fromkeys((sys.prefix, sys.base_prefix)):
        path = Path(prefix) / "lib" / _INTEL_LIB
        if path.is_file():
            return path
    import importlib.metadata

    try:
        dist = importlib.metadata.distribution("intel-opencl-rt")
    except importlib.metadata.PackageNotFoundError:
        return None
    for f in dist.files or ():
        if f.name == _INTEL_LIB:
            path = Path(os.path.normpath(dist.locate_file(f)))
            if path.is_file():
                return path
    return None


def system_icds() -> dict[str, str]:
    """{file name: library line} of the ``.icd`` files the loader would read by default."""
    folder = Path(os.environ.get("OPENCL_VENDOR_PATH") or SYSTEM_VENDORS)
    out = {}
    try:
        names = sorted(p.name for p in folder.iterdir() if p.suffix == ".icd")
    except OSError:
        return out
    for name in names:
        try:
            line = (folder / name).read_text(errors="replace").strip()
        except OSError:
            continue
        if line:
            out[name] = line
    return out


def _write_vendors(icds: dict[str, str]) -> Path:
    """A vendors folder holding ``icds`` under the cache folder, named by its content
    (so processes share it and a changed system set gets a new one), made atomically."""
    text = "\n".join(f"{k}\0{v}" for k, v in sorted(icds.items()))
    folder = cache_dir() / "icd" / hashlib.sha256(text.encode()).hexdigest()[:16]
    if folder.is_dir():
        return folder
    folder.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=".icd-", dir=folder.parent))
    try:
        for name, line in icds.items():
            (tmp / name).write_text(line + "\n")
        os.rename(tmp, folder)
    except OSError:
        for p in tmp.iterdir():
            p.unlink()
        tmp.rmdir()
        if not folder.is_dir():
            raise
    return folder


def register() -> None:
    """Point ocl-icd at a vendors folder that adds the intel-opencl-rt wheel's CPU runtime
    to the system's drivers (module docstring).  Idempotent; never raises."""
    if registered["why_not"] != "not yet run":
        return
    if os.environ.get("PYJULIA4D_NO_BUNDLED_OPENCL"):
        registered["why_not"] = "PYJULIA4D_NO_BUNDLED_OPENCL is set"
        return
    if os.environ.get("OCL_ICD_VENDORS"):
        registered["why_not"] = "OCL_ICD_VENDORS is set"
        return
    lib = intel_library()
    if lib is None:
        registered["why_not"] = "intel-opencl-rt is not installed"
        return
    icds = system_icds()
    if any(Path(v).name.startswith(_INTEL_LIB) for v in icds.values()):
        registered["why_not"] = "the system has Intel's CPU runtime"
        return
    icds["pyjulia4d-intel-cpu.icd"] = str(lib)
    try:
        folder = _write_vendors(icds)
    except OSError as e:
        registered["why_not"] = registered["failed"] = f"cannot write the vendors folder ({e.strerror or e})"
        return
    os.environ["OCL_ICD_VENDORS"] = str(folder)
    registered.update(library=str(lib), folder=str(folder), why_not="")


def pyopencl_cache() -> None:
    """Turn pyopencl's on-disk caches off (``PYOPENCL_NO_CACHE``) where their folder cannot be
    made.  pyopencl keeps each kernel's argument setter in a pytools PersistentDict under the
    user's cache folder (``$XDG_CACHE_HOME/pytools``) and, where that folder cannot be made
    (an ``XDG_CACHE_HOME`` under /proc, a read-only home), stopped the first render with a
    traceback; without the cache it only generates the setters again, as pyjulia4d's own
    program cache costs only time where it cannot be written.  Called before pyopencl is
    imported (which reads the setting); a user's own ``PYOPENCL_NO_CACHE`` stands where the
    folder can be made."""
    try:
        import platformdirs   # pytools' own way to the folder (a dependency of pytools)
    except ImportError:
        return
    try:   # made as pyopencl makes it at its first kernel: the one exact test (root passes access())
        folder = platformdirs.user_cache_dir("pytools", "pytools")
        os.makedirs(folder, exist_ok=True)
        if not os.access(folder, os.W_OK):
            raise PermissionError(folder)
    except (OSError, ValueError):
        os.environ["PYOPENCL_NO_CACHE"] = "1"
