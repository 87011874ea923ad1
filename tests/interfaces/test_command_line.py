"""The command line people expect: --version, help, `keys`, rendering an image again from the
scene it holds, the optional extras missing, and what a first render on a new scene met
(camera.fit beyond the coordinate range, double precision refused before any build, the
cluster's header camera)."""
from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import pyjulia4d
from pyjulia4d import Scene, SceneError
from pyjulia4d.app import cli
from pyjulia4d.scene import keys
from pyjulia4d.scene.ranges import key_names, valid_range

from processes import cli_process as _cli


# ------------------------------------------------------------------ the command line

def test_version(capsys) -> None:
    with pytest.raises(SystemExit) as e:
        cli.main(["--version"])
    assert e.value.code == 0
    assert capsys.readouterr().out.strip() == f"pyjulia4d {pyjulia4d.__version__}"


def test_help_names_the_command(capsys) -> None:
    with pytest.raises(SystemExit):
        cli.main(["--help"])
    assert capsys.readouterr().out.startswith("usage: pyjulia4d ")


def test_keys_lists_every_key_with_default_range_and_meaning(capsys) -> None:
    assert cli.main(["keys"]) == 0
    out = capsys.readouterr().out
    for key in key_names():
        i = out.index(f"\n{key} = " if out.index(key) else f"{key} = ")
        block = out[i:].strip().splitlines()[:3]
        assert block[0] == f"{key} = {keys.default_text(key)}"
        assert block[1] == f"    range: {valid_range(key)}"
        assert block[2].startswith("    ") and len(block[2].strip()) > 3
    assert set(keys.MEANINGS) == set(key_names())


def test_keys_defaults_are_the_scenes() -> None:
    """Every default printed reads back as the default scene's value (camera.fit aside; the
    march keys that march.quality "auto" sets are custom's defaults, which it takes for the
    default scene's quaternion square)."""
    d = Scene.default()
    for key in key_names():
        if key == "camera.fit":
            continue
        section, _, name = key.partition(".")
        text = keys.default_text(key)
        back = Scene.from_dict({"camera": {"position": list(Scene.default().camera.position)}},
                               [f"{key}={text.strip('[]').strip(chr(34))}"] if text != "[]" else [])
        assert getattr(getattr(back, section), name) == getattr(getattr(d, section), name), key


def test_keys_section_and_bad_section(capsys) -> None:
    assert cli.main(["keys", "image"]) == 0
    out = capsys.readouterr().out
    assert [ln.split(" = ")[0] for ln in out.splitlines() if not ln.startswith(" ")] == \
        ["image.width", "image.height", "image.samples", "image.adaptive", "image.bits", "image.alpha",
         "image.exr", "image.noise", "image.exposure", "image.tonemap", "image.denoise"]
    assert cli.main(["keys", "octonion"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pyjulia4d: error: octonion: unknown section") and err.count("\n") == 1


@pytest.mark.parametrize("fmt", [".png", ".exr"])
def test_render_an_image_again(tmp_path: Path, fmt: str) -> None:
    """render IMAGE reads the scene from its header - the camera camera.fit chose included -
    and gives the same picture."""
    first = tmp_path / f"first{fmt}"
    assert cli.main(["render", "--width", "40", "--height", "30", "-o", str(first)]) == 0
    again = tmp_path / "again.png"
    assert cli.main(["render", str(first), "-o", str(again)]) == 0
    if fmt == ".png":
        assert np.array_equal(np.asarray(Image.open(first)), np.asarray(Image.open(again)))
    from pyjulia4d.app.output import read_header

    assert read_header(first)["pyjulia4d.scene"] == read_header(again)["pyjulia4d.scene"]
    assert "fit = false" in read_header(again)["pyjulia4d.scene"]


def test_render_an_image_default_output_and_overrides(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert cli.main(["render", "--width", "20", "--height", "16", "-o", "a.png"]) == 0
    assert cli.main(["render", "a.png", "--width", "10"]) == 0
    with Image.open(tmp_path / "a-rerender.png") as im:
        assert im.size == (10, 16)


@pytest.mark.parametrize("make,why", [
    (lambda p: None, "cannot read: no such file"),
    (lambda p: p.write_bytes(b"not a png"), "not a readable PNG file"),
    (lambda p: p.mkdir(), "is a directory, not an image"),
    (lambda p: Image.new("RGB", (4, 4)).save(p), "holds no pyjulia4d scene"),
    (lambda p: os.mkfifo(p), "not a regular file"),   # was "no such file"
])
def test_render_an_image_bad(tmp_path: Path, capsys, make, why) -> None:
    src = tmp_path / "src.png"
    make(src)
    before = set(tmp_path.iterdir())
    assert cli.main(["render", str(src), "-o", str(tmp_path / "out.png")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"pyjulia4d: error: {src}: {why}") and err.count("\n") == 1
    assert set(tmp_path.iterdir()) == before


@pytest.mark.parametrize("name,data,what", [
    ("src.tif", b"II*\x00garbage", "TIF"),              # tifffile logs what it found wrong: not shown
    ("src.tif", b"MM\x00*\x00\x00\x00\x08" + b"\xff" * 40, "TIF"),
    ("src.exr", b"v/1\x01" + b"\x00" * 50, "EXR"),
    ("src.png", b"\x89PNG\r\n\x1a\n" + b"\x00" * 20, "PNG"),
])
def test_a_damaged_image_is_one_line(tmp_path: Path, name, data, what) -> None:
    """In a process of its own, where nothing catches a library's log records: the one line and
    nothing else on the standard error (this process's own test logging would hide them)."""
    src = tmp_path / name
    src.write_bytes(data)
    p = _cli(["render", str(src), "-o", str(tmp_path / "out.png")], tmp_path)
    assert p.returncode == 2
    assert p.stderr == f"pyjulia4d: error: {src}: not a readable {what} file (damaged, truncated or another " \
                       f"format)\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]


@pytest.mark.parametrize("description", ["{", "[" * 100000 + "]" * 100000, '"a string"', "made by a scanner"])
def test_a_tiff_described_by_another_program_holds_no_scene(tmp_path: Path, capsys, description) -> None:
    """A readable TIFF whose description is not pyjulia4d's JSON object: it holds no scene (it was
    called damaged, "not a readable TIF file")."""
    import tifffile

    src = tmp_path / "src.tif"
    tifffile.imwrite(src, np.zeros((4, 4, 4), np.uint8), description=description)
    assert cli.main(["render", str(src), "-o", str(tmp_path / "out.png")]) == 2
    assert capsys.readouterr().err == f"pyjulia4d: error: {src}: holds no pyjulia4d scene (not rendered by " \
                                      f"pyjulia4d, or its metadata was stripped)\n"


def test_render_an_image_with_a_bad_embedded_scene(tmp_path: Path, capsys) -> None:
    from PIL import PngImagePlugin

    info = PngImagePlugin.PngInfo()
    info.add_text("pyjulia4d.scene", "[fractal]\nmax_iter = -3\n")
    src = tmp_path / "src.png"
    Image.new("RGBA", (4, 4)).save(src, pnginfo=info)
    assert cli.main(["render", str(src), "-o", str(tmp_path / "out.png")]) == 2
    assert capsys.readouterr().err == "pyjulia4d: error: fractal.max_iter: must be in [1, 1000000], got -3\n"
    assert not (tmp_path / "out.png").exists()


# ------------------------------------------------------------------ extras

@pytest.mark.parametrize("args,message", [
    (["--workers", "2"], "pyjulia4d: error: --workers: needs Dask distributed, which is not installed: "
                         "pip install 'pyjulia4d[cluster]'"),
    (["--scheduler", "tcp://127.0.0.1:1"], "pyjulia4d: error: --scheduler: needs Dask distributed"),
    (["--video", "out.mp4", "--workers", "0"], "pyjulia4d: error: out.mp4: video needs imageio-ffmpeg, which is "
                                                "not installed: pip install 'pyjulia4d[video]'"),
])
def test_missing_extras_get_one_line(tmp_path: Path, args, message) -> None:
    scene = tmp_path / "a.toml"
    scene.write_text("[image]\nwidth = 8\nheight = 6\n[animation]\nframes = 2\n"
                     "[[keyframe]]\nframe = 0\nfractal.max_iter = 8\n[[keyframe]]\nframe = 1\nfractal.max_iter = 9\n")
    p = _cli(["animate", str(scene), "-o", str(tmp_path / "f_##.png"), *args], tmp_path,
             prelude="import sys; sys.modules['distributed'] = None; sys.modules['imageio_ffmpeg'] = None; ")
    assert p.returncode == 2, p.stderr
    assert p.stderr.startswith(message) and p.stderr.count("\n") == 1
    assert sorted(f.name for f in tmp_path.iterdir()) == ["a.toml"]


def test_animate_without_the_cluster_extra_renders_in_process(tmp_path: Path) -> None:
    scene = tmp_path / "a.toml"
    scene.write_text("[image]\nwidth = 8\nheight = 6\n[animation]\nframes = 2\n"
                     "[[keyframe]]\nframe = 0\nfractal.max_iter = 8\n[[keyframe]]\nframe = 1\nfractal.max_iter = 9\n")
    p = _cli(["animate", str(scene), "-o", str(tmp_path / "f_##.png")], tmp_path,
             prelude="import sys; sys.modules['distributed'] = None; ")
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "f_00.png").is_file() and (tmp_path / "f_01.png").is_file()


# ------------------------------------------------------------------ bugs of first contact

def test_camera_fit_beyond_the_coordinate_range_names_the_bailout() -> None:
    """bailout 1e6 on a pair without a polynomial escape bound: the bound is the bailout
    ball, which no camera within +-1e6 frames; refused before any pass, naming the key that
    made it so (not camera.position, which the user never set)."""
    from pyjulia4d import render

    scene = Scene.from_dict({"fractal": {"algebra": "cquat", "bailout": 1e6}, "image": {"width": 16, "height": 12}})
    with pytest.raises(SceneError, match=r"^fractal\.bailout: camera\.fit: the first pass would need a camera"):
        render(scene)


def test_double_refused_before_any_build(monkeypatch) -> None:
    """A device without cl_khr_fp64: the one-line message comes before camera.fit's pass, the
    probe or any program build."""
    from pyjulia4d.opencl import build
    render_module = sys.modules["pyjulia4d.opencl.executor"]   # the package's name "render" is the function

    def no_build(*a, **k):
        raise AssertionError("a program was built")

    monkeypatch.setattr(render_module, "has_fp64", lambda dev: False)
    monkeypatch.setattr(build, "program", no_build)
    scene = Scene.from_dict({"render": {"float": "double"}, "image": {"width": 16, "height": 12}})
    assert scene.camera.fit
    with pytest.raises(SceneError, match=r"^render\.float: device '.*' has no cl_khr_fp64"):
        render_module.render(scene)


def test_cluster_tiles_record_the_fitted_camera() -> None:
    """render --workers: the result's scene (the header's) is the camera the tiles used."""
    from harness import device
    from pyjulia4d import render
    from pyjulia4d.app.cluster import render_tiled

    scene = Scene.from_dict({"image": {"width": 48, "height": 36}})
    result, used = render_tiled(None, scene, tile=16)   # the tiles' device: PYJULIA4D_DEVICE's, else the default
    assert result.scene == used and not used.camera.fit
    whole = render(scene, device=device())              # the same device: its fit is the same to the bit
    assert whole.scene == used
    assert np.array_equal(whole.color, result.color)
