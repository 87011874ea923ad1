"""The kernels of a render plan on one device, tile by tile (executor.py runs the tiles).

``TileRunner`` holds a plan's programs, its argument records cast to the device's precision
(pipeline/plan.py) and two slots of tile buffers (opencl/pool.py keeps them between renders);
``enqueue`` queues one tile's kernels - the march (rays made in the kernel), normals, light
terms and shading, the mirror bounce - and the maps of what the plan reads back.  ``launch``
is the one place a kernel is enqueued.
"""
from __future__ import annotations

import threading
from collections import OrderedDict

import numpy as np
import pyopencl as cl
import pyopencl.array as cla

from pyjulia4d.opencl import build, pool
from pyjulia4d.pipeline import colormap, kernel_config
from pyjulia4d.pipeline.plan import Plan, Tile, gradient_step
from pyjulia4d.scene.model import Scene


_queues: dict[int, tuple[cl.Context, cl.CommandQueue]] = {}


def queue_for(device: cl.Device) -> tuple[cl.Context, cl.CommandQueue]:
    """One context and queue per device, kept for the process."""
    key = device.int_ptr
    if key not in _queues:
        ctx = cl.Context([device])
        # profiling: the kernels' own time, summed from their events (render's kernel_seconds)
        _queues[key] = (ctx, cl.CommandQueue(
            ctx, properties=cl.command_queue_properties.PROFILING_ENABLE))
    return _queues[key]


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


def _float4(v3, w=0.0):
    return np.array((*(float(x) for x in v3), float(w)), cl.cltypes.float4)


# The floor of normals.step = "auto": a central difference of the estimate over a step h
# carries its rounding error divided by h; at h = epsilon = 5e-7 (the final preset) float32
# differences are noise (2.8 degrees median on the c = 0 ball, against 0.1 at 1e-5).
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


def march_items(n: int, tile_w: int, lanes: int, packets: int = 1) -> int:
    """Work-items of the march over a tile of n pixels, tile_w wide: one per ray, or one
    per ``packets`` neighbouring blocks of pixels in a row (kernels/march/march.cl,
    kernel_config.march_packets; the light terms take the march's, the Jacobian normals one
    block each)."""
    if lanes == 1:
        return n
    bw, bh = kernel_config.packet_block(lanes)
    blocks_x = -(-tile_w // bw)
    return -(-blocks_x // packets) * -(-(n // tile_w) // bh)


# Kernels whose scalar arguments' types pyopencl knows (set_scalar_arg_dtypes): it then packs
# them itself, where its generic path took 7-10 us an argument (0.46 ms a 640x480 tile's
# four launches on Intel's runtime, before the first kernel could start; 0.03 ms typed).
# Keyed by handle, holding the kernel so that no other takes its address; the oldest let go.
_typed: "OrderedDict[int, cl.Kernel]" = OrderedDict()
_kept_lock = threading.Lock()   # _typed and _constants (below) are shared by renders in threads
TYPED_KEEP = 256


def type_arguments(kernel: cl.Kernel, args: tuple) -> None:
    """Tell pyopencl the types of ``kernel``'s arguments, from a first call's ``args`` (numpy
    scalars and vectors, buffers, None), once per kernel: 0.25 ms, repaid by its second launch."""
    key = kernel.int_ptr
    if _typed.get(key) is kernel:
        return
    types = []
    for a in args:
        if a is None or isinstance(a, cl.MemoryObjectHolder):
            types.append(None)
        elif isinstance(a, (np.generic, np.ndarray)):
            types.append(a.dtype)
        else:   # a Python number would be packed at a guessed width
            raise TypeError(f"kernel {kernel.function_name}: argument of type {type(a).__name__}; "
                            "pass a numpy scalar or a buffer")
    kernel.set_scalar_arg_dtypes(types)
    with _kept_lock:
        _typed[key] = kernel
        while len(_typed) > TYPED_KEEP:
            _typed.popitem(last=False)


def launch(queue: cl.CommandQueue, kernel: cl.Kernel, n: int, *args, lanes: int = 1,
           items: int | None = None) -> cl.Event | None:
    """Enqueue ``kernel`` over n items, ``lanes`` per work-item (packets of rays) or
    ``items`` work-items: n_items = n first, then ``args``.  Returns the launch's event."""
    if n <= 0:
        return None
    type_arguments(kernel, (np.int32(n),) + args)
    loc = local_size(kernel, queue.device)
    items = -(-n // lanes) if items is None else items
    return kernel(queue, (-(-items // loc) * loc,), (loc,), np.int32(n), *args)


def launch_normals(queue, prg, scene: Scene, method: str, frame, pr: Precision,
                   point, depth, status, normal, flags, size: tuple[int, int] | None = None,
                   lanes: int = 1) -> cl.Event | None:
    """Enqueue the normals kernel of ``method`` (kernels/normals/<method>.cl) on the march's
    device buffers of one tile of ``size`` = (width, height) pixels (default: the whole
    image); writes ``normal`` (unit camera-coordinate normal, w 0) and ORs each hit's guard
    flags into ``flags`` (the march's)."""
    f = scene.fractal
    w, h = size or (scene.image.width, scene.image.height)
    n = w * h
    c = pr.v4(f.c)
    eye, fwd, right, up = (pr.v4(v) for v in (frame.position, frame.forward, frame.right, frame.up))
    kernel = build.kernel(prg, f"normals_{method}")
    if method == "jacobian":
        return launch(queue, kernel, n, point.data, status.data, c, np.int32(f.max_iter),
                      pr.scalar(f.bailout), right, up, fwd, normal.data, flags.data, lanes=lanes)
    if method == "gradient":
        return launch(queue, kernel, n, point.data, status.data, c, np.int32(f.max_iter),
                      pr.scalar(f.bailout), pr.scalar(gradient_step(scene)), right, up, fwd, normal.data,
                      flags.data)
    return launch(queue, kernel, n, point.data, depth.data, status.data, np.int32(w), np.int32(h), eye,
                  right, up, fwd, normal.data, flags.data)



# Small read-only arrays the kernels take (colour map, lights), kept by context and content:
# each upload waited for its copy, 0.09 ms a buffer, three a render before its first kernel.
_constants: "OrderedDict[tuple, cla.Array]" = OrderedDict()
CONSTANTS_KEEP = 32


def constant(queue: cl.CommandQueue, ary: np.ndarray) -> cla.Array:
    """``ary`` on ``queue``'s device, uploaded once per context and content; the kernels only
    read it."""
    key = (queue.context.int_ptr, ary.dtype.str, ary.shape, ary.tobytes())
    with _kept_lock:
        got = _constants.get(key)
        if got is not None:
            _constants.move_to_end(key)
            return got
    got = cla.to_device(queue, ary)
    with _kept_lock:
        _constants[key] = got
        while len(_constants) > CONSTANTS_KEEP:
            _constants.popitem(last=False)
    return got


# The device buffers each output needs (march/march.cl, normals_*.cl, shade.cl); status, flags,
# depth, bracket and the normals' guard word are read back always (one tile's worth): the
# streamed counts, guards and bracket statistics come from them.
_READ = {"color": ("rgba",), "alpha": ("status",), "depth": ("depth",), "bracket": ("bracket",),
         "unresolved": ("unresolved",),
         "normal": ("normal",), "position": ("point",), "status": ("status",),
         "samples": ("samples",)}


class TileRunner:
    """The kernels of one plan on one device, with two slots of tile buffers (and the host's
    maps of them) so that one tile's kernels run while the previous one is filed."""

    SLOTS = 2

    def __init__(self, plan: Plan, dev: cl.Device):
        self.plan = plan
        self.ctx, self.queue = queue_for(dev)
        self.prg = build.program(self.ctx, plan.config)
        self.march_prg = build.program(self.ctx, plan.march_config)
        self.pr = pr = Precision(plan.double)
        nmax = max(t.n for t in plan.tiles)
        read = {"status", "flags", "depth", "bracket", "unresolved"} | {b for k in plan.outputs for b in _READ[k]}
        self.read = read
        nb = max(bw * bh for _, _, bw, bh in (t.cone_blocks() for t in plan.tiles)) if plan.march.cone else 0
        extra = "EXTRA_SHADOWS" in plan.config.defines
        # slots of these shapes given back by an earlier runner (opencl/pool.py), else new ones
        self.slot_key = (self.ctx.int_ptr, nmax, plan.double, frozenset(read), plan.normals, plan.shades, nb,
                         plan.reflects, plan.light_terms, extra)
        self.slots = pool.take(self.slot_key) or [self.make_slot(nmax, nb, extra) for _ in range(self.SLOTS)]
        # the plan's argument records (pipeline/plan.py), in the order the kernels declare them
        fr, ma, sa, la = plan.frame, plan.march, plan.shade, plan.light_args
        self.eye, self.fwd, self.right, self.up = (pr.v4(v) for v in (fr.position, fr.forward, fr.right, fr.up))
        self.camera = (self.eye, self.fwd, self.right, self.up, pr.scalar(fr.tan_half_fov),
                       np.int32(plan.scene.image.width), np.int32(plan.scene.image.height))
        self.march_const = (pr.v4(ma.c), np.int32(ma.max_iter), pr.scalar(ma.bailout), pr.scalar(ma.epsilon),
                            pr.scalar(ma.radius), pr.scalar(ma.near), pr.scalar(ma.far),
                            np.int32(ma.z_resolution), np.int32(ma.post_steps), np.int32(ma.max_steps))
        self.shade_const = (self.eye, self.right, self.up, self.fwd, pr.v4(sa.light),
                            _float4(sa.color), _float4(sa.background), _float4(sa.light_color),
                            _float4(sa.sky), np.float32(sa.ambient), np.float32(sa.diffuse), np.float32(sa.specular),
                            np.float32(sa.shininess))
        self.fog = (np.float32(sa.fog), np.float32(sa.fog_start))
        self.march_k = build.kernel(self.march_prg, "march")
        self.cone_k = build.kernel(self.march_prg, "cone_starts") if plan.march.cone else None
        self.cone_const = (pr.v4(ma.c), np.int32(ma.max_iter), pr.scalar(ma.bailout), pr.scalar(ma.radius),
                           pr.scalar(ma.near), pr.scalar(ma.far), np.int32(ma.max_steps))
        planes = plan.clip.planes
        self.clip_n = tuple(pr.v4(planes[k][0] if k < len(planes) else (0, 0, 0, 0)) for k in range(4))
        self.clip_args = ((np.int32(len(planes)),) + self.clip_n +
                          (pr.v4([planes[k][1] if k < len(planes) else 0.0 for k in range(4)]),)
                          if planes else ())
        self.clip_k = build.kernel(self.prg, "clip_normals") if planes and plan.normals else None
        self.shade_k = build.kernel(self.prg, "shade") if plan.shades else None
        # shade/light.cl: in the march's program, in its packets (kernel_config.march_config)
        self.light_k = build.kernel(self.march_prg, "light_terms") if plan.light_terms else None
        self.light_const = ((pr.v4(ma.c), np.int32(ma.max_iter), pr.scalar(ma.bailout), pr.scalar(ma.epsilon),
                             self.right, self.up, self.fwd, pr.v4(sa.light), pr.scalar(ma.radius),
                             pr.scalar(la.step), pr.scalar(la.bias), pr.scalar(la.softness), np.int32(la.max_steps),
                             pr.scalar(la.ao_distance), pr.scalar(la.ao_strength), pr.v4(la.trap))
                            if plan.light_terms else ())
        lut = colormap.table(sa.colormap) if sa.colormap is not None else np.zeros((2, 4), np.float32)
        self.lut = constant(self.queue, lut.view(cl.cltypes.float4).ravel())
        self.n_lut = np.int32(len(lut))
        self.no_terms = constant(self.queue, np.zeros(1, cl.cltypes.float4))
        # shading.lights: positions or directions, colours; their visibility per pixel where
        # shadows are traced (-D EXTRA_SHADOWS)
        self.lights_geo = constant(self.queue, np.array([pr.v4(g) for g in sa.lights_geo]))
        self.lights_rgb = constant(self.queue, np.array([_float4(c[:3], c[3]) for c in sa.lights_rgb]))
        if plan.reflects:
            self.refl_prg = build.program(self.ctx, plan.reflect_config)
            self.refl_march_k = build.kernel(self.refl_prg, "march")
            self.reflect_rays_k = build.kernel(self.prg, "reflect_rays")
            self.reflect_color_k = build.kernel(self.prg, "reflect_color")
            self.refl_bias = pr.scalar(la.bias)

    def make_slot(self, nmax: int, nb: int, extra: bool) -> tuple[dict, dict]:
        """One slot: the device buffers of a tile of up to nmax pixels (nb cone blocks) and
        the host views of those read back while they are mapped (``enqueue``, ``release``).
        The buffers read back are allocated in host-reachable memory (ALLOC_HOST_PTR), which
        a CPU device maps without a copy."""
        plan, pr, q = self.plan, self.pr, self.queue
        mapped = cl.mem_flags.READ_WRITE | cl.mem_flags.ALLOC_HOST_PTR

        def empty(name: str, dtype) -> cla.Array:
            if name not in self.read:
                return cla.empty(q, nmax, dtype)
            return cla.empty(q, nmax, dtype, allocator=lambda size: cl.Buffer(self.ctx, mapped, size))

        bufs = {"depth": empty("depth", pr.scalar), "bracket": empty("bracket", pr.scalar),
                "unresolved": empty("unresolved", pr.scalar), "point": empty("point", pr.vec_dtype),
                "status": empty("status", np.int32), "samples": empty("samples", np.int32),
                "flags": empty("flags", np.int32)}
        if plan.normals:
            bufs["normal"] = empty("normal", pr.vec_dtype)
        if plan.shades:
            bufs["rgba"] = empty("rgba", cl.cltypes.float4)
        if nb:   # march/cone.cl: (t_lo, t_last) per block of the tile
            bufs["cone"] = cla.empty(q, nb, pr.cone_dtype)
        if plan.reflects:   # the reflected rays, their march, normals and colour
            for k in ("origins", "dirs", "point2", "normal2"):
                bufs[k] = cla.empty(q, nmax, pr.vec_dtype)
            for k in ("depth2", "bracket2", "unresolved2"):
                bufs[k] = cla.empty(q, nmax, pr.scalar)
            for k in ("status2", "samples2", "flags2"):
                bufs[k] = cla.empty(q, nmax, np.int32)
            bufs["refl"] = cla.empty(q, nmax, cl.cltypes.float4)
        if plan.light_terms:
            bufs["terms"] = cla.empty(q, nmax, cl.cltypes.float4)
            bufs["vis_extra"] = cla.empty(q, nmax if extra else 1, cl.cltypes.float4)
        return bufs, {}

    def release(self, slot: int) -> None:
        """Unmap the slot's read-back buffers (its tile filed), before its next tile's kernels
        write them again."""
        _, maps = self.slots[slot]
        for a in maps.values():
            a.base.release(self.queue)
        maps.clear()

    def close(self) -> None:
        """Give the slots back for the next runner of the same shapes (opencl/pool.py); once
        every tile is filed, so nothing still writes them."""
        if self.slots:
            for slot in range(len(self.slots)):
                self.release(slot)
            pool.give(self.slot_key, self.slots)
            self.slots = []

    def enqueue(self, tile: Tile, slot: int, sample: int = 0, samples: int = 1
                ) -> tuple[list[cl.Event], list[cl.Event]]:
        """Queue the tile's kernels - rays through sample ``sample`` of ``samples`` of each
        pixel (rays.cl; one: the centre) - and the maps of what is read back from ``slot``:
        (kernel events, map events); nothing waits."""
        plan, pr, q = self.plan, self.pr, self.queue
        bufs, maps = self.slots[slot]
        n = tile.n
        kernels, cone = [], ()
        if self.cone_k is not None:
            bx0, by0, bw, bh = tile.cone_blocks()
            kernels.append(launch(q, self.cone_k, bw * bh, np.int32(bw), np.int32(bx0), np.int32(by0), *self.camera,
                                  *self.cone_const, bufs["cone"].data, lanes=plan.lanes * plan.march_packets))
            cone = (bufs["cone"].data, np.int32(bw))
        kernels.append(launch(q, self.march_k, n, np.int32(tile.aw), *self.camera, np.int32(tile.ax0),
                              np.int32(tile.ay0), np.int32(sample), np.int32(samples), *self.march_const,
                              bufs["depth"].data, bufs["point"].data, bufs["status"].data, bufs["samples"].data,
                              bufs["flags"].data, bufs["bracket"].data, bufs["unresolved"].data, *self.clip_args,
                              *cone, items=march_items(n, tile.aw, plan.lanes, plan.march_packets)))
        if plan.normals:
            method = plan.scene.normals.method
            packet = plan.normals_in_march_config
            kernels.append(launch_normals(q, self.march_prg if packet else self.prg, plan.scene, method,
                                          plan.frame, pr, bufs["point"], bufs["depth"], bufs["status"],
                                          bufs["normal"], bufs["flags"], size=(tile.aw, tile.ah),
                                          lanes=plan.lanes if packet else 1))
            if self.clip_k is not None:
                kernels.append(launch(q, self.clip_k, n, bufs["flags"].data, bufs["status"].data, self.right,
                                      self.up, self.fwd, *self.clip_n, bufs["normal"].data))
        if plan.reflects:
            kernels += self.enqueue_reflection(tile, bufs)
        if plan.light_terms:
            kernels.append(launch(q, self.light_k, n, np.int32(tile.aw), bufs["point"].data, bufs["normal"].data,
                                  bufs["status"].data, bufs["bracket"].data, self.eye, *self.light_const,
                                  self.lights_geo.data, self.lights_rgb.data, bufs["terms"].data,
                                  bufs["vis_extra"].data,
                                  items=march_items(n, tile.aw, plan.lanes, plan.march_packets)))
        if plan.shades:
            terms = bufs["terms"] if plan.light_terms else self.no_terms
            vis_extra = bufs["vis_extra"] if plan.light_terms else self.no_terms
            refl = bufs["refl"] if plan.reflects else self.no_terms
            kernels.append(launch(q, self.shade_k, n, bufs["status"].data, bufs["normal"].data,
                                  bufs["point"].data, *self.shade_const, terms.data, self.lut.data,
                                  self.n_lut, *self.fog, self.lights_geo.data, self.lights_rgb.data,
                                  vis_extra.data, refl.data, np.float32(plan.shade.reflection),
                                  bufs["rgba"].data))
        # read back by mapping (the slot's last maps were let go once its tile was filed): no
        # copy on a CPU device, where copies took 0.1-0.5 ms a buffer of 512x480 pixels on
        # Intel's runtime, in line between this tile's kernels and the next's
        mapped = []
        for k in self.read:
            maps[k], ev = cl.enqueue_map_buffer(q, bufs[k].data, cl.map_flags.READ, 0, (n,), bufs[k].dtype,
                                                is_blocking=False)
            mapped.append(ev)
        return kernels, mapped

    def enqueue_reflection(self, tile: Tile, bufs: dict) -> list:
        """shade/reflect.cl: the reflected ray of each hit, marched like a camera ray (the
        march reading given rays, in the same packets), its normals and its colour."""
        plan, pr, q, n = self.plan, self.pr, self.queue, tile.n
        sa = plan.shade
        ev = [launch(q, self.reflect_rays_k, n, bufs["point"].data, bufs["normal"].data, bufs["status"].data,
                     self.eye, self.right, self.up, self.fwd, self.refl_bias, pr.scalar(plan.radius),
                     bufs["origins"].data, bufs["dirs"].data)]
        ev.append(launch(q, self.refl_march_k, n, np.int32(tile.aw), bufs["origins"].data, bufs["dirs"].data,
                         *self.march_const, bufs["depth2"].data, bufs["point2"].data, bufs["status2"].data,
                         bufs["samples2"].data, bufs["flags2"].data, bufs["bracket2"].data,
                         bufs["unresolved2"].data, *self.clip_args,
                         items=march_items(n, tile.aw, plan.lanes, plan.march_packets)))
        packet = plan.normals_in_march_config
        ev.append(launch_normals(q, self.march_prg if packet else self.prg, plan.scene, plan.scene.normals.method,
                                 plan.frame, pr, bufs["point2"], bufs["depth2"], bufs["status2"], bufs["normal2"],
                                 bufs["flags2"], size=(tile.aw, tile.ah), lanes=plan.lanes if packet else 1))
        if self.clip_k is not None:
            ev.append(launch(q, self.clip_k, n, bufs["flags2"].data, bufs["status2"].data, self.right, self.up,
                             self.fwd, *self.clip_n, bufs["normal2"].data))
        ev.append(launch(q, self.reflect_color_k, n, bufs["status2"].data, bufs["normal2"].data,
                         bufs["point2"].data, bufs["dirs"].data, self.right, self.up, self.fwd,
                         pr.v4(sa.light), _float4(sa.color), _float4(sa.background), _float4(sa.light_color),
                         _float4(sa.sky), np.float32(sa.ambient), np.float32(sa.diffuse), bufs["refl"].data))
        return ev

    def collect(self, tile: Tile, slot: int) -> dict[str, np.ndarray]:
        """The slot's mapped arrays of ``tile``, shaped (ah, aw[, 4]) over its box (valid once
        the slot's map events have completed, until ``release``)."""
        _, maps = self.slots[slot]
        shape = (tile.ah, tile.aw)
        out = {}
        for k in self.read:
            a = maps[k]
            if k in ("point", "normal"):
                out[k] = a.view(self.pr.scalar).reshape(*shape, 4)
            elif k == "rgba":   # shade.cl's four planes, seen as (ah, aw, 4)
                out[k] = a.view(np.float32).reshape(4, *shape).transpose(1, 2, 0)
            else:
                out[k] = a.reshape(shape)
        return out
