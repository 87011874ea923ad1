"""Run single kernels of a scene's program on plain numpy arrays (test helper)."""
from __future__ import annotations

import os

import numpy as np
import pyopencl as cl
import pyopencl.array as cla

from pyjulia4d.opencl import build
from pyjulia4d.opencl.records import Packed, Precision
from pyjulia4d.pipeline import signatures
from pyjulia4d.pipeline import kernel_config
from pyjulia4d.opencl.devices import select_device
from pyjulia4d.opencl.runner import launch, queue_for


def device():
    """The device under test: PYJULIA4D_DEVICE if set, else the default choice."""
    return select_device(os.environ.get("PYJULIA4D_DEVICE") or None)


def packet_widths(widths=(4, 8, 16), double: bool = False):
    """The packet widths the device under test survives: those up to the width its probe
    found for the precision (pyjulia4d/opencl/lanes.py runs the probe in a child process; a width a
    driver crashes on - PyPI's PoCL on float16 - must never run in the test process itself)."""
    from pyjulia4d.opencl.lanes import lanes_for

    most = lanes_for(device(), "packet", double)
    return [w for w in widths if w <= most]


class Runner:
    """Kernels of one build configuration; arrays in, arrays out."""

    def __init__(self, config: kernel_config.KernelConfig):
        self.config = config
        self.ctx, self.queue = queue_for(device())
        self.prg = build.program(self.ctx, config)
        self.double = "REAL_DOUBLE" in config.defines
        self.real = np.float64 if self.double else np.float32
        self.vdt = cl.cltypes.double4 if self.double else cl.cltypes.float4

    def buf4(self, a):
        a = np.ascontiguousarray(np.asarray(a, self.real).reshape(-1, 4))
        return cla.to_device(self.queue, a.view(self.vdt).ravel())

    def buf(self, a, dtype=None):
        return cla.to_device(self.queue, np.ascontiguousarray(a, dtype or self.real))

    def out4(self, n):
        return cla.empty(self.queue, n, self.vdt)

    def out(self, n, dtype=None):
        return cla.empty(self.queue, n, dtype or self.real)

    def get4(self, a):
        return a.get().view(self.real).reshape(-1, 4).astype(np.float64)

    def __call__(self, name, size, *args, lanes: int = 1, items: int | None = None):
        """Run kernel ``name`` over ``size`` = (n,) items the way render.py does
        (render.launch: padded work-groups, n passed first, ``lanes`` per work-item or
        ``items`` work-items)."""
        conv = [a.data if isinstance(a, cla.Array) else a for a in args]
        (n,) = size
        launch(self.queue, cl.Kernel(self.prg, name), n, *conv, lanes=lanes, items=items)
        self.queue.finish()

    def named(self, name, size, *, lanes: int = 1, items: int | None = None, **values):
        """Run kernel ``name`` as ``__call__`` does, every argument given by name and packed in
        the kernel's declared order by its signature (pipeline/signatures.py): a name missing
        or unknown is an error, and each value is cast to its parameter's type."""
        packed = Packed(signatures.SIGNATURES[name].all_given(), {}, Precision(self.double), self.config.defines)
        self(name, size, *packed(**values), lanes=lanes, items=items)
