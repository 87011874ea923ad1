"""A picture's backdrop: a gradient or an image behind the set (shading.background_gradient,
shading.background_image), put in once the picture is whole.

The kernels give every pixel a c + (1 - a) B, where a is the share of its samples that hit
the set, c their colour and B the flat shading.background their misses saw.  A backdrop
B(x, y) replaces B pixel by pixel: colour += (1 - a) (B(x, y) - B), exact for every pixel,
partly covered edges included, since the misses' share of each pixel is known (alpha).  It
is done before the tone map, as the flat background is (it is light in the same linear units),
and after the denoiser, which then never blurs it.  The mirror bounce and fog still see the
flat colour, and the path tracer's misses its environment: the backdrop is what the camera
sees behind the set, as a photographer's backdrop is.

- A gradient: stops [position, r, g, b] (sRGB, as shading.gradient's) from the top of the
  frame (0) to its bottom (1), interpolated per pixel row in sRGB, then made linear.
- An image (PNG, JPEG, TIFF, EXR, HDR; read by OpenImageIO): scaled to cover the frame and
  centred, cropping what overhangs (OpenImageIO's resize, a Lanczos filter); 8- and 16-bit
  images are sRGB and made linear, floating-point ones (EXR, HDR) taken as linear light.
"""
from __future__ import annotations

import functools
import os
from pathlib import Path

import numpy as np

from pyjulia4d.pipeline.colormap import srgb_to_linear
from pyjulia4d.pipeline.environment import three_channels
from pyjulia4d.scene.checks import SceneError

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".exr", ".hdr")
MAX_PIXELS = 1 << 27   # a backdrop image is read whole: 134 Mpixel at most (1.5 GiB as float32 RGB)


def has_backdrop(shading) -> bool:
    """Whether [shading] names a gradient or an image behind the set."""
    return bool(shading.background_gradient) or shading.background_image != "none"


def gradient(stops, height: int, width: int) -> np.ndarray:
    """(H, W, 3) float32 linear light: the stops' colours down the frame, one per row centre."""
    st = np.asarray(stops, np.float64)
    v = (np.arange(height) + 0.5) / height
    srgb = np.stack([np.interp(v, st[:, 0], st[:, k]) for k in (1, 2, 3)], axis=1)
    rows = srgb_to_linear(np.clip(srgb, 0.0, 1.0)).astype(np.float32)
    return np.ascontiguousarray(np.broadcast_to(rows[:, None, :], (height, width, 3)))


def image(value: str, height: int, width: int) -> np.ndarray:
    """(H, W, 3) float32 linear light: the image ``value`` names, covering the frame
    (module docstring); a SceneError naming shading.background_image where it cannot be
    read, is empty or too large, or holds values that are not light."""
    p = Path(value).expanduser()
    try:
        st = os.stat(p)
    except OSError as e:
        raise SceneError("shading.background_image", f"{value}: cannot read it: {e.strerror or e}") from None
    return _covered(str(p), st.st_size, st.st_mtime_ns, value, height, width).copy()


@functools.lru_cache(maxsize=4)
def _covered(path: str, size: int, mtime: int, value: str, height: int, width: int) -> np.ndarray:
    import OpenImageIO as oiio

    key = "shading.background_image"
    buf = oiio.ImageBuf(path)
    spec = buf.spec() if not buf.has_error else None
    if spec is None or spec.width < 1 or spec.height < 1 or spec.nchannels < 1:
        raise SceneError(key, f"{value}: not an image OpenImageIO can read ({' '.join(buf.geterror().split())[:160]})")
    if spec.width * spec.height > MAX_PIXELS:
        raise SceneError(key, f"{value}: {spec.width}x{spec.height} is larger than {MAX_PIXELS} pixels")
    linear = spec.format.basetype in (oiio.FLOAT, oiio.HALF, oiio.DOUBLE)
    # the largest centred part of the image with the frame's aspect, then resized to the frame
    w, h = spec.width, spec.height
    cw, ch = (w, max(1, round(w * height / width))) if w * height <= h * width else (max(1, round(h * width / height)), h)
    x0, y0 = spec.x + (w - cw) // 2, spec.y + (h - ch) // 2
    crop = oiio.ImageBufAlgo.cut(buf, oiio.ROI(x0, x0 + cw, y0, y0 + ch, 0, 1, 0, min(spec.nchannels, 3)))
    out = oiio.ImageBufAlgo.resize(crop, roi=oiio.ROI(0, width, 0, height, 0, 1, 0, crop.nchannels))
    if out.has_error:
        raise SceneError(key, f"{value}: cannot be resized ({' '.join(out.geterror().split())[:160]})")
    rgb = three_channels(np.asarray(out.get_pixels(oiio.FLOAT), np.float32).reshape(height, width, -1))
    if not np.all(np.isfinite(rgb)):
        raise SceneError(key, f"{value}: holds non-finite values, which are not light")
    rgb = np.maximum(rgb, 0.0)   # a Lanczos filter rings a little below 0 at hard edges
    if not linear:
        rgb = srgb_to_linear(np.clip(rgb, 0.0, 1.0)).astype(np.float32)
    rgb.setflags(write=False)
    return rgb


def backdrop(scene, height: int, width: int) -> np.ndarray | None:
    """The scene's backdrop, (H, W, 3) float32 linear light, or None (the flat background)."""
    sh = scene.shading
    if sh.background_image != "none":
        return image(sh.background_image, height, width)
    if sh.background_gradient:
        return gradient(sh.background_gradient, height, width)
    return None


def check_backdrop(scene) -> None:
    """Read the scene's backdrop image at the frame's size before any render (kept for its
    finish): a file that cannot be used is one SceneError, before any kernel runs."""
    if scene.shading.background_image != "none":
        image(scene.shading.background_image, scene.image.height, scene.image.width)


def put_behind(result, scene) -> None:
    """Put the scene's backdrop behind a whole picture (module docstring): result.color
    changed in place where pixels missed, result.backdrop kept for the writers, which take
    it out again for straight and premultiplied alpha."""
    if result.color is None or result.alpha is None or not has_backdrop(scene.shading):
        return
    h, w = result.color.shape[:2]
    back = backdrop(scene, h, w)
    flat = np.asarray(scene.shading.background, np.float32)
    miss = (1.0 - np.asarray(result.alpha, np.float32))[..., None]
    result.color = np.asarray(result.color, np.float32) + miss * (back - flat)
    result.backdrop = back
