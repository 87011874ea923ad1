"""The path tracer's environment (shading.environment): an equirectangular image of the
light that comes from every direction, read once per render, and the distribution its
light is sampled from.

The image's column u = (x + 0.5) / W and row v = (y + 0.5) / H see the scene direction
    (sin(theta) sin(phi), cos(theta), -sin(theta) cos(phi)),  phi = 2 pi u - pi,  theta = pi v:
+y is up, the middle column looks along -z (towards the default camera), as Blender's and
Mandelbulber2's spherical maps are laid out.  Directions are the scene's: the 4D ray's
direction turned back by the slice's rotation (camera.to_world), so the environment stays
fixed as the camera moves.

Sampling (Pharr, Jakob & Humphreys, "Physically Based Rendering", 4th ed., 2023, §12.5.2,
piecewise-constant 2D distributions): a texel is drawn with probability proportional to its
luminance times sin(theta) (its solid angle), by the marginal distribution of rows and the
conditional one of columns within the row, then a uniform point in it; the density of a
direction in a texel of probability p is p W H / (2 pi^2 sin(theta)).  The kernels
(kernels/path/environment.cl) and the twin (reference/path_environment.py) look texels up
nearest, so a texel's radiance is constant over it, as its density is.
"""
from __future__ import annotations

import functools
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pyjulia4d.resources import data_dir
from pyjulia4d.scene.checks import SceneError

SHIPPED = {"sky": "sky.exr"}   # the words shading.environment takes for the packaged images
MAX_SIDE = 16384               # pixels: an 8k map is 400 MB of float32 RGBA already
LUMA = np.array([0.2126, 0.7152, 0.0722])
# The brightest pixel a map may hold.  A path's light is the map's times shading.ambient and
# shading.sky (each at most 1e3), and a pixel's film keeps the sum of its squared deviations in
# float32 (Welford's M2, up to 65536 paths): under 1e9 that stays below 1e35, where float32
# ends at 3.4e38; a map of 1e20 made it infinite and the stated noise 0.  An unclipped sun
# in a photographed sky reaches about 1e5.
MAX_RADIANCE = 1e9


@dataclass(frozen=True)
class Environment:
    """An environment image (H, W, 4 float32, alpha 0) and its sampling distribution:
    ``marginal`` (H + 1,) the cumulative probability of the rows, ``conditional`` (H, W + 1)
    each row's cumulative probability of its columns, both float64 from 0 to 1."""
    image: np.ndarray
    marginal: np.ndarray
    conditional: np.ndarray
    name: str
    mean: float = 1.0   # the mean luminance over the sphere (each texel by its solid angle)

    @property
    def width(self) -> int:
        return self.image.shape[1]

    @property
    def height(self) -> int:
        return self.image.shape[0]


def path_of(value: str) -> Path:
    """The file shading.environment names: a packaged image's word, or a path."""
    return data_dir() / SHIPPED[value] if value in SHIPPED else Path(value).expanduser()


def load(value: str) -> Environment:
    """The environment ``value`` names (shading.environment other than "uniform"), read and
    checked; a SceneError naming the key where the file is missing, unreadable, not an
    image, not 2:1 or holds values that are not light (negative, NaN, inf) or above MAX_RADIANCE."""
    p = path_of(value)
    try:
        st = os.stat(p)
    except OSError as e:
        raise SceneError("shading.environment", f"{value}: cannot read it: {e.strerror or e}") from None
    return _load(str(p), st.st_size, st.st_mtime_ns, value)


def check_environment(scene) -> None:
    """The map a scene names in shading.environment read and checked before any render, whatever
    its integrator (only the path tracer's light comes from it): a file named that cannot be
    used is one SceneError, as a backdrop image's is, not a scene that renders until its
    integrator changes.  The words ("uniform" and the packaged images') need no reading."""
    value = scene.shading.environment
    if value != "uniform" and value not in SHIPPED:
        load(value)


@functools.lru_cache(maxsize=4)
def _load(path: str, size: int, mtime: int, value: str) -> Environment:
    import OpenImageIO as oiio

    key = "shading.environment"
    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise SceneError(key, f"{value}: not an image OpenImageIO can read ({' '.join(oiio.geterror().split())[:160]})")
    try:
        spec = inp.spec()
        w, h, nc = spec.width, spec.height, spec.nchannels
        if not (1 <= h <= MAX_SIDE // 2 and w == 2 * h):
            raise SceneError(key, f"{value}: {w}x{h} is not an equirectangular map: expected width = 2 x height, "
                                  f"at most {MAX_SIDE} wide")
        if nc < 1:
            raise SceneError(key, f"{value}: has no channels")
        pixels = inp.read_image(0, 0, 0, min(nc, 3), "float")
        err = inp.geterror()
    finally:
        inp.close()
    if pixels is None or err:
        raise SceneError(key, f"{value}: cannot read its pixels ({' '.join(str(err).split())[:160] or 'truncated?'})")
    rgb = three_channels(np.asarray(pixels, np.float32).reshape(h, w, -1))
    if not np.all(np.isfinite(rgb)) or np.any(rgb < 0):
        raise SceneError(key, f"{value}: holds negative or non-finite values, which are not light")
    if np.any(rgb > MAX_RADIANCE):
        raise SceneError(key, f"{value}: holds values up to {float(rgb.max()):.3g}; a map's light is 0 to "
                              f"{MAX_RADIANCE:.0e}")
    return build(rgb, value)


def three_channels(a: np.ndarray) -> np.ndarray:
    """(H, W, 1-3) pixels as (H, W, 3): grey repeated, a second channel's third taken from the first."""
    if a.shape[2] == 1:
        return np.repeat(a, 3, axis=2)
    if a.shape[2] == 2:
        return np.concatenate([a, a[..., :1]], axis=2)
    return a


def build(rgb: np.ndarray, name: str = "") -> Environment:
    """The environment of an (H, W, 3) image of radiance: its distribution (see the module
    docstring); an image with no light at all is sampled uniformly."""
    h, w = rgb.shape[:2]
    theta = np.pi * (np.arange(h) + 0.5) / h
    weight = (rgb.astype(np.float64) @ LUMA) * np.sin(theta)[:, None]
    mean = float(weight.sum() / (w * np.sin(theta).sum()))
    if not weight.sum() > 0:
        weight = np.ones_like(weight) * np.sin(theta)[:, None]
    rows = weight.sum(axis=1)
    marginal = np.concatenate([[0.0], np.cumsum(rows)]) / rows.sum()
    marginal[-1] = 1.0
    safe = np.where(rows > 0, rows, 1.0)
    conditional = np.concatenate([np.zeros((h, 1)), np.cumsum(weight, axis=1)], axis=1) / safe[:, None]
    conditional[:, -1] = 1.0
    image = np.zeros((h, w, 4), np.float32)
    image[..., :3] = rgb
    for a in (image, marginal, conditional):
        a.setflags(write=False)
    return Environment(image, marginal, conditional, name, mean)


def texel_pdf(env: Environment, row: np.ndarray, col: np.ndarray) -> np.ndarray:
    """The density (per steradian) of directions in texel (row, col)."""
    h, w = env.height, env.width
    p = (env.marginal[row + 1] - env.marginal[row]) * (env.conditional[row, col + 1] - env.conditional[row, col])
    s = np.sin(np.pi * (row + 0.5) / h)
    return p * w * h / (2 * math.pi ** 2 * np.maximum(s, 1e-12))
