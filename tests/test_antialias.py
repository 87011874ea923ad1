"""Supersampling (image.samples): stratified jittered rays (rays.cl sample_offset) against
the float64 reference, determinism, and outputs other than RGBA from the pixel centres."""
import numpy as np
import pytest

from pyjulia4d import reference as ref
from pyjulia4d.render import render
from pyjulia4d.scene import Scene

SMALL = ["image.width=40", "image.height=30"]


def test_sample_offsets_are_stratified():
    # sample k of n lies in cell (k mod g, k div g) of the g x g grid over the pixel
    x, y = np.meshgrid(np.arange(50), np.arange(40))
    for n in (2, 4, 9, 10):
        g = int(np.ceil(np.sqrt(n)))
        for k in range(n):
            ox, oy = ref.sample_offset(x.ravel(), y.ravel(), k, n)
            assert np.all((ox >= (k % g) / g) & (ox < (k % g + 1) / g))
            assert np.all((oy >= (k // g) / g) & (oy < (k // g + 1) / g))
    # and spread inside their cell: no pattern shared by all pixels
    ox, _ = ref.sample_offset(x.ravel(), y.ravel(), 0, 4)
    assert np.std(ox) > 0.1


@pytest.mark.parametrize("over", [[], ["fractal.algebra=hypercomplex", "fractal.c=-0.123,0,-0.745,0",
                                       "camera.position=1.7,5.7,-5.7", "camera.fov=15"]])
def test_supersampled_colour_matches_reference(over):
    s = Scene.default().with_overrides(SMALL + over + ["image.samples=4"])
    k, r = render(s), ref.render(s)
    # an edge pixel's mean depends on which samples hit: a sample flipping between float32
    # and float64 moves it by up to 1/4; most pixels agree to float32 shading
    dc = np.abs(k.color - r.color).max(axis=-1)
    assert np.median(dc) < 1e-3 and np.mean(dc < 0.3) > 0.99
    np.testing.assert_allclose(k.alpha.mean(), r.alpha.mean(), atol=0.01)
    # partial coverage shows on the silhouette
    assert np.any((k.alpha > 0) & (k.alpha < 1))


def test_supersampling_is_deterministic_and_keeps_the_centres():
    s1 = Scene.default().with_overrides(SMALL)
    s4 = s1.with_overrides(["image.samples=4"])
    a, b, c = render(s4), render(s4), render(s1)
    np.testing.assert_array_equal(a.color, b.color)
    for name in ("depth", "normal", "position", "status", "bracket"):
        np.testing.assert_array_equal(getattr(a, name), getattr(c, name), err_msg=name)
    assert a.counts == c.counts
