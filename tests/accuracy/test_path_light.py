"""The path tracer against answers known without it.

The Julia set of q^2 + 0 is the closed unit 4-ball, so with c = 0 the picture is a ball whose
light has closed forms:
- the white furnace: a grey Lambertian ball of albedo a in a uniform environment of
  radiance 1 (an image of 1s: the environment's own sampling) sends back a in every direction (convex: every bounce escapes), whatever the
  number of bounces - any bias in the sampling, the multiple importance weights or the
  Russian roulette shows as a departure from a;
- a Lambertian ball under a distant light of colour C (the sky off): a C max(n . l, 0), n the
  ball's radius through the hit, averaged over each pixel's area (the pixel's jitter), which
  the test integrates from the exact ray-sphere intersections.
Departures are judged against the render's own stated noise (pipeline/film.py): a pixel's
mean lies within 5 of its standard errors, the picture's within 4 of its own.
"""
from __future__ import annotations

import numpy as np

import pyjulia4d
from pyjulia4d.geometry.camera import camera_frame
from pyjulia4d.scene.model import Scene

W, H = 32, 24
BALL = {"fractal": {"c": [0, 0, 0, 0]}, "camera": {"position": [0, 0, -3.2, 0], "fov": 45},
        "march": {"epsilon": 1e-6}}


# Every ball is lit the same way - an environment image and one distant light, each black
# where a test does not use it - so that all compile one program.
DARK = [{"direction": [0, 1, 0], "color": [0, 0, 0]}]


def sky_file(tmp_path, upper: float, lower: float):
    """A 64x32 environment image of radiance ``upper`` above the horizon, ``lower`` below."""
    import OpenImageIO as oiio
    img = np.full((32, 64, 3), lower, np.float32)
    img[:16] = upper
    path = tmp_path / f"sky_{upper}_{lower}.exr"
    out = oiio.ImageOutput.create(str(path))
    out.open(str(path), oiio.ImageSpec(64, 32, 3, "float"))
    out.write_image(img)
    out.close()
    return str(path)


def ball(shading: dict, samples: int, bounces: int = 4) -> pyjulia4d.RenderResult:
    d = {k: dict(v) for k, v in BALL.items()}
    d["shading"] = {"integrator": "path", "bounces": bounces, "specular": 0.0, "metallic": 0.0, "lights": DARK,
                    "color": [0.5, 0.5, 0.5], **shading}
    d["image"] = {"width": W, "height": H, "samples": samples}
    return pyjulia4d.render(Scene.from_dict(d))


def judge(r, expected) -> None:
    full = r.alpha == 1.0
    assert full.sum() > 100
    got = r.color[full].astype(np.float64)
    sd = np.sqrt(r.film.variance[full].astype(np.float64))
    z = (got - expected[full]) / np.maximum(sd, 1e-5)   # float32 rounding where a pixel has no variance
    assert np.abs(z).max() < 5.5, np.abs(z).max()
    total_sd = np.sqrt((sd ** 2).sum()) / got.size
    assert abs(got.mean() - expected[full].mean()) < 4 * total_sd + 1e-6


def test_white_furnace_returns_the_albedo(tmp_path) -> None:
    white = sky_file(tmp_path, 1.0, 1.0)
    r = ball({"light_color": [0, 0, 0], "ambient": 1.0, "sky": [1, 1, 1], "background": [1, 1, 1],
              "environment": white}, samples=64)
    judge(r, np.full(r.color.shape, 0.5))
    # one bounce is direct light alone: the sky seen from a convex ball, also a
    judge(ball({"light_color": [0, 0, 0], "ambient": 1.0, "background": [1, 1, 1], "environment": white}, 64,
               bounces=1), np.full(r.color.shape, 0.5))


def pixel_truth(scene: Scene, radiance, n: int = 16) -> np.ndarray:
    """radiance(normals (m, 3)) -> (m, 3), averaged over each pixel's area: n x n points of
    the pixel, each ray's first crossing of the unit sphere (the 3D slice of the unit 4-ball),
    whose normal is the point itself."""
    fr = camera_frame(scene)
    out = np.zeros((H, W, 3))
    k = (np.arange(n) + 0.5) / n
    ox, oy = np.meshgrid(k, k)
    for y in range(H):
        for x in range(W):
            u = (2 * (x + ox.ravel()) / W - 1) * fr.tan_half_fov * W / H
            v = (1 - 2 * (y + oy.ravel()) / H) * fr.tan_half_fov
            d = fr.forward + u[:, None] * fr.right + v[:, None] * fr.up
            d /= np.linalg.norm(d, axis=1, keepdims=True)
            b = d @ fr.position
            disc = b * b - (fr.position @ fr.position - 1)
            t = -b - np.sqrt(np.maximum(disc, 0))
            p = fr.position + t[:, None] * d
            out[y, x] = np.where((disc > 0)[:, None], radiance(p[:, :3]), 0.0).mean(axis=0)
    return out


def lambert_truth(scene: Scene, light_dir, color, albedo: float) -> np.ndarray:
    """a C max(n . l, 0) over each pixel's area."""
    l = np.asarray(light_dir, float) / np.linalg.norm(light_dir)
    return pixel_truth(scene, lambda nrm: albedo * np.asarray(color) * np.maximum(nrm @ l, 0)[:, None])


def test_lambertian_ball_under_a_distant_light(tmp_path) -> None:
    light = [1.0, 1.5, -1.0]
    r = ball({"light_color": [0, 0, 0], "ambient": 0.0, "environment": sky_file(tmp_path, 0.0, 0.0),
              "lights": [{"direction": light + [0], "color": [0.9, 0.7, 0.5]}]}, samples=48, bounces=1)
    judge(r, lambert_truth(r.scene, light, [0.9, 0.7, 0.5], 0.5))


def test_lambertian_ball_under_two_lights(tmp_path) -> None:
    """Next-event estimation chooses a light by what it can give the point (path.cl
    light_weight): a sun and a dimmer point light from the other side, each lighting the half
    of the ball that faces it, sum to their closed forms.  Both are grey, so a sample's value
    is the same whichever light it drew (each light's share is its part of the sum): a
    light drawn seldom where it gives little cannot leave a pixel's stated noise short of
    its error, as a coloured one can over 48 samples."""
    sun, key = [1.0, 1.5, -1.0], np.array([-3.0, 0.5, -2.0])
    r = ball({"light_color": [0.35, 0.35, 0.35], "light": key.tolist() + [0.0], "ambient": 0.0,
              "environment": sky_file(tmp_path, 0.0, 0.0),
              "lights": [{"direction": sun + [0], "color": [0.8, 0.8, 0.8]}]}, samples=48, bounces=1)
    lk = lambda p: (key - p) / np.linalg.norm(key - p, axis=1, keepdims=True)   # noqa: E731
    point = pixel_truth(r.scene, lambda nrm: 0.5 * 0.35 * np.maximum((nrm * lk(nrm)).sum(axis=1), 0)[:, None]
                        * np.ones(3))
    judge(r, lambert_truth(r.scene, sun, [0.8, 0.8, 0.8], 0.5) + point)


def test_stated_noise_is_the_measured_error() -> None:
    """The standard error each pixel states at 16 samples against its actual distance from a
    256-sample render of the same scene: the RMS of the two within a factor 1.5.  The
    reference's first 16 samples are the render's (one sample sequence), so the difference's
    variance is s^2/16 - s^2/256; the reference's own stated noise squared (s^2/256) is added
    back."""
    sc = Scene.from_dict({"shading": {"integrator": "path", "bounces": 3}, "camera": {"fit": False},
                          "image": {"width": 24, "height": 18, "samples": 16}})
    r = pyjulia4d.render(sc)
    ref = pyjulia4d.render(sc.replace(**{"image.samples": 256}))
    lum = np.array([0.2126, 0.7152, 0.0722])
    err = (r.color - ref.color) @ lum
    measured = np.sqrt(np.mean(err ** 2) + np.mean(ref.film.noise ** 2))
    stated = np.sqrt(np.mean(r.film.noise ** 2))
    assert stated > 0 and 1 / 1.5 < measured / stated < 1.5, (measured, stated)


def test_lambertian_ball_under_a_sky_image(tmp_path) -> None:
    """An environment image of radiance 1 above the horizon and 0 below (the map's importance
    sampling, not a uniform sphere's): a Lambertian surface of normal n gets the irradiance
    pi (1 + n_y) / 2 of a uniform upper hemisphere, so sends back a (1 + n_y) / 2."""
    r = ball({"light_color": [0, 0, 0], "ambient": 1.0, "sky": [1, 1, 1], "environment": sky_file(tmp_path, 1.0, 0.0)},
             samples=48, bounces=2)
    judge(r, pixel_truth(r.scene, lambda nrm: np.repeat(0.5 * (1 + nrm[:, 1:2]) / 2, 3, axis=1)))
