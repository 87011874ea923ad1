"""Run a scene's kernels: rays -> march -> normals -> shade.

Every per-pixel step is an OpenCL kernel; Python only sets up the frame, picks
the program and moves whole buffers.  ``reference.render`` is the float64 numpy
twin of this function.
"""
from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field

import numpy as np
import pyopencl as cl
import pyopencl.array as cla
from tqdm import tqdm

from . import build, workload
from .camera import camera_frame, light_position, march_radius
from .devices import has_fp64, select_device
from .scene import Scene, SceneError

STATUS_MISS, STATUS_HIT, STATUS_CAPPED = 0, 1, 2  # kernels/real.cl
# Guard flags (kernels/real.cl): the march's flags buffer and the normals' w component
GUARD_NORMAL_FALLBACK = 1   # degenerate or non-finite normal replaced by the view axis
GUARD_JACOBIAN_TINY = 2     # Jacobian iteration stopped: q_n about to underflow (c ~ 0)
GUARD_ULP_STEP = 4          # de: a step below the spacing of t raised to one ulp


@dataclass
class RenderResult:
    """Image buffers (row 0 at the top) and what the render cost."""
    color: np.ndarray      # (H, W, 3) float32, background where missed
    alpha: np.ndarray      # (H, W) float32, 1 on a hit
    depth: np.ndarray      # (H, W) float32, distance along the unit 4D ray; +inf on a miss
    normal: np.ndarray     # (H, W, 3) float32, unit, camera coordinates; 0 on a miss
    position: np.ndarray   # (H, W, 4) float32, the 4D hit point; NaN on a miss
    status: np.ndarray     # (H, W) int32, STATUS_* per pixel
    samples: np.ndarray    # (H, W) int32, set tests (fixed) or estimates (de) before the hit
    device_name: str = ""
    seconds: float = 0.0         # the whole render: set-up, build, kernels, read-back
    kernel_seconds: float = 0.0  # the kernels alone
    guards: dict = field(default_factory=dict)  # pixels each numerical guard fired on (count_guards)

    @property
    def hit_fraction(self) -> float:
        return float(np.mean(self.status == STATUS_HIT))

    @property
    def capped(self) -> int:
        """Pixels whose march ran into the step cap (counted, never hidden)."""
        return int(np.sum(self.status == STATUS_CAPPED))

    def exr_channels(self) -> dict[str, np.ndarray]:
        f = np.float32
        ch = {"R": self.color[..., 0], "G": self.color[..., 1], "B": self.color[..., 2],
              "A": self.alpha, "Z": self.depth}
        for k, name in enumerate("XYZ"):
            ch[f"N.{name}"] = self.normal[..., k]
        for k, name in enumerate("XYZW"):
            ch[f"P.{name}"] = self.position[..., k]
        return {k: np.ascontiguousarray(v, dtype=f) for k, v in ch.items()}


def count_guards(status, depth, guard) -> dict[str, int]:
    """Pixels each numerical guard fired on (issue 4: nothing clamped without being counted).
    ``guard`` holds the flags (kernels/real.cl) of the march kernel's flags buffer ORed
    with those the normals kernels write into the normal's w."""
    status, guard = (np.asarray(a).ravel() for a in (status, guard))
    hit = status == STATUS_HIT
    guard = guard.astype(np.int64)
    return {
        # de step below the spacing of t raised to one ulp (march_de.cl): effective epsilon = ulp(t)
        "ulp_step": int(np.sum((guard & GUARD_ULP_STEP) != 0)),
        # normal replaced by the view axis: degenerate or non-finite gradient (normals_*.cl)
        "normal_fallback": int(np.sum(hit & ((guard & GUARD_NORMAL_FALLBACK) != 0))),
        # Jacobian iteration stopped before q_n underflowed to 0 (normals_jacobian.cl)
        "jacobian_tiny": int(np.sum(hit & ((guard & GUARD_JACOBIAN_TINY) != 0))),
        # the hit is the eye itself, depth 0 (camera inside the set; shade.cl takes the view axis)
        "eye_hit": int(np.sum(hit & (np.asarray(depth).ravel() == 0))),
    }


_queues: dict[int, tuple[cl.Context, cl.CommandQueue]] = {}


def queue_for(device: cl.Device) -> tuple[cl.Context, cl.CommandQueue]:
    """One context and queue per device, kept for the process."""
    key = device.int_ptr
    if key not in _queues:
        ctx = cl.Context([device])
        _queues[key] = (ctx, cl.CommandQueue(ctx))
    return _queues[key]


class Precision:
    """numpy types matching the kernels' real / real4 for one precision."""

    def __init__(self, double: bool):
        self.scalar = np.float64 if double else np.float32
        self.vec_dtype = cl.cltypes.double4 if double else cl.cltypes.float4
        self.vec = cl.cltypes.make_double4 if double else cl.cltypes.make_float4

    def v4(self, v) -> np.ndarray:
        return self.vec(*[float(x) for x in v])


def _float4(v3, w=0.0):
    return cl.cltypes.make_float4(*[float(x) for x in v3], float(w))


def launch_normals(queue, prg, scene: Scene, method: str, frame, pr: Precision,
                   point, depth, status, normal) -> None:
    """Enqueue the normals kernel of ``method`` (kernels/normals_<method>.cl) on the march's
    device buffers; writes ``normal`` (unit camera-coordinate normal, guard flags in w)."""
    f, m = scene.fractal, scene.march
    w, h = scene.image.width, scene.image.height
    n = w * h
    c = pr.v4(f.c)
    eye, fwd, right, up = (pr.v4(v) for v in (frame.position, frame.forward, frame.right, frame.up))
    if method == "jacobian":
        cl.Kernel(prg, "normals_jacobian")(queue, (n,), None, point.data, status.data, c, np.int32(f.max_iter),
                                           pr.scalar(f.bailout), right, up, fwd, normal.data)
    elif method == "gradient":
        step = m.epsilon if scene.normals.step == "auto" else float(scene.normals.step)
        cl.Kernel(prg, "normals_gradient")(queue, (n,), None, point.data, status.data, c, np.int32(f.max_iter),
                                           pr.scalar(f.bailout), pr.scalar(step), right, up, fwd, normal.data)
    else:
        cl.Kernel(prg, "normals_zbuffer")(queue, (w, h), None, point.data, depth.data, status.data,
                                          np.int32(w), np.int32(h), eye, right, up, fwd, normal.data)


def render(scene: Scene, device: cl.Device | str | None = None, progress: bool = False,
           force: bool = False) -> RenderResult:
    """Render ``scene`` on an OpenCL device (default: a GPU if any, else PoCL).
    ``force`` renders a scene ``workload.check`` would refuse as hopeless (hours of work)."""
    t_start = time.perf_counter()
    dev = device if isinstance(device, cl.Device) else select_device(device)
    workload.check(scene, dev, force=force)  # before any kernel: hopeless or overflowing settings
    double = scene.render.float == "double"
    if double and not has_fp64(dev):
        raise SceneError("render.float", f"device '{dev.name.strip()}' has no cl_khr_fp64 (double precision); use \"single\"")
    frame = camera_frame(scene)
    ctx, queue = queue_for(dev)
    prg = build.program(ctx, build.scene_config(scene))
    pr = Precision(double)
    w, h = scene.image.width, scene.image.height
    n = w * h
    f, m = scene.fractal, scene.march

    origins = cla.empty(queue, n, pr.vec_dtype)
    dirs = cla.empty(queue, n, pr.vec_dtype)
    depth = cla.empty(queue, n, pr.scalar)
    point = cla.empty(queue, n, pr.vec_dtype)
    status = cla.empty(queue, n, np.int32)
    samples = cla.empty(queue, n, np.int32)
    flags = cla.empty(queue, n, np.int32)
    normal = cla.empty(queue, n, pr.vec_dtype)
    rgba = cla.empty(queue, n, cl.cltypes.float4)

    queue.finish()
    t_kernels = time.perf_counter()
    eye, fwd, right, up = (pr.v4(v) for v in (frame.position, frame.forward, frame.right, frame.up))
    cl.Kernel(prg, "generate_rays")(queue, (w, h), None, eye, fwd, right, up, pr.scalar(frame.tan_half_fov),
                      np.int32(w), np.int32(h), origins.data, dirs.data)

    c = pr.v4(f.c)
    near = -1.0 if m.near == "auto" else float(m.near)
    far = -1.0 if m.far == "auto" else float(m.far)
    march_args = (origins.data, dirs.data, c, np.int32(f.max_iter), pr.scalar(f.bailout),
                  pr.scalar(m.epsilon), pr.scalar(march_radius(scene)), pr.scalar(near),
                  pr.scalar(far), np.int32(m.z_resolution), np.int32(m.post_steps),
                  np.int32(m.max_steps), depth.data, point.data, status.data, samples.data,
                  flags.data)
    # rows in chunks, so a progress bar can move and no single launch runs for minutes
    rows = max(1, min(h, (1 << 16) // w))
    march_kernel = cl.Kernel(prg, "march")
    with tqdm(total=h, unit="row", file=sys.stderr, delay=1.0, leave=False,
              disable=not progress, desc="march") as bar:
        for y0 in range(0, h, rows):
            y1 = min(h, y0 + rows)
            march_kernel(queue, ((y1 - y0) * w,), None, *march_args, global_offset=(y0 * w,))
            queue.finish()
            bar.update(y1 - y0)

    launch_normals(queue, prg, scene, scene.normals.method, frame, pr, point, depth, status, normal)

    sh = scene.shading
    lp = light_position(scene)
    light = pr.v4(lp if lp is not None else frame.position)
    cl.Kernel(prg, "shade")(queue, (n,), None, status.data, normal.data, point.data, eye, right, up, fwd, light,
              _float4(sh.color), _float4(sh.background), _float4(sh.light_color),
              np.float32(sh.ambient), np.float32(sh.diffuse), np.float32(sh.specular),
              np.float32(sh.shininess), rgba.data)
    queue.finish()
    kernel_seconds = time.perf_counter() - t_kernels

    def vec(a, k):
        return a.get().view(pr.scalar).reshape(h, w, 4)[..., :k].astype(np.float32)

    col = rgba.get().view(np.float32).reshape(h, w, 4)
    # guard flags (kernels/real.cl): the march's buffer and the normals' w
    gflags = flags.get() | normal.get().view(pr.scalar).reshape(n, 4)[:, 3].astype(np.int32)
    st, sm = status.get(), samples.get()
    result = RenderResult(
        color=np.ascontiguousarray(col[..., :3]), alpha=np.ascontiguousarray(col[..., 3]),
        depth=depth.get().reshape(h, w).astype(np.float32),
        normal=vec(normal, 3), position=vec(point, 4),
        status=st.reshape(h, w), samples=sm.reshape(h, w),
        device_name=dev.name.strip(), kernel_seconds=kernel_seconds,
        guards=count_guards(st, depth.get(), gflags))
    result.seconds = time.perf_counter() - t_start
    return result

