"""A plan's passes over its tiles on one device (the OpenCL executor's execution): the centre
of every pixel, keeping every output the plan names, then image.samples passes of colour
and alpha through stratified samples of each pixel (antialiasing), over the whole region or,
with image.adaptive, over the blocks holding a pixel antialias.py flags.  Everything read
comes from the plan (pipeline/plan.py); opencl/runner.py enqueues each tile's kernels.
"""
from __future__ import annotations

import dataclasses
import time
from typing import Callable

import numpy as np
import pyopencl as cl

from pyjulia4d.opencl.path import path_pass
from pyjulia4d.opencl.runner import TileRunner
from pyjulia4d.pipeline import antialias
from pyjulia4d.pipeline.codes import STATUS_CAPPED, STATUS_HIT, STATUS_MISS
from pyjulia4d.pipeline.plan import Plan, Tile, make_tiles
from pyjulia4d.pipeline.progress import Progress
from pyjulia4d.pipeline.result import RenderResult, add_counts, count_guards, stored_depth
from pyjulia4d.pipeline.store import IN_MEMORY, ImageStore, new_zeros
from pyjulia4d.pipeline.workload import OUTPUTS_TABLE


def kernel_seconds(events) -> float:
    """The device time of completed, profiled events."""
    total = 0
    for ev in events:
        if ev is not None:
            total += ev.profile.end - ev.profile.start
    return total * 1e-9


class Filing:
    """The images a plan keeps over its region (in ``store``), and the counts and guards of
    the tiles filed into them."""

    def __init__(self, plan: Plan, store: ImageStore):
        self.plan, self.store = plan, store
        _, _, W, H = plan.region
        self.img = {k: store.empty(OUTPUTS_TABLE[k].shape(H, W), np.dtype(OUTPUTS_TABLE[k].dtype))
                    for k in plan.outputs}
        self.counts = {"miss": 0, "hit": 0, "capped": 0}
        self.guards: dict[str, int] = {}

    def at(self, t: Tile) -> tuple[slice, slice]:
        """The tile's pixels in the arrays (which cover the region)."""
        rx, ry, _, _ = self.plan.region
        rows, cols = t.dst()
        return slice(rows.start - ry, rows.stop - ry), slice(cols.start - rx, cols.stop - rx)

    def file(self, t: Tile, got: dict[str, np.ndarray]) -> None:
        """The tile's own pixels of every kept output, its statuses counted and its guards."""
        img, keep = self.img, self.plan.outputs
        own, dst = t.own(), self.at(t)
        st = got["status"][own]
        for name, code in (("miss", STATUS_MISS), ("hit", STATUS_HIT), ("capped", STATUS_CAPPED)):
            self.counts[name] += int(np.count_nonzero(st == code))
        # guard flags (kernels/common/codes.cl): the march's, and the normals kernels' ORed in
        add_counts(self.guards, count_guards(st, got["depth"][own], got["flags"][own]))
        if "color" in keep:
            copy_xyz(img["color"][dst], got["rgba"][own])
        if "alpha" in keep:
            img["alpha"][dst] = got["rgba"][own][..., 3] if "rgba" in got else (st == STATUS_HIT)
        src = {k: got[k][own] for k in ("depth", "bracket", "unresolved", "status", "samples") if k in keep}
        if "depth" in src and "bracket" in src:
            src["depth"], src["bracket"] = stored_depth(src["depth"], src["bracket"])
        for k, v in src.items():
            img[k][dst] = v
        if "normal" in keep:
            copy_xyz(img["normal"][dst], got["normal"][own])
        if "position" in keep:
            img["position"][dst] = got["point"][own]
        rx, _, W, _ = self.plan.region
        if t.x0 + t.w == rx + W:   # the last tile of its row (make_tiles: row by row)
            self.store.release(dst[0])


class Centre:
    """image.adaptive: the centre pass's colour and alpha over the region and the one-pixel
    ring around it (flags of border pixels look outside the region), as antialias.flag_edges
    takes them."""

    def __init__(self, plan: Plan):
        self.plan = plan
        rx, ry, W, H = plan.region
        IW, IH = plan.image.width, plan.image.height
        self.ex0, self.ey0 = max(0, rx - 1), max(0, ry - 1)
        ex1, ey1 = min(IW, rx + W + 1), min(IH, ry + H + 1)
        self.color = new_zeros((ey1 - self.ey0, ex1 - self.ex0, 3), np.float32) if plan.shades else None
        self.alpha = new_zeros((ey1 - self.ey0, ex1 - self.ex0), np.float32)

    def note(self, t: Tile, got: dict[str, np.ndarray]) -> None:
        rows, cols = t.dst()
        dst = slice(rows.start - self.ey0, rows.stop - self.ey0), slice(cols.start - self.ex0, cols.stop - self.ex0)
        c, a = _centre_values(got, t.own(), self.plan.shades)
        if self.color is not None:
            self.color[dst] = c
        self.alpha[dst] = a

    def flags(self) -> np.ndarray:
        """The region's pixels antialias.flag_edges flags."""
        rx, ry, W, H = self.plan.region
        y, x = ry - self.ey0, rx - self.ex0
        return antialias.flag_edges(self.color, self.alpha)[y:y + H, x:x + W]


def run_plan(plan: Plan, dev: cl.Device, progress: bool = False,
             on_progress: Callable[[int, int], None] | None = None, store: ImageStore = IN_MEMORY) -> RenderResult:
    """Execute ``plan`` on ``dev``, tile by tile: its pixels through rays, march, normals and
    shading, the antialiasing passes, filed into the image; the counts, guards and kernel
    time go into the result (its ``seconds`` are the kernels' and the filing's).
    ``on_progress(pixels done, pixels in all)`` is called as each tile is filed.  The images
    are ``store``'s (pipeline/store.py), each row of tiles let go once filed."""
    t_start = time.perf_counter()
    path = plan.path
    if path is not None:   # the centre pass keeps all but the colour, which the path pass makes
        plan = dataclasses.replace(plan, outputs=plan.outputs - {"color"})
    runner = TileRunner(plan, dev)
    _, _, W, H = plan.region
    filing = Filing(plan, store)
    centre = Centre(plan) if plan.passes > 1 and plan.image.adaptive else None
    kernel_events: list = []

    def centre_file(t: Tile, got: dict[str, np.ndarray]) -> None:
        filing.file(t, got)
        if centre is not None:
            centre.note(t, got)

    film = None
    total = W * H * (plan.passes + (path.samples if path is not None else 0))
    with Progress(total, "render", "px", enabled=progress, line=_render_line,
                  unit_scale=True, hook=on_progress) as bar:
        # the centre of each pixel: every output (depth, normal, position come from it)
        run_tiles(runner, plan.tiles, centre_file, kernel_events, bar)
        runner.close()
        if plan.passes > 1:
            antialias_passes(plan, dev, filing, centre, kernel_events, bar)
        if path is not None:
            film = path_pass(dataclasses.replace(plan, path=path), dev, filing.at, kernel_events, bar)
    img = filing.img
    if film is not None:
        img["color"] = np.ascontiguousarray(film.mean[..., :3])
        if "alpha" in img:
            img["alpha"] = np.ascontiguousarray(film.mean[..., 3])
    result = RenderResult(
        color=img.get("color"), alpha=img.get("alpha"), depth=img.get("depth"),
        normal=img.get("normal"), position=img.get("position"), status=img.get("status"),
        samples=img.get("samples"), bracket=img.get("bracket"), unresolved=img.get("unresolved"),
        counts=filing.counts, device_name=dev.name.strip(), kernel_seconds=kernel_seconds(kernel_events),
        lanes=plan.lanes, guards=filing.guards, scene=plan.scene, march_method=plan.march.method)
    if film is not None:
        result.film = film.result()
    result.seconds = time.perf_counter() - t_start
    return result


def antialias_passes(plan: Plan, dev: cl.Device, filing: Filing, centre: Centre | None, kernel_events: list,
                     bar) -> None:
    """image.samples more passes of colour and alpha alone, each through its own stratified
    sample of every pixel (rays.cl sample_offset); colour and alpha become their mean.  With
    ``centre`` (image.adaptive) the samples run over the blocks holding a flagged pixel, and
    the flagged pixels alone take their mean (antialias.py)."""
    S, keep, img = plan.image.samples, plan.outputs, filing.img
    _, _, W, H = plan.region
    IW, IH = plan.image.width, plan.image.height
    cplan = dataclasses.replace(plan, outputs=frozenset({"color", "alpha", "bracket", "unresolved"}))
    tiles, flags = cplan.tiles, None
    if centre is not None:
        ring = tuple(t for box in antialias.ring(plan.region, IW, IH)
                     for t in make_tiles(IW, IH, max(box[2], box[3]), plan.halo, box))
        if ring:
            ring_runner = TileRunner(dataclasses.replace(cplan, tiles=ring), dev)
            run_tiles(ring_runner, ring, centre.note, kernel_events, bar)
            ring_runner.close()
        flags = centre.flags()
        tiles = antialias.block_tiles(flags, plan.region, IW, IH, plan.halo, max(t.n for t in plan.tiles))
        bar.set_total(W * H + sum(t.w * t.h for t in ring) + S * sum(t.w * t.h for t in tiles))
    crunner = TileRunner(dataclasses.replace(cplan, tiles=tiles), dev) if tiles else None
    acc_c = new_zeros((H, W, 3), np.float32) if "color" in keep else None
    acc_a = new_zeros((H, W), np.float32)

    def add(t: Tile, got: dict[str, np.ndarray]) -> None:
        own, dst = t.own(), filing.at(t)
        if acc_c is not None:
            acc_c[dst] += got["rgba"][own][..., :3]
        acc_a[dst] += got["rgba"][own][..., 3]

    for k in range(S if tiles else 0):
        run_tiles(crunner, tiles, add, kernel_events, bar, sample=k, samples=S)
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
    (``run_tiles``): on any device but a CPU."""
    return not dev.type & cl.device_type.CPU


def run_tiles(runner: TileRunner, tiles, file, kernel_events: list, bar, sample: int = 0,
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
