"""sky.exr, the environment shading.environment = "sky" names: an analytic clear daylight,
made by this module (``python -m pyjulia4d.data.sky`` writes it again) so that the file is
reproducible and its numbers stated.

An equirectangular map, 512 x 256 half floats (pipeline/environment.py's layout: +y up),
of linear Rec. 709 radiance:
- the sky: from the zenith's blue (0.30, 0.50, 1.00) to the horizon's white (1, 1, 1) by
  (1 - cos(zenith angle))^2, brightened towards the sun by a circumsolar glow
  1 + 3 exp(-angle / 0.2 rad);
- the ground below the horizon: a warm grey (0.30, 0.27, 0.24), darkening away from it;
- the sun: a disc of 2 degrees' radius (four texels across, so that sampling finds it and
  a nearest-texel lookup holds it) towards SUN, the direction of the default key light.
Scaled so that the whole map gives an upward-facing surface an irradiance of pi: a white
matte surface facing up under it is 1 bright; the sun gives 60 % of that, the sky the rest.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

WIDTH, HEIGHT = 512, 256
SUN = np.array([-2.0, 5.0, -4.0]) / math.sqrt(45.0)   # shading.light's default, from the origin
SUN_RADIUS = math.radians(2.0)
SUN_SHARE = 0.6
ZENITH, HORIZON, GROUND = np.array([0.30, 0.50, 1.00]), np.array([1.0, 1.0, 1.0]), np.array([0.30, 0.27, 0.24])


def directions() -> np.ndarray:
    """(H, W, 3): each texel centre's direction (pipeline/environment.py's layout)."""
    v = (np.arange(HEIGHT) + 0.5) / HEIGHT
    u = (np.arange(WIDTH) + 0.5) / WIDTH
    theta, phi = np.meshgrid(np.pi * v, 2 * np.pi * u - np.pi, indexing="ij")
    return np.stack([np.sin(theta) * np.sin(phi), np.cos(theta), -np.sin(theta) * np.cos(phi)], axis=-1)


def make_sky() -> np.ndarray:
    """The map, (H, W, 3) float32."""
    d = directions()
    up = d[..., 1]
    angle = np.arccos(np.clip(d @ SUN, -1, 1))
    t = (1 - np.clip(up, 0, 1)) ** 2
    sky = (ZENITH * (1 - t[..., None]) + HORIZON * t[..., None]) * (1 + 3 * np.exp(-angle / 0.2))[..., None]
    ground = GROUND * (0.4 + 0.6 * np.exp(4 * np.minimum(up, 0)))[..., None]
    img = np.where((up >= 0)[..., None], sky, ground)
    sun = angle <= SUN_RADIUS
    # irradiance on an upward surface, by texel: L cos(zenith) dOmega, dOmega = (2 pi / W)(pi / H) sin(theta)
    theta = np.arccos(np.clip(up, -1, 1))
    d_omega = (2 * np.pi / WIDTH) * (np.pi / HEIGHT) * np.sin(theta)
    cos_up = np.maximum(up, 0)
    lum = img @ np.array([0.2126, 0.7152, 0.0722])
    sky_e = float((lum * cos_up * d_omega)[~sun].sum())
    img = img * ((1 - SUN_SHARE) * np.pi / sky_e)
    sun_e = float((cos_up * d_omega)[sun].sum())
    img[sun] = np.array([1.0, 0.95, 0.85]) * (SUN_SHARE * np.pi / sun_e) / 0.9655   # 0.9655: that colour's luminance
    return img.astype(np.float32)


def write(path: Path) -> None:
    import OpenImageIO as oiio

    spec = oiio.ImageSpec(WIDTH, HEIGHT, 3, "half")
    spec.attribute("compression", "zip")
    spec.attribute("ImageDescription", "pyjulia4d sky: pyjulia4d/data/sky.py")
    out = oiio.ImageOutput.create(str(path))
    if out is None or not out.open(str(path), spec):
        raise OSError(f"cannot write {path}: {oiio.geterror()}")
    out.write_image(make_sky())
    out.close()


if __name__ == "__main__":
    write(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).with_name("sky.exr"))
