"""The default device remembered, so that a command loads only the OpenCL runtime it renders on.

The ICD loader opens every runtime it is told of at the first OpenCL call: on the
development machine Intel's CPU runtime, Debian's PoCL and PyPI's PoCL, each with its own
LLVM.  Opening all three took 217 MiB and about 0.08 CPU-s of a command that renders on one
of them (`/usr/bin/time python -m pyjulia4d render --width 8 --height 6`; 127 MiB with Intel's
runtime alone).  So once ``select_device(None)`` has chosen the default over all of them,
``remember`` keeps that choice with what it was chosen from, and ``narrow`` - called by
the command line before its first OpenCL call - points the loader at a one-line ``.icd``
file naming the chosen runtime's library alone, as long as nothing it was chosen from has
changed.

The library of a platform is found by ``dladdr`` on the first entry of its dispatch table:
every ICD object begins with a pointer to its vendor's table of entry points (the Khronos
ICD extension, cl_khr_icd), and those functions live in the vendor's library.

What "nothing changed" means: the same ``.icd`` files in the loader's folders, with the
same contents (``icd_key``, under which the choice is kept), and every runtime library
found last time with the same size and modification time (``library_stats``).  A choice is remembered only when every ICD file gave a
platform and every platform a device: a runtime that showed nothing (a GPU driver without
its GPU) could show a GPU next time, which the default would have to take.  The record
holds the chosen device's key (devices.device_key) and the closing line's words about the
choice, which name the devices passed over.  Nothing is narrowed where the user set
``OCL_ICD_VENDORS`` themselves, where ``--device``, ``--workers`` or ``--scheduler`` is
given, or where the program is not the command line (``allow``: the Python interface, and
tests that run the command line in their own process, keep every runtime).
"""
from __future__ import annotations

import ctypes
import hashlib
import json
import os
from pathlib import Path

from pyjulia4d.files import atomic_write
from pyjulia4d.opencl import runtimes
from pyjulia4d.resources import cache_dir

RECORD = "default_device.json"
_allowed = {"on": False}


def allow() -> None:
    """Let ``narrow`` act in this process: called by the program's entry point alone."""
    _allowed["on"] = True


def _icd_folders() -> list[Path]:
    """The folders whose ``.icd`` files the loader reads: its vendors folder, and pyopencl's
    own (its wheel's PoCL)."""
    env = os.environ.get("OCL_ICD_VENDORS", "")
    folders = [Path(env) if env and os.path.isdir(env) else
               Path(os.environ.get("OPENCL_VENDOR_PATH") or runtimes.SYSTEM_VENDORS)]
    try:
        import importlib.util

        spec = importlib.util.find_spec("pyopencl")
        if spec is not None and spec.origin:
            folders.append(Path(spec.origin).parent / ".libs")
    except (ImportError, ValueError):
        pass
    return folders


def _icd_files() -> dict[str, str]:
    """{path: contents} of every ``.icd`` file the loader reads."""
    out = {}
    for folder in _icd_folders():
        try:
            names = sorted(p for p in folder.iterdir() if p.suffix == ".icd")
        except OSError:
            continue
        for p in names:
            try:
                out[str(p)] = p.read_text(errors="replace").strip()
            except OSError:
                out[str(p)] = "(unreadable)"
    return out


def _stat(path: str) -> list:
    try:
        st = os.stat(path)
        return [st.st_size, st.st_mtime_ns]
    except OSError:
        return []


def icd_key() -> str:
    """The ICD files the loader reads, with their contents, as one key."""
    return hashlib.sha256(json.dumps(_icd_files(), sort_keys=True).encode()).hexdigest()[:32]


def library_stats(libraries) -> dict[str, list]:
    """{path: [size, mtime_ns]} of runtime libraries ([] for one that is gone)."""
    return {str(p): _stat(str(p)) for p in sorted(libraries)}


class _DlInfo(ctypes.Structure):
    _fields_ = [("dli_fname", ctypes.c_char_p), ("dli_fbase", ctypes.c_void_p),
                ("dli_sname", ctypes.c_char_p), ("dli_saddr", ctypes.c_void_p)]


def platform_library(platform) -> str:
    """The file of the runtime library behind a pyopencl Platform ("" where not found): the
    library holding the first function of its ICD dispatch table."""
    try:
        libc = ctypes.CDLL(None)
        libc.dladdr.argtypes = [ctypes.c_void_p, ctypes.POINTER(_DlInfo)]
        table = ctypes.c_void_p.from_address(platform.int_ptr).value
        fn = ctypes.c_void_p.from_address(table).value if table else None
        info = _DlInfo()
        if not fn or not libc.dladdr(fn, ctypes.byref(info)) or not info.dli_fname:
            return ""
        path = os.fsdecode(info.dli_fname)
        return path if os.path.isabs(path) and os.path.isfile(path) else ""
    except (OSError, AttributeError, ValueError, TypeError):
        return ""


def _record_path() -> Path:
    return cache_dir() / RECORD


def _records() -> dict:
    try:
        known = json.loads(_record_path().read_text())
    except (OSError, ValueError):
        return {}
    return known if isinstance(known, dict) else {}


KEEP = 8   # ICD sets remembered (a user switching PYJULIA4D_NO_BUNDLED_OPENCL keeps both)


def remember(device, rows, reason: str) -> None:
    """Keep ``device`` (chosen by select_device(None) over ``rows``, the full enumeration:
    devices.indexed_devices) and the closing line's ``reason`` for later commands under the
    ICD files' key, when every ICD file gave a platform and every platform a device.  Never
    raises."""
    try:
        import pyopencl as cl

        from pyjulia4d.opencl.devices import device_key

        platforms = cl.get_platforms()
        with_devices = {p.int_ptr for _, p, _ in rows}
        if len(platforms) != len(_icd_files()) or any(p.int_ptr not in with_devices for p in platforms):
            return
        libs = [platform_library(p) for p in platforms]
        chosen = platform_library(device.platform)
        if not chosen or not all(libs):
            return
        record = {"libraries": library_stats(libs), "library": chosen, "device": device_key(device),
                  "reason": reason}
        known, key = _records(), icd_key()
        if known.get(key) == record:
            return
        known.pop(key, None)
        known = dict(list(known.items())[-(KEEP - 1):])
        known[key] = record
        path = _record_path()
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_write(path) as tmp:
            tmp.write_text(json.dumps(known, indent=1))
    except Exception:   # a cache that cannot be kept only costs loading every runtime
        return


def select(spec: str | None):
    """devices.select_device for the command line: the default device (``spec`` None) is
    looked up with only its runtime loaded where it was remembered, and remembered where it
    was not."""
    from pyjulia4d.opencl.devices import default_reason, indexed_devices, select_device

    if spec is None:
        narrow()
    dev = select_device(spec)
    if spec is None and not runtimes.narrowed:
        remember(dev, indexed_devices(), default_reason(dev))
    return dev


def forget() -> None:
    """Drop the remembered default for the present ICD files (it failed a render): the next
    command loads every runtime and chooses again.  Never raises."""
    try:
        known = _records()
        if known.pop(icd_key(), None) is not None:
            with atomic_write(_record_path()) as tmp:
                tmp.write_text(json.dumps(known, indent=1))
    except OSError:
        return


NO_NARROW = "PYJULIA4D_NO_NARROW"   # set for a command started again after its narrowed default failed


def again_with_every_runtime() -> None:
    """The remembered default device failed a render in a process whose loader holds its
    runtime alone (``narrow``), so no other device can take over here: forget it, and run
    the command again from the start with every runtime loaded, where the next device that
    works takes over (executor.render; the render has written nothing yet).  Returns where
    the loader was not narrowed."""
    import sys

    if not runtimes.narrowed:
        return
    forget()
    env = dict(os.environ, **{NO_NARROW: "1"})
    env.pop("OCL_ICD_VENDORS", None)   # narrow()'s; register() sets its own again
    sys.stdout.flush()
    sys.stderr.flush()
    os.execve(sys.executable, [sys.executable, "-m", "pyjulia4d", *sys.argv[1:]], env)


def narrow() -> bool:
    """Point the ICD loader at the remembered default device's runtime alone (module
    docstring), before any OpenCL call; True if it did.  Sets runtimes.narrowed to the
    record, which select_device(None) and default_reason then read."""
    if not _allowed["on"] or runtimes.narrowed or runtimes.user_vendors() or os.environ.get(NO_NARROW):
        return False
    record = _records().get(icd_key())
    if not isinstance(record, dict) or not all(isinstance(record.get(k), str) for k in
                                               ("library", "device", "reason")):
        return False
    libs = record.get("libraries")
    if not isinstance(libs, dict) or library_stats(libs) != libs or record["library"] not in libs:
        return False
    lib = record["library"]
    icd = cache_dir() / "icd" / f"only-{hashlib.sha256(lib.encode()).hexdigest()[:16]}.icd"
    try:
        if not icd.is_file() or icd.read_text().strip() != lib:
            icd.parent.mkdir(parents=True, exist_ok=True)
            with atomic_write(icd) as tmp:
                tmp.write_text(lib + "\n")
    except OSError:
        return False
    os.environ["OCL_ICD_VENDORS"] = str(icd)
    runtimes.narrowed.update(record)
    return True
