"""Build the OpenCL program of a kernel configuration (kernel_config.py).

Built programs are kept per (context, pieces, switches) for the process, and their
binaries on disk across processes in ``<cache>/programs`` (resources.cache_dir), keyed by
the source, the options and the device and driver (devices.device_key): not every driver
caches its own (PoCL does; others may not).  A binary that no longer loads is rebuilt
from source.
"""
from __future__ import annotations

import hashlib
import threading

import pyopencl as cl

from pyjulia4d.opencl.capabilities import capabilities
from pyjulia4d.opencl.failures import DeviceFailure, on_device
from pyjulia4d.opencl.devices import build, cannot_compile, compile_error, device_key
from pyjulia4d.pipeline.kernel_config import KernelConfig, source
from pyjulia4d.files import atomic_write
from pyjulia4d.resources import cache_dir


_programs: dict[tuple, cl.Program] = {}
_kernels = threading.local()


def programs_built() -> int:
    """How many programs this process has built or loaded (a cluster worker reports how many
    a unit added: none, once it has them)."""
    return len(_programs)


def _from_binary(ctx: cl.Context, dev: cl.Device, path, opts) -> cl.Program | None:
    """The program from a cached binary, or None (none cached, or it no longer loads)."""
    try:
        binary = path.read_bytes()
    except OSError:
        return None
    try:
        return build(cl.Program(ctx, [dev], [binary]), opts)
    except (cl.Error, RuntimeError, ValueError):
        return None


def _save_binary(prg: cl.Program, path) -> None:
    """Write the program's binary atomically; a cache that cannot be written costs only time."""
    try:
        binary = prg.get_info(cl.program_info.BINARIES)[0]
        if not binary:
            return
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_write(path) as tmp:
            tmp.write_bytes(bytes(binary))
    except (cl.Error, OSError):
        pass


def options(config: KernelConfig, dev: cl.Device) -> list[str]:
    """The build options of ``config`` on ``dev``: its switches, then the device's own
    (capabilities.py: what the device links, never what its compiler predefines)."""
    return [f"-D{d}" for d in config.defines + capabilities(dev).defines()]


def program(ctx: cl.Context, config: KernelConfig) -> cl.Program:
    """Build (once per context and configuration) and return the program."""
    key = (ctx.int_ptr, config)
    prg = _programs.get(key)
    if prg is None:
        dev = ctx.devices[0]
        if compile_error(dev):  # a compiler that fails on everything: one line, not a build log
            raise cannot_compile(dev)
        opts = options(config, dev)
        src = source(config)
        digest = hashlib.sha256("\0".join([src, " ".join(opts), device_key(dev), cl.VERSION_TEXT])
                                .encode()).hexdigest()
        path = cache_dir() / "programs" / f"{digest}.bin"
        prg = _from_binary(ctx, dev, path, opts)
        if prg is None:
            with on_device(dev, f"the build of {config.pieces[-1]}.cl"):
                prg = build(cl.Program(ctx, src), opts)
            _save_binary(prg, path)
        _programs[key] = prg
    return prg


def kernel(prg: cl.Program, name: str) -> cl.Kernel:
    """The program's kernel ``name``, made once per thread.  Making one costs pyopencl a
    lookup of its argument setter in an on-disk cache (0.4 ms here, five kernels a render);
    a kernel holds its arguments from set to enqueue, so threads that render at once (the
    explorer's preview and file renders, a Dask worker's threads) never share one."""
    cache = getattr(_kernels, "made", None)
    if cache is None:
        cache = _kernels.made = {}
    got = cache.get((prg.int_ptr, name))
    if got is None or got[0] is not prg:   # the program itself, not a later one at its address
        try:
            made = cl.Kernel(prg, name)
        except cl.Error as e:
            raise DeviceFailure(prg.get_info(cl.program_info.DEVICES)[0], f"making kernel '{name}'", e) from None
        got = cache[(prg.int_ptr, name)] = (prg, made)
    return got[1]
