"""The kernels of a render plan on one device, tile by tile (opencl/passes.py runs the tiles).

``TileRunner`` holds a plan's programs, each kernel's arguments packed once from the plan's
records by the kernel's signature (pipeline/signatures.py, opencl/records.py) and two slots of tile buffers (opencl/pool.py keeps them between renders);
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
from pyjulia4d.opencl.failures import DeviceFailure, kernel_name, launched
from pyjulia4d.opencl.records import Packed, Precision, float4
from pyjulia4d.pipeline import colormap, kernel_config, signatures as sig
from pyjulia4d.pipeline.plan import Plan, Tile
from pyjulia4d.pipeline.workload import OUTPUTS_TABLE


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
    kernel_config.march_packets; the light terms their own, light_packets, the Jacobian normals one
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
    launched(kernel)
    try:
        return kernel(queue, (-(-items // loc) * loc,), (loc,), np.int32(n), *args)
    except cl.Error as e:   # refused, or out of resources: one line naming the device and kernel
        raise DeviceFailure(queue.device, f"running kernel '{kernel_name(kernel)}'", e) from None


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
        read = {"status", "flags", "depth", "bracket", "unresolved"} | {b for k in plan.outputs for b in OUTPUTS_TABLE[k].buffers}
        self.read = read
        nb = max(bw * bh for _, _, bw, bh in (t.cone_blocks() for t in plan.tiles)) if plan.march.cone else 0
        extra = "EXTRA_SHADOWS" in plan.config.defines
        # slots of these shapes given back by an earlier runner (opencl/pool.py), else new ones
        self.slot_key = (self.ctx.int_ptr, nmax, plan.double, frozenset(read), plan.normals, plan.shades, nb,
                         plan.reflects, plan.light_terms, extra)
        self.slots = pool.take(self.slot_key) or [self.make_slot(nmax, nb, extra) for _ in range(self.SLOTS)]
        # each kernel's arguments (pipeline/signatures.py) packed from the plan's records once;
        # a launch gives only its tile's place and buffers
        rec = plan.records()
        lut = colormap.table_of(plan.shade.colormap) if plan.shade.colormap is not None else None
        march_defines = plan.march_config.defines
        self.lut = constant(self.queue, (lut if lut is not None else np.zeros((2, 4), np.float32))
                            .view(cl.cltypes.float4).ravel())
        self.no_terms = constant(self.queue, np.zeros(1, cl.cltypes.float4))
        # shading.lights: positions or directions, colours; their visibility per pixel where
        # shadows are traced (-D EXTRA_SHADOWS)
        sa = plan.shade
        lights = dict(lights_geo=constant(self.queue, np.array([pr.v4(g) for g in sa.lights_geo])),
                      lights_rgb=constant(self.queue, np.array([float4(c) for c in sa.lights_rgb])))
        self.march_k = build.kernel(self.march_prg, "march")
        self.march_args = Packed(sig.MARCH, rec, pr, march_defines)
        self.cone_k = build.kernel(self.march_prg, "cone_starts") if plan.march.cone else None
        self.cone_args = Packed(sig.CONE_STARTS, rec, pr) if plan.march.cone else None
        normals = sig.NORMALS[plan.normals_args.method]
        packet = plan.normals_in_march_config
        self.normals_k = build.kernel(self.march_prg if packet else self.prg, normals.kernel) if plan.normals else None
        self.normals_args = Packed(normals, rec, pr) if plan.normals else None
        self.normals_lanes = plan.lanes if packet else 1
        planes = plan.clip.planes
        self.clip_k = build.kernel(self.prg, "clip_normals") if planes and plan.normals else None
        self.clip_args = Packed(sig.CLIP, rec, pr) if self.clip_k is not None else None
        self.shade_k = build.kernel(self.prg, "shade") if plan.shades else None
        self.shade_args = (Packed(sig.SHADE, rec, pr, lut=self.lut, n_lut=len(lut) if lut is not None else 2, **lights)
                           if plan.shades else None)
        # shade/light.cl: in the march's program, in its packets (kernel_config.march_config)
        self.light_k = build.kernel(self.march_prg, "light_terms") if plan.light_terms else None
        self.light_args = Packed(sig.LIGHT_TERMS, rec, pr, **lights) if plan.light_terms else None
        if plan.reflects:
            self.refl_prg = build.program(self.ctx, plan.reflect_config)
            self.refl_march_k = build.kernel(self.refl_prg, "march")
            self.refl_march_args = Packed(sig.MARCH, rec, pr, plan.reflect_config.defines)
            self.reflect_rays_k = build.kernel(self.prg, "reflect_rays")
            self.reflect_rays_args = Packed(sig.REFLECT_RAYS, rec, pr)
            self.reflect_color_k = build.kernel(self.prg, "reflect_color")
            self.reflect_color_args = Packed(sig.REFLECT_COLOR, rec, pr)

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
        plan, q = self.plan, self.queue
        bufs, maps = self.slots[slot]
        n = tile.n
        items = march_items(n, tile.aw, plan.lanes, plan.march_packets)
        kernels, cone = [], {}
        if self.cone_k is not None:
            bx0, by0, bw, bh = tile.cone_blocks()
            kernels.append(launch(q, self.cone_k, bw * bh, *self.cone_args(blocks_w=bw, bx0=bx0, by0=by0,
                                                                           cone=bufs["cone"]),
                                  lanes=plan.lanes * plan.march_packets))
            cone = dict(cone=bufs["cone"], cone_w=bw)
        kernels.append(launch(q, self.march_k, n, *self.march_args(
            tile_w=tile.aw, x0=tile.ax0, y0=tile.ay0, pixel_sample=sample, pixel_samples=samples,
            **self.march_outputs(bufs, ""), **cone), items=items))
        if plan.normals:
            kernels += self.enqueue_normals(tile, bufs, "")
        if plan.reflects:
            kernels += self.enqueue_reflection(tile, bufs, items)
        if plan.light_terms:
            kernels.append(launch(q, self.light_k, n, *self.light_args(
                tile_w=tile.aw, point=bufs["point"], normal=bufs["normal"], status=bufs["status"],
                bracket=bufs["bracket"], terms=bufs["terms"], vis_extra=bufs["vis_extra"]),
                items=march_items(n, tile.aw, plan.lanes, plan.light_packets)))
        if plan.shades:
            terms = bufs["terms"] if plan.light_terms else self.no_terms
            vis_extra = bufs["vis_extra"] if plan.light_terms else self.no_terms
            refl = bufs["refl"] if plan.reflects else self.no_terms
            kernels.append(launch(q, self.shade_k, n, *self.shade_args(
                status=bufs["status"], normal=bufs["normal"], point=bufs["point"], terms=terms,
                vis_extra=vis_extra, refl=refl, rgba=bufs["rgba"])))
        # read back by mapping (the slot's last maps were let go once its tile was filed): no
        # copy on a CPU device, where copies took 0.1-0.5 ms a buffer of 512x480 pixels on
        # Intel's runtime, in line between this tile's kernels and the next's
        mapped = []
        for k in self.read:
            maps[k], ev = cl.enqueue_map_buffer(q, bufs[k].data, cl.map_flags.READ, 0, (n,), bufs[k].dtype,
                                                is_blocking=False)
            mapped.append(ev)
        return kernels, mapped

    @staticmethod
    def march_outputs(bufs: dict, suffix: str) -> dict:
        """The march's output buffers by parameter name: the camera rays' (suffix ""), or the
        reflected rays' ("2")."""
        return {k: bufs[k + suffix] for k in ("depth", "point", "status", "samples", "flags", "bracket", "unresolved")}

    def enqueue_normals(self, tile: Tile, bufs: dict, suffix: str) -> list:
        """The normals of the march's hits (kernels/normals/<method>.cl), then the cut faces'
        (march/clip.cl): each hit's unit camera-coordinate normal, its guard flags ORed into the
        march's; ``suffix`` as for march_outputs."""
        q, n = self.queue, tile.n
        point, status, flags, normal = (bufs[k + suffix] for k in ("point", "status", "flags", "normal"))
        given = dict(point=point, status=status, normal=normal, flags=flags)
        if self.plan.normals_args.method == "zbuffer":
            given.update(depth=bufs["depth" + suffix], width=tile.aw, height=tile.ah)
        ev = [launch(q, self.normals_k, n, *self.normals_args(**given), lanes=self.normals_lanes)]
        if self.clip_k is not None:
            ev.append(launch(q, self.clip_k, n, *self.clip_args(flags=flags, status=status, normal=normal)))
        return ev

    def enqueue_reflection(self, tile: Tile, bufs: dict, items: int) -> list:
        """shade/reflect.cl: the reflected ray of each hit, marched like a camera ray (the
        march reading given rays, in the same packets), its normals and its colour."""
        q, n = self.queue, tile.n
        ev = [launch(q, self.reflect_rays_k, n, *self.reflect_rays_args(
            point=bufs["point"], normal=bufs["normal"], status=bufs["status"], origins=bufs["origins"],
            dirs=bufs["dirs"]))]
        ev.append(launch(q, self.refl_march_k, n, *self.refl_march_args(
            tile_w=tile.aw, origins=bufs["origins"], dirs=bufs["dirs"], **self.march_outputs(bufs, "2")),
            items=items))
        ev += self.enqueue_normals(tile, bufs, "2")
        ev.append(launch(q, self.reflect_color_k, n, *self.reflect_color_args(
            status=bufs["status2"], normal=bufs["normal2"], point=bufs["point2"], dirs=bufs["dirs"],
            refl=bufs["refl"])))
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
