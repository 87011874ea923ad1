"""Twin of kernels/march/cone.cl: where the camera rays of each CONE_BLOCK x CONE_BLOCK block
of pixels may start the distance-estimate march - the block's centre ray marched with the
estimate while its balls hold the cone of the block's rays (radius k t, k = CONE_SPREAD
pixel widths of the image plane at distance 1); see that file for why each step is safe."""
from __future__ import annotations

import numpy as np

from pyjulia4d.geometry.camera import Frame
from pyjulia4d.pipeline.plan import CONE_BLOCK, MarchArgs, cone_blocks
from pyjulia4d.reference.formula import QUATERNION_SQR, Formula
from pyjulia4d.reference.iterate import julia_distance_formula
from pyjulia4d.reference.march import ball_span

CONE_SPREAD = 2.8285   # 2 sqrt(2), rounded up (march/cone.cl)


def centre_rays(frame: Frame, width: int, height: int, region: tuple[int, int, int, int] | None = None
                ) -> tuple[np.ndarray, np.ndarray, float]:
    """The centre rays (origins, unit directions) of the CONE_BLOCK x CONE_BLOCK blocks that the
    pixels of ``region`` (default: the image) meet, row-major, and k: every ray of a block
    passes within k t of its centre ray's point at t (march/cone.cl cone_dirs, CONE_SPREAD)."""
    x0, y0, w, h = region or (0, 0, width, height)
    bx0, by0, bw, bh = cone_blocks(x0, y0, w, h)
    by, bx = (a.ravel() for a in np.mgrid[by0:by0 + bh, bx0:bx0 + bw])
    u = (2 * (CONE_BLOCK * bx + CONE_BLOCK / 2) / width - 1) * frame.tan_half_fov * (width / height)
    v = (1 - 2 * (CONE_BLOCK * by + CONE_BLOCK / 2) / height) * frame.tan_half_fov
    d = frame.forward + u[:, None] * frame.right + v[:, None] * frame.up
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    o = np.tile(np.asarray(frame.position, np.float64), (len(d), 1))
    return o, d, CONE_SPREAD * 2 * frame.tan_half_fov / height


def cone_starts(frame: Frame, width: int, height: int, args: MarchArgs, formula: Formula = QUATERNION_SQR,
                region: tuple[int, int, int, int] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """march/cone.cl with the march's record (``args``: pipeline/plan.MarchArgs): (t_lo,
    t_last) of the blocks that the pixels of ``region`` = (x0, y0, w, h) (default: the image)
    meet, row-major: the cone is covered from t_lo, and t_last is the last centre point whose
    ball held it (-1: none did)."""
    c, max_iter, bailout, max_steps = args.c, args.max_iter, args.bailout, args.max_steps
    o, d, k = centre_rays(frame, width, height, region)
    t, far, meets = ball_span(o, d, args.radius, args.near, args.far)
    active = meets & (far >= t)
    t_lo, t_last = np.full(len(d), np.inf), np.full(len(d), -1.0)
    for i in range(max_steps):
        if not active.any():
            break
        dist, escaped = julia_distance_formula(o + t[:, None] * d, c, max_iter, bailout, formula)
        r = k * t
        held = active & escaped & (dist > 2 * r)
        if i == 0:
            t_lo = np.where(held, t - (dist - r), t_lo)
        t_last = np.where(held, t, t_last)
        t = np.where(held, (t + dist) / (1 + k), t)
        active = held & (t <= far)
    return t_lo, t_last


def cone_of_pixels(cone: tuple[np.ndarray, np.ndarray], region: tuple[int, int, int, int]
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Each pixel of ``region`` = (x0, y0, w, h), row-major, given its block's (t_lo, t_last)
    from cone_starts over the same region (march/march.cl CONE_AT)."""
    x0, y0, w, h = region
    bx0, by0, bw, _ = cone_blocks(x0, y0, w, h)
    y, x = np.mgrid[y0:y0 + h, x0:x0 + w]
    idx = ((y // CONE_BLOCK - by0) * bw + x // CONE_BLOCK - bx0).ravel()
    return cone[0][idx], cone[1][idx]
