"""A kernel's signature (pipeline/signatures.py) packed for one device's precision.

``Packed`` binds a signature to the plan's records once: the constants are cast to the
kernel's types then (real: the plan's precision; float: always float32, as shading is), and
each launch fills in only what the launch itself gives (the tile's place, its buffers), by
name.  A name missing or left over is an error, so the host cannot pass two swapped or
forgotten values where the kernel declares others.
"""
from __future__ import annotations

import numpy as np
import pyopencl as cl

from pyjulia4d.pipeline.signatures import Signature


class Precision:
    """numpy types matching the kernels' real / real4 for one precision."""

    def __init__(self, double: bool):
        self.scalar = np.float64 if double else np.float32
        self.vec_dtype = cl.cltypes.double4 if double else cl.cltypes.float4
        self.cone_dtype = cl.cltypes.double2 if double else cl.cltypes.float2

    def v4(self, v) -> np.ndarray:
        """A real4 argument (cltypes' make_float4 compiles a lambda with eval at every call:
        a millisecond of each render's set-up)."""
        return np.array(tuple(float(x) for x in v), self.vec_dtype)


def float4(v) -> np.ndarray:
    """A float4 argument from three values (w = 0) or four."""
    vals = tuple(float(x) for x in v)
    return np.array(vals if len(vals) == 4 else vals + (0.0,), cl.cltypes.float4)


def _buffer(v):
    """A kernel's buffer argument: a pyopencl array's data, or a buffer as it is."""
    return getattr(v, "data", v)


def converter(type_: str, pr: Precision):
    """The cast of a value to a parameter of OpenCL type ``type_``."""
    if type_.endswith("*"):
        return _buffer
    return {"int": np.int32, "real": pr.scalar, "float": np.float32, "real4": pr.v4, "float4": float4}[type_]


class Packed:
    """``signature`` bound to ``records`` (Plan.records(); a record's field by the source's
    "record.field") and ``fixed`` values by name, under the -D switches ``defines``; calling
    it with the launch's own values by name gives the kernel's arguments after n_items, in
    its declared order."""

    def __init__(self, signature: Signature, records: dict, pr: Precision, defines=(), **fixed):
        self.kernel = signature.kernel
        template, late = [], []
        for i, p in enumerate(signature.compiled(defines)):
            conv = converter(p.type, pr)
            if p.source:
                rec, _, field = p.source.partition(".")
                template.append(conv(getattr(records[rec], field)))
            elif p.name in fixed:
                template.append(conv(fixed[p.name]))
            else:
                template.append(None)
                late.append((i, p.name, conv))
        self.template, self.late = template, tuple(late)
        self.names = frozenset(name for _, name, _ in late)

    def __call__(self, **given) -> tuple:
        if given.keys() != self.names:
            missing, extra = sorted(self.names - given.keys()), sorted(given.keys() - self.names)
            raise TypeError(f"kernel {self.kernel}: missing {missing}, unexpected {extra}")
        out = list(self.template)
        for i, name, conv in self.late:
            out[i] = conv(given[name])
        return tuple(out)
