"""The Python interface's inputs: scenes checked when built in Python, render()'s own
arguments, hostile objects, paths of the wrong type, saved headers, the animation, mesh and
reference interfaces - each a one-line error naming the argument before anything is written."""
from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import pytest
from PIL import Image

import pyjulia4d
from pyjulia4d import Scene, SceneError
from pyjulia4d.app import cli



# ------------------------------------------------------------------ Python scenes

D = Scene.default()


@pytest.mark.parametrize("build,message", [
    (lambda: dataclasses.replace(D.fractal, max_iter=-5), "fractal.max_iter: must be in [1, 1000000], got -5"),
    (lambda: dataclasses.replace(D.fractal, c=(float("nan"), 0, 0, 0)), "fractal.c: element 0: not a finite number"),
    (lambda: dataclasses.replace(D.image, width=0), "image.width: must be in [1, 2147483647], got 0"),
    (lambda: dataclasses.replace(D.fractal, algebra="octonion"), "fractal.algebra: expected one of"),
    (lambda: dataclasses.replace(D.march, epsilon="small"), "march.epsilon: expected a number"),
    (lambda: dataclasses.replace(D, fractal="x"), "fractal: expected a pyjulia4d.scene.Fractal"),
    (lambda: dataclasses.replace(D, camera=dataclasses.replace(D.camera, target=D.camera.position)),
     "camera.target: equals camera.position"),
    (lambda: dataclasses.replace(D, fractal=dataclasses.replace(D.fractal, algebra="cquat", function="sin")),
     "fractal.function: 'sin' is not defined for the cquat algebra"),
    (lambda: dataclasses.replace(D, march=dataclasses.replace(D.march, near=2.0, far=1.0)),
     "march.far: must be greater than march.near"),
    (lambda: pyjulia4d.scene.Light(), "shading.lights[]: give exactly one of position and direction"),
])
def test_python_scenes_are_checked_when_built(build, message) -> None:
    with pytest.raises(SceneError) as e:
        build()
    assert str(e.value).startswith(message)


def test_python_values_are_normalised() -> None:
    f = dataclasses.replace(D.fractal, c=[0, 1, 0, 0], bailout=3)
    assert f.c == (0.0, 1.0, 0.0, 0.0) and isinstance(f.bailout, float)
    cam = dataclasses.replace(D.camera, position=[1, 2, 3])
    assert cam.position == (1.0, 2.0, 3.0, 0.0)
    assert hash(Scene(fractal=f, camera=cam))   # frozen and hashable, as from a file


def test_render_refuses_a_non_scene() -> None:
    from pyjulia4d import render

    with pytest.raises(SceneError, match=r"^scene: expected a pyjulia4d.Scene, got dict$"):
        render({"fractal": {}})


def test_default_scene_and_command_line_scene_differ_in_camera_only() -> None:
    a, b = Scene.default().to_dict(), Scene.from_dict({}).to_dict()
    assert b["camera"]["fit"] is True and a["camera"]["fit"] is False
    a["camera"]["fit"] = True
    assert a == b


# ------------------------------------------------------------------ render()'s own arguments

@pytest.mark.parametrize("kw,message", [
    (dict(outputs=3), "outputs: expected a list of output names"),
    (dict(outputs=[1, 2]), "outputs: expected output names"),
    (dict(outputs=["bogus"]), "outputs: unknown output 'bogus'"),
    (dict(region=(0.5, 0, 4, 4)), "region: expected (x0, y0, width, height), whole numbers"),
    (dict(region="abcd"), "region: expected (x0, y0, width, height)"),
    (dict(region=(0, 0, 100, 100)), "region: (0, 0, 100, 100) is not inside the 16x12 image"),
    (dict(device=123), "device: expected None, a pyopencl Device or a --device text"),
    (dict(lanes=7), "lanes: expected one of 1, 4, 8, 16 rays per work-item, got 7"),
    (dict(lanes=0), "lanes: expected one of 1, 4, 8, 16"),
    (dict(lanes="x"), "lanes: expected one of 1, 4, 8, 16"),
    (dict(lanes=True), "lanes: expected one of 1, 4, 8, 16"),
    (dict(tile=0), "tile: expected a tile side in [1, 8192] pixels, got 0"),
    (dict(tile=10 ** 9), "tile: expected a tile side in [1, 8192]"),
    (dict(tile="a"), "tile: expected a tile side"),
    (dict(progress="yes"), "progress: expected True or False, got 'yes'"),
    (dict(force="no"), "force: expected True or False"),
    (dict(calibrate=None), "calibrate: expected True or False"),
])
def test_render_arguments_are_checked(kw, message) -> None:
    """Bad Python arguments get the one-line SceneError naming the argument, before any
    kernel is built - never a TypeError, a ZeroDivisionError or a driver's build failure."""
    from pyjulia4d import render

    with pytest.raises(SceneError) as e:
        render(Scene.default().with_overrides(["image.width=16", "image.height=12"]), **kw)
    assert str(e.value).startswith(message)


class Hostile:
    """An object whose every protocol method fails: a bad argument must still be named in
    one line, never let the object's own exception through."""
    def __iter__(self):
        raise RuntimeError("boom")

    def __eq__(self, other):
        raise RuntimeError("boom")

    def __hash__(self):
        return 1

    def __repr__(self):
        raise RuntimeError("boom")

    def __len__(self):
        return 4


@pytest.mark.parametrize("kw,message", [
    (dict(region=Hostile()), "region: expected (x0, y0, width, height), whole numbers, got <a Hostile>"),
    (dict(outputs=Hostile()), "outputs: expected a list of output names"),
    (dict(outputs=[Hostile(), Hostile()]), "outputs: expected a list of output names"),
    (dict(tile=Hostile()), "tile: expected a tile side in [1, 8192] pixels, got <a Hostile>"),
    (dict(lanes=Hostile()), "lanes: expected one of 1, 4, 8, 16 rays per work-item, got <a Hostile>"),
    (dict(force=Hostile()), "force: expected True or False, got <a Hostile>"),
])
def test_hostile_objects_are_named_in_one_line(kw, message) -> None:
    from pyjulia4d import render

    with pytest.raises(SceneError) as e:
        render(Scene.default().with_overrides(["image.width=16", "image.height=12"]), **kw)
    assert str(e.value).startswith(message) and "\n" not in str(e.value)


def test_hostile_objects_in_the_scene_and_output_interfaces(tmp_path) -> None:
    from pyjulia4d.app.mesh import build_mesh
    from pyjulia4d.app.output import OutputError, write_image

    with pytest.raises(SceneError, match=r"^overrides: expected a list of SECTION.KEY=VALUE texts, got <a Hostile>$"):
        Scene.default().with_overrides(Hostile())
    with pytest.raises(SceneError, match=r"^--resolution: expected a whole number .* got <a Hostile>$"):
        build_mesh(Scene.default(), resolution=Hostile())
    with pytest.raises(OutputError, match=r"^output path: expected a str or an os.PathLike, got Hostile$"):
        write_image(Hostile(), None)


@pytest.mark.parametrize("path", [0, 5, None, b"scene.toml", 2.5])
def test_a_scene_path_must_be_a_path(path) -> None:
    """An int would be opened as a file descriptor - and closed after the read: refused
    before anything is opened; so are bytes, None and other types."""
    import os

    r, w = os.pipe()
    try:
        with pytest.raises(SceneError, match=r"^scene: expected the path of a scene file"):
            Scene.from_toml(path if path != 5 else r)
        os.fstat(r)   # still open
    finally:
        os.close(r)
        os.close(w)


@pytest.mark.parametrize("path", [5, None, b"/tmp/x.png", ["a.png"]])
def test_an_output_path_must_be_a_path(path, tmp_path) -> None:
    from pyjulia4d.app.output import OutputError, write_image

    with pytest.raises(OutputError, match=r"^output path: expected a str or an os.PathLike"):
        write_image(path, None)


def _path_calls():
    from pyjulia4d.app import animation, video
    from pyjulia4d.app.explore.notebook import Explorer
    from pyjulia4d.app.output import check_output_path
    from pyjulia4d.interop.povray import writer

    return [(check_output_path, "output path: expected"), (animation.check_pattern, "frame pattern: expected"),
            (lambda p: animation.strip([p], "sheet.png"), "frame path: expected"),
            (lambda p: animation.strip([], p), "contact sheet path: expected"),
            (video.check_video_path, "video path: expected"), (video.read_frame, "frame path: expected"),
            (writer.import_pov, "POV-Ray scene path: expected"),
            (lambda p: writer.check_toml_path(p, "a.pov"), "scene file path: expected"),
            (lambda p: Explorer(folder=p), "--folder: expected")]


@pytest.mark.parametrize("bad", [3, None, b"a.png", Hostile()], ids=["int", "None", "bytes", "hostile"])
def test_every_path_argument_takes_a_path(bad) -> None:
    """Each function of the package that takes a path refuses anything but a str or an
    os.PathLike in one line of its own error (a ValueError), before it opens anything."""
    for call, message in _path_calls():
        with pytest.raises(ValueError) as e:
            call(bad)
        assert str(e.value).startswith(message) and "a str or an os.PathLike" in str(e.value), call


def test_a_file_that_is_no_frame_is_named(tmp_path) -> None:
    from pyjulia4d.app.output import OutputError
    from pyjulia4d.app.video import read_frame

    fake = tmp_path / "frame.png"
    fake.write_text("not a picture")
    with pytest.raises(OutputError, match=r"frame.png: cannot read it as a frame \(UnidentifiedImageError"):
        read_frame(fake)
    with pytest.raises(OutputError, match=r"missing.png: cannot read it as a frame \(FileNotFoundError"):
        read_frame(tmp_path / "missing.png")


def test_device_and_workers_of_the_wrong_type() -> None:
    from pyjulia4d.app.cluster import check_workers, worker_device
    from pyjulia4d.opencl.devices import DeviceError, select_device

    for bad in (3, Hostile(), b"cpu"):
        with pytest.raises(DeviceError, match=r"^device: expected None or a text"):
            select_device(bad)
        with pytest.raises(DeviceError, match=r"^device: expected None or a text"):
            worker_device(bad)
    for bad in (Hostile(), 2.5, True, None):
        with pytest.raises(SceneError, match=r"^--workers: expected a whole number of workers"):
            check_workers(bad)
    assert check_workers(3) == 3 and check_workers(" 2 ") == 2


@pytest.mark.parametrize("header,message", [
    (5, "header: expected None or a dict of text entries, got int"),
    (Hostile(), "header: expected None or a dict of text entries, got Hostile"),
    ({"k" * 80: "v"}, "header: key 'kkk"),
    ({"": "v"}, "header: key '': expected 1 to 79 printable Latin-1 characters"),
    ({"ключ": "v"}, "header: key 'ключ': expected 1 to 79 printable Latin-1"),
    ({" a": "v"}, "header: key ' a'"),
    ({"a\x00b": "v"}, "header: key 'a\\x00b'"),
    ({"a": 1}, "header: a: expected text without NUL"),
    ({"a": "x\x00"}, "header: a: expected text without NUL"),
    ({"pyjulia4d.scene": "junk"}, "header: key 'pyjulia4d.scene': the pyjulia4d.* entries are the render's own"),
])
@pytest.mark.parametrize("ext", ["png", "exr", "tif"])
def test_a_saved_images_header_is_checked_before_anything_is_written(header, message, ext, tmp_path) -> None:
    from pyjulia4d import render
    from pyjulia4d.app.output import OutputError

    r = render(Scene.default().with_overrides(["image.width=8", "image.height=6"]))
    with pytest.raises(OutputError) as e:
        r.save(tmp_path / f"x.{ext}", header=header)
    assert str(e.value).startswith(message) and "\n" not in str(e.value)
    assert list(tmp_path.iterdir()) == []
    r.save(tmp_path / f"x.{ext}", header={"artist": "A. Person", "note": "ünïcode välue"})
    from pyjulia4d.app.output import read_header

    got = read_header(tmp_path / f"x.{ext}")
    assert got["artist"] == "A. Person" and got["note"] == "ünïcode välue" and "pyjulia4d.scene" in got


@pytest.mark.parametrize("bad", [0, -1.0, float("nan"), float("inf"), True, "1e-3", Hostile()])
def test_a_reports_stated_bound_is_checked(bad) -> None:
    from pyjulia4d import render

    r = render(Scene.default().with_overrides(["image.width=8", "image.height=6"]))
    with pytest.raises(SceneError, match=r"^stated_p99: expected None or a positive finite number"):
        r.report(bad)


def test_the_animation_interface_names_bad_arguments(tmp_path) -> None:
    """docs/animation.md's Python interface: keyframes.load, Animation.scene and with_camera."""
    from pyjulia4d.scene import keyframes

    src = tmp_path / "a.toml"
    src.write_text("[animation]\nframes = 3\n[[keyframe]]\nframe = 0\nfractal.c = [0, 0.5, 0, 0]\n"
                   "[[keyframe]]\nframe = 2\nfractal.c = [0, 0.7, 0, 0]\n")
    anim = keyframes.load(src)
    cases = [(lambda: keyframes.load(src, Hostile()), "overrides: expected a list of SECTION.KEY=VALUE texts"),
             (lambda: keyframes.load(src, 5), "overrides: expected a list of SECTION.KEY=VALUE texts, got 5"),
             (lambda: keyframes.from_table(5), "scene: expected a table, got 5"),
             (lambda: anim.scene("1"), "frame: expected a whole frame number, got '1'"),
             (lambda: anim.scene(Hostile()), "frame: expected a whole frame number, got <a Hostile>"),
             (lambda: anim.scene(3), "--frames: frame 3 is outside 0..2"),
             (lambda: anim.with_camera(Hostile(), [0, 0, 0]), "camera.position: expected a list of 3 or 4 numbers"),
             (lambda: anim.with_camera([1, 2, 3], None), "camera.target: expected a list of 3 or 4 numbers"),
             (lambda: keyframes.parse_frames(5, 3), "--frames: expected A:B")]
    for call, message in cases:
        with pytest.raises(SceneError) as e:
            call()
        assert str(e.value).startswith(message), str(e.value)
    assert anim.scene(1).fractal.c[1] == pytest.approx(0.6)


def test_animate_checks_its_arguments_before_any_frame(tmp_path) -> None:
    from pyjulia4d.app import animation
    from pyjulia4d.scene import keyframes

    src = tmp_path / "a.toml"
    src.write_text("[image]\nwidth = 8\nheight = 6\n[animation]\nframes = 2\n")
    anim = keyframes.load(src)
    pattern = str(tmp_path / "f" / "m_##.png")
    for kw, message in [(dict(frames=5), "frames: expected a list of frame numbers, got 5"),
                        (dict(frames=Hostile()), "frames: expected a list of frame numbers"),
                        (dict(frames=[0, "1"]), "frames: expected whole frame numbers, got '1'"),
                        (dict(frames=[0, 0]), "frames: a frame is named twice"),
                        (dict(force=Hostile()), "force: expected True or False"),
                        (dict(progress="yes"), "progress: expected True or False"),
                        (dict(on_written=5), "on_written: expected None or a callable")]:
        with pytest.raises(SceneError) as e:
            animation.animate(anim, pattern, workers=0, **kw)
        assert str(e.value).startswith(message), str(e.value)
    with pytest.raises(SceneError, match=r"^anim: expected an Animation"):
        animation.animate(Scene.default(), pattern, workers=0)
    assert list(tmp_path.iterdir()) == [src]


@pytest.mark.parametrize("bad", [5, b"/tmp", Hostile()], ids=["int", "bytes", "hostile"])
def test_an_image_stores_folder_is_a_path(bad) -> None:
    from pyjulia4d.pipeline.store import ImageStore

    with pytest.raises(SceneError, match=r"^store: expected None or a folder, a str or an os.PathLike"):
        ImageStore(bad)


def test_a_mesh_and_a_header_path_are_checked(tmp_path) -> None:
    from pyjulia4d.app.mesh import write_mesh
    from pyjulia4d.app.output import OutputError, read_header

    with pytest.raises(OutputError, match=r"^mesh path: expected a str or an os.PathLike, got int"):
        write_mesh(5, None)
    with pytest.raises(OutputError, match=r"m.stl: expected a MeshResult to write, got NoneType"):
        write_mesh(tmp_path / "m.stl", None)
    with pytest.raises(OutputError, match=r"^image path: expected a str or an os.PathLike, got Hostile"):
        read_header(Hostile())
    assert read_header(tmp_path / "missing.png") is None and list(tmp_path.iterdir()) == []


def test_mesh_executor_is_checked_before_it_is_compared() -> None:
    from pyjulia4d.app.mesh import build_mesh

    with pytest.raises(SceneError, match=r"^executor: expected 'opencl' or 'reference', got <a Hostile>"):
        build_mesh(Scene.default(), resolution=8, executor=Hostile())


def test_one_output_name_is_one_output() -> None:
    from pyjulia4d import render

    r = render(Scene.default().with_overrides(["image.width=16", "image.height=12"]), outputs="depth")
    assert r.depth is not None and r.color is None


@pytest.mark.parametrize("bad", [None, 3, "scene", {"fractal": {}}])
def test_reference_refuses_a_non_scene(bad) -> None:
    from pyjulia4d import reference

    with pytest.raises(SceneError, match=r"^scene: expected a pyjulia4d.Scene"):
        reference.render(bad)


@pytest.mark.parametrize("text,message", [
    ("[fractal\n", "src.png (its scene): invalid TOML"),
    ("[animation]\nframes = 3\n", "animation: a keyframed scene"),
    ("x" * (1 << 20 + 1), "src.png: its scene is larger than 1 MiB"),
])
def test_render_an_image_whose_scene_is_bad(tmp_path: Path, capsys, monkeypatch, text, message) -> None:
    from PIL import PngImagePlugin

    monkeypatch.chdir(tmp_path)
    info = PngImagePlugin.PngInfo()
    info.add_text("pyjulia4d.scene", text)
    Image.new("RGBA", (4, 4)).save("src.png", pnginfo=info)
    assert cli.main(["render", "src.png"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"pyjulia4d: error: {message}") and err.count("\n") == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["src.png"]


@pytest.mark.parametrize("build, hint", [
    (lambda: Scene.from_dict({"shading": {"colour": [1, 0, 0]}}), "; did you mean 'shading.color'?"),
    (lambda: Scene.default().with_overrides(["camra.fov=30"]), "; did you mean 'camera.fov'?"),
    (lambda: Scene.default().with_overrides(["shading.fov=30"]), "; did you mean 'camera.fov'?"),
    (lambda: Scene.default().with_overrides(["march.z_res=300"]), "; did you mean 'march.z_resolution'?"),
    (lambda: Scene.from_dict({"fractal": {"algebra": "quaternian"}}), "; did you mean 'quaternion'?"),
    (lambda: Scene.from_dict({"shading": {"coloring": "Iteration"}}), "; did you mean 'iteration'?"),
])
def test_an_unknown_key_or_word_names_the_one_meant(build, hint) -> None:
    with pytest.raises(SceneError) as e:
        build()
    assert str(e.value).endswith(hint) and "\n" not in str(e.value)


def test_nothing_is_suggested_where_nothing_is_close() -> None:
    with pytest.raises(SceneError) as e:
        Scene.default().with_overrides(["march.qqqqqq=1"])
    assert str(e.value) == "march.qqqqqq: unknown key"


def test_colour_map_names_take_any_case() -> None:
    assert Scene.from_dict({"shading": {"colormap": "SPECTRAL"}}).shading.colormap == "Spectral"
    assert Scene.default().with_overrides(["shading.colormap=Viridis"]).shading.colormap == "viridis"


def test_lights_take_the_scene_files_toml_on_the_command_line() -> None:
    toml = Scene.default().with_overrides(
        ["shading.lights=[{position = [1, 2, 3], color = [1, 0, 0]}, {direction = [0, 1, 0], intensity = 2}]"])
    words = Scene.default().with_overrides(["shading.lights=position 1,2,3 color 1,0,0; direction 0,1,0 intensity 2"])
    assert toml.shading.lights == words.shading.lights and len(toml.shading.lights) == 2
    with pytest.raises(SceneError, match="not a TOML array of light tables"):
        Scene.default().with_overrides(["shading.lights=[{position = [1, 2, 3]"])


@pytest.mark.parametrize("value, says", [
    ([[0, 1, 0, 0]], "expected 2 to 16 stops, got 1"),
    ([[0.5, 1, 0, 0], [0.2, 0, 0, 1]], "positions rise"),
    ([[0, 1, 0, 0], [1, 2, 0, 0]], "expected numbers in [0, 1]"),
    ([[0, 1, 0], [1, 0, 0, 1]], "expected [position, r, g, b]"),
    ("[[0, 1, 0, 0], [1", "not a TOML array of stops"),
])
def test_a_bad_gradient_is_one_line(value, says) -> None:
    with pytest.raises(SceneError, match=re.escape(says)) as e:
        Scene.from_dict({"shading": {"gradient": value}})
    assert "\n" not in str(e.value)
