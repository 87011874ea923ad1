"""Linear light to the display's (image.exposure, image.tonemap): applied once to the whole
picture as PNG, TIFF and video frames are written (app/output.py), never to an EXR,
which keeps the scene's own values.  Returns display-linear values in [0, 1]; the writers
encode them with the sRGB transfer function as they do every picture.

- "clamp": the values as they are (the writers cut at 1): the direct integrator's look.
- "aces": the ACES 1.0 SDR video output transform for an sRGB display, from OpenColorIO's
  built-in ACES config (Academy Color Encoding System; OpenColorIO 2.2's
  "cg-config-v2.2.0_aces-v1.3_ocio-v2.4"), from linear Rec. 709.
- "agx": Sobotka's AgX (2023; the Blender 4.0 default view): a 3x3 inset towards the
  achromatic axis, a log2 encoding over [-12.47, 4.03] stops about middle grey 0.18, a
  sigmoid, the inset's inverse, then the 2.2 power its sigmoid was fitted for.  The sigmoid
  is Wrensch's polynomial fit ("Minimal AgX Implementation", 2023), within 0.005 of the
  original's lookup table.
"""
from __future__ import annotations

import functools

import numpy as np

ACES_CONFIG = "cg-config-v2.2.0_aces-v1.3_ocio-v2.4"

# AgX's inset and outset (Wrensch 2023; rows: the output channels' weights of r, g, b)
AGX_INSET = np.array([[0.842479062253094, 0.0784335999999992, 0.0792237451477643],
                      [0.0423282422610123, 0.878468636469772, 0.0791661274605434],
                      [0.0423756549057051, 0.0784336, 0.879142973793104]])
AGX_OUTSET = np.array([[1.19687900512017, -0.0980208811401368, -0.0990297440797205],
                       [-0.0528968517574562, 1.15190312990417, -0.0989611768448433],
                       [-0.0529716355144438, -0.0980434501171241, 1.15107367264116]])
AGX_MIN_EV, AGX_MAX_EV = -12.47393, 4.026069


def agx(x: np.ndarray) -> np.ndarray:
    """AgX of linear Rec. 709 (..., 3): display-linear values in [0, 1]."""
    v = np.maximum(np.asarray(x, np.float64) @ AGX_INSET.T, 1e-10)
    v = (np.clip(np.log2(v), AGX_MIN_EV, AGX_MAX_EV) - AGX_MIN_EV) / (AGX_MAX_EV - AGX_MIN_EV)
    v2 = v * v
    v4 = v2 * v2
    s = (15.5 * v4 * v2 - 40.14 * v4 * v + 31.96 * v4 - 6.868 * v2 * v + 0.4298 * v2 + 0.1191 * v - 0.00232)
    return np.clip(np.clip(s, 0.0, 1.0) @ AGX_OUTSET.T, 0.0, 1.0) ** 2.2


@functools.lru_cache(maxsize=1)
def _aces_processor():
    import PyOpenColorIO as ocio

    cfg = ocio.Config.CreateFromBuiltinConfig(ACES_CONFIG)
    proc = cfg.getProcessor("Linear Rec.709 (sRGB)", "sRGB - Display", "ACES 1.0 - SDR Video",
                            ocio.TRANSFORM_DIR_FORWARD)
    return proc.getDefaultCPUProcessor()


def aces(x: np.ndarray) -> np.ndarray:
    """The ACES 1.0 SDR video transform of linear Rec. 709 (..., 3), through OpenColorIO:
    display-linear values in [0, 1] (its sRGB-encoded output decoded)."""
    from pyjulia4d.pipeline.colormap import srgb_to_linear

    rgb = np.ascontiguousarray(np.nan_to_num(np.asarray(x, np.float32), nan=0.0, posinf=65504.0))
    _aces_processor().applyRGB(rgb)
    return srgb_to_linear(np.clip(rgb, 0.0, 1.0))


def display(color: np.ndarray, exposure: float = 0.0, tonemap: str = "clamp") -> np.ndarray:
    """``color`` (H, W, 3), linear light, times 2^exposure through the tone map: what the
    writers encode.  The default (0, "clamp") gives ``color`` itself."""
    if exposure == 0 and tonemap == "clamp":
        return color
    x = np.asarray(color, np.float32) * np.float32(2.0 ** exposure)
    if tonemap == "agx":
        return agx(x).astype(np.float32)
    if tonemap == "aces":
        return aces(x).astype(np.float32)
    return x
