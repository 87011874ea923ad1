"""CLI behaviour on bad input: exit 2, one stderr line, no traceback, no file.

Bad input fails before any kernel is built, so these are fast.  The in-process
tests swap in a fake ``pyjulia4d.render`` module and need no OpenCL at all.
"""
from __future__ import annotations

import os
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import pyjulia4d
from pyjulia4d.app import cli

PKG_ROOT = str(Path(pyjulia4d.__file__).resolve().parent.parent)


def run_cli(args: list[str], cwd: Path) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ)
    # the child imports the same pyjulia4d as this test process (installed or checkout)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [PKG_ROOT, env.get("PYTHONPATH")]))
    return subprocess.run(
        [sys.executable, "-m", "pyjulia4d", *args],
        cwd=cwd, env=env, capture_output=True, text=True, timeout=120,
    )


def _scene_file(tmp_path: Path, text: str = "[image]\nwidth = 8\nheight = 6\n") -> Path:
    path = tmp_path / "scene.toml"
    path.write_text(text)
    return path


BAD_ARGS = {
    "unknown-key": (["--set", "march.zres=3"], "march.zres: unknown key"),
    "bad-int": (["--set", "fractal.max_iter=abc"], "fractal.max_iter: expected an integer, got 'abc'"),
    "nan": (["--set", "march.epsilon=nan"], "march.epsilon: not a finite number"),
    "inf": (["--set", "fractal.c=0,inf,0,0"], "fractal.c: element 1: not a finite number"),
    "zero-up": (["--set", "camera.up=0,0,0"], "camera.up: zero-length vector"),
    "zero-limbo": (["--set", "camera.limbo=0,0,0,0"], "camera.limbo: zero-length vector"),
    "zero-normal": (["--set", "slice.normal=0,0,0,0"], "slice.normal: zero-length vector"),
    "width-0": (["--width", "0"], "image.width: must be in [1, 2147483647], got 0"),
    "height-abc": (["--height", "abc"], "image.height: expected an integer, got 'abc'"),
    "max-iter-0": (["--set", "fractal.max_iter=0"], "fractal.max_iter: must be in [1, 1000000], got 0"),
    "epsilon-0": (["--set", "march.epsilon=0"], "march.epsilon: must be in [1e-12, 1], got 0"),
    "malformed": (["--set", "fractal.c"], "fractal.c: malformed override, expected SECTION.KEY=VALUE"),
    "bad-ext": (["-o", "out.jpg"], "out.jpg: unsupported output format '.jpg' (use .png, .exr, .tif or .tiff)"),
    "no-dir": (["-o", "nowhere/out.png"], "nowhere/out.png: directory 'nowhere' does not exist"),
    "huge-normal": (["--set", "slice.normal=1e300,1e300,1e300,1e300"],
                    "slice.normal: element 0: must be in [-1e6, 1e6], got 1e+300"),
    "huge-specular": (["--set", "shading.specular=1e308"], "shading.specular: must be in [0, 1e3], got 1e+308"),
    "width-twice": (["--width", "8", "--set", "image.width=9"],
                    "image.width: given twice, by --width and by --set image.width; use one"),
    "height-twice": (["--set", "image.height = 6", "--height", "6"],
                     "image.height: given twice, by --height and by --set image.height; use one"),
    "name-too-long": (["-o", "n" * 300 + ".png"],
                      # a message shows a long path's start and end (files.shown_path)
                      "n" * 120 + "..." + "n" * 113 + ".png: file name too long (304 bytes; this file system "
                      "allows 255)"),
    "empty-set": (["--set", "="], "--set: missing key in '=', expected SECTION.KEY=VALUE"),
    "unknown-flag": (["--bogus"], "unrecognized arguments: --bogus (see --help)"),
    "missing-value": (["--width"], "argument --width: expected one argument (see --help)"),
    "channels-png": (["--channels", "Z"], "--channels: 'Z': a PNG holds RGBA only; write .exr for Z, N or P"),
    "channels-unknown": (["-o", "out.exr", "--channels", "Z,Q"],
                         "--channels: unknown channel group 'Q'; use names from RGBA, Z, N, P"),
    "channels-empty": (["-o", "out.exr", "--channels", ""],
                       "--channels: '': empty name in the list; use names from RGBA, Z, N, P"),
}


@pytest.mark.parametrize("name", list(BAD_ARGS))
def test_bad_input_exits_2(tmp_path: Path, name: str) -> None:
    args, message = BAD_ARGS[name]
    # every other case also reads a (valid) scene file
    scene = ["scene.toml"] if list(BAD_ARGS).index(name) % 2 else []
    _scene_file(tmp_path)
    before = set(tmp_path.iterdir())
    p = run_cli(["render", *scene, *args], tmp_path)
    assert p.returncode == 2, p.stderr
    assert "Traceback" not in p.stderr
    assert p.stderr.splitlines() == [f"pyjulia4d: error: {message}"]
    assert p.stdout == ""
    assert set(tmp_path.iterdir()) == before


@pytest.mark.parametrize(
    "text,start",
    [
        ("[fractal\n", "pyjulia4d: error: scene.toml: invalid TOML: "),
        ("[zork]\n", "pyjulia4d: error: zork: unknown key"),
        ("[camera]\nup = [0, 0, 0]\n", "pyjulia4d: error: camera.up: zero-length vector"),
    ],
)
def test_bad_scene_file(tmp_path: Path, text: str, start: str) -> None:
    _scene_file(tmp_path, text)
    p = run_cli(["render", "scene.toml"], tmp_path)
    assert p.returncode == 2 and "Traceback" not in p.stderr
    lines = p.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith(start), p.stderr
    assert sorted(x.name for x in tmp_path.iterdir()) == ["scene.toml"]


def test_missing_scene_file(tmp_path: Path) -> None:
    p = run_cli(["render", "missing.toml"], tmp_path)
    assert p.returncode == 2 and "Traceback" not in p.stderr
    lines = p.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("pyjulia4d: error: missing.toml: cannot read: ")
    assert list(tmp_path.iterdir()) == []


def test_unknown_device(tmp_path: Path) -> None:
    p = run_cli(["render", "--device", "no-such-device-xyz"], tmp_path)
    assert p.returncode == 2 and "Traceback" not in p.stderr
    lines = p.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("pyjulia4d: error: "), p.stderr
    assert list(tmp_path.iterdir()) == []


def test_usage_error_exits_2(tmp_path: Path) -> None:
    p = run_cli(["render", "--bogus"], tmp_path)
    assert p.returncode == 2 and "Traceback" not in p.stderr
    assert p.stderr == "pyjulia4d: error: unrecognized arguments: --bogus (see --help)\n"


def test_scene_file_too_large(tmp_path: Path) -> None:
    """/dev/zero is read no further than the size bound: one line, status 2."""
    p = run_cli(["render", "/dev/zero"], tmp_path)
    assert p.returncode == 2, p.stderr
    assert p.stderr == "pyjulia4d: error: /dev/zero: larger than 1 MiB, not a scene file\n"
    assert list(tmp_path.iterdir()) == []


def test_devices_command(tmp_path: Path) -> None:
    p = run_cli(["devices"], tmp_path)
    assert "Traceback" not in p.stderr
    if p.returncode == 0:
        lines = p.stdout.splitlines()
        # one line per device, then why the default was chosen and whether Intel's runtime
        # from PyPI is registered
        assert lines and all(line[:1].isdigit() for line in lines[:-1])
        assert ", the default: " in lines[-2] and lines[-1].startswith("Intel's CPU runtime from PyPI: ")
    else:  # no OpenCL platform on this machine
        assert p.returncode == 2 and len(p.stderr.splitlines()) == 1


# ------------------------------------------------------------ in process, fake render


class FakeResult:
    def __init__(self, h: int, w: int) -> None:
        self.color = np.full((h, w, 3), 0.5, np.float32)
        self.alpha = np.ones((h, w), np.float32)
        self.device_name = "fake device"
        self.seconds = 1.234
        self.hit_fraction = 0.412
        self.capped = 0
        self.guards = {"ulp_step": 0, "normal_fallback": 0}
        self.fell_back = ""

    def exr_channels(self) -> dict[str, np.ndarray]:
        return {"R": self.color[..., 0], "A": self.alpha}

    def report(self, stated_p99=None) -> tuple[dict[str, str], str]:
        return {"pyjulia4d.device": self.device_name}, ""


class FakeRender:
    """Stands in for pyjulia4d.render.render; records calls, optionally raises."""

    def __init__(self) -> None:
        self.calls: list[tuple] = []
        self.exc: BaseException | None = None

    def __call__(self, scene, device=None, progress=False, force=False, outputs=None, store=None,
                 fallback=None) -> FakeResult:
        self.calls.append((scene, device, progress))
        if self.exc is not None:
            raise self.exc
        return FakeResult(scene.image.height, scene.image.width)


@pytest.fixture
def fake_render(monkeypatch: pytest.MonkeyPatch) -> FakeRender:
    fake = FakeRender()
    mod = types.ModuleType("pyjulia4d.opencl.executor")
    mod.render = fake  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "pyjulia4d.opencl.executor", mod)
    monkeypatch.setattr(pyjulia4d, "render", mod, raising=False)
    monkeypatch.setattr(cli, "select_device", lambda spec: f"device<{spec}>")
    return fake


def test_render_success(tmp_path, monkeypatch, fake_render, capsys) -> None:
    monkeypatch.chdir(tmp_path)
    assert cli.main(["render", "--width", "8", "--height", "6", "--set", "fractal.max_iter=5"]) == 0
    out = capsys.readouterr().out
    assert out == "rendered julia.png (8x6) in 1.23 s on fake device\n"
    assert cli.main(["render", "--width", "8", "--height", "6", "--verbose"]) == 0
    assert capsys.readouterr().out == "rendered julia.png (8x6) in 1.23 s on fake device, 41.2% of pixels hit\n"
    (scene, device, progress), _ = fake_render.calls
    assert scene.fractal.max_iter == 5 and device == "device<None>" and progress is True
    assert Image.open(tmp_path / "julia.png").size == (8, 6)


def test_render_default_name_from_scene(tmp_path, monkeypatch, fake_render, capsys) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "blob.toml").write_text("[image]\nwidth = 4\nheight = 3\n")
    assert cli.main(["render", "blob.toml", "--device", "cpu"]) == 0
    assert (tmp_path / "blob.png").exists()
    assert fake_render.calls[0][1] == "device<cpu>"


@pytest.mark.parametrize(
    "exc,status,line",
    [
        (ValueError("render.float: no fp64"), 2, "pyjulia4d: error: render.float: no fp64"),
        (KeyboardInterrupt(), 130, "pyjulia4d: interrupted"),
    ],
)
def test_render_failure(tmp_path, monkeypatch, fake_render, capsys, exc, status, line) -> None:
    monkeypatch.chdir(tmp_path)
    fake_render.exc = exc
    assert cli.main(["render", "--width", "4", "--height", "3", "-o", "x.exr"]) == status
    captured = capsys.readouterr()
    assert captured.err.splitlines() == [line] and captured.out == ""
    assert list(tmp_path.iterdir()) == []


def test_hopeless_settings_refused_by_the_cli(tmp_path: Path) -> None:
    """A legal scene estimated at hours of work: one line naming the key, status 2, no file."""
    out = tmp_path / "big.png"
    p = run_cli(["render", "-o", str(out), "--width", "3840", "--height", "2160",
                 "--set", "march.method=fixed", "--set", "march.z_resolution=1000000000"], tmp_path)
    assert p.returncode == 2, p.stderr
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("pyjulia4d: error: march.z_resolution: 1000000000 ")
    assert "--force" in lines[0] and "Traceback" not in p.stderr
    assert not out.exists()


def test_precision_warning_is_one_line(tmp_path: Path) -> None:
    """A warning (epsilon below float32's spacing) is one stderr line; the render still runs."""
    out = tmp_path / "w.png"
    p = run_cli(["render", "-o", str(out), "--width", "8", "--height", "6",
                 "--set", "march.epsilon=1e-9"], tmp_path)
    assert p.returncode == 0, p.stderr
    warn = [l for l in p.stderr.splitlines() if "warning" in l]
    assert len(warn) == 1 and warn[0].startswith("pyjulia4d: warning: march.epsilon: 1e-09 is below")
    assert "RuntimeWarning" not in p.stderr and out.exists()
