"""Run a scene's kernels: rays -> march -> normals -> shade.

Every per-pixel step is an OpenCL kernel; Python only sets up the frame, picks
the program and moves whole buffers.  ``reference.render`` is the float64 numpy
twin of this function.
"""
from __future__ import annotations

import math
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
from .lanes import lanes_for
from .scene import Scene, SceneError

STATUS_MISS, STATUS_HIT, STATUS_CAPPED = 0, 1, 2  # kernels/real.cl
# Guard flags (kernels/real.cl): the march's flags buffer and the normals' w component
GUARD_NORMAL_FALLBACK = 1   # degenerate or non-finite normal replaced by the view axis
GUARD_JACOBIAN_TINY = 2     # Jacobian iteration stopped: q_n about to underflow (c ~ 0)
GUARD_ULP_STEP = 4          # de: a step below the spacing of t raised to one ulp
GUARD_SHELL_MISS = 8        # de: within epsilon by the estimate, never inside: a miss


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
    bracket: np.ndarray = None  # (H, W) float32: the surface lies in [depth, depth + bracket]; +inf off hits
    device_name: str = ""
    seconds: float = 0.0         # the whole render: set-up, build, kernels, read-back
    kernel_seconds: float = 0.0  # the kernels alone
    guards: dict = field(default_factory=dict)  # pixels each numerical guard fired on (count_guards)
    lanes: int = 1               # rays per work-item of the march (pyjulia4d/lanes.py)

    @property
    def hit_fraction(self) -> float:
        return float(np.mean(self.status == STATUS_HIT))

    def bracket_stats(self) -> dict[str, float]:
        """p50 / p99 / max of the certified bracket width over the pixels hit (refine.cl):
        each hit's surface crossing lies within its width behind its depth.  NaN when
        nothing was hit."""
        hit = self.status == STATUS_HIT
        b = np.asarray(self.bracket, np.float64)[hit] if self.bracket is not None else np.empty(0)
        if b.size == 0:
            return {"p50": math.nan, "p99": math.nan, "max": math.nan}
        return {"p50": float(np.percentile(b, 50)), "p99": float(np.percentile(b, 99)),
                "max": float(b.max())}

    def report(self, stated_p99: float | None = None) -> tuple[dict[str, str], str]:
        """What a render says about itself: (header entries for PNG/EXR, the tail of the
        closing line).  Capped rays, the guards that fired and the certified depth bracket
        (p50/p99/max) are never hidden; with ``stated_p99`` (the bound a quality preset
        states) the line says whether this render's bracket p99 is within it."""
        b = self.bracket_stats()
        bracket = " ".join(f"{k}={v:.3g}" for k, v in b.items())
        header = {
            "pyjulia4d.device": self.device_name,
            "pyjulia4d.rays_per_work_item": str(self.lanes),
            "pyjulia4d.render_seconds": "%.6f" % self.seconds,
            "pyjulia4d.capped_pixels": str(self.capped),
            "pyjulia4d.guards": " ".join(f"{k}={v}" for k, v in self.guards.items()),
            "pyjulia4d.depth_bracket": bracket,
        }
        fired = [f"{k} {v}" for k, v in self.guards.items() if v]
        tail = f", {self.capped} capped" if self.capped else ""
        tail += f"; guards fired: {', '.join(fired)}" if fired else ""
        if not math.isnan(b["p99"]):
            tail += f"; depth bracket p50 {b['p50']:.2g} p99 {b['p99']:.2g} max {b['max']:.2g}"
            if stated_p99 is not None:
                ok = b["p99"] <= stated_p99
                tail += (f" (within the preset's stated {stated_p99:.0e})" if ok else
                         f" (ABOVE the preset's stated {stated_p99:.0e}: this scene needs a finer "
                         f"preset or more march.post_steps)")
                header["pyjulia4d.preset_bound_met"] = "yes" if ok else "no"
        return header, tail

    @property
    def capped(self) -> int:
        """Pixels whose march ran into the step cap (counted, never hidden)."""
        return int(np.sum(self.status == STATUS_CAPPED))

    def exr_channels(self) -> dict[str, np.ndarray]:
        f = np.float32
        ch = {"R": self.color[..., 0], "G": self.color[..., 1], "B": self.color[..., 2],
              "A": self.alpha, "Z": self.depth}
        if self.bracket is not None:
            ch["Z.bracket"] = self.bracket
        for k, name in enumerate("XYZ"):
            ch[f"N.{name}"] = self.normal[..., k]
        for k, name in enumerate("XYZW"):
            ch[f"P.{name}"] = self.position[..., k]
        return {k: np.ascontiguousarray(v, dtype=f) for k, v in ch.items()}


def count_guards(status, depth, guard) -> dict[str, int]:
    """Pixels each numerical guard fired on (nothing clamped without being counted).
    ``guard`` holds the flags (kernels/real.cl) of the march kernel's flags buffer ORed
    with those the normals kernels write into the normal's w."""
    status, guard = (np.asarray(a).ravel() for a in (status, guard))
    hit = status == STATUS_HIT
    guard = guard.astype(np.int32, copy=False)

    def fired(flag, on=None):
        m = (guard & flag) != 0
        return int(np.count_nonzero(m if on is None else m & on))

    return {
        # de step below the spacing of t raised to one ulp (march_de.cl): effective epsilon = ulp(t)
        "ulp_step": fired(GUARD_ULP_STEP),
        # normal replaced by the view axis: degenerate or non-finite gradient (normals_*.cl)
        "normal_fallback": fired(GUARD_NORMAL_FALLBACK, hit),
        # Jacobian iteration stopped before q_n underflowed to 0 (normals_jacobian.cl)
        "jacobian_tiny": fired(GUARD_JACOBIAN_TINY, hit),
        # de: within epsilon of the set by the estimate, yet no point inside: a miss (march_de.cl)
        "shell_miss": fired(GUARD_SHELL_MISS),
        # the hit is the eye itself, depth 0 (camera inside the set; shade.cl takes the view axis)
        "eye_hit": int(np.count_nonzero(hit & (np.asarray(depth).ravel() == 0))),
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


# The floor of normals.step = "auto": a central difference of the estimate over a step h
# carries its rounding error divided by h; at h = epsilon = 5e-7 (the final preset) float32
# differences are noise (2.8 degrees median on the c = 0 ball, against 0.1 at 1e-5).
GRADIENT_STEP_FLOOR = {"single": 1e-5, "double": 1e-8}


def gradient_step(scene: Scene) -> float:
    """The gradient normals' difference step: normals.step, or for "auto" march.epsilon
    floored at GRADIENT_STEP_FLOOR[render.float]."""
    if scene.normals.step != "auto":
        return float(scene.normals.step)
    return max(scene.march.epsilon, GRADIENT_STEP_FLOOR[scene.render.float])


# Every kernel is launched in work-groups of one fixed size over a range padded to a whole
# number of them, the true item count passed as its first argument (kernels return past it):
# PoCL compiles a work-group function per local size, and with the local size left to the
# driver (None) it picked one per global size, so every new image size recompiled
# (+0.27 s measured at 321x241 after 320x240).
LOCAL_SIZE = 64
_local: dict[tuple[int, int], int] = {}


def local_size(kernel: cl.Kernel, device: cl.Device) -> int:
    """LOCAL_SIZE, or the largest power of two the device allows for this kernel."""
    key = (kernel.int_ptr, device.int_ptr)
    if key not in _local:
        most = kernel.get_work_group_info(cl.kernel_work_group_info.WORK_GROUP_SIZE, device)
        size = LOCAL_SIZE
        while size > most and size > 1:
            size //= 2
        _local[key] = size
    return _local[key]


def march_items(n: int, tile_w: int, lanes: int) -> int:
    """Work-items of the march over a tile of n pixels, tile_w wide: one per ray, or one
    per block of pixels (kernels/march.cl)."""
    if lanes == 1:
        return n
    bw, bh = build.packet_block(lanes)
    return -(-tile_w // bw) * -(-(n // tile_w) // bh)


def launch(queue: cl.CommandQueue, kernel: cl.Kernel, n: int, *args, lanes: int = 1,
           items: int | None = None) -> None:
    """Enqueue ``kernel`` over n items, ``lanes`` per work-item (packets of rays) or
    ``items`` work-items: n_items = n first, then ``args``."""
    if n <= 0:
        return
    loc = local_size(kernel, queue.device)
    items = -(-n // lanes) if items is None else items
    kernel(queue, (-(-items // loc) * loc,), (loc,), np.int32(n), *args)


def launch_normals(queue, prg, scene: Scene, method: str, frame, pr: Precision,
                   point, depth, status, normal, size: tuple[int, int] | None = None,
                   lanes: int = 1) -> None:
    """Enqueue the normals kernel of ``method`` (kernels/normals_<method>.cl) on the march's
    device buffers of one tile of ``size`` = (width, height) pixels (default: the whole
    image); writes ``normal`` (unit camera-coordinate normal, guard flags in w)."""
    f = scene.fractal
    w, h = size or (scene.image.width, scene.image.height)
    n = w * h
    c = pr.v4(f.c)
    eye, fwd, right, up = (pr.v4(v) for v in (frame.position, frame.forward, frame.right, frame.up))
    kernel = cl.Kernel(prg, f"normals_{method}")
    if method == "jacobian":
        launch(queue, kernel, n, point.data, status.data, c, np.int32(f.max_iter), pr.scalar(f.bailout),
               right, up, fwd, normal.data, lanes=lanes)
    elif method == "gradient":
        launch(queue, kernel, n, point.data, status.data, c, np.int32(f.max_iter), pr.scalar(f.bailout),
               pr.scalar(gradient_step(scene)), right, up, fwd, normal.data)
    else:
        launch(queue, kernel, n, point.data, depth.data, status.data, np.int32(w), np.int32(h), eye, right,
               up, fwd, normal.data)


# Tiles of at most TILE x TILE pixels (plus a one-pixel halo for the Z-buffer normals,
# which difference neighbours): device memory stays under ~28 MB single / ~48 MB double
# at any image size, no launch runs for minutes, and the progress bar moves per tile;
# 262,144 work-items per launch still fill a large GPU.
TILE = 512


def tiles(width: int, height: int, tile: int = TILE):
    """(x0, y0, w, h) of the image's tiles, row by row."""
    for y0 in range(0, height, tile):
        for x0 in range(0, width, tile):
            yield x0, y0, min(tile, width - x0), min(tile, height - y0)


def render(scene: Scene, device: cl.Device | str | None = None, progress: bool = False,
           force: bool = False, tile: int = TILE, lanes: int | None = None) -> RenderResult:
    """Render ``scene`` on an OpenCL device (default: a GPU if any, else PoCL), tile by tile.
    ``force`` renders a scene ``workload.check`` would refuse as hopeless (hours of work).
    ``lanes`` (rays per work-item of the march) overrides render.variant's choice
    (lanes.lanes_for); the tests and the width probe use it."""
    t_start = time.perf_counter()
    dev = device if isinstance(device, cl.Device) else select_device(device)
    workload.check(scene, dev, force=force)  # before any kernel: hopeless, overflowing or too large
    double = scene.render.float == "double"
    if double and not has_fp64(dev):
        raise SceneError("render.float", f"device '{dev.name.strip()}' has no cl_khr_fp64 (double precision); use \"single\"")
    frame = camera_frame(scene)
    ctx, queue = queue_for(dev)
    prg = build.program(ctx, build.scene_config(scene))
    if lanes is None:
        lanes = lanes_for(dev, scene.render.variant, double)
    march_prg = prg if lanes == 1 else build.program(ctx, build.march_config(scene, lanes))
    pr = Precision(double)
    W, H = scene.image.width, scene.image.height
    f, m, sh = scene.fractal, scene.march, scene.shading
    halo = 1 if scene.normals.method == "zbuffer" else 0

    # the whole image on the host, float32 (workload.check refuses what would not fit)
    color = np.empty((H, W, 3), np.float32)
    alpha = np.empty((H, W), np.float32)
    depth_img = np.empty((H, W), np.float32)
    bracket_img = np.empty((H, W), np.float32)
    normal_img = np.empty((H, W, 3), np.float32)
    position = np.empty((H, W, 4), np.float32)
    status_img = np.empty((H, W), np.int32)
    samples_img = np.empty((H, W), np.int32)
    guard_img = np.empty((H, W), np.int32)

    # device buffers for the largest tile, reused
    tw_max, th_max = min(tile, W) + 2 * halo, min(tile, H) + 2 * halo
    nmax = tw_max * th_max
    origins, dirs, point, normal = (cla.empty(queue, nmax, pr.vec_dtype) for _ in range(4))
    depth, bracket = (cla.empty(queue, nmax, pr.scalar) for _ in range(2))
    status, samples, flags = (cla.empty(queue, nmax, np.int32) for _ in range(3))
    rgba = cla.empty(queue, nmax, cl.cltypes.float4)
    buffers = {"rgba": rgba, "depth": depth, "bracket": bracket, "normal": normal, "point": point,
               "status": status, "samples": samples, "flags": flags}
    stage = {name: np.empty(nmax, buf.dtype) for name, buf in buffers.items()}

    eye, fwd, right, up = (pr.v4(v) for v in (frame.position, frame.forward, frame.right, frame.up))
    c = pr.v4(f.c)
    near = -1.0 if m.near == "auto" else float(m.near)
    far = -1.0 if m.far == "auto" else float(m.far)
    march_const = (c, np.int32(f.max_iter), pr.scalar(f.bailout), pr.scalar(m.epsilon),
                   pr.scalar(march_radius(scene)), pr.scalar(near), pr.scalar(far),
                   np.int32(m.z_resolution), np.int32(m.post_steps), np.int32(m.max_steps))
    lp = light_position(scene)
    light = pr.v4(lp if lp is not None else frame.position)
    rays_k, shade_k = (cl.Kernel(prg, k) for k in ("generate_rays", "shade"))
    march_k = cl.Kernel(march_prg, "march")

    queue.finish()
    kernel_seconds = 0.0
    with tqdm(total=W * H, unit="px", unit_scale=True, file=sys.stderr, delay=1.0, leave=False,
              disable=not progress, desc="render") as bar:
        for x0, y0, tw, th in tiles(W, H, tile):
            t0 = time.perf_counter()
            # the tile with its halo, clipped to the image
            ax0, ay0 = max(0, x0 - halo), max(0, y0 - halo)
            ax1, ay1 = min(W, x0 + tw + halo), min(H, y0 + th + halo)
            aw, ah = ax1 - ax0, ay1 - ay0
            n = aw * ah
            launch(queue, rays_k, n, eye, fwd, right, up, pr.scalar(frame.tan_half_fov), np.int32(W),
                   np.int32(H), np.int32(ax0), np.int32(ay0), np.int32(aw), origins.data, dirs.data)
            launch(queue, march_k, n, np.int32(aw), origins.data, dirs.data, *march_const, depth.data,
                   point.data, status.data, samples.data, flags.data, bracket.data,
                   items=march_items(n, aw, lanes))
            if scene.normals.method == "jacobian":   # in packets too (build.march_config)
                launch_normals(queue, march_prg, scene, "jacobian", frame, pr, point, depth, status,
                               normal, size=(aw, ah), lanes=lanes)
            else:
                launch_normals(queue, prg, scene, scene.normals.method, frame, pr, point, depth, status,
                               normal, size=(aw, ah))
            launch(queue, shade_k, n, status.data, normal.data, point.data, eye, right, up, fwd, light,
                    _float4(sh.color), _float4(sh.background), _float4(sh.light_color),
                    np.float32(sh.ambient), np.float32(sh.diffuse), np.float32(sh.specular),
                    np.float32(sh.shininess), rgba.data)
            queue.finish()
            kernel_seconds += time.perf_counter() - t0

            # the tile's own pixels, without the halo
            ys, xs = slice(y0 - ay0, y0 - ay0 + th), slice(x0 - ax0, x0 - ax0 + tw)
            dst = (slice(y0, y0 + th), slice(x0, x0 + tw))

            # the tile's n items into staging arrays made once (no allocation, no page
            # faults per tile), all copies queued before one wait
            for name, buf in buffers.items():
                cl.enqueue_copy(queue, stage[name][:n], buf.data, is_blocking=False)
            queue.finish()

            def get(name, k=None):
                a = stage[name][:n]
                if k is not None:
                    return a.view(pr.scalar).reshape(ah, aw, 4)[ys, xs, :k]
                return a.reshape(ah, aw)[ys, xs]

            col = stage["rgba"][:n].view(np.float32).reshape(ah, aw, 4)[ys, xs]
            color[dst] = col[..., :3]
            alpha[dst] = col[..., 3]
            depth_img[dst] = get("depth")
            bracket_img[dst] = get("bracket")
            nrm = get("normal", 4)
            normal_img[dst] = nrm[..., :3]
            position[dst] = get("point", 4)
            status_img[dst] = get("status")
            samples_img[dst] = get("samples")
            # guard flags (kernels/real.cl): the march's buffer and the normals' w
            guard_img[dst] = get("flags") | nrm[..., 3].astype(np.int32)
            bar.update(tw * th)

    result = RenderResult(
        color=color, alpha=alpha, depth=depth_img, normal=normal_img, position=position,
        status=status_img, samples=samples_img, bracket=bracket_img,
        device_name=dev.name.strip(), kernel_seconds=kernel_seconds, lanes=lanes,
        guards=count_guards(status_img, depth_img, guard_img))
    result.seconds = time.perf_counter() - t_start
    return result
