"""How long a render will take, from a quick probe render of the scene itself, and tiles
sized by it.

workload.estimate bounds the work from above (every ray to its step cap); for the
distance-estimate march the bound is 50-100x the truth, and for the fixed scan it
ignores where the rays stop.  So before the render proper, ``predict`` runs the render's own
kernels on about PROBE_RAYS of its pixels (blocks spread evenly over the image) and
scales their kernel time per pixel to the image and its passes.  Measured on the development machine
(tests/render/test_calibrate.py, README "Performance"): within a factor of 2 of the kernel time
of the render proper on scenes of every method.  The prediction then

- refuses above REFUSE_SECONDS and warns above WARN_SECONDS (``judge``), naming the key
  that dominates the work (workload.estimate) and saying the prediction came from a probe;
- sizes the tiles so that one takes about TILE_SECONDS (``tile_side``): work is queued a
  tile at a time, so Ctrl-C is honoured within a tile or two, and the progress moves.

Renders whose upper bound is below SKIP_BELOW_SECONDS (and WARN_SECONDS) are not probed
(``wanted``).
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

from pyjulia4d.pipeline.plan import Plan
from pyjulia4d.pipeline.workload import PROBE_RAYS, WorkloadError

WARN_SECONDS = 60.0            # say how long, when it is longer than this
REFUSE_SECONDS = 6 * 3600.0    # refuse (unless forced) when it is longer than this
# No probe where even the upper bound (workload.estimate) is shorter than this and than
# WARN_SECONDS: there is nothing to refuse or warn about, and the default tiles stay.  The
# probe's 35 launches of 8x8 blocks cost 0.19 of a 640x480 render's 0.49 CPU-s on Intel's
# runtime (0.09 of 0.57 on PoCL; benchmarks/peers/peers.py's plain look); that render's bound is
# 12 s, its truth 0.1 s, so Ctrl-C, honoured between tiles, still comes within a tile.
SKIP_BELOW_SECONDS = 20.0
TILE_SECONDS = 0.1             # the work of one tile: the latency of Ctrl-C
MIN_TILE = 16


def wanted(bound_seconds: float) -> bool:
    """Whether a render whose work is bounded by ``bound_seconds`` needs the probe."""
    return bound_seconds > min(SKIP_BELOW_SECONDS, WARN_SECONDS)


@dataclass(frozen=True)
class Prediction:
    seconds: float             # predicted kernel seconds of the render (all its passes)
    seconds_per_pixel: float   # per pixel and pass, from the probe
    probe_pixels: int
    probe_seconds: float       # the probe's kernel seconds

    def describe(self) -> str:
        return (f"predicted from a probe render of {self.probe_pixels} of its pixels in "
                f"{self.probe_seconds * 1e3:.0f} ms")


PROBE_BOX = 8   # the probe's blocks of pixels: whole packets of rays (common/lanes.cl), as the render has them


def probe_tiles(plan: Plan) -> tuple:
    """About PROBE_RAYS pixels of the plan's region in PROBE_BOX x PROBE_BOX blocks on an even
    grid: full-resolution pixels, so that a packet of rays diverges as much as in the
    render proper (a scaled-down image over-predicted 2-4x: its neighbouring rays are
    further apart)."""
    from pyjulia4d.pipeline.plan import make_tiles
    x0, y0, w, h = plan.region
    W, H = plan.image.width, plan.image.height
    b = PROBE_BOX
    n = max(1, PROBE_RAYS // (b * b))
    nx = max(1, min(-(-w // b), round(math.sqrt(n * w / h))))
    ny = max(1, min(-(-h // b), round(n / nx)))
    tiles = []
    for j in range(ny):
        for i in range(nx):
            bx = x0 + min(max(0, w - b), (2 * i + 1) * w // (2 * nx) - b // 2)
            by = y0 + min(max(0, h - b), (2 * j + 1) * h // (2 * ny) - b // 2)
            bx, by = max(x0, bx), max(y0, by)
            tiles += make_tiles(W, H, b, plan.halo, (bx, by, min(b, x0 + w - bx), min(b, y0 + h - by)))
    return tuple(tiles)


def predict(plan: Plan, run_tiles) -> Prediction:
    """The probe: ``run_tiles(tiles)`` runs the plan's kernels over the tiles (opencl/passes.py) and
    returns their kernel seconds; scaled to the region's pixels and the rays each takes (its
    passes; a path-traced render's paths, at most: Plan.rays_per_pixel)."""
    tiles = probe_tiles(plan)
    pixels = sum(t.w * t.h for t in tiles)
    seconds = run_tiles(tiles)
    spp = seconds / pixels
    _, _, w, h = plan.region
    return Prediction(spp * w * h * plan.rays_per_pixel, spp, pixels, seconds)


def _duration(seconds: float) -> str:
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 7200:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


def judge(plan: Plan, pred: Prediction, force: bool) -> None:
    """Refuse a render predicted above REFUSE_SECONDS (unless ``force``); warn above WARN_SECONDS."""
    key, value = plan.estimate.dominant, plan.estimate.value
    text = f"about {_duration(pred.seconds)} on this device ({pred.describe()})"
    if pred.seconds > REFUSE_SECONDS and not force:
        raise WorkloadError(key, f"{value} would take {text}, over the limit of "
                                 f"{REFUSE_SECONDS / 3600:g} h; lower {key}, or force it "
                                 f"(--force; render(..., force=True))")
    if pred.seconds > WARN_SECONDS:
        warnings.warn(f"{key}: {value}: this render will take {text}", RuntimeWarning, stacklevel=3)


def tile_side(pred: Prediction, most: int) -> int:
    """The side of square tiles of about TILE_SECONDS each, in [MIN_TILE, most], a multiple
    of MIN_TILE (whole packets of rays)."""
    if pred.seconds_per_pixel <= 0:
        return most
    side = math.sqrt(TILE_SECONDS / pred.seconds_per_pixel)
    return int(max(MIN_TILE, min(most, side // MIN_TILE * MIN_TILE)))
