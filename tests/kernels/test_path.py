"""kernels/path/path.cl against its float64 twin (reference/path.py), sample by sample.

Both run the same plan with the same random numbers (path/sample.cl path_rand, bit for bit
the twin's), so they trace the same paths.  In double precision the marches agree to
rounding, and the kernel keeps throughput and radiance in float32 (path.cl: float4), so a
sample's radiance agrees to float32 rounding compounded over the bounces: within 1e-5
relative plus 1e-6 absolute.  A path may still part ways where float32 radiance meets a
threshold (the Russian roulette's q, a shadow ray exactly at a light's distance): at most 1 %
of the pixels may differ, none on these scenes so far.  In single precision the marches
themselves differ in the last bits of a hit point, and a grazing bounce can take another
way: most pixels agree, and the picture's mean does to 2 %.
"""
from __future__ import annotations

import numpy as np
import pyopencl as cl
import pytest

from pyjulia4d.opencl.path import PathRunner
from pyjulia4d.opencl.runner import launch
from pyjulia4d.pipeline.plan import make_plan
from pyjulia4d.reference.path import PathTwin
from pyjulia4d.reference.path_sample import path_rand
from pyjulia4d.scene.model import Scene
from tests.harness import device, packet_widths

W, H = 16, 12


def scene(**sections) -> Scene:
    d = {"shading": {"integrator": "path", "bounces": 3}, "image": {"width": W, "height": H, "samples": 2},
         "render": {"float": "double"}}
    for k, v in sections.items():
        d.setdefault(k, {}).update(v)
    return Scene.from_dict(d)


def one_sample(sc: Scene, s: int, lanes: int = 1):
    """Sample s of every pixel, from the kernels (the march in packets of ``lanes`` rays) and
    from the twin: (kernel rgba, twin rgb, twin coverage).  From s = 1 on the kernels run
    samples s - 1 and s in one launch and the second is taken: a launch's later samples
    (path.cl item_sample) are the twin's too."""
    dev = device()
    plan = make_plan(sc, dev, lanes)
    assert plan.path.batch == 2   # a picture this small takes all its samples in one launch
    runner = PathRunner(plan, dev)
    t = plan.tiles[0]
    k = 2 if s > 0 else 1
    ev = runner.sample(t, s - k + 1, k)
    cl.wait_for_events([ev[-1]])
    rad = runner.b["rad"][(k - 1) * t.n:k * t.n].get().view(np.float32).reshape(-1, 4)
    y, x = np.mgrid[0:t.ah, 0:t.aw]
    R, A, _ = PathTwin(plan).trace(x.ravel(), y.ravel(), s)
    return rad, R, A


FEATURES = {
    "bounces": dict(shading={"bounces": 4, "roughness": 0.8}),
    # one program for the lights, a soft one among them, the colour map's glow and a cut
    "next-event, lights, glow, cut": dict(
        shading={"lights": [{"direction": [1, 1, 0], "color": [1, 0.6, 0.3]},
                            {"position": [0.5, 2, -1], "color": [0.3, 0.5, 1], "radius": 0.4}],
                 "coloring": "trap", "emission": 1.5}, clip={"planes": [[0, 0, 1, 0]]}),
    "sky alone": dict(shading={"light_color": [0, 0, 0], "ambient": 1.0}),
    "uniform sky": dict(shading={"environment": "uniform"}),
    "ggx metal": dict(shading={"metallic": 1.0, "roughness": 0.15}),
    "sphere light, sun": dict(shading={"light_radius": 0.6, "lights": [{"direction": [1, 2, -1], "color": [1, 1, 1],
                                                                         "radius": 4.0}]}),
    "lens": dict(camera={"aperture": 0.15, "focus": 2.5}),
    "no estimate, fixed scan": dict(fractal={"algebra": "hypercomplex", "function": "sin"}, normals={"method": "zbuffer"},
                                    march={"method": "fixed", "z_resolution": 200}),
}


# the default run keeps the features that share the default scene's program and one that
# compiles its own (lights, a colour map's glow, a cut); the rest run with -m slow
SLOW = ("uniform sky", "sphere light, sun", "no estimate, fixed scan")


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow if n in SLOW else ()) for n in FEATURES])
def test_sample_matches_twin(name: str) -> None:
    for s in ((0, 7) if name == "bounces" else (7,)):
        rad, R, A = one_sample(scene(**FEATURES[name]), s)
        close = np.all(np.abs(rad[:, :3] - R) <= 1e-5 * np.abs(R) + 1e-6, axis=1)
        assert close.mean() >= 0.99, (name, s, np.abs(rad[:, :3] - R).max())
        assert np.array_equal(rad[:, 3], A)
        assert R.sum() > 0   # something was lit: not a comparison of two black pictures


@pytest.mark.slow
def test_packets_march_the_same_paths() -> None:
    """The march and the Jacobian normals in packets (the renders' way, lanes.lanes_for)."""
    widths = packet_widths(double=True)
    if not widths:
        pytest.skip("the device runs no packets in double precision")
    rad, R, A = one_sample(scene(**FEATURES["bounces"]), 2, lanes=widths[-1])
    close = np.all(np.abs(rad[:, :3] - R) <= 1e-5 * np.abs(R) + 1e-6, axis=1)
    assert close.mean() >= 0.99


def test_single_precision_mostly_agrees() -> None:
    rad, R, A = one_sample(scene(render={"float": "single"}), 3)
    close = np.all(np.abs(rad[:, :3] - R) <= 1e-3 * np.abs(R) + 1e-4, axis=1)
    assert close.mean() >= 0.95
    assert abs(rad[:, :3].mean() - R.mean()) <= 0.02 * R.mean()


def test_camera_rays_are_the_twins() -> None:
    """path_camera alone: each pixel's jittered point and lens point (path_rand's dimensions
    0-3, bit for bit the twin's) give the twin's rays to float64 rounding."""
    sc = scene(camera={"aperture": 0.2, "focus": 3.0})
    dev = device()
    plan = make_plan(sc, dev, 1)
    runner = PathRunner(plan, dev)
    t, b = plan.tiles[0], runner.b
    cl.enqueue_fill_buffer(runner.queue, b["film_count"].data, np.uint8(0), 0, b["film_count"].nbytes)
    launch(runner.queue, runner.k["path_camera"], t.n, *runner.camera_args(
        n_pix=t.n, tile_w=t.aw, x0=t.ax0, y0=t.ay0, sample=5, film_m2=b["film_m2"], film_count=b["film_count"],
        origins=b["origins"], dirs=b["dirs"], thru=b["thru"], rad=b["rad"]))
    o = b["origins"][:t.n].get().view(np.float64).reshape(-1, 4)
    d = b["dirs"][:t.n].get().view(np.float64).reshape(-1, 4)
    y, x = np.mgrid[0:t.ah, 0:t.aw]
    key, o2, d2 = PathTwin(plan).camera(x.ravel(), y.ravel(), 5)
    assert np.array_equal(key, (y.ravel() * W + x.ravel()).astype(np.uint32))
    assert np.abs(o - o2).max() < 1e-12 and np.abs(d - d2).max() < 1e-12
    assert np.abs(o - o2[:1]).max() > 1e-3   # the lens moved the origins: its dimensions were drawn


def test_a_pixels_samples_of_a_pair_are_a_0_2_net() -> None:
    """path_rand's pairs (2j, 2j + 1): a pixel's 2^m samples from any multiple of 2^m on put
    exactly one point in each cell of every 2^a x 2^b grid with a + b = m (Owen-scrambled
    Sobol' is a (0, 2)-sequence); counter-based random numbers would leave cells empty."""
    m = 8
    for pixel, first, pair in ((0, 0, 2), (7, 256, 3), (123456, 2 ** 30, 9)):
        s = np.arange(first, first + 2 ** m)
        px = np.full(2 ** m, pixel, np.uint32)
        x, y = path_rand(px, s, 2 * pair), path_rand(px, s, 2 * pair + 1)
        for a in range(m + 1):
            cell = np.floor(x * 2 ** a).astype(int) * 2 ** (m - a) + np.floor(y * 2 ** (m - a)).astype(int)
            assert np.all(np.bincount(cell, minlength=2 ** m) == 1), (pixel, first, pair, a)


def test_path_rand_is_uniform_and_independent() -> None:
    """Over pixels (each scrambled by its own seeds): uniform per dimension (chi-square over 64
    bins), uncorrelated between neighbouring pixels, samples and dimensions."""
    n = 200_000
    pixel = np.arange(n, dtype=np.uint32)
    a, b, c = path_rand(pixel, 3, 9), path_rand(pixel + 1, 3, 9), path_rand(pixel, 4, 9)
    d = path_rand(pixel, 3, 10)
    counts = np.histogram(a, bins=64, range=(0, 1))[0]
    chi2 = ((counts - n / 64) ** 2 / (n / 64)).sum()
    assert chi2 < 120   # 63 degrees of freedom: p < 1e-5 above ~120
    for other in (b, c, d):
        assert abs(np.corrcoef(a, other)[0, 1]) < 0.01   # 4.5 sigma at n = 200,000
