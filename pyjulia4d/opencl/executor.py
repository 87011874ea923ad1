"""Execute a render plan (plan.py): per tile, march -> normals -> shade, then assemble.

Every per-pixel step is an OpenCL kernel (the march makes its own rays); Python only
enqueues tiles and files the outputs the plan keeps from their mapped buffers.  Two tiles are
in flight: the kernels of one run while the host files the other, with no finish() between
them (``_run_tiles``: on a CPU device the next tile is queued once the last one is done).
``reference.render`` is the float64 numpy twin of this module's ``render``.
"""
from __future__ import annotations

import dataclasses
import time
import warnings
from typing import Callable

import numpy as np
import pyopencl as cl

from pyjulia4d.pipeline import antialias
from pyjulia4d.fractal.registry import march_method
from pyjulia4d.opencl.devices import check_device, device_of, has_fp64
from pyjulia4d.opencl.lanes import lanes_for, march_lanes, packet_pairs
from pyjulia4d.opencl.runner import TileRunner, local_size, march_items
from pyjulia4d.pipeline.calibrate import Prediction, judge, predict, tile_side, wanted
from pyjulia4d.pipeline.framing import fit_camera
from pyjulia4d.pipeline.codes import STATUS_CAPPED, STATUS_HIT, STATUS_MISS
from pyjulia4d.pipeline.plan import TILE, Plan, Tile, check_flag, check_lanes, check_tile, make_plan, make_tiles
from pyjulia4d.pipeline.progress import Progress, silent
from pyjulia4d.pipeline.result import RenderResult, add_counts, count_guards
from pyjulia4d.pipeline.store import IN_MEMORY, ImageStore, new_zeros
from pyjulia4d.scene.checks import SceneError
from pyjulia4d.scene.model import Scene


def _seconds(events) -> float:
    """The device time of completed, profiled events."""
    total = 0
    for ev in events:
        if ev is not None:
            total += ev.profile.end - ev.profile.start
    return total * 1e-9


def render(scene: Scene, device: cl.Device | str | None = None, progress: bool = False,
           force: bool = False, tile: int = TILE, lanes: int | None = None,
           outputs=None, region=None, calibrate: bool = True,
           on_progress: Callable[[int, int], None] | None = None, store: ImageStore = IN_MEMORY) -> RenderResult:
    """Render ``scene`` on an OpenCL device (default: a GPU if any, else PoCL), tile by tile.
    ``force`` renders a scene ``workload.check`` would refuse as hopeless (hours of work).
    ``lanes`` (rays per work-item of the march) overrides render.variant's choice
    (lanes.lanes_for); the tests and the width probe use it.  ``outputs`` names the arrays
    kept (workload.OUTPUTS; None: all): a depth-only render of any size keeps 8 bytes per
    pixel on the host (depth and its bracket) and two tiles on the device.  ``region`` =
    (x0, y0, w, h) renders those pixels of the image alone, bit for bit as the whole
    render has them (the distributed renderer's unit of one frame).  ``calibrate``: a probe
    render of the scene predicts the time first (calibrate.py: refuse, warn, size the tiles
    so that Ctrl-C is honoured within a tile); False renders in tiles of ``tile``.
    ``on_progress(pixels done, pixels in all)`` is called as each tile is filed (antialiasing's
    passes count again); an exception it raises abandons the render (the explorer's stale
    previews).  ``store``: where the host images live (pipeline/store.py; in memory, or in a
    file for images larger than memory should hold)."""
    t_start = time.perf_counter()
    if not isinstance(scene, Scene):
        raise SceneError("scene", f"expected a pyjulia4d.Scene, got {type(scene).__name__}")
    check_device(device)
    for name, value in (("progress", progress), ("calibrate", calibrate), ("force", force)):
        check_flag(name, value)
    if on_progress is not None and not callable(on_progress):
        raise SceneError("on_progress", f"expected None or a callable, got {type(on_progress).__name__}")
    if lanes is not None:
        check_lanes(lanes)
    check_tile(tile)
    dev = device_of(device)
    plan, prediction = plan_render(scene, dev, lanes, outputs, force, tile, region, calibrate)
    if not isinstance(store, ImageStore):
        raise SceneError("store", f"expected a pyjulia4d.pipeline.store.ImageStore, got {type(store).__name__}")
    result = run_plan(plan, dev, progress, on_progress, store)
    result.prediction = prediction
    result.seconds = time.perf_counter() - t_start
    return result


def plan_render(scene: Scene, dev: cl.Device, lanes: int | None = None, outputs=None, force: bool = False,
                tile: int = TILE, region=None, calibrate: bool = True) -> tuple[Plan, Prediction | None]:
    """Planning, the steps before the render's tiles: refuse a double-precision scene on a
    device without fp64; with camera.fit, refuse hopeless work, then place the camera from a
    first pass (framing.py: the plan of a small probe image, run by run_plan); the packet
    width (lanes.py); the plan (pipeline/plan.py); and, with ``calibrate``, the time
    predicted from a probe of the plan's own kernels (calibrate.py: refuse, warn, retile).
    Returns the plan and the prediction (None where none was made)."""
    double = scene.render.float == "double"
    if double and not has_fp64(dev):   # before any kernel is built, the framing pass's included
        raise SceneError("render.float", f"device '{dev.name.strip()}' has no cl_khr_fp64 (double precision); use \"single\"")
    if lanes is None:
        lanes = march_lanes(lanes_for(dev, scene.render.variant, double), march_method(scene))
    pairs = packet_pairs(dev, lanes, double)
    if scene.camera.fit:   # framing.py: a quick first pass places the camera
        with warnings.catch_warnings():   # refuse before any pass runs; warn after it
            warnings.simplefilter("ignore")
            make_plan(scene, dev, lanes, outputs=outputs, force=force, tile=tile, region=region, pairs=pairs)

            def first_pass(s: Scene, outs) -> RenderResult:
                return run_plan(make_plan(s, dev, lanes, outputs=outs, force=True, pairs=pairs), dev)

            scene, _ = fit_camera(scene, first_pass)
    plan = make_plan(scene, dev, lanes, outputs=outputs, force=force, tile=tile, region=region, pairs=pairs)
    prediction = None
    if calibrate and wanted(plan.estimate.seconds):
        def run_probe(tiles) -> float:
            """The probe's kernel seconds, divided by the compute units a tile of the render
            keeps busy: each probe block is one work-group, run by one of them."""
            events: list = []
            probe = TileRunner(dataclasses.replace(plan, tiles=tiles), dev)
            _run_tiles(probe, tiles, lambda t, got: None, events, silent())
            probe.close()
            big = max(plan.tiles, key=lambda t: t.n)
            groups = -(-march_items(big.n, big.aw, plan.lanes, plan.march_packets) // local_size(probe.march_k, dev))
            return _seconds(events) / max(1, min(dev.max_compute_units, groups))

        prediction = predict(plan, run_probe)
        judge(plan, prediction, force)
        side = tile_side(prediction, tile)
        if side < tile:
            plan = plan.retile(side)
    return plan, prediction


def run_plan(plan: Plan, dev: cl.Device, progress: bool = False,
             on_progress: Callable[[int, int], None] | None = None, store: ImageStore = IN_MEMORY) -> RenderResult:
    """Execute ``plan`` on ``dev``, tile by tile: its pixels through rays, march, normals and
    shading, the antialiasing passes, filed into the image; the counts, guards and kernel
    time go into the result (its ``seconds`` are the kernels' and the filing's).
    ``on_progress``: as for render.  The images are ``store``'s (pipeline/store.py), each
    row of tiles let go once filed."""
    t_start = time.perf_counter()
    scene, lanes = plan.scene, plan.lanes
    runner = TileRunner(plan, dev)
    rx, ry, W, H = plan.region
    keep = plan.outputs
    shapes = {"color": (H, W, 3), "alpha": (H, W), "depth": (H, W), "bracket": (H, W), "unresolved": (H, W),
              "normal": (H, W, 3), "position": (H, W, 4), "status": (H, W), "samples": (H, W)}
    img = {k: store.empty(shapes[k], np.int32 if k in ("status", "samples") else np.float32) for k in keep}
    counts = {"miss": 0, "hit": 0, "capped": 0}
    guards: dict[str, int] = {}
    kernel_events: list = []

    def at(t: Tile) -> tuple[slice, slice]:
        """The tile's pixels in the arrays (which cover the region)."""
        rows, cols = t.dst()
        return slice(rows.start - ry, rows.stop - ry), slice(cols.start - rx, cols.stop - rx)

    def file(t: Tile, got: dict[str, np.ndarray]) -> None:
        own, dst = t.own(), at(t)
        st = got["status"][own]
        for name, code in (("miss", STATUS_MISS), ("hit", STATUS_HIT), ("capped", STATUS_CAPPED)):
            counts[name] += int(np.count_nonzero(st == code))
        # guard flags (kernels/common/codes.cl): the march's, and the normals kernels' ORed in
        add_counts(guards, count_guards(st, got["depth"][own], got["flags"][own]))
        if "color" in keep:
            copy_xyz(img["color"][dst], got["rgba"][own])
        if "alpha" in keep:
            img["alpha"][dst] = got["rgba"][own][..., 3] if "rgba" in got else (st == STATUS_HIT)
        for k, src in (("depth", "depth"), ("bracket", "bracket"), ("unresolved", "unresolved"), ("status", "status"),
                       ("samples", "samples")):
            if k in keep:
                img[k][dst] = got[src][own]
        if "normal" in keep:
            copy_xyz(img["normal"][dst], got["normal"][own])
        if "position" in keep:
            img["position"][dst] = got["point"][own]
        if t.x0 + t.w == rx + W:   # the last tile of its row (make_tiles: row by row)
            store.release(dst[0])

    S = scene.image.samples
    aa = S > 1 and bool({"color", "alpha"} & keep)
    adaptive = aa and scene.image.adaptive
    IW, IH = scene.image.width, scene.image.height
    centre_file = file
    if adaptive:
        # antialias.py: the centre's colour and alpha over the region and the one-pixel ring
        # around it (flags of border pixels look outside the region), as the flags take them
        ex0, ey0 = max(0, rx - 1), max(0, ry - 1)
        ex1, ey1 = min(IW, rx + W + 1), min(IH, ry + H + 1)
        centre_c = new_zeros((ey1 - ey0, ex1 - ex0, 3), np.float32) if plan.shades else None
        centre_a = new_zeros((ey1 - ey0, ex1 - ex0), np.float32)

        def note(t: Tile, got: dict[str, np.ndarray]) -> None:
            rows, cols = t.dst()
            dst = slice(rows.start - ey0, rows.stop - ey0), slice(cols.start - ex0, cols.stop - ex0)
            c, a = _centre_values(got, t.own(), plan.shades)
            if centre_c is not None:
                centre_c[dst] = c
            centre_a[dst] = a

        def centre_file(t: Tile, got: dict[str, np.ndarray]) -> None:
            file(t, got)
            note(t, got)

    with Progress(W * H * (1 + S if aa else 1), "render", "px", enabled=progress, line=_render_line,
                  unit_scale=True, hook=on_progress) as bar:
        # the centre of each pixel: every output (depth, normal, position come from it)
        _run_tiles(runner, plan.tiles, centre_file, kernel_events, bar)
        runner.close()
        if aa:
            # image.samples more passes of colour and alpha alone, each through its own
            # stratified sample of every pixel (rays.cl sample_offset); RGBA is their mean
            cplan = dataclasses.replace(plan, outputs=frozenset({"color", "alpha", "bracket", "unresolved"}))
            tiles, flags = cplan.tiles, None
            if adaptive:
                # image.adaptive: the samples run over the blocks holding a flagged pixel,
                # and the flagged pixels alone take their mean (antialias.py)
                ring = tuple(t for box in antialias.ring(plan.region, IW, IH)
                             for t in make_tiles(IW, IH, max(box[2], box[3]), plan.halo, box))
                if ring:
                    ring_runner = TileRunner(dataclasses.replace(cplan, tiles=ring), dev)
                    _run_tiles(ring_runner, ring, note, kernel_events, bar)
                    ring_runner.close()
                flags = antialias.flag_edges(centre_c, centre_a)[ry - ey0:ry - ey0 + H, rx - ex0:rx - ex0 + W]
                tiles = antialias.block_tiles(flags, plan.region, IW, IH, plan.halo,
                                              max(t.n for t in plan.tiles))
                bar.set_total(W * H + sum(t.w * t.h for t in ring) + S * sum(t.w * t.h for t in tiles))
            crunner = TileRunner(dataclasses.replace(cplan, tiles=tiles), dev) if tiles else None
            acc_c = new_zeros((H, W, 3), np.float32) if "color" in keep else None
            acc_a = new_zeros((H, W), np.float32)

            def add(t: Tile, got: dict[str, np.ndarray]) -> None:
                own, dst = t.own(), at(t)
                if acc_c is not None:
                    acc_c[dst] += got["rgba"][own][..., :3]
                acc_a[dst] += got["rgba"][own][..., 3]

            for k in range(S if tiles else 0):
                _run_tiles(crunner, tiles, add, kernel_events, bar, sample=k, samples=S)
            if crunner is not None:
                crunner.close()
            # the means in place: no image-sized temporaries, whose first touch is new memory's
            if acc_c is not None:
                np.divide(acc_c, S, out=acc_c)
            if "alpha" in keep:
                np.divide(acc_a, S, out=acc_a)
            if flags is None:
                if acc_c is not None:
                    img["color"] = acc_c
                if "alpha" in keep:
                    img["alpha"] = acc_a
            else:
                if acc_c is not None:
                    np.copyto(img["color"], acc_c, where=flags[..., None])
                if "alpha" in keep:
                    np.copyto(img["alpha"], acc_a, where=flags)

    result = RenderResult(
        color=img.get("color"), alpha=img.get("alpha"), depth=img.get("depth"),
        normal=img.get("normal"), position=img.get("position"), status=img.get("status"),
        samples=img.get("samples"), bracket=img.get("bracket"), unresolved=img.get("unresolved"), counts=counts,
        device_name=dev.name.strip(), kernel_seconds=_seconds(kernel_events), lanes=lanes,
        guards=guards, scene=scene)
    result.seconds = time.perf_counter() - t_start
    return result


def copy_xyz(dst: np.ndarray, src: np.ndarray) -> None:
    """dst[..., k] = src[..., k] for k < 3: a tile's (h, w, 4) colour (shade.cl's planes: whole
    rows) or normal into the image's (h, w, 3), one channel at a time (numpy's copy of a
    [..., :3] slice of interleaved values as one strided block took 4.5x as long: 1.15
    against 0.26 ms for 512x480 pixels)."""
    for k in range(3):
        dst[..., k] = src[..., k]


def _centre_values(got: dict[str, np.ndarray], own, shaded: bool):
    """A tile's centre colour (None where the plan does not shade) and alpha over its own
    pixels, as the render keeps them (``file``): what antialias.flag_edges compares."""
    if shaded:
        rgba = got["rgba"][own]
        return rgba[..., :3], rgba[..., 3]
    return None, (got["status"][own] == STATUS_HIT).astype(np.float32)


def _render_line(n: int, total: int, spent: float, left: float, note: str) -> str:
    return f"render: {100 * n / total:.0f}% of {total} pixels, {spent:.0f} s, about {left:.0f} s left"


def queue_ahead(dev: cl.Device) -> bool:
    """Whether a tile's kernels are queued before the host waits for the tile before
    (``_run_tiles``): on any device but a CPU."""
    return not dev.type & cl.device_type.CPU


def _run_tiles(runner: TileRunner, tiles, file, kernel_events: list, bar, sample: int = 0,
               samples: int = 1) -> None:
    """Every tile through ``runner`` in two slots: tile i + 1's kernels run while tile i is
    filed (``file(tile, arrays)``).  A GPU has tile i + 1 queued before the host waits for
    tile i, so that it never waits for the host.  A CPU device has it queued once tile i is
    done: Intel's CPU runtime runs queued kernels in the thread that waits for an event
    until its queue is empty, so with a tile queued ahead every tile was filed after the
    last kernel, the other core idle (a 640x480 render's last 3-4 ms of 30)."""
    ahead = queue_ahead(runner.queue.device)
    pending = None   # (tile, slot, kernel events, map events) queued, not yet filed
    for i, t in enumerate(tiles):
        slot = i % TileRunner.SLOTS
        if pending is not None and not ahead:
            cl.wait_for_events(pending[3])
        kernels, mapped = runner.enqueue(t, slot, sample, samples)
        runner.queue.flush()   # running while the host files the tile before
        if pending is not None:
            _file_pending(runner, pending, file, kernel_events, bar)
        pending = (t, slot, kernels, mapped)
    if pending is not None:
        _file_pending(runner, pending, file, kernel_events, bar)


def _file_pending(runner: TileRunner, pending, file, kernel_events: list, bar) -> None:
    t, slot, kernels, mapped = pending
    cl.wait_for_events(mapped)
    kernel_events.extend(kernels)
    try:
        file(t, runner.collect(t, slot))
    finally:
        runner.release(slot)
    bar.update(t.w * t.h)
