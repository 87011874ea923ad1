"""A gradient or an image behind the set (pipeline/backdrop.py): put in pixel by pixel from
each pixel's share of missed samples, and taken out again exactly for straight (PNG, TIFF)
and premultiplied (EXR) alpha."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from harness import device
from pyjulia4d import Scene
from pyjulia4d.app.output import background_of, straight_colour, wants_alpha, write_image
from pyjulia4d.opencl.executor import render
from pyjulia4d.pipeline import backdrop
from pyjulia4d.pipeline.colormap import srgb_to_linear
from pyjulia4d.scene.checks import SceneError

ROOT = Path(__file__).resolve().parents[2]
STOPS = "[[0, 0.1, 0.2, 0.4], [0.5, 0.9, 0.5, 0.2], [1, 0.2, 0.9, 0.3]]"
SMALL = ["image.width=48", "image.height=36", "image.samples=4"]


def test_gradient_runs_down_the_frame():
    g = backdrop.gradient([[0, 1, 0, 0], [1, 0, 0, 1]], 4, 3)
    assert g.shape == (4, 3, 3) and np.all(g[:, 0] == g[:, 2])
    # row centres at 1/8, 3/8, 5/8, 7/8 of the way down, interpolated in sRGB, then linear
    want = srgb_to_linear(np.array([[1 - v, 0, v] for v in (0.125, 0.375, 0.625, 0.875)]))
    assert np.allclose(g[:, 1], want, atol=1e-6)


def test_the_backdrop_replaces_the_flat_background_exactly():
    flat = render(Scene.default().with_overrides(SMALL), device=device())
    got = render(Scene.default().with_overrides(SMALL + [f"shading.background_gradient={STOPS}"]), device=device())
    back = backdrop.gradient(got.scene.shading.background_gradient, 36, 48)
    assert np.array_equal(got.backdrop, back)
    part = (flat.alpha > 0) & (flat.alpha < 1)
    assert part.sum() > 10   # edges partly covered: the case that fringes when done wrong
    want = flat.color + (1 - flat.alpha)[..., None] * back   # the flat background here is black
    assert np.allclose(got.color, want, atol=1e-6)
    # straight alpha takes each pixel's own backdrop out again: the set's colour, as on black
    seen = flat.alpha > 0
    assert np.allclose(straight_colour(got.color, got.alpha, background_of(got, got.scene))[seen],
                       straight_colour(flat.color, flat.alpha, (0, 0, 0))[seen], atol=1e-5)


def _photo(path: Path, w: int, h: int) -> None:
    """Left half red, right half blue, a green band across the middle third of the rows."""
    img = np.zeros((h, w, 3), np.uint8)
    img[:, : w // 2, 0] = 255
    img[:, w // 2:, 2] = 255
    img[h // 3: 2 * h // 3, :, 1] = 255
    Image.fromarray(img).save(path)


def test_an_image_covers_the_frame_centred(tmp_path):
    p = tmp_path / "wide.png"
    _photo(p, 400, 100)   # 4:1 into a 2:1 frame: the middle half of its width is kept
    got = backdrop.image(str(p), 50, 100)
    assert got.shape == (50, 100, 3)
    assert got[25, 10, 0] > 0.9 and got[25, 90, 2] > 0.9        # still red left, blue right
    assert got[2, 50, 1] < 0.05 and got[25, 50, 1] > 0.9        # the band's rows kept whole
    tall = tmp_path / "tall.png"
    _photo(tall, 100, 400)   # 1:4 into 2:1: the middle eighth of its rows, all green
    assert backdrop.image(str(tall), 50, 100)[:, :, 1].min() > 0.9


def test_image_is_read_as_srgb_and_exr_as_linear(tmp_path):
    p = tmp_path / "grey.png"
    Image.fromarray(np.full((8, 8, 3), 128, np.uint8)).save(p)
    assert np.allclose(backdrop.image(str(p), 4, 4), srgb_to_linear(np.array(128 / 255)), atol=1e-3)
    import OpenImageIO as oiio
    e = tmp_path / "grey.exr"
    out = oiio.ImageOutput.create(str(e))
    out.open(str(e), oiio.ImageSpec(8, 8, 3, oiio.FLOAT))
    out.write_image(np.full((8, 8, 3), 0.25, np.float32))
    out.close()
    assert np.allclose(backdrop.image(str(e), 4, 4), 0.25, atol=1e-4)


def test_alpha_auto_is_opaque_on_a_backdrop(tmp_path):
    got = render(Scene.default().with_overrides(SMALL + [f"shading.background_gradient={STOPS}"]), device=device())
    assert not wants_alpha(got.scene)
    write_image(tmp_path / "a.png", got)
    assert Image.open(tmp_path / "a.png").mode == "RGB"
    keep = got.scene.with_overrides(["image.alpha=true"])
    assert wants_alpha(keep) and wants_alpha(Scene.default())


def test_exr_compositing_layout_is_premultiplied_over_the_backdrop(tmp_path):
    import OpenEXR

    flat = render(Scene.default().with_overrides(SMALL + ["image.exr=compositing"]), device=device())
    got = render(Scene.default().with_overrides(SMALL + ["image.exr=compositing", f"shading.background_gradient={STOPS}"]),
                 device=device())
    write_image(tmp_path / "flat.exr", flat)
    write_image(tmp_path / "grad.exr", got)
    a = OpenEXR.File(str(tmp_path / "flat.exr"), separate_channels=True).channels()
    b = OpenEXR.File(str(tmp_path / "grad.exr"), separate_channels=True).channels()
    for c in ("ViewLayer.Combined.R", "ViewLayer.Combined.G", "ViewLayer.Combined.B"):
        assert np.allclose(a[c].pixels, b[c].pixels, atol=1e-5), c


@pytest.mark.parametrize("keys, words", [
    (["shading.background_image=missing.png"], "shading.background_image: missing.png: cannot read it"),
    (["shading.background_image=bad.png"], "shading.background_image: bad.png: not an image"),
    ([f"shading.background_gradient={STOPS}", "shading.background_image=bad.png"], "give one"),
    (["shading.background_image=notes.txt"], "shading.background_image: expected \"none\" or the path of an image"),
    (["shading.background_gradient=[[0,1,1,1]]"], "shading.background_gradient: expected 2 to 16 stops"),
])
def test_bad_backdrops_are_one_line_and_leave_nothing(tmp_path, keys, words):
    (tmp_path / "bad.png").write_bytes(b"not a png at all")
    args = ["render", "--width", "16", "--height", "12", "-o", "out.png"]
    for k in keys:
        args += ["--set", k]
    p = subprocess.run([sys.executable, "-m", "pyjulia4d", *args], capture_output=True, text=True, cwd=tmp_path,
                       env=dict(os.environ, PYTHONPATH=str(ROOT)), timeout=120)
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1 and words in p.stderr, p.stderr
    assert sorted(x.name for x in tmp_path.iterdir()) == ["bad.png"]


def test_a_scene_object_with_both_is_refused():
    with pytest.raises(SceneError, match="give one"):
        Scene.default().with_overrides([f"shading.background_gradient={STOPS}", "shading.background_image=x.png"])
