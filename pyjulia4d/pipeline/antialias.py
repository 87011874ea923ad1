"""Adaptive antialiasing (image.adaptive = true with image.samples = N > 1): the N sample
passes run only where the centre pass shows an edge.

The rule (reference.flag_edges is its float64 twin, tests/render/test_antialias.py checks both):

- a pixel is *flagged* when one of its 8 neighbours differs from it in alpha (hit/miss or
  partial cover) or in any colour channel by more than THRESHOLD, colour compared
  sRGB-encoded - the values a PNG stores (output.write_png) and a viewer shows, so that a
  step is judged alike in the darks and the lights (a linear step of 1/64 is 33 of 255
  sRGB codes up from black and under 2 near white).  8 neighbours, not 4: a fractal's
  silhouette has corners and filaments that run diagonally between pixel centres, which a
  diagonal neighbour sees first; the extra cost is a one-pixel ring (benchmarks/accuracy/antialias_error.py
  measures the flagged share);
- the sample passes run over the BLOCK x BLOCK blocks of the image that hold a flagged
  pixel (a row's consecutive blocks merged into one tile: fewer launches);
- a flagged pixel takes the mean of its N samples, every other pixel keeps its centre
  sample.  Per pixel, not per block: the image does not depend on the block grid, so no
  block seams, and where every pixel is flagged it equals the uniform supersampled image
  bit for bit (the samples are summed in the same order).
"""
from __future__ import annotations

import numpy as np

from pyjulia4d.pipeline.plan import Tile, make_tiles

THRESHOLD = 1.0 / 64.0   # largest sRGB-encoded (or alpha) step between neighbours left alone
# Side of the blocks the sample passes run over.  Larger blocks run more unflagged pixels
# but in fewer launches, and the launches cost more: on PoCL (2 cores) the default scene
# with image.samples = 4 took 1.82 / 1.61 / 1.44 kernel seconds at 1280x960 and 0.18 /
# 0.15 / 0.14 at 320x240 with blocks of 8 / 16 / 32 (render().kernel_seconds, medians of
# 2 and 5 renders, 2026-11-25); uniform passes took 1.53 and 0.12 s.
BLOCK = 32


def _srgb32(x: np.ndarray) -> np.ndarray:
    """colormap.linear_to_srgb (IEC 61966-2-1) in float32: a megapixel in a fraction of
    its time (flags a step of the threshold alike to ~1e-7)."""
    x = np.clip(np.asarray(x, np.float32), np.float32(0), np.float32(1))
    lo = x <= np.float32(0.0031308)
    out = np.power(x, np.float32(1 / 2.4), dtype=np.float32)
    out *= np.float32(1.055)
    out -= np.float32(0.055)
    out[lo] = x[lo] * np.float32(12.92)
    return out


def flag_edges(color: np.ndarray | None, alpha: np.ndarray, threshold: float | None = None) -> np.ndarray:
    """(H, W) bool: the pixels one of whose 8 neighbours differs from them by more than
    ``threshold`` (default THRESHOLD) in alpha or in a channel of the sRGB-encoded ``color``
    (linear light, (H, W, 3); None: alpha alone)."""
    t = THRESHOLD if threshold is None else threshold
    h, w = np.shape(alpha)
    v = np.empty((h, w, 4 if color is not None else 1), np.float32)
    v[..., -1] = np.nan_to_num(alpha, nan=0.0)
    if color is not None:
        v[..., :3] = _srgb32(np.nan_to_num(color, nan=0.0))
    out = np.zeros(v.shape[:2], bool)
    # each unordered pair of neighbours once (right, down, down-right, down-left); a pair
    # that differs flags both its pixels
    for a, b in (((slice(None), slice(0, -1)), (slice(None), slice(1, None))),
                 ((slice(0, -1), slice(None)), (slice(1, None), slice(None))),
                 ((slice(0, -1), slice(0, -1)), (slice(1, None), slice(1, None))),
                 ((slice(0, -1), slice(1, None)), (slice(1, None), slice(0, -1)))):
        d = np.abs(v[a] - v[b]).max(axis=-1) > t
        out[a] |= d
        out[b] |= d
    return out


def block_tiles(flags: np.ndarray, region: tuple[int, int, int, int], width: int, height: int,
                halo: int, most: int) -> tuple[Tile, ...]:
    """The tiles the sample passes run over: the BLOCK x BLOCK blocks of ``region`` (x0, y0,
    w, h; ``flags`` covers it) holding a flagged pixel, consecutive blocks of a row merged
    into one tile whose box (with its ``halo``, plan.make_tiles) holds at most ``most``
    pixels (a lone block's box may hold more)."""
    x0, y0, w, h = region
    b = BLOCK
    ny, nx = -(-h // b), -(-w // b)
    pad = np.zeros((ny * b, nx * b), bool)
    pad[:h, :w] = flags
    hot = pad.reshape(ny, b, nx, b).any(axis=(1, 3))
    tiles: list[Tile] = []

    def tile(i: int, k: int) -> Tile:   # blocks i..k of the row j, as one tile with its halo
        bx, by, bh = x0 + i * b, y0 + j * b, min(b, h - j * b)
        bw = min((k + 1) * b, w) - i * b
        return make_tiles(width, height, max(bw, bh), halo, (bx, by, bw, bh))[0]

    for j in range(ny):
        i = 0
        while i < nx:
            if not hot[j, i]:
                i += 1
                continue
            k = i
            while k + 1 < nx and hot[j, k + 1] and tile(i, k + 1).n <= most:
                k += 1
            tiles.append(tile(i, k))
            i = k + 1
    return tuple(tiles)


def ring(region: tuple[int, int, int, int], width: int, height: int) -> tuple[tuple[int, int, int, int], ...]:
    """The boxes (x0, y0, w, h) of the one-pixel ring around ``region`` inside the image: a
    region's border pixels are flagged by neighbours outside it, so a region renders as the
    same pixels of the whole image (the distributed renderer's unit)."""
    x0, y0, w, h = region
    ex0, ey0, ex1, ey1 = max(0, x0 - 1), max(0, y0 - 1), min(width, x0 + w + 1), min(height, y0 + h + 1)
    boxes = []
    if ey0 < y0:
        boxes.append((ex0, ey0, ex1 - ex0, 1))
    if ey1 > y0 + h:
        boxes.append((ex0, y0 + h, ex1 - ex0, 1))
    if ex0 < x0:
        boxes.append((ex0, y0, 1, h))
    if ex1 > x0 + w:
        boxes.append((x0 + w, y0, 1, h))
    return tuple(boxes)
