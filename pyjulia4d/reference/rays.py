"""Twin of kernels/rays.cl: the camera rays of each pixel and its stratified samples."""
from __future__ import annotations

import numpy as np

from pyjulia4d.geometry.camera import Frame

def sample_hash(x, y, s):
    """rays.cl sample_hash on uint32 arrays."""
    M = 0xFFFFFFFF
    x, y, s = (np.asarray(a, np.uint64) for a in (x, y, s))
    h = ((x * 73856093) & M) ^ ((y * 19349663) & M) ^ ((s * 83492791) & M)
    h = (h ^ 61) ^ (h >> 16)
    h = (h * 9) & M
    h ^= h >> 4
    h = (h * 0x27D4EB2D) & M
    h ^= h >> 15
    return h


def sample_offset(x, y, k: int, n: int):
    """Sample k of n in each pixel (rays.cl sample_offset): (ox, oy) in [0, 1)^2."""
    if n <= 1:
        return np.full(np.shape(x), 0.5), np.full(np.shape(x), 0.5)
    g = int(np.ceil(np.sqrt(np.float32(n))))
    h1 = sample_hash(x, y, 2 * k)
    h2 = sample_hash(x, y, 2 * k + 1)
    return ((k % g + (h1 >> 8).astype(np.float64) / 16777216.0) / g,
            (k // g + (h2 >> 8).astype(np.float64) / 16777216.0) / g)


def generate_rays(frame: Frame, width: int, height: int, x0: int = 0, y0: int = 0,
                  tile_w: int | None = None, tile_h: int | None = None, sample: int = 0, samples: int = 1):
    """Pinhole 4D camera (Ödegaard & Wennergren §4): returns (origins, dirs), row-major, row 0 on top,
    for the tile of tile_w x tile_h pixels at (x0, y0) (default: the whole image), through
    sample ``sample`` of ``samples`` of each pixel (its centre for one)."""
    tw = width - x0 if tile_w is None else tile_w
    th = height - y0 if tile_h is None else tile_h
    y, x = np.mgrid[y0:y0 + th, x0:x0 + tw]
    ox, oy = sample_offset(x.ravel(), y.ravel(), sample, samples)
    aspect = width / height
    u = (2 * (x.ravel() + ox) / width - 1) * frame.tan_half_fov * aspect
    v = (1 - 2 * (y.ravel() + oy) / height) * frame.tan_half_fov
    d = frame.forward + u[:, None] * frame.right + v[:, None] * frame.up
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return np.tile(frame.position, (tw * th, 1)), d
