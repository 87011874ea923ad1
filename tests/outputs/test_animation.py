"""Keyframed animation (pyjulia4d/scene/keyframes.py, animation.py, video.py): interpolation,
bad keyframes, numbered frames with their scene in the header, resuming after SIGKILL,
and the video played back."""
from __future__ import annotations

import math
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import pyjulia4d
from pyjulia4d.app import cli
from pyjulia4d.app.animation import animate, frame_path, remove_stale_temps
from pyjulia4d.app.output import read_header
from pyjulia4d.scene.keyframes import from_table, interpolate, load
from pyjulia4d.scene.model import Scene

ROOT = Path(pyjulia4d.__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"

MORPH = """
[fractal]
max_iter = 8
[camera]
position = [1.8, 1.6, -2.2, 0.0]
[image]
width = {w}
height = {h}
[animation]
frames = {frames}
fps = 12
interpolation = "linear"
[[keyframe]]
frame = 0
fractal.c = [0.0, 0.0, 0.0, 0.0]
[[keyframe]]
frame = {last}
fractal.c = [-0.803762, -0.40615, 0.0, 0.0]
"""


def morph_file(tmp_path: Path, frames: int = 6, w: int = 48, h: int = 36) -> Path:
    p = tmp_path / "morph.toml"
    p.write_text(MORPH.format(frames=frames, last=frames - 1, w=w, h=h))
    return p


# ---------------------------------------------------------------- interpolation


def test_every_method_passes_through_its_keyframes():
    frames, values = (0, 4, 10, 11), [np.array([0.0, 1.0]), np.array([2.0, -1.0]), np.array([3.0, 5.0]),
                                      np.array([-1.0, 0.0])]
    for method in ("linear", "smooth", "catmull-rom"):
        for f, v in zip(frames, values):
            assert np.array_equal(interpolate(frames, values, f, method), v)
        # held before the first keyframe and after the last
        assert np.array_equal(interpolate(frames, values, -3, method), values[0])
        assert np.array_equal(interpolate(frames, values, 20, method), values[-1])


def test_linear_and_smooth_between_two_keyframes():
    assert interpolate((0, 10), [np.array(0.0), np.array(1.0)], 2.5, "linear") == pytest.approx(0.25)
    # smoothstep 3u^2 - 2u^3 at u = 0.25: 0.15625; its slope is 0 at the keyframes
    assert interpolate((0, 10), [np.array(0.0), np.array(1.0)], 2.5, "smooth") == pytest.approx(0.15625)
    near = interpolate((0, 10), [np.array(0.0), np.array(1.0)], 1e-3, "smooth")
    assert 0 < near < 1e-6


def test_catmull_rom_reproduces_a_quadratic_between_inner_keyframes():
    """Uniform keyframes of p(t) = t^2: the central-difference tangents are exact, so the
    Hermite cubic is p itself on the inner segments."""
    ts = (0, 3, 6, 9, 12)
    vals = [np.array(float(t * t)) for t in ts]
    for t in np.linspace(3, 9, 13):
        assert interpolate(ts, vals, t, "catmull-rom") == pytest.approx(t * t, rel=1e-12)
    # and linear, which does not: the chord lies above the parabola
    assert interpolate(ts, vals, 4.5, "linear") > 4.5 ** 2


def test_keys_not_keyframed_stay_and_integers_round():
    anim = from_table({"fractal": {"c": [-0.2, 0.8, 0, 0]}, "camera": {"position": [1.8, 1.6, -2.2, 0]},
                       "animation": {"frames": 5, "interpolation": "linear"},
                       "keyframe": [{"frame": 0, "fractal": {"max_iter": 4}, "shading.ao": 0.0},
                                    {"frame": 4, "fractal": {"max_iter": 9}, "shading.ao": 0.4}]})
    iters = [anim.scene(n).fractal.max_iter for n in range(5)]
    assert iters == [4, 5, 7, 8, 9]  # 4 + 5n/4 rounded: 4, 5.25, 6.5, 7.75, 9
    assert [anim.scene(n).shading.ao for n in range(5)] == pytest.approx([0.0, 0.1, 0.2, 0.3, 0.4])
    assert all(anim.scene(n).fractal.c == (-0.2, 0.8, 0.0, 0.0) for n in range(5))
    assert all(anim.scene(n).camera == anim.base.camera for n in range(5))


def _turned(degrees: float) -> str:
    """A keyframe of the camera turned through the xw plane by ``degrees`` (position and limbo)."""
    c, s_ = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    r = lambda v: round(v, 6) + 0.0   # noqa: E731  (+ 0.0: no -0.0)
    return (f"[[keyframe]]\nframe = {round(degrees / 5)}\ncamera.position = [{r(1.8 * c)}, 1.6, -2.2, {r(1.8 * s_)}]\n"
            f"camera.limbo = [{r(-s_)}, 0.0, 0.0, {r(c)}]\n")


KEYED_CAMERA = """
[camera]
position = [1.8, 1.6, -2.2, 0.0]
target = [0.0, 0.0, 0.0, 0.0]
[animation]
frames = 25
""" + "".join(_turned(d) for d in (0, 30, 60, 90, 120))


def test_a_keyed_camera_is_reorthonormalised_every_frame(tmp_path):
    """The camera turned about the set in the x-w plane by keyframed positions and limbos,
    every 30 degrees (the way before slice.turn): each frame's up and limbo orthonormal."""
    scene = tmp_path / "keyed.toml"
    scene.write_text(KEYED_CAMERA)
    anim = load(scene)
    assert not anim.base.camera.fit  # the keyframes place the camera: no framing pass
    for n in range(0, anim.frames, 5):
        cam = anim.scene(n).camera
        f = np.subtract(cam.target, cam.position)
        f /= np.linalg.norm(f)
        up, limbo = np.array(cam.up), np.array(cam.limbo)
        assert np.linalg.norm(up) == pytest.approx(1) and np.linalg.norm(limbo) == pytest.approx(1)
        assert abs(up @ f) < 1e-12 and abs(limbo @ f) < 1e-12 and abs(up @ limbo) < 1e-12
    # a quarter turn: the picture's x axis has become w (limbo = -e_x)
    assert np.allclose(anim.scene(18).camera.limbo, (-1, 0, 0, 0), atol=1e-6)


def test_a_turn_through_w_is_two_keyframes():
    """examples/w_rotation.toml: slice.turn's xw angle keyed linearly from 0 to 355 degrees,
    5 degrees a frame; its frame at 90 degrees sees what the keyed camera's quarter turn saw
    (the camera turned into w: position (0, 1.6, -2.2, 1.8), limbo -e_x)."""
    from pyjulia4d.geometry.camera import camera_frame

    anim = load(EXAMPLES / "w_rotation.toml")
    assert anim.frames == 72 and [anim.scene(n).slice.turn[2] for n in (0, 1, 18, 71)] == pytest.approx([0, 5, 90, 355])
    fr = camera_frame(anim.scene(18))
    assert np.allclose(fr.position, (0.0, 1.6, -2.2, 1.8), atol=1e-9)


@pytest.mark.parametrize("name", ["c_morph", "w_rotation", "slice_sweep"])
def test_the_examples_load_and_every_frame_is_valid(name):
    anim = load(EXAMPLES / f"{name}.toml")
    assert anim.frames >= 24 and anim.tracks
    scenes = [anim.scene(n) for n in range(anim.frames)]
    key = anim.tracks[0].key
    section, _, k = key.partition(".")
    assert getattr(getattr(scenes[0], section), k) != getattr(getattr(scenes[-1], section), k)


# ---------------------------------------------------------------- bad input


BAD = {
    "unknown-key": ("[[keyframe]]\nframe = 0\nfractal.cc = [0, 0, 0, 0]\n", "keyframe[1].fractal.cc: unknown key"),
    "non-numeric": ('[[keyframe]]\nframe = 0\nfractal.algebra = "cquat"\n',
                    "keyframe[1].fractal.algebra: not numeric"),
    "light-eye": ('[[keyframe]]\nframe = 0\nshading.light = "eye"\n', "keyframe[1].shading.light: not numeric"),
    "size": ("[[keyframe]]\nframe = 0\nimage.width = 64\n", "keyframe[1].image.width: cannot change between frames"),
    "no-frame": ("[[keyframe]]\nfractal.max_iter = 5\n", "keyframe[1].frame: missing"),
    "out-of-order": ("[[keyframe]]\nframe = 5\nfractal.max_iter = 5\n[[keyframe]]\nframe = 2\nfractal.max_iter = 6\n",
                     "keyframe[2].frame: 2 is out of order"),
    "duplicated": ("[[keyframe]]\nframe = 5\nfractal.max_iter = 5\n[[keyframe]]\nframe = 5\nfractal.max_iter = 6\n",
                   "keyframe[2].frame: 5 is duplicated"),
    "bad-value": ("[[keyframe]]\nframe = 0\nfractal.c = [0, nan, 0, 0]\n",
                  "keyframe[1].fractal.c: element 1: not a finite number"),
    # keyframes valid one by one, frame 3's interpolated scene is not: the target
    # meets the position on the way
    "frame-invalid": ("[camera]\nfit = false\n[[keyframe]]\nframe = 0\ncamera.target = [0.0, 0.0, 0.0, 0.0]\n"
                      "[[keyframe]]\nframe = 6\ncamera.target = [3.6, 3.2, -4.4, 0.0]\n"
                      "[animation]\ninterpolation = \"linear\"\n",
                      "frame[3].camera.target: equals camera.position"),
    # catmull-rom overshoots a [0, 1] key between keyframes
    "overshoot": ("[[keyframe]]\nframe = 0\nshading.ao = 0.0\n[[keyframe]]\nframe = 2\nshading.ao = 1.0\n"
                  "[[keyframe]]\nframe = 6\nshading.ao = 1.0\n[[keyframe]]\nframe = 8\nshading.ao = 0.0\n",
                  "frame[3].shading.ao: must be in [0, 1]"),
    "anim-key": ("[animation]\nspeed = 2\n[[keyframe]]\nframe = 0\nshading.ao = 0.0\n", "animation.speed: unknown key"),
    "fps": ("[animation]\nfps = 0\n[[keyframe]]\nframe = 0\nshading.ao = 0.0\n", "animation.fps: must be in (0, 1e3]"),
    "fit-and-keys": ("[camera]\nfit = true\n[[keyframe]]\nframe = 0\ncamera.position = [1, 2, 3]\n",
                     "camera.fit: true, but keyframes move camera.position"),
    "base-invalid": ("[fractal]\nmax_iter = 0\n", "fractal.max_iter: must be in [1, 1000000], got 0"),
}
BAD_ARGS = {
    "frames-range": (["--frames", "3:40"], "--frames: 3:40 is not within 0:5"),
    "frames-text": (["--frames", "a:b"], "--frames: expected A:B"),
    "no-hash": (["-o", "out.png"], "the file name needs one run of '#'"),
    "two-runs": (["-o", "a_##_##.png"], "found 2"),
    "bad-ext": (["-o", "f_##.jpg"], "unsupported output format '.jpg'"),
    "video-ext": (["--video", "out.avi"], "out.avi: unsupported video format '.avi' (use .mp4, .webm or .gif)"),
    "video-dir": (["--video", "nowhere/out.mp4"], "directory 'nowhere' does not exist"),
    "workers": (["--workers", "-1"], "--workers: must be in [0, 1024], got -1"),
    "workers-text": (["--workers", "two"], "--workers: expected a whole number of workers"),
    "both": (["--workers", "2", "--scheduler", "tcp://127.0.0.1:8786"], "--workers: give --workers"),
    "scheduler": (["--scheduler", "localhost"], "--scheduler: expected an address such as tcp://HOST:8786"),
    "set-anim": (["--set", "animation.frames=0"], "animation.frames: must be in [1, 1000000], got 0"),
    "channels": (["--channels", "Z"], "--channels: 'Z': a PNG holds RGBA only"),
}


def _only_input(tmp_path: Path, keep: set[str]) -> list[str]:
    return sorted(p.name for p in tmp_path.iterdir() if p.name not in keep)


@pytest.mark.parametrize("name", sorted(BAD))
def test_bad_keyframes_one_line_status_2_no_file(tmp_path, capsys, monkeypatch, name):
    text, expected = BAD[name]
    (tmp_path / "anim.toml").write_text(text)
    monkeypatch.chdir(tmp_path)
    rc = cli.main(["animate", "anim.toml", "-o", "out/f_####.png", "--video", "v.mp4", "--workers", "0"])
    err = capsys.readouterr().err
    assert rc == 2
    assert err.count("\n") == 1 and err.startswith("pyjulia4d: error: ") and expected in err, err
    assert _only_input(tmp_path, {"anim.toml"}) == []


@pytest.mark.parametrize("name", sorted(BAD_ARGS))
def test_bad_animate_arguments_one_line_status_2_no_file(tmp_path, capsys, monkeypatch, name):
    args, expected = BAD_ARGS[name]
    morph_file(tmp_path)
    monkeypatch.chdir(tmp_path)
    base = ["animate", "morph.toml"] + ([] if "-o" in args else ["-o", "out/f_####.png"])
    rc = cli.main(base + args + ([] if "--workers" in args or "--scheduler" in args else ["--workers", "0"]))
    err = capsys.readouterr().err
    assert rc == 2
    assert err.count("\n") == 1 and err.startswith("pyjulia4d: error: ") and expected in err, err
    assert _only_input(tmp_path, {"morph.toml"}) == []


# ---------------------------------------------------------------- frames and headers


def test_exr_frames_carry_their_number_and_scene(tmp_path):
    import tomllib

    anim = load(morph_file(tmp_path, frames=4))
    out = tmp_path / "exr"
    s = animate(anim, str(out / "m_##.exr"), workers=0)
    assert sorted(s.rendered) == [0, 1, 2, 3] and not s.current
    for n in range(4):
        hdr = read_header(out / f"m_{n:02d}.exr")
        assert hdr["pyjulia4d.frame"] == str(n)
        back = Scene.from_dict(tomllib.loads(hdr["pyjulia4d.scene"]))
        assert back == anim.scene(n)
    assert anim.scene(0).fractal.c == (0.0, 0.0, 0.0, 0.0)
    assert anim.scene(3).fractal.c == (-0.803762, -0.40615, 0.0, 0.0)


def test_only_changed_frames_render_again(tmp_path):
    """Frames whose recorded scene still matches are kept; a changed keyframe re-renders only
    the frames it moves (linear: the frames after the keyframe before it)."""
    text = MORPH.format(frames=6, last=5, w=48, h=36).replace(
        "[[keyframe]]\nframe = 5\n", "[[keyframe]]\nframe = 3\nshading.ao = 0.6\n[[keyframe]]\nframe = 5\n"
        "shading.ao = 0.6\n")
    (tmp_path / "a.toml").write_text(text)
    pattern = str(tmp_path / "f" / "a_#.png")
    first = animate(load(tmp_path / "a.toml"), pattern, workers=0)
    assert sorted(first.rendered) == list(range(6))
    stamp = {n: os.stat(frame_path(pattern, n)).st_mtime_ns for n in range(6)}
    (tmp_path / "a.toml").write_text(text.replace("frame = 5\nshading.ao = 0.6", "frame = 5\nshading.ao = 0.2"))
    second = animate(load(tmp_path / "a.toml"), pattern, workers=0)
    assert sorted(second.rendered) == [4, 5] and sorted(second.current) == [0, 1, 2, 3]
    assert all(os.stat(frame_path(pattern, n)).st_mtime_ns == stamp[n] for n in range(4))
    # another size: every frame is another scene
    third = animate(load(tmp_path / "a.toml", ["image.width=40"]), pattern, workers=0)
    assert sorted(third.rendered) == list(range(6))


def test_stale_temporary_files_are_removed(tmp_path):
    frames = [tmp_path / f"j_{n:03d}.png" for n in range(3)]
    stale = [tmp_path / ".j_001.abcd_123.png", tmp_path / ".j_002.x1y2z3w4.png"]
    other = [tmp_path / ".j_001.toolongname.png", tmp_path / "j_001.png.bak", tmp_path / ".k_001.abcd_123.png"]
    for p in stale + other:
        p.write_bytes(b"")
    assert sorted(remove_stale_temps(frames)) == sorted(stale)
    assert all(p.exists() for p in other) and not any(p.exists() for p in stale)


def _pixels(path: Path) -> np.ndarray:
    with Image.open(path) as im:
        return np.asarray(im)


def _env() -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), env.get("PYTHONPATH")]))
    return env


def test_sigkill_mid_run_then_resume_renders_each_missing_frame_once(tmp_path):
    """SIGKILL an animation (a 1-worker local cluster, the default on a CPU) once some of its
    frames are written; the rerun renders exactly the missing ones, leaves no temporary
    file - in the frames' folder, nor in $TMPDIR, where it removes the killed run's cluster
    folder - and the frames equal an uninterrupted (in-process) run's."""
    n = 40
    scene = morph_file(tmp_path, frames=n, w=96, h=72)
    pattern = str(tmp_path / "run" / "m_###.png")
    cmd = [sys.executable, "-m", "pyjulia4d", "animate", str(scene), "-o", pattern, "--workers", "1"]
    temp = tmp_path / "temp"   # the runs' $TMPDIR: what the killed run's cluster left there
    temp.mkdir()
    env = {**_env(), "TMPDIR": str(temp)}
    proc = subprocess.Popen(cmd, cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 60
    try:
        while time.monotonic() < deadline:
            done = [p for p in (tmp_path / "run").glob("m_*.png")] if (tmp_path / "run").exists() else []
            if len(done) >= 3 or proc.poll() is not None:
                break
            time.sleep(0.005)
        proc.send_signal(signal.SIGKILL)
    finally:
        proc.wait(timeout=30)
        proc.stdout.close()
        proc.stderr.close()
    assert proc.returncode == -signal.SIGKILL, "the run ended before it could be killed"
    time.sleep(0.5)  # the worker process notices its parent is gone
    survived = sorted((tmp_path / "run").glob("m_*.png"))
    assert 3 <= len(survived) < n
    # whatever a kill leaves is whole: every frame file decodes, with its scene recorded
    stamps = {p.name: os.stat(p).st_mtime_ns for p in survived}
    for p in survived:
        assert read_header(p)["pyjulia4d.frame"] == str(int(p.stem.split("_")[1]))
    # a temp file the kill may have left (and one planted as a kill mid-write leaves it)
    (tmp_path / "run" / ".m_039.k1ll_ed2.png").write_bytes(b"\x89PNG partial")

    assert [p.name.split("-")[2] for p in temp.iterdir()] == [str(proc.pid)]   # the killed run's own folder
    again = subprocess.run(cmd, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
    assert again.returncode == 0, again.stderr
    assert list(temp.iterdir()) == []   # the rerun removed it, and its own
    m = re.search(r"rendered (\d+) frames? .*; (\d+) already up to date", again.stdout)
    assert m, again.stdout
    assert int(m.group(1)) == n - len(survived) and int(m.group(2)) == len(survived)
    files = sorted(os.listdir(tmp_path / "run"))
    assert files == [f"m_{k:03d}.png" for k in range(n)]  # every frame, no temporary file
    for p in survived:  # not rendered twice
        assert os.stat(p).st_mtime_ns == stamps[p.name]

    whole = animate(load(scene), str(tmp_path / "whole" / "m_###.png"), workers=0)
    assert sorted(whole.rendered) == list(range(n))
    for k in range(n):
        a, b = tmp_path / "run" / f"m_{k:03d}.png", tmp_path / "whole" / f"m_{k:03d}.png"
        assert np.array_equal(_pixels(a), _pixels(b)), k
        assert read_header(a)["pyjulia4d.scene"] == read_header(b)["pyjulia4d.scene"]


# ---------------------------------------------------------------- video


@pytest.mark.parametrize("ext", ["mp4", "webm"])
def test_video_plays_back_with_the_frames(tmp_path, capsys, ext):
    import imageio.v2 as imageio

    scene = morph_file(tmp_path, frames=6, w=48, h=36)
    pattern = str(tmp_path / "f" / "m_##.png")
    video = tmp_path / f"m.{ext}"
    assert cli.main(["animate", str(scene), "-o", pattern, "--video", str(video), "--workers", "0"]) == 0
    line = capsys.readouterr().out
    assert f"video {video} (6 frames at 12 fps)" in line
    reader = imageio.get_reader(str(video), format="FFMPEG")
    try:
        assert reader.get_meta_data()["fps"] == pytest.approx(12)
        got = [f for f in reader]
    finally:
        reader.close()
    assert len(got) == 6
    for k, frame in enumerate(got[:3]):
        src = _pixels(Path(pattern.replace("##", f"{k:02d}")))[..., :3].astype(float)
        assert frame.shape == src.shape
        assert np.abs(frame.astype(float) - src).mean() < 4.0  # lossy, but these frames
    # consecutive frames differ (the set morphs) more than the codec's error
    assert np.abs(got[0].astype(float) - got[5].astype(float)).mean() > 10.0
    assert not any(p.name.startswith(".") for p in tmp_path.iterdir())


def test_a_gif_loops_the_frames(tmp_path, capsys):
    """--video OUT.gif: an animated GIF through Pillow, each frame the rendered one within its
    own palette's dithering, at animation.fps in GIF's hundredths of a second, looping."""
    from PIL import Image, ImageSequence

    scene = morph_file(tmp_path, frames=6, w=48, h=36)
    pattern = str(tmp_path / "f" / "m_##.png")
    gif = tmp_path / "m.gif"
    assert cli.main(["animate", str(scene), "-o", pattern, "--video", str(gif), "--workers", "0"]) == 0
    assert f"video {gif} (6 frames at 12 fps)" in capsys.readouterr().out
    with Image.open(gif) as im:
        assert im.format == "GIF" and im.n_frames == 6 and im.info.get("loop") == 0
        frames = [np.asarray(f.convert("RGB")).astype(float) for f in ImageSequence.Iterator(im)]
        durations = [f.info["duration"] for f in ImageSequence.Iterator(im)]
    assert durations == [80] * 6   # 1 / 12 s in hundredths: 8
    for k, frame in enumerate(frames):
        src = _pixels(Path(pattern.replace("##", f"{k:02d}")))[..., :3].astype(float)
        assert frame.shape == src.shape
        assert np.abs(frame - src).mean() < 4.0   # 256 colours, dithered
    assert np.abs(frames[0] - frames[5]).mean() > 10.0
    assert not any(p.name.startswith(".") for p in tmp_path.iterdir())


def test_the_closing_line_says_where_the_frames_were_rendered():
    """Frames rendered in this process (workers=0) are said so; they were "1 worker"."""
    from pyjulia4d.app.animation import Summary, closing_line
    from pyjulia4d.app.cluster import LOCAL_WORKER

    here = Summary(range(2), rendered=[0, 1], seconds=1.0, workers={(LOCAL_WORKER, 7)}, devices={"CPU X"})
    assert closing_line(here, "f_#.png", None, 24.0).startswith(
        "rendered 2 frames to f_#.png in 1.00 s, 0.50 s per frame on CPU X (in this process)")
    two = Summary(range(2), rendered=[0, 1], seconds=1.0, workers={("tcp://a:1", 7), ("tcp://b:1", 8)},
                  devices={"CPU X"})
    assert "on CPU X (on 2 workers)" in closing_line(two, "f_#.png", None, 24.0)


# ---------------------------------------------------------------- motion blur

SPIN = """
[image]
width = 48
height = 36
[camera]
position = [1.8, 1.6, -2.2, 0.0]
target = [0.0, 0.0, 0.0, 0.0]
[animation]
frames = 3
interpolation = "linear"
shutter = 0.5
motion_samples = 4
[[keyframe]]
frame = 0
slice.turn = [0, 0, 0, 0, 0, 0]
[[keyframe]]
frame = 2
slice.turn = [40, 0, 0, 0, 0, 0]
"""


def test_motion_blur_moments_spread_over_the_shutter():
    import tomllib

    anim = from_table(tomllib.loads(SPIN))
    assert anim.moments(1) == (0.8125, 0.9375, 1.0625, 1.1875)   # 1 + 0.5 ((k + 1/2) / 4 - 1/2)
    assert anim.scene_at(0.9375).slice.turn[0] == pytest.approx(40 * 0.9375 / 2)
    assert from_table(tomllib.loads(SPIN.replace("shutter = 0.5", "shutter = 0"))).moments(1) == ()


def test_a_blurred_frame_is_the_mean_of_its_moments(tmp_path):
    # the file animate writes holds exactly the mean colour and alpha of the frame's renders
    # at its moments (pipeline/motion.py), and says so in its header; without a shutter the
    # frame is the plain render of its scene
    import tomllib

    from pyjulia4d.app.output import write_image
    from pyjulia4d.opencl.executor import render
    from pyjulia4d.pipeline.motion import blend

    anim = from_table(tomllib.loads(SPIN))
    animate(anim, str(tmp_path / "f_####.png"), frames=[1], progress=False)
    parts = [render(anim.scene_at(t)) for t in anim.moments(1)]
    mean = blend(parts, anim.shutter)
    assert np.allclose(mean.color, np.mean([p.color for p in parts], axis=0), atol=1e-6)
    mean.scene = anim.scene(1)
    write_image(tmp_path / "want.png", mean)
    got, want = (np.asarray(Image.open(tmp_path / n)) for n in ("f_0001.png", "want.png"))
    assert np.array_equal(got, want)
    assert read_header(tmp_path / "f_0001.png")["pyjulia4d.motion_blur"].startswith("4 moments over 0.5 of a frame")
    still = np.asarray(Image.open(tmp_path / "want.png"))
    plain = render(anim.scene(1))
    assert not np.array_equal(mean.alpha, plain.alpha)   # the turn through the shutter shows
    assert still.shape == got.shape


def test_motion_blur_noise_is_that_of_the_mean():
    # K independent path-traced estimates: the mean's variance is sum var_k / K^2
    from pyjulia4d.opencl.executor import render
    from pyjulia4d.pipeline.motion import blend

    s = Scene.default().with_overrides(["image.width=24", "image.height=18", "shading.integrator=path",
                                        "image.samples=4"])
    a, b = render(s), render(s, first_sample=4)
    m = blend([a, b], 0.5)
    cov = a.film.noise > 0
    assert np.allclose(m.film.noise[cov], np.sqrt(a.film.noise[cov] ** 2 + b.film.noise[cov] ** 2) / 2, rtol=1e-5)
    assert np.array_equal(m.film.paths, a.film.paths + b.film.paths)


@pytest.mark.parametrize("setting, says", [("shutter = 1.5", "animation.shutter: "),
                                           ("motion_samples = 1", "animation.motion_samples: ")])
def test_bad_motion_blur_settings_are_one_line(tmp_path, setting, says):
    text = SPIN.replace("shutter = 0.5", setting) if "shutter" in setting else SPIN.replace("motion_samples = 4", setting)
    (tmp_path / "a.toml").write_text(text)
    p = subprocess.run([sys.executable, "-m", "pyjulia4d", "animate", "a.toml", "-o", "f_####.png"], cwd=tmp_path,
                       capture_output=True, text=True, env=dict(os.environ, PYTHONPATH=str(ROOT)), timeout=120)
    assert p.returncode == 2 and p.stderr.strip().startswith(f"pyjulia4d: error: {says}"), p.stderr
    assert sorted(x.name for x in tmp_path.iterdir()) == ["a.toml"]
