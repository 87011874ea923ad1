"""Colour maps for shading.coloring: a matplotlib colour map sampled into a table the shade
kernel interpolates (kernels/shade/shade.cl, -D COLORMAP).  matplotlib's maps are sRGB
colours; the kernels shade in linear light and the PNG writer encodes sRGB, so the table
holds the maps' colours converted to linear light: a fully lit hit shows the map's own
colour."""
from __future__ import annotations

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


def lookup(lut: np.ndarray, values: np.ndarray) -> np.ndarray:
    """(n, 3) linear colours of ``values`` (clipped to [0, 1]) in the table ``lut``, linearly
    interpolated between its entries as the shade kernel does (shade/shade.cl, -D COLORMAP)."""
    x = np.clip(values, 0.0, 1.0) * (len(lut) - 1)
    k = np.minimum(x.astype(int), len(lut) - 2)
    fr = (x - k)[:, None]
    return lut[k, :3] * (1 - fr) + lut[k + 1, :3] * fr


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
