"""Twin of pipeline/antialias.py's edge flags (image.adaptive)."""
from __future__ import annotations

import numpy as np

from pyjulia4d.pipeline import colormap


def flag_edges(color, alpha, threshold: float):
    """Twin of antialias.flag_edges, written apart: (H, W) bool, True where some pixel of the
    3 x 3 neighbourhood (clipped to the image) differs from the centre by more than
    ``threshold`` in alpha or in a channel of the sRGB-encoded colour."""
    v = np.concatenate([colormap.linear_to_srgb(np.nan_to_num(np.asarray(color, np.float64))),
                        np.nan_to_num(np.asarray(alpha, np.float64))[..., None]], axis=-1)
    h, w = v.shape[:2]
    p = np.pad(v, ((1, 1), (1, 1), (0, 0)), mode="edge")   # an edge copy never differs
    out = np.zeros((h, w), bool)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            out |= np.abs(p[1 + dy:1 + dy + h, 1 + dx:1 + dx + w] - v).max(axis=-1) > threshold
    return out
