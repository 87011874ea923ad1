"""PNG/EXR writers: content, metadata, atomicity."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import OpenEXR
import pytest
from PIL import Image

from pyjulia4d import output
from pyjulia4d.output import OutputError, check_output_path, write_exr, write_image, write_png

H, W = 5, 7
EXR_NAMES = ["R", "G", "B", "A", "Z", "N.X", "N.Y", "N.Z", "P.X", "P.Y", "P.Z", "P.W"]


def _color_alpha() -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(1)
    color = rng.uniform(-0.2, 1.2, (H, W, 3)).astype(np.float32)
    alpha = (rng.random((H, W)) > 0.5).astype(np.float32)
    return color, alpha


def test_png_rgba8(tmp_path) -> None:
    color, alpha = _color_alpha()
    color[0, 0] = np.nan
    path = tmp_path / "out.png"
    write_png(path, color, alpha, {"pyjulia4d.scene": "[image]\nwidth = 7\n"})
    im = Image.open(path)
    assert im.mode == "RGBA" and im.size == (W, H)
    a = np.asarray(im)
    assert a.dtype == np.uint8
    np.testing.assert_array_equal(a[..., 3], np.rint(alpha * 255))
    expect = np.rint(np.clip(np.nan_to_num(color), 0, 1) * 255)
    np.testing.assert_array_equal(a[..., :3], expect)
    assert im.info["pyjulia4d.scene"] == "[image]\nwidth = 7\n"
    assert [p.name for p in tmp_path.iterdir()] == ["out.png"]


def test_exr_channels_and_header(tmp_path) -> None:
    rng = np.random.default_rng(2)
    channels = {n: rng.random((H, W)).astype(np.float32) for n in EXR_NAMES}
    channels["Z"][0, 0] = np.inf
    channels["P.X"][1, 1] = np.nan
    header = {"pyjulia4d.scene": "[fractal]\nmax_iter = 3\n", "pyjulia4d.device": "cpu", "pyjulia4d.render_seconds": "1.500000"}
    path = tmp_path / "out.EXR"
    write_exr(path, channels, header)
    f = OpenEXR.File(str(path), separate_channels=True)
    got = f.channels()
    assert sorted(got) == sorted(EXR_NAMES)
    for n in EXR_NAMES:
        px = got[n].pixels
        assert px.dtype == np.float32 and px.shape == (H, W)
        np.testing.assert_array_equal(px, channels[n])  # NaN == NaN here
    hdr = f.header()
    for k, v in header.items():
        assert hdr[k] == v
    assert isinstance(channels["R"], np.ndarray)  # caller's dict left alone


@dataclass
class FakeResult:
    color: np.ndarray
    alpha: np.ndarray

    def exr_channels(self) -> dict[str, np.ndarray]:
        return {"R": self.color[..., 0], "G": self.color[..., 1], "B": self.color[..., 2], "A": self.alpha}


def test_write_image_dispatch(tmp_path) -> None:
    res = FakeResult(*_color_alpha())
    write_image(tmp_path / "a.PNG", res, {"k": "v"})
    write_image(tmp_path / "b.exr", res, {"k": "v"})
    assert Image.open(tmp_path / "a.PNG").mode == "RGBA"
    assert OpenEXR.File(str(tmp_path / "b.exr"), header_only=True).header()["k"] == "v"
    with pytest.raises(OutputError, match=r"unsupported output format '\.jpg' \(use \.png or \.exr\)"):
        write_image(tmp_path / "c.jpg", res, {})
    assert not (tmp_path / "c.jpg").exists()


def test_check_output_path(tmp_path) -> None:
    assert check_output_path(tmp_path / "x.exr") == tmp_path / "x.exr"
    with pytest.raises(OutputError) as info:
        check_output_path(tmp_path / "x.jpg")
    assert str(info.value) == f"{tmp_path / 'x.jpg'}: unsupported output format '.jpg' (use .png or .exr)"
    with pytest.raises(OutputError, match="does not exist"):
        check_output_path(tmp_path / "nope" / "x.png")
    (tmp_path / "d.png").mkdir()
    with pytest.raises(OutputError, match="is a directory"):
        check_output_path(tmp_path / "d.png")


@pytest.mark.parametrize("fmt", ["png", "exr"])
@pytest.mark.parametrize("exc", [RuntimeError, KeyboardInterrupt])
def test_failed_write_leaves_nothing(tmp_path, monkeypatch, fmt: str, exc: type[BaseException]) -> None:
    def boom(*args, **kwargs):
        raise exc("disk on fire")

    if fmt == "png":
        monkeypatch.setattr(Image.Image, "save", boom)
    else:
        monkeypatch.setattr(OpenEXR.File, "write", boom)
    with pytest.raises(exc):
        write_image(tmp_path / f"out.{fmt}", FakeResult(*_color_alpha()), {})
    assert list(tmp_path.iterdir()) == []


def test_failed_write_keeps_previous_file(tmp_path, monkeypatch) -> None:
    path = tmp_path / "out.png"
    path.write_bytes(b"old")
    monkeypatch.setattr(output.os, "replace", lambda *a: (_ for _ in ()).throw(OSError(28, "No space left")))
    with pytest.raises(OutputError, match="cannot write: No space left"):
        write_image(path, FakeResult(*_color_alpha()), {})
    assert path.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["out.png"]
