"""Render a scene on an OpenCL device: check the arguments, plan (pipeline/plan.py, with the
steps that need the device: the packet width, the camera's framing pass, the time probe),
then execute the plan's passes over its tiles (opencl/passes.py).

Every per-pixel step is an OpenCL kernel (the march makes its own rays); Python only
enqueues tiles and files the outputs the plan keeps from their mapped buffers.
``reference.render`` is the float64 numpy twin of this module's ``render``.
"""
from __future__ import annotations

import dataclasses
import time
import warnings
from typing import Callable

import pyopencl as cl

from pyjulia4d.fractal.registry import march_method
from pyjulia4d.opencl.devices import (DeviceError, check_device, device_key, device_of, device_type, has_fp64,
                                      select_device)
from pyjulia4d.opencl.failures import DeviceFailure, on_device
from pyjulia4d.opencl.lanes import lanes_for, march_lanes, packet_pairs
from pyjulia4d.opencl.passes import kernel_seconds, run_plan, run_tiles
from pyjulia4d.pipeline.backdrop import check_backdrop
from pyjulia4d.pipeline.environment import check_environment
from pyjulia4d.pipeline.film import check_denoiser, finish
from pyjulia4d.opencl.runner import TileRunner, local_size, march_items
from pyjulia4d.pipeline import workload
from pyjulia4d.pipeline.calibrate import Prediction, judge, predict, tile_side, wanted
from pyjulia4d.pipeline.framing import fit_camera
from pyjulia4d.pipeline.plan import TILE, Plan, RenderArgs, check_arguments, check_flag, check_lanes, plan_from
from pyjulia4d.pipeline.progress import silent
from pyjulia4d.pipeline.result import RenderResult
from pyjulia4d.pipeline.store import IN_MEMORY, ImageStore
from pyjulia4d.pipeline.workload import resolve_outputs
from pyjulia4d.scene.checks import SceneError
from pyjulia4d.scene.model import Scene

__all__ = ["render", "plan_render", "run_plan"]


def render(scene: Scene, device: cl.Device | str | None = None, progress: bool = False,
           force: bool = False, tile: int = TILE, lanes: int | None = None,
           outputs=None, region=None, calibrate: bool = True,
           on_progress: Callable[[int, int], None] | None = None, store: ImageStore = IN_MEMORY,
           first_sample: int = 0, fallback: bool | None = None) -> RenderResult:
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
    file for images larger than memory should hold).  ``first_sample``: a path-traced render's
    paths are its samples from this index on (0 to plan.MAX_FIRST_SAMPLE): a later batch of the
    same picture, which film.merge joins to the earlier (the explorer's progressive refinement).
    ``fallback`` (default: where ``device`` is None): a device that fails (opencl/failures.py)
    hands the render to the next device that works, and ``result.fell_back`` says which
    failed and how; otherwise its failure is raised, one DeviceFailure line."""
    t_start = time.perf_counter()
    args = check_arguments(scene, outputs, force, tile, region, first_sample)
    check_device(device)
    for name, value in (("progress", progress), ("calibrate", calibrate)):
        check_flag(name, value)
    if on_progress is not None and not callable(on_progress):
        raise SceneError("on_progress", f"expected None or a callable, got {type(on_progress).__name__}")
    if lanes is not None:
        check_lanes(lanes)
    if not isinstance(store, ImageStore):
        raise SceneError("store", f"expected a pyjulia4d.pipeline.store.ImageStore, got {type(store).__name__}")
    check_denoiser(scene)
    check_environment(scene)
    if args.region is None:
        check_backdrop(scene)
    if fallback is not None:
        check_flag("fallback", fallback)
    dev = device_of(device)
    failed: list[DeviceFailure] = []
    while True:
        try:
            with on_device(dev):
                plan, prediction = plan_render(scene, dev, args, lanes, calibrate)
                result = run_plan(plan, dev, progress, on_progress, store)
            break
        except DeviceFailure as e:
            if not (device is None if fallback is None else fallback):
                raise
            failed.append(e)
            try:   # the next device that works takes over (failures.py)
                dev = select_device(None, skip=frozenset(device_key(f.device) for f in failed))
            except DeviceError:
                raise failed[0] from None
    result.fell_back = "; ".join(f"{f}" for f in failed)
    result.prediction = prediction
    if args.region is None:   # a whole picture: post-processed once (a cluster's tiles, once joined)
        finish(result, result.scene or scene)
    result.seconds = time.perf_counter() - t_start
    return result


def resolve_float(scene: Scene, dev: cl.Device) -> Scene:
    """``scene`` with render.float "auto" replaced by what runs on ``dev``: the set's choice
    (Scene.precision, quality.auto_precision) on a CPU with fp64, else "single" (a GPU's double
    rate is a fraction of its single; a device without fp64 has none)."""
    if scene.render.float != "auto":
        return scene
    chosen = scene.precision if device_type(dev) == "CPU" and has_fp64(dev) else "single"
    return scene.replace(**{"render.float": chosen})


def plan_render(scene: Scene, dev: cl.Device, args: RenderArgs, lanes: int | None = None,
                calibrate: bool = True) -> tuple[Plan, Prediction | None]:
    """Planning, the steps before the render's tiles, for arguments already checked
    (plan.check_arguments): refuse a double-precision scene on a device without fp64; the
    packet width (lanes.py); refuse hopeless work (workload.check); with camera.fit, place the
    camera from a first pass (framing.py: the plan of a small probe image, run by run_plan);
    the plan (pipeline/plan.py), made once; and, with ``calibrate``, the time predicted from a
    probe of the plan's own kernels (calibrate.py: refuse, warn, retile).  Returns the plan
    and the prediction (None where none was made).  render.float "auto" is resolved for the
    device first (resolve_float), so the plan and the result state the precision that ran."""
    scene = resolve_float(scene, dev)
    double = scene.precision == "double"
    if double and not has_fp64(dev):   # before any kernel is built, the framing pass's included
        raise SceneError("render.float", f"device '{dev.name.strip()}' has no cl_khr_fp64 (double precision); use \"single\"")
    if lanes is None:
        lanes = march_lanes(lanes_for(dev, scene.render.variant, double), march_method(scene), dev)
    pairs = packet_pairs(dev, lanes, double)
    estimate = None
    if scene.camera.fit:   # framing.py: a quick first pass places the camera
        with warnings.catch_warnings():   # refuse before any pass runs; warn after it
            warnings.simplefilter("ignore")
            estimate = workload.check(scene, dev, force=args.force, outputs=args.outputs)

            def first_pass(s: Scene, outs) -> RenderResult:
                probe = RenderArgs(resolve_outputs(outs), force=True)
                return run_plan(plan_from(s, dev, lanes, probe, pairs), dev)

            scene, _ = fit_camera(scene, first_pass)
        workload.check_numerics(scene)   # its warnings, for the camera chosen
    plan = plan_from(scene, dev, lanes, args, pairs, estimate)
    prediction = None
    if calibrate and wanted(plan.estimate.seconds):
        def run_probe(tiles) -> float:
            """The probe's kernel seconds, divided by the compute units a tile of the render
            keeps busy: each probe block is one work-group, run by one of them."""
            events: list = []
            probe = TileRunner(dataclasses.replace(plan, tiles=tiles), dev)
            run_tiles(probe, tiles, lambda t, got: None, events, silent())
            probe.close()
            big = max(plan.tiles, key=lambda t: t.n)
            groups = -(-march_items(big.n, big.aw, plan.lanes, plan.march_packets) // local_size(probe.march_k, dev))
            return kernel_seconds(events) / max(1, min(dev.max_compute_units, groups))

        prediction = predict(plan, run_probe)
        judge(plan, prediction, args.force)
        side = tile_side(prediction, args.tile)
        if side < args.tile:
            plan = plan.retile(side)
    return plan, prediction


