"""Every writer of an output path turns what the system refuses into one line naming the
(shortened) path and the reason, with exit status 2 on the command line, and leaves nothing
behind, temporary files included: render, animate's frames and video, mesh, import-pov's
scene, the explorer's saves and RenderResult.save, each under ENAMETOOLONG, ELOOP and ENOTDIR
(made for real: a name too long, a link loop, a file as a folder) and EACCES, EROFS and ENOSPC
(the system's answer to making the temporary file beside the output, raised where it is
made: a test as root passes every permission, and no read-only or full disk is at hand)."""
from __future__ import annotations

import errno
import os
import tempfile
from pathlib import Path

import pytest

from pyjulia4d import Scene
from pyjulia4d.app import cli
from pyjulia4d.app.output import OutputError

ROOT = Path(__file__).resolve().parents[2]
SMALL = ["--width", "8", "--height", "6"]
ERRNOS = ("ENAMETOOLONG", "ELOOP", "ENOTDIR", "EACCES", "EROFS", "ENOSPC")


def reasons(code: str) -> tuple[str, ...]:
    """How a message may say the system's reason: its own words (os.strerror), or for a file
    standing where a folder must be, the checks' own "is not a directory"."""
    said = os.strerror(getattr(errno, code))
    return (said, "is not a directory") if code == "ENOTDIR" else (said,)


def _bad_path(tmp: Path, code: str, name: str) -> str:
    """An output path the system refuses with ``code``: made for real where it can be."""
    if code == "ENAMETOOLONG":
        return str(tmp / "/".join(["d" * 200] * 21) / name)
    if code == "ELOOP":
        (tmp / "loop").symlink_to(tmp / "loop")
        return str(tmp / "loop" / name)
    if code == "ENOTDIR":
        (tmp / "file").write_text("x")
        return str(tmp / "file" / name)
    return str(tmp / "out" / name)


@pytest.fixture
def refusing(monkeypatch):
    """For EACCES, EROFS, ENOSPC: making any file under the output folder fails with that code."""
    def arm(code: str, tmp: Path) -> None:
        if code in ("ENAMETOOLONG", "ELOOP", "ENOTDIR"):
            return
        (tmp / "out").mkdir()
        real_mkstemp, real_open, real_mkdir = tempfile.mkstemp, os.open, os.mkdir
        number = getattr(errno, code)

        def under(p) -> bool:
            return str(p).startswith(str(tmp / "out"))

        def mkstemp(*a, **k):
            if under(k.get("dir", a[2] if len(a) > 2 else "")):
                raise OSError(number, os.strerror(number))
            return real_mkstemp(*a, **k)

        def os_open(p, *a, **k):
            if under(p) and a and a[0] & os.O_CREAT:
                raise OSError(number, os.strerror(number), str(p))
            return real_open(p, *a, **k)

        def mkdir(p, *a, **k):
            if under(p):
                raise OSError(number, os.strerror(number), str(p))
            return real_mkdir(p, *a, **k)

        monkeypatch.setattr(tempfile, "mkstemp", mkstemp)
        monkeypatch.setattr(os, "open", os_open)
        monkeypatch.setattr(os, "mkdir", mkdir)
    return arm


def _files(tmp: Path) -> set[str]:
    return {str(p.relative_to(tmp)) for p in tmp.rglob("*") if p.is_file()} - {"file", "scene.pov"}


def _one_line(capsys, code: str, path: str) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    line = err[0]
    assert "Traceback" not in line and any(r in line for r in reasons(code)), line
    assert len(line) < 700, line   # the path shortened
    return line


POV = """camera { location <0, 0, -3> look_at <0, 0, 0> }
light_source { <2, 3, -4> color rgb 1 }
julia_fractal { <-0.2, 0.8, 0, 0> quaternion sqr max_iteration 8 precision 20 pigment { rgb 1 } }
"""

# (writer, the output's file name, the command line)
COMMANDS = {
    "render": ("a.png", lambda out, tmp: ["render", *SMALL, "-o", out]),
    "render_exr": ("a.exr", lambda out, tmp: ["render", *SMALL, "-o", out]),
    "animate": ("f_####.png", lambda out, tmp: ["animate", str(ROOT / "examples" / "c_morph.toml"), "--set",
                                                 "image.width=8", "--set", "image.height=6", "--frames", "0:1",
                                                 "-o", out]),
    "mesh": ("m.stl", lambda out, tmp: ["mesh", "--resolution", "16", "-o", out]),
    "import_pov": ("s.toml", lambda out, tmp: ["import-pov", str(tmp / "scene.pov"), "-o", out]),
}


@pytest.mark.parametrize("code", ERRNOS)
@pytest.mark.parametrize("writer", list(COMMANDS))
def test_a_command_names_the_refused_path_in_one_line(writer, code, tmp_path, capsys, refusing):
    (tmp_path / "scene.pov").write_text(POV)
    name, argv = COMMANDS[writer]
    out = _bad_path(tmp_path, code, name)
    refusing(code, tmp_path)
    assert cli.main(argv(out, tmp_path)) == 2
    _one_line(capsys, code, out)
    assert _files(tmp_path) == set()


@pytest.mark.parametrize("code", ERRNOS)
def test_animate_video_names_the_refused_path(code, tmp_path, capsys, refusing):
    pytest.importorskip("imageio_ffmpeg")
    frames = tmp_path / "frames"
    frames.mkdir()
    out = _bad_path(tmp_path, code, "v.mp4")
    refusing(code, tmp_path)
    argv = ["animate", str(ROOT / "examples" / "c_morph.toml"), "--set", "image.width=8", "--set",
            "image.height=6", "--frames", "0:1", "-o", str(frames / "f_####.png"), "--video", out]
    assert cli.main(argv) == 2
    _one_line(capsys, code, out)
    assert {f for f in _files(tmp_path) if not f.startswith("frames/")} == set()


@pytest.mark.parametrize("code", ERRNOS)
def test_render_result_save_names_the_refused_path(code, tmp_path, refusing):
    from pyjulia4d import render
    r = render(Scene.default().with_overrides(["image.width=8", "image.height=6"]))
    out = _bad_path(tmp_path, code, "a.png")
    refusing(code, tmp_path)
    with pytest.raises(OutputError) as e:
        r.save(out)
    assert any(r in str(e.value) for r in reasons(code)) and len(str(e.value)) < 700
    assert _files(tmp_path) == set()


@pytest.mark.parametrize("code", ERRNOS)
def test_the_explorers_saves_name_the_refused_path(code, tmp_path, refusing):
    """The explorer writes plain names into its folder: here the folder is what the system refuses."""
    from pyjulia4d.app.explore.session import Session
    scene = Scene.default().with_overrides(["image.width=8", "image.height=6"])
    folder = Path(_bad_path(tmp_path, code, "x")).parent
    s = Session(scene, lambda *a: None, folder, lambda *a: None)
    s.keyframes = [(0, scene), (4, scene.with_overrides(["fractal.c=-0.3,0.7,0,0"]))]
    refusing(code, tmp_path)
    for save in (lambda: s.save_scene("x.toml"), lambda: s.save_animation("y.toml")):
        with pytest.raises(ValueError) as e:
            save()
        assert any(r in str(e.value) for r in reasons(code)) and len(str(e.value)) < 700, str(e.value)
    assert _files(tmp_path) == set()
