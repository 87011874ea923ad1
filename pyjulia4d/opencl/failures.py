"""A device that fails mid-render, said in one line: the device, the step and the OpenCL error.

pyopencl raises its own exceptions (``cl.Error`` and its LogicError, RuntimeError and
MemoryError) for a build that fails, a kernel that cannot be made (``clCreateKernel``:
INVALID_KERNEL_NAME where a compiler built a program without linking a function it
declared), an enqueue refused or out of resources, and a device lost while it runs
(OUT_OF_RESOURCES or DEVICE_NOT_AVAILABLE from the next call that waits on it).  ``on_device``
turns each into a DeviceFailure, a DeviceError (one line and exit status 2 on the command
line), naming the device, the step (``build.program``: the build; ``build.kernel``: making the
kernel; ``runner.launch``: running it; anything after: the last kernel launched) and the
error's name; a failed build keeps the first error line of its log.  Where the user did not
pick the device, executor.render then renders on the next device that works
(``devices.select_device`` with the failed ones skipped) and says so in the closing line.
"""
from __future__ import annotations

import threading
from contextlib import contextmanager

import pyopencl as cl

from pyjulia4d.opencl.devices import DeviceError

_last = threading.local()   # the kernel this thread launched last, to name a failure found later


class DeviceFailure(DeviceError):
    """An OpenCL device failed at one step of a render (module docstring)."""

    def __init__(self, device: cl.Device, step: str, error: BaseException):
        self.device = device
        self.step = step
        self.code = error_name(error)
        name, platform = _names(device)
        detail = _detail(error)
        super().__init__(f"device '{name}' ({platform}): {step} failed: {self.code}"
                         + (f" ({detail})" if detail else ""))


def _names(device: cl.Device) -> tuple[str, str]:
    try:
        return device.name.strip(), device.platform.name.strip()
    except (cl.Error, AttributeError):   # a device lost may not answer either
        return "?", "?"


def error_name(error: BaseException) -> str:
    """The OpenCL status name of a pyopencl error (``BUILD_PROGRAM_FAILURE``), or its type."""
    code = getattr(error, "code", None)
    if isinstance(code, int):
        for name in dir(cl.status_code):
            if name.isupper() and getattr(cl.status_code, name) == code:
                return name
        return f"error {code}"
    return type(error).__name__


def _detail(error: BaseException) -> str:
    """The first line of a build log that names an error (the compiler's own words); ""
    for other failures, whose status name says it."""
    lines = [ln.strip() for ln in str(error).splitlines() if ln.strip()]
    found = [ln for ln in lines[1:] if "error" in ln.lower()]
    text = found[0] if found else ""
    return text if len(text) <= 200 else text[:197] + "..."


def launched(kernel: cl.Kernel) -> None:
    """Note the kernel this thread launches (runner.launch), for a failure found after it
    (its name is asked only then: a query per launch would cost each launch)."""
    _last.kernel = kernel


def kernel_name(kernel: cl.Kernel | None) -> str:
    try:
        return kernel.function_name if kernel is not None else ""
    except (cl.Error, AttributeError):
        return "?"


def last_launched() -> str:
    return kernel_name(getattr(_last, "kernel", None))


@contextmanager
def on_device(device: cl.Device, step: str | None = None):
    """Turn a pyopencl error raised inside into a DeviceFailure of ``device`` at ``step``
    (None: after the last kernel launched, or "the render" before any)."""
    try:
        yield
    except cl.Error as e:
        if step is None:
            last = last_launched()
            step = f"the render after kernel '{last}'" if last else "the render"
        raise DeviceFailure(device, step, e) from None
