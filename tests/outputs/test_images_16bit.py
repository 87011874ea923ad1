"""16-bit PNG and 8/16-bit TIFF outputs (image.bits; app/output.py): the pixels against the
sRGB transfer function at 65535 levels, read back by other libraries (pypng, tifffile,
Pillow), the header's scene kept and rendered again, and bad values in one line."""
from __future__ import annotations

import json

import numpy as np
import png
import pytest
import tifffile
from PIL import Image

from pyjulia4d.app.cli import main
from pyjulia4d.app.output import read_header, rgba_levels, write_png, write_tiff
from pyjulia4d.scene.checks import SceneError
from pyjulia4d.scene.model import Scene

H, W = 6, 9


def srgb(x):   # IEC 61966-2-1
    x = np.clip(np.nan_to_num(np.asarray(x, np.float64)), 0, 1)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)


def colour_alpha():
    rng = np.random.default_rng(5)
    color = rng.uniform(-0.1, 1.1, (H, W, 3)).astype(np.float32)
    color[0, 0] = np.nan
    return color, (rng.random((H, W)) > 0.4).astype(np.float32)


def test_16_bit_levels_are_the_transfer_function_at_65535():
    color, alpha = colour_alpha()
    got = rgba_levels(color, alpha, 16)
    assert got.dtype == np.uint16
    # float32 in, float64 transfer: within one level of 65535 sRGB(x)
    assert np.max(np.abs(got[..., :3].astype(float) - 65535 * srgb(color))) <= 1
    assert np.array_equal(got[..., 3], np.rint(alpha * 65535).astype(np.uint16))
    eight = rgba_levels(color, alpha, 8)
    assert np.max(np.abs(got.astype(float) / 257 - eight)) <= 0.5 + 1e-9


def test_16_bit_png_reads_back_with_pypng_and_keeps_its_text(tmp_path):
    color, alpha = colour_alpha()
    path = tmp_path / "deep.png"
    write_png(path, color, alpha, {"pyjulia4d.scene": "[image]\nbits = 16  # é\n", "k": "v"}, bits=16)
    w, h, rows, info = png.Reader(filename=str(path)).asDirect()
    assert (w, h, info["bitdepth"], info["planes"]) == (W, H, 16, 4)
    back = np.vstack([np.asarray(r, np.uint16) for r in rows]).reshape(H, W, 4)
    assert np.array_equal(back, rgba_levels(color, alpha, 16))
    assert read_header(path) == {"pyjulia4d.scene": "[image]\nbits = 16  # é\n", "k": "v"}
    with Image.open(path) as im:   # another reader sees an RGBA PNG
        assert im.size == (W, H)


@pytest.mark.parametrize("bits", [8, 16])
def test_tiff_reads_back_with_tifffile_and_keeps_its_text(tmp_path, bits):
    color, alpha = colour_alpha()
    path = tmp_path / "out.tif"
    write_tiff(path, color, alpha, {"pyjulia4d.scene": "x = 1", "pyjulia4d.device": "é"}, bits=bits)
    with tifffile.TiffFile(path) as t:
        page = t.pages[0]
        assert page.dtype == (np.uint8 if bits == 8 else np.uint16) and page.shape == (H, W, 4)
        assert json.loads(page.description)["pyjulia4d.device"] == "é"
        assert np.array_equal(page.asarray(), rgba_levels(color, alpha, bits))
    assert read_header(path) == {"pyjulia4d.scene": "x = 1", "pyjulia4d.device": "é"}
    assert [p.name for p in tmp_path.iterdir()] == ["out.tif"]


@pytest.mark.parametrize("out", ["deep.png", "deep.tif", "deep.tiff"])
def test_a_16_bit_render_keeps_its_scene_and_renders_again_to_the_same_pixels(tmp_path, monkeypatch, out):
    monkeypatch.chdir(tmp_path)
    assert main(["render", "--width", "40", "--height", "30", "--set", "image.bits=16", "-o", out]) == 0
    again = "again" + out[out.index("."):]
    assert main(["render", out, "-o", again]) == 0

    def pixels(name):
        if name.endswith(".png"):
            w, h, rows, info = png.Reader(filename=name).asDirect()
            assert info["bitdepth"] == 16
            return np.vstack([np.asarray(r, np.uint16) for r in rows])
        return tifffile.imread(name)

    first = pixels(out)
    assert first.dtype == np.uint16 and first.max() > 255
    assert np.array_equal(first, pixels(again))
    assert Scene.from_dict({}).image.bits == 8
    assert "bits = 16" in read_header(tmp_path / out)["pyjulia4d.scene"]


@pytest.mark.parametrize("value", ["12", "8.0", "true", "sixteen"])
def test_bits_other_than_8_or_16_are_one_line(tmp_path, monkeypatch, capsys, value):
    monkeypatch.chdir(tmp_path)
    assert main(["render", "--set", f"image.bits={value}", "-o", "x.png"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pyjulia4d: error: image.bits: expected 8 or 16, got") and err.count("\n") == 1
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(SceneError, match="image.bits: expected 8 or 16"):
        Scene.default().replace(**{"image.bits": 32})


def test_a_tiff_holds_rgba_only(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["render", "--channels", "Z", "-o", "x.tif"]) == 2
    assert "a TIFF holds RGBA only" in capsys.readouterr().err


def test_tiff_frames_read_for_video(tmp_path):
    from pyjulia4d.app.video import read_frame

    color, alpha = colour_alpha()
    write_tiff(tmp_path / "f.tif", color, alpha, {}, bits=16)
    frame = read_frame(tmp_path / "f.tif")
    assert frame.dtype == np.uint8 and frame.shape == (H, W, 3)
    assert np.max(np.abs(frame.astype(int) - rgba_levels(color, alpha, 8)[..., :3])) <= 1
