"""Colour maps for shading.coloring: a matplotlib colour map, or the user's own gradient
(shading.gradient: colour stops, as Blender's colour ramp), sampled into a table the shade
kernel interpolates (kernels/shade/shade.cl, -D COLORMAP).  The maps and the stops are sRGB
colours; the kernels shade in linear light and the PNG writer encodes sRGB, so the table
holds their colours converted to linear light: a fully lit hit shows the map's own colour.

The colour value v (in [0, 1]) can be moved and stretched first: v' = color_offset +
color_scale v, then clamped to [0, 1], repeated (v' mod 1) or mirrored (a triangle wave of
period 2), as shading.color_repeat says.  That map is baked into the table, sampled finely
enough for the repeats (TABLE_SIZE entries a period), so the kernels and the float64
executor look it up as they look up a plain map."""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

TABLE_SIZE = 256


def srgb_to_linear(x: np.ndarray) -> np.ndarray:
    """The sRGB transfer function inverted (IEC 61966-2-1)."""
    x = np.asarray(x, np.float64)
    return np.where(x <= 0.04045, x / 12.92, ((x + 0.055) / 1.055) ** 2.4)


def linear_to_srgb(x: np.ndarray) -> np.ndarray:
    """The sRGB transfer function (IEC 61966-2-1), for values in [0, 1]."""
    x = np.clip(np.asarray(x, np.float64), 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)


def levels_u8_reference(x: np.ndarray, srgb: bool = True) -> np.ndarray:
    """8-bit levels of ``x`` as the writers have always made them, one value at a time: x as
    float32, NaN as 0, sRGB-encoded in float64 (``srgb``; else linear), the result as float32
    clipped to [0, 1], times 255, rounded half to even.  ``levels_u8`` gives the same levels
    from tables; this is their definition."""
    x = np.nan_to_num(np.asarray(x, np.float32), nan=0.0)
    if srgb:
        x = linear_to_srgb(x)
    x = np.nan_to_num(np.asarray(x, np.float32), nan=0.0)
    return np.rint(np.clip(x, 0.0, 1.0) * np.float32(255.0)).astype(np.uint8)


# levels_u8's tables: float32 values in [0, 1] taken by their bit patterns (which order them
# as the values), in buckets of 2^SHIFT neighbouring values
U8_SHIFT = 16
ONE_BITS = 0x3F800000    # 1.0f
INF_BITS = 0x7F800000    # +inf; above it NaNs, and from 0x80000000 the sign bit
TABLES_FROM = 1 << 16    # values converted in all, from which levels_u8 builds its tables


@lru_cache(maxsize=None)
def u8_tables() -> tuple[np.ndarray, np.ndarray] | None:
    """levels_u8's tables of the sRGB levels: for each bucket of 2^U8_SHIFT float32 values in
    [0, 1], the level of its first value (uint8) and the bit pattern of the first value in it
    whose level is one more (uint32; 0xFFFFFFFF where the level does not change inside it).
    The level is a non-decreasing function of the value, and its 255 steps lie far enough
    apart that a bucket holds at most one; each step is found by bisection on the bit
    patterns against ``levels_u8_reference``.  None where the bucket starts and ends show
    otherwise (a platform whose power rounds differently): the reference is used then."""
    n = (ONE_BITS >> U8_SHIFT) + 1
    starts = np.arange(n, dtype=np.uint32) << U8_SHIFT
    level = levels_u8_reference(starts.view(np.float32))
    ends = np.minimum(starts + np.uint32((1 << U8_SHIFT) - 1), np.uint32(ONE_BITS))
    last = levels_u8_reference(ends.view(np.float32))
    if np.any(last.astype(int) - level > 1) or np.any(np.diff(level.astype(int)) < 0):
        return None
    thr = np.full(n, 0xFFFFFFFF, np.uint32)
    steps = np.flatnonzero(last > level)           # buckets with a step inside (after their start)
    lo, hi = starts[steps].astype(np.int64), ends[steps].astype(np.int64)   # level(lo) low, level(hi) high
    want = level[steps]
    while np.any(hi - lo > 1):
        mid = (lo + hi) // 2
        up = levels_u8_reference(mid.astype(np.uint32).view(np.float32)) > want
        hi = np.where(up, mid, hi)
        lo = np.where(up, lo, mid)
    thr[steps] = hi.astype(np.uint32)
    level.setflags(write=False)
    thr.setflags(write=False)
    return level, thr


def levels_u8(x: np.ndarray, srgb: bool = True, total: int | None = None) -> np.ndarray:
    """``levels_u8_reference(x, srgb)``, the same levels bit for bit.  sRGB levels come from
    ``u8_tables``: a value's bucket gives its level, plus one where the value is at or past
    the bucket's step; values above 1 (and +inf) take the level of 1, NaNs and values below
    0 (the sign bit set, -0 included) level 0.  A 640x480 image's colour took 1.7 ms instead
    of 9.4 (float64 powers).  Building the tables takes about 1.2 ms, the reference's time for
    some 80,000 values: below TABLES_FROM values (``total``: all the caller will convert,
    default x's), unless they are built already, the reference gives the levels; so do linear
    levels (no power to spare: the reference took 2.1 ms, tables 2.8)."""
    if not srgb or ((np.size(x) if total is None else total) < TABLES_FROM and not u8_tables.cache_info().currsize):
        return levels_u8_reference(x, srgb)
    tables = u8_tables()
    if tables is None:
        return levels_u8_reference(x, srgb)
    level, thr = tables
    a = np.asarray(x, np.float32)
    b = (a if a.flags.c_contiguous else a.copy()).view(np.uint32)   # any shape, 0-d too
    c = np.minimum(b, np.uint32(ONE_BITS))
    k = c >> np.uint32(U8_SHIFT)
    out = level[k]
    out += c >= thr[k]
    out *= b <= np.uint32(INF_BITS)
    return out


def lookup(lut: np.ndarray, values: np.ndarray) -> np.ndarray:
    """(n, 3) linear colours of ``values`` (clipped to [0, 1]) in the table ``lut``, linearly
    interpolated between its entries as the shade kernel does (shade/shade.cl, -D COLORMAP)."""
    x = np.clip(values, 0.0, 1.0) * (len(lut) - 1)
    k = np.minimum(x.astype(int), len(lut) - 2)
    fr = (x - k)[:, None]
    return lut[k, :3] * (1 - fr) + lut[k + 1, :3] * fr


TABLE_MOST = 16384   # entries: 64 periods of TABLE_SIZE


@dataclass(frozen=True)
class ColorSpec:
    """What the colour table is made of: a map's name, or the user's stops ((position, r, g,
    b) sRGB, positions rising from 0 to 1), and the map of the colour value onto them."""
    name: str
    stops: tuple | None = None
    offset: float = 0.0
    scale: float = 1.0
    repeat: str = "clamp"


def spec_of(shading) -> ColorSpec:
    """The ColorSpec of a [shading] (scene.model.Shading)."""
    stops = tuple(tuple(float(x) for x in s) for s in shading.gradient) or None
    return ColorSpec(shading.colormap, stops, float(shading.color_offset), float(shading.color_scale),
                     shading.color_repeat)


def wrap(v: np.ndarray, repeat: str) -> np.ndarray:
    """v onto [0, 1]: clamped, repeated (v mod 1) or mirrored (a triangle wave of period 2)."""
    if repeat == "repeat":
        return np.mod(v, 1.0)
    if repeat == "mirror":
        return 1.0 - np.abs(np.mod(v, 2.0) - 1.0)
    return np.clip(v, 0.0, 1.0)


@lru_cache(maxsize=64)
def table_of(spec: ColorSpec) -> np.ndarray:
    """(n, 4) float32 linear RGB, alpha 1: the colour at evenly spaced colour values v in
    [0, 1] of the map or stops, after the value's map (the module docstring)."""
    periods = 1.0 if spec.repeat == "clamp" else max(1.0, abs(spec.scale))
    n = int(min(TABLE_MOST, max(TABLE_SIZE, TABLE_SIZE * math.ceil(periods))))
    v = wrap(spec.offset + spec.scale * np.linspace(0.0, 1.0, n), spec.repeat)
    if spec.stops is not None:
        st = np.asarray(spec.stops, np.float64)
        srgb = np.stack([np.interp(v, st[:, 0], st[:, k]) for k in (1, 2, 3)], axis=1)
    else:
        import matplotlib

        srgb = np.asarray(matplotlib.colormaps[spec.name](v), np.float64)[:, :3]
    rgba = np.ones((n, 4))
    rgba[:, :3] = srgb_to_linear(np.clip(srgb, 0.0, 1.0))
    out = np.ascontiguousarray(rgba, np.float32)
    out.setflags(write=False)
    return out


@lru_cache(maxsize=None)
def table(name: str, n: int = TABLE_SIZE) -> np.ndarray:
    """(n, 4) float32: the colour map ``name`` at n evenly spaced values, linear RGB, alpha 1."""
    import matplotlib

    rgba = np.asarray(matplotlib.colormaps[name](np.linspace(0.0, 1.0, n)), np.float64)
    rgba[:, :3] = srgb_to_linear(rgba[:, :3])
    rgba[:, 3] = 1.0
    out = np.ascontiguousarray(rgba, np.float32)
    out.setflags(write=False)
    return out
