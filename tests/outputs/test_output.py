"""PNG/EXR writers: content, metadata, atomicity."""
from __future__ import annotations

import dataclasses
import os
import signal
import threading
import time
from dataclasses import dataclass

import numpy as np
import OpenEXR
import OpenImageIO
import pytest
from PIL import Image

from pyjulia4d.app import output
from pyjulia4d.app.output import OutputError, check_output_path, read_header, write_exr, write_image, write_png

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
    # linear light in, sRGB out (IEC 61966-2-1: 0.0031308 -> 12.92 x, else 1.055 x^(1/2.4) - 0.055)
    x = np.clip(np.nan_to_num(color).astype(np.float64), 0, 1)
    srgb = np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)
    np.testing.assert_array_equal(a[..., :3], np.rint(srgb * 255))
    assert im.info["pyjulia4d.scene"] == "[image]\nwidth = 7\n"
    assert [p.name for p in tmp_path.iterdir()] == ["out.png"]


def test_png_bands_match_the_transfer_function(tmp_path) -> None:
    """write_png encodes in bands of PNG_BAND_ROWS rows (peak memory): on an image of several
    bands and a ragged last one, every pixel is the sRGB transfer function of IEC 61966-2-1
    rounded to 8 bits, NaN as 0, values outside [0, 1] clipped."""
    rng = np.random.default_rng(3)
    h, w = 2 * output.PNG_BAND_ROWS + 7, 5
    color = rng.uniform(-0.1, 1.1, (h, w, 3)).astype(np.float32)
    color[0, 0, 0] = np.nan
    alpha = rng.uniform(0, 1, (h, w)).astype(np.float32)
    write_png(tmp_path / "b.png", color, alpha)
    got = np.asarray(Image.open(tmp_path / "b.png"))
    x = np.clip(np.nan_to_num(color.astype(np.float64)), 0, 1)
    srgb = np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)
    assert np.array_equal(got[..., :3], np.rint(srgb * 255).astype(np.uint8))
    assert np.array_equal(got[..., 3], np.rint(alpha.astype(np.float64) * 255).astype(np.uint8))


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
    with pytest.raises(OutputError, match=r"unsupported output format '\.jpg' \(use \.png, \.exr, \.tif or \.tiff\)"):
        write_image(tmp_path / "c.jpg", res, {})
    assert not (tmp_path / "c.jpg").exists()


def test_check_output_path(tmp_path) -> None:
    assert check_output_path(tmp_path / "x.exr") == tmp_path / "x.exr"
    with pytest.raises(OutputError) as info:
        check_output_path(tmp_path / "x.jpg")
    assert str(info.value) == f"{tmp_path / 'x.jpg'}: unsupported output format '.jpg' (use .png, .exr, .tif or .tiff)"
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
        monkeypatch.setattr(OpenImageIO.ImageOutput, "write_scanlines", boom)
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


@pytest.mark.parametrize("fmt", ["png", "exr", "tif"])
def test_a_link_is_written_through(tmp_path, fmt: str) -> None:
    """An output path that is a symbolic link: the file it names is replaced and the link stays
    (latest.png, a link to the newest picture, updates that picture); a link to a folder that
    does not exist is one line, with nothing written anywhere."""
    pics = tmp_path / "pics"
    pics.mkdir()
    (pics / f"a.{fmt}").write_bytes(b"old")
    link = tmp_path / f"latest.{fmt}"
    link.symlink_to(pics / f"a.{fmt}")
    write_image(link, FakeResult(*_color_alpha()), {"k": "v"})
    assert link.is_symlink() and os.readlink(link) == str(pics / f"a.{fmt}")
    assert (pics / f"a.{fmt}").read_bytes()[:3] != b"old" and _names(pics) == [f"a.{fmt}"]
    assert read_header(link)["k"] == "v"
    dangling = tmp_path / f"gone.{fmt}"
    dangling.symlink_to(tmp_path / "nowhere" / f"x.{fmt}")
    with pytest.raises(OutputError, match="No such file or directory") as info:
        write_image(dangling, FakeResult(*_color_alpha()), {})
    assert "\n" not in str(info.value) and dangling.is_symlink()
    assert _names(tmp_path) == sorted([f"gone.{fmt}", f"latest.{fmt}", "pics"])


# ------------------------------------------------------------ names, paths, signals

def _names(directory) -> list[str]:
    return sorted(p.name for p in directory.iterdir())


@pytest.mark.parametrize("stem", ["n" * 251, "é" * 125, "n" * 240 + ".tar"])
def test_longest_names_are_written(tmp_path, stem: str) -> None:
    """A name of up to NAME_MAX bytes is written: the temp name's stem is shortened to fit."""
    path = tmp_path / (stem + ".png")
    assert len(os.fsencode(path.name)) <= 255
    write_image(path, FakeResult(*_color_alpha()), {})
    assert _names(tmp_path) == [path.name]


@pytest.mark.parametrize("name", ["n" * 252 + ".png", "n" * 296 + ".exr", "é" * 126 + ".png"])
def test_too_long_name_refused(tmp_path, name: str) -> None:
    with pytest.raises(OutputError, match=r": file name too long \(\d+ bytes; this file system allows 255\)$"):
        check_output_path(tmp_path / name)
    assert _names(tmp_path) == []


def test_temp_name_fits(tmp_path) -> None:
    p = tmp_path / ("x" * 251 + ".exr")
    prefix, suffix = output.temp_affixes(p, 255)
    assert len(os.fsencode(prefix + suffix)) + output.RANDOM_CHARS <= 255
    assert prefix.startswith(".xxx") and suffix == ".exr"
    prefix, _ = output.temp_affixes(tmp_path / ("é" * 125 + ".png"), 255)
    assert prefix.startswith(".é") and len(os.fsencode(prefix)) + 4 + output.RANDOM_CHARS <= 255


def test_too_long_path_refused(tmp_path, monkeypatch) -> None:
    """A directory reachable by a path of ~4000 bytes, an output whose path (or its temp
    file's) passes PATH_MAX: refused up front, not after the render."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "d").mkdir()
    parent = "d/.." + "/d/.." * 799  # 3999 bytes, resolves to "."
    with pytest.raises(OutputError, match=r": path too long \(\d+ bytes with the temporary file's name; the limit is 4095\)$"):
        check_output_path(parent + "/" + "n" * 100 + ".png")
    with pytest.raises(OutputError, match=r": directory '.*': File name too long$"):
        check_output_path(parent + "/d/.." * 30 + "/x.png")
    assert _names(tmp_path) == ["d"]


def test_unusable_directories(tmp_path) -> None:
    (tmp_path / "f").write_text("")
    with pytest.raises(OutputError, match=r"f/x\.png: '.*f' is not a directory$"):
        check_output_path(tmp_path / "f" / "x.png")
    with pytest.raises(OutputError, match=r"^'': empty output path$"):
        check_output_path("")
    with pytest.raises(OutputError, match=r"names a directory \(trailing '/'\)$"):
        check_output_path(f"{tmp_path}/x.png/")
    if os.path.isdir("/proc/self"):  # a directory no one can create files in, root included
        with pytest.raises(OutputError, match=r"^/proc/x\.png: cannot create a file in '/proc': "):
            check_output_path("/proc/x.png")
    if os.geteuid() != 0:  # root writes into read-only directories
        ro = tmp_path / "ro"
        ro.mkdir(mode=0o555)
        with pytest.raises(OutputError, match=r"cannot create a file in .*: Permission denied$"):
            check_output_path(ro / "x.png")
    assert _names(tmp_path) == ["f"] + (["ro"] if os.geteuid() != 0 else [])


class _Signalled(BaseException):
    pass


@pytest.mark.parametrize("fmt", ["png", "exr"])
def test_signal_during_write_leaves_nothing(tmp_path, monkeypatch, fmt: str) -> None:
    """A signal whose handler raises (as the CLI's SIGTERM/SIGHUP one does) while the temp
    file is being written: the temp file is removed, the output never appears."""
    def handler(signum, frame):
        raise _Signalled(signum)

    def write_then_signal(real):
        def wrapped(*args, **kwargs):
            real(*args, **kwargs)  # the temp file exists and holds data now
            signal.raise_signal(signal.SIGTERM)
        return wrapped

    if fmt == "png":
        monkeypatch.setattr(Image.Image, "save", write_then_signal(Image.Image.save))
    else:
        monkeypatch.setattr(OpenImageIO.ImageOutput, "write_scanlines",
                            write_then_signal(OpenImageIO.ImageOutput.write_scanlines))
    old = signal.signal(signal.SIGTERM, handler)
    try:
        with pytest.raises(_Signalled):
            write_image(tmp_path / f"out.{fmt}", FakeResult(*_color_alpha()), {})
    finally:
        signal.signal(signal.SIGTERM, old)
    assert _names(tmp_path) == []


@pytest.mark.parametrize("call", [1, 2], ids=["probe", "write"])
def test_signal_while_creating_the_temp_file_is_deferred(tmp_path, monkeypatch, call: int) -> None:
    """A signal that arrives while a temp file is created (check_output_path's probe, then
    the write's own) is raised only once its name is known, so it is removed - also when
    another thread (as OpenCL's workers) is the one the signal is delivered to."""
    real = output.tempfile.mkstemp
    calls = []
    done = threading.Event()
    other = threading.Thread(target=done.wait)  # a thread that does not hold the signal
    other.start()

    def mkstemp_then_signal(*args, **kwargs):
        made = real(*args, **kwargs)
        calls.append(made)
        if len(calls) == call:
            os.kill(os.getpid(), signal.SIGTERM)  # to the process: any thread may take it
            time.sleep(0.05)  # Python runs the handler here unless it is deferred
        return made

    monkeypatch.setattr(output.tempfile, "mkstemp", mkstemp_then_signal)
    old = signal.signal(signal.SIGTERM, lambda s, f: (_ for _ in ()).throw(_Signalled(s)))
    try:
        with pytest.raises(_Signalled):
            write_image(tmp_path / "out.png", FakeResult(*_color_alpha()), {})
    finally:
        signal.signal(signal.SIGTERM, old)
        done.set()
        other.join()
    assert len(calls) == call and _names(tmp_path) == []


def test_png_edges_are_the_sets_own_colour_or_opaque(tmp_path):
    """Straight alpha: an edge pixel the set covers in part holds the set's colour, the
    background its missed samples saw taken out, so composited over that background it is the
    render again (to 8-bit rounding); with image.alpha = false the PNG is opaque RGB, the
    picture on shading.background as rendered."""
    from pyjulia4d import Scene, render
    from pyjulia4d.pipeline.colormap import linear_to_srgb, srgb_to_linear

    s = Scene.default().with_overrides(["shading.background=0,0.8,0", "image.samples=4", "image.width=96",
                                        "image.height=72"])
    r = render(s)
    out = tmp_path / "a.png"
    output.write_image(out, r)
    px = np.asarray(Image.open(out)).astype(np.float64) / 255
    a = r.alpha.astype(np.float64)
    part = (a > 0.2) & (a < 0.8)
    assert part.sum() > 20
    over = px[..., :3] * 0 + srgb_to_linear(px[..., :3]) * a[..., None] + (1 - a[..., None]) * np.array([0, 0.8, 0])
    got, want = linear_to_srgb(over[part]), linear_to_srgb(np.clip(r.color[part], 0, 1))
    assert np.abs(got - want).max() < 3 / 255 / np.min(a[part]) + 1e-3
    opaque = tmp_path / "o.png"
    output.write_image(opaque, dataclasses.replace(r, scene=s.with_overrides(["image.alpha=false"])))
    with Image.open(opaque) as im:
        assert im.mode == "RGB"
        rgb = np.asarray(im).astype(np.float64) / 255
    assert np.abs(rgb - linear_to_srgb(np.clip(r.color, 0, 1))).max() <= 0.5 / 255 + 1e-6
