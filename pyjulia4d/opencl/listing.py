"""``pyjulia4d devices``: one line per OpenCL device, with what it can build and which is the default."""
from __future__ import annotations

import pyopencl as cl

from pyjulia4d.opencl import runtimes
from pyjulia4d.opencl.capabilities import capabilities
from pyjulia4d.opencl.devices import (DeviceError, compile_error, default_reason, device_type, has_fp64,
                                      indexed_devices, is_simulator, select_device)


def _caps(device: cl.Device) -> str:
    """What builds on ``device`` read from it (capabilities.py), for describe_devices."""
    c = capabilities(device)
    return f"OpenCL C {c.cl_c // 100}.{c.cl_c // 10 % 10}, {c.describe()}"


def describe_devices() -> str:
    """One line per device: ``P:D  platform | device | type, N CUs, fp64 yes/no``, and
    whether it compiles (a device that cannot is never picked by default)."""
    rows = indexed_devices()
    if not rows:
        raise DeviceError("no OpenCL platform found (install pyopencl[pocl] for a CPU device)")
    out = []
    chosen = None
    try:
        chosen = select_device(None)
    except DeviceError:
        pass
    for idx, p, d in rows:
        err = compile_error(d)
        mark = "  (default)" if chosen is not None and d.int_ptr == chosen.int_ptr else ""
        if is_simulator(d):
            mark += "  (a simulator: used only where named, such as --device oclgrind)"
        out.append(f"{idx}  {p.name.strip()} {p.version.strip()} | {d.name.strip()} | {device_type(d)}, "
                   f"{d.max_compute_units} compute units, fp64 {'yes' if has_fp64(d) else 'no'}, "
                   f"driver {d.driver_version.strip()}"
                   + (f", cannot compile: {err}" if err else f", {_caps(d)}") + mark)
    if chosen is not None:
        out.append(default_reason(chosen))
    lib = runtimes.registered["library"]
    out.append(f"Intel's CPU runtime from PyPI: registered ({lib})" if lib else
               f"Intel's CPU runtime from PyPI: not registered ({runtimes.registered['why_not']})")
    return "\n".join(out)
