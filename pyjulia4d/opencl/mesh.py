"""The mesh kernels (kernels/mesh/mesh.cl) on an OpenCL device: a MeshPlan's grid sampled a
block of z-layers at a time, and the vertices placed on the surface."""
from __future__ import annotations

import numpy as np
import pyopencl as cl
import pyopencl.array as cla

from pyjulia4d.opencl import build
from pyjulia4d.opencl.records import Packed, Precision
from pyjulia4d.opencl.runner import launch, queue_for
from pyjulia4d.pipeline import signatures as sig
from pyjulia4d.pipeline.mesh_plan import MeshPlan


class MeshRunner:
    """The program of one plan on one device."""

    def __init__(self, plan: MeshPlan, dev: cl.Device):
        self.plan = plan
        self.ctx, self.queue = queue_for(dev)
        prg = build.program(self.ctx, plan.config)
        self.sample_k = build.kernel(prg, "mesh_sample")
        self.vertex_k = build.kernel(prg, "mesh_vertices")
        pr = self.pr = Precision(plan.double)
        records, defines = {"mesh": plan, "clip": plan.clip}, plan.config.defines
        self.sample_args = Packed(sig.MESH_SAMPLE, records, pr, defines, nx=plan.n, ny=plan.n)
        self.vertex_args = Packed(sig.MESH_VERTICES, records, pr, defines)

    def sample(self, k0: int, nk: int) -> np.ndarray:
        """The inside mask of grid layers k0 .. k0 + nk - 1: uint8, shape (nk, n, n), [k, j, i]."""
        n = self.plan.n
        count = nk * n * n
        out = cla.empty(self.queue, count, np.uint8)
        launch(self.queue, self.sample_k, count, *self.sample_args(k0=k0, inside=out))
        return out.get().reshape(nk, n, n)

    def vertices(self, ends_a: np.ndarray, ends_b: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Vertices (m, 4) on the surface between world points ends_a and ends_b (one inside,
        one outside, either order), the width of each one's bracket (0 on the ball's cut
        face, -1 where the ends agree), and the bracket's inside end (m, 4)."""
        m = len(ends_a)
        if m == 0:
            return np.empty((0, 4)), np.empty(0), np.empty((0, 4))
        pr = self.pr
        o, i = (cla.to_device(self.queue, _as_vec4(a, pr)) for a in (ends_a, ends_b))
        vertex = cla.empty(self.queue, m, pr.vec_dtype)
        inner = cla.empty(self.queue, m, pr.vec_dtype)
        width = cla.empty(self.queue, m, pr.scalar)
        launch(self.queue, self.vertex_k, m, *self.vertex_args(ends_a=o, ends_b=i, vertex=vertex, width=width,
                                                                inside_end=inner))
        return _from_vec4(vertex.get()), width.get().astype(np.float64), _from_vec4(inner.get())


def _from_vec4(a: np.ndarray) -> np.ndarray:
    """An array of real4 as (m, 4) float64."""
    return np.stack([a[k] for k in ("x", "y", "z", "w")], axis=1).astype(np.float64)


def _as_vec4(a: np.ndarray, pr: Precision) -> np.ndarray:
    """(m, 4) floats as an array of the kernels' real4."""
    out = np.empty(len(a), pr.vec_dtype)
    for k, name in enumerate(("x", "y", "z", "w")):
        out[name] = a[:, k]
    return out
