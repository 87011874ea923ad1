"""Rendering on a Dask cluster (pyjulia4d/app/cluster.py): a worker killed mid-animation,
tiles equal to the whole render, programs built once per worker, the render command's
--workers."""
from __future__ import annotations

import logging
import os
import signal
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from pyjulia4d.app import cli
from pyjulia4d import render
from pyjulia4d.app.animation import animate, frame_path
from pyjulia4d.app.output import read_header
from pyjulia4d.app.cluster import render_many, render_tiled
from pyjulia4d.scene.keyframes import from_table
from pyjulia4d.scene.model import Scene

import distributed  # noqa: E402  (a dependency: the tests fail without it)

from harness import device  # noqa: E402

OUTPUTS = ("color", "alpha", "depth", "normal", "position", "status", "samples", "bracket")


@pytest.fixture(scope="module")
def cluster():
    """A local cluster of 2 worker processes, one thread each (as --workers 2 starts)."""
    lc = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address="127.0.0.1:0", silence_logs=logging.ERROR)
    client = distributed.Client(lc, set_as_default=False)
    try:
        yield lc, client
    finally:
        client.close()
        lc.close()


def _morph(frames: int, w: int = 64, h: int = 48):
    return from_table({"fractal": {"max_iter": 8}, "camera": {"position": [1.8, 1.6, -2.2, 0.0]},
                       "image": {"width": w, "height": h},
                       "animation": {"frames": frames, "interpolation": "linear"},
                       "keyframe": [{"frame": 0, "fractal": {"c": [0.0, 0.0, 0.0, 0.0]}},
                                    {"frame": frames - 1, "fractal": {"c": [-0.803762, -0.40615, 0.0, 0.0]}}]})


def _pixels(path: Path) -> np.ndarray:
    with Image.open(path) as im:
        return np.asarray(im)


def test_a_worker_killed_mid_animation_loses_no_frame(cluster, tmp_path):
    """SIGKILL the worker process that is rendering while frames are coming back: the
    scheduler hands its frames to the other worker (and the nanny restarts it); every frame
    is written once, each equal bit for bit to a single-process render."""
    lc, client = cluster
    n = 24
    anim = _morph(n, 96, 72)
    pids = client.run(os.getpid)  # worker address -> pid
    written: list[int] = []
    killed: dict = {}

    def on_written(frame: int, path: Path) -> None:
        written.append(frame)
        if len(written) == 2 and not killed:
            busy = {a: len(ts) for a, ts in client.processing().items() if ts}
            assert busy, "no worker was rendering at the kill"
            addr = max(busy, key=busy.get)
            killed.update(addr=addr, pid=pids[addr], busy=busy[addr])
            os.kill(pids[addr], signal.SIGKILL)

    s = animate(anim, str(tmp_path / "c" / "m_##.png"), scheduler=lc.scheduler_address,
                on_written=on_written)
    assert killed and killed["busy"] >= 1
    assert sorted(written) == list(range(n)) and len(written) == n  # each exactly once
    assert sorted(s.rendered) == list(range(n))
    # the scheduler saw the worker go: its address is gone from the cluster
    client.wait_for_workers(2, timeout=60)
    assert killed["addr"] not in client.scheduler_info()["workers"]
    single = animate(anim, str(tmp_path / "one" / "m_##.png"), workers=0)
    assert sorted(single.rendered) == list(range(n))
    for k in range(n):
        a, b = frame_path(str(tmp_path / "c" / "m_##.png"), k), frame_path(str(tmp_path / "one" / "m_##.png"), k)
        assert np.array_equal(_pixels(a), _pixels(b)), k
        assert read_header(a)["pyjulia4d.scene"] == read_header(b)["pyjulia4d.scene"]


def _same(a: np.ndarray | None, b: np.ndarray | None) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a, b, equal_nan=True)


@pytest.mark.parametrize("over", [
    [],
    ["normals.method=zbuffer"],                           # a one-pixel halo across tiles
    ["image.samples=2", "camera.fit=true"],               # antialiasing; the fit resolved once
    # paths and their film (the film's join; in one process, tests/render/test_path_render.py)
    pytest.param(["shading.integrator=path", "image.samples=3"], marks=pytest.mark.slow),
])
def test_tiles_on_two_workers_equal_the_whole_render(cluster, over):
    _, client = cluster
    scene = Scene.from_dict({"camera": {"position": [1.8, 1.6, -2.2, 0.0]}},
                            ["image.width=90", "image.height=70"] + over)
    whole = render(scene, device=device())
    tiled, fitted = render_tiled(client, scene, tile=32)
    assert "9 tiles on 2 workers" in tiled.device_name
    for name in OUTPUTS:
        assert _same(getattr(whole, name), getattr(tiled, name)), name
    assert whole.counts == tiled.counts and whole.guards == tiled.guards
    if whole.film is not None:   # the path tracer's film, joined from the tiles
        for name in ("paths", "variance", "noise", "albedo", "covered"):
            assert np.array_equal(getattr(whole.film, name), getattr(tiled.film, name)), name
    assert fitted.camera.fit is False
    if "camera.fit=true" in over:
        assert fitted.camera.position != scene.camera.position


def test_each_worker_builds_its_programs_once(cluster):
    """Units after a worker's first build nothing: the OpenCL programs stay built in the
    long-lived worker process (build.program's cache), frame after frame."""
    _, client = cluster
    client.restart()  # fresh worker processes: nothing built yet
    scene = Scene.from_dict({"camera": {"position": [1.8, 1.6, -2.2, 0.0]}},
                            ["image.width=48", "image.height=36", "shading.ao=0.3"])
    infos = []
    units = [(k, scene.replace(**{"fractal.c": [-0.2, 0.8 - 0.01 * k, 0.0, 0.0]}), {}) for k in range(8)]
    render_many(client, units, lambda tag, result, info: infos.append((tag, info)))
    by_pid: dict[int, list] = {}
    for tag, info in sorted(infos):
        by_pid.setdefault(info.pid, []).append(info.programs_built)
    assert len(by_pid) == 2, by_pid  # both workers had frames
    for built in by_pid.values():
        assert built[0] > 0 and built[1:] == [0] * (len(built) - 1), by_pid


def test_render_command_with_workers_writes_the_same_image(tmp_path, capsys):
    a, b = tmp_path / "a.png", tmp_path / "b.png"
    common = ["render", "--width", "80", "--height", "60", "--set", "camera.position=1.8,1.6,-2.2,0"]
    assert cli.main(common + ["-o", str(a)]) == 0
    assert cli.main(common + ["-o", str(b), "--workers", "2"]) == 0
    out = capsys.readouterr().out
    assert "(1 tile on 1 worker)" in out  # 80x60: one tile of the plan
    assert np.array_equal(_pixels(a), _pixels(b))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.png", "b.png"]


@pytest.mark.parametrize("args,expected", [
    (["--workers", "x"], "--workers: expected a whole number of workers, got 'x'"),
    (["--workers", "1", "--scheduler", "tcp://127.0.0.1:1"], "--workers: give --workers"),
    (["--scheduler", "nowhere"], "--scheduler: expected an address such as tcp://HOST:8786"),
])
def test_render_cluster_options_bad_input(tmp_path, capsys, args, expected):
    rc = cli.main(["render", "-o", str(tmp_path / "x.png"), "--width", "8", "--height", "6"] + args)
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and expected in err, err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("address,expected", [
    ("tcp://127.0.0.1:99999", "the port must be in [1, 65535], got '99999'"),
    ("tcp://127.0.0.1:0", "the port must be in [1, 65535], got '0'"),
    ("tcp://h:" + "9" * 5000, "the port must be in [1, 65535], got '999"),
    ("http://example.com", "cannot connect to 'http://example.com': unknown address scheme 'http'"),
    ("tcp://[::1", "cannot connect to 'tcp://[::1': invalid address"),
])
def test_a_bad_scheduler_address_is_one_line_with_no_traceback_at_exit(tmp_path, address, expected):
    """In a process of its own: a Client whose start failed was left half-made, and its
    finalizer printed a traceback when the interpreter exited (after waiting 20 s)."""
    import subprocess
    import sys

    p = subprocess.run([sys.executable, "-m", "pyjulia4d", "render", "--width", "8", "--height", "6",
                        "-o", str(tmp_path / "x.png"), "--scheduler", address],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 2 and p.stderr.count("\n") == 1 and expected in p.stderr, p.stderr
    assert list(tmp_path.iterdir()) == []


def _serve_once(answer: bytes | None):
    """A TCP server on a free local port that answers its first connection with ``answer``
    (None: says nothing and holds the connection); its address, and a stop function."""
    import socket
    import threading

    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(4)
    held = []

    def run():
        try:
            conn, _ = srv.accept()
        except OSError:
            return
        held.append(conn)
        if answer is not None:
            conn.sendall(answer)

    threading.Thread(target=run, daemon=True).start()

    def stop():
        for c in held:
            c.close()
        srv.close()
    return f"tcp://127.0.0.1:{srv.getsockname()[1]}", stop


@pytest.mark.parametrize("answer,expected", [
    # Dask's reader takes "HTTP/1.1" for the length of a 3 EiB frame
    (b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n", "what answers there is not a Dask scheduler"),
    (None, "no Dask scheduler answered within 1 s"),
])
def test_a_server_that_is_no_scheduler_is_one_line(answer, expected):
    from pyjulia4d.app.cluster import reach_scheduler
    from pyjulia4d.scene.checks import SceneError

    address, stop = _serve_once(answer)
    try:
        with pytest.raises(SceneError) as e:
            reach_scheduler(address, timeout=0.5)
    finally:
        stop()
    assert str(e.value).startswith(f"--scheduler: cannot connect to '{address}': ") and expected in str(e.value)
    assert "\n" not in str(e.value)


def test_a_unit_that_fails_on_its_worker_is_one_line(tmp_path):
    """A worker whose device cannot be had (PYJULIA4D_DEVICE names none): the command's one
    line, without the worker's own log of the failed task and its traceback, and without
    Dask's warning that port 8787 (its HTTP server's default) is taken, as it is here."""
    import socket
    import subprocess
    import sys

    temp = tmp_path / "temp"
    temp.mkdir()
    out = tmp_path / "out"
    out.mkdir()
    env = dict(os.environ, PYJULIA4D_DEVICE="no-such-device", TMPDIR=str(temp))
    with socket.socket() as held:
        try:
            held.bind(("127.0.0.1", 8787))
            held.listen()
        except OSError:
            pass   # already taken: the same for the test
        p = subprocess.run([sys.executable, "-m", "pyjulia4d", "render", "--width", "8", "--height", "6",
                            "-o", str(out / "x.png"), "--workers", "1"],
                           capture_output=True, text=True, timeout=300, env=env)
    assert p.returncode == 2 and p.stderr.count("\n") == 1, p.stderr
    assert "device 'no-such-device': no matching OpenCL device" in p.stderr
    assert list(out.iterdir()) == [] and list(temp.iterdir()) == []   # the cluster's own folders too


def test_a_cluster_command_leaves_nothing_in_the_temporary_folder(tmp_path):
    """An animation on a local cluster of 2 workers: its frames, and nothing of the cluster's -
    Dask's scratch and lock files, the units' encoding folders - left in $TMPDIR."""
    import subprocess
    import sys

    temp = tmp_path / "temp"
    temp.mkdir()
    scene = tmp_path / "anim.toml"
    scene.write_text("[fractal]\nmax_iter = 8\n[image]\nwidth = 24\nheight = 18\n[animation]\nframes = 3\n"
                     "[[keyframe]]\nframe = 0\nfractal.c = [0.0, 0.0, 0.0, 0.0]\n"
                     "[[keyframe]]\nframe = 2\nfractal.c = [-0.8, -0.4, 0.0, 0.0]\n")
    p = subprocess.run([sys.executable, "-m", "pyjulia4d", "animate", str(scene), "--workers", "2",
                        "-o", str(tmp_path / "f" / "a_#.png")], capture_output=True, text=True, timeout=300,
                       env=dict(os.environ, TMPDIR=str(temp)))
    assert p.returncode == 0, p.stderr
    assert sorted(x.name for x in (tmp_path / "f").iterdir()) == ["a_0.png", "a_1.png", "a_2.png"]
    assert list(temp.iterdir()) == []


def test_a_new_cluster_folder_removes_those_of_runs_that_are_gone(tmp_path, monkeypatch):
    """files.process_scratch, the local cluster's folder: the folders of commands whose process
    no longer exists are removed (a SIGKILLed run could not remove its own), those of running
    ones and names not its own kept."""
    import subprocess
    import sys
    import tempfile

    from pyjulia4d.app.cluster import SCRATCH_PREFIX
    from pyjulia4d.files import process_scratch

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True).stdout.strip()
    dead = tmp_path / f"{SCRATCH_PREFIX}{gone}-abc"
    (dead / "dask-scratch-space").mkdir(parents=True)
    alive = tmp_path / f"{SCRATCH_PREFIX}{os.getppid()}-def"
    alive.mkdir()
    other = tmp_path / f"{SCRATCH_PREFIX}notapid"
    other.mkdir()
    new = Path(process_scratch(SCRATCH_PREFIX))
    assert not dead.exists() and alive.exists() and other.exists()
    assert new.parent == tmp_path and new.name.startswith(f"{SCRATCH_PREFIX}{os.getpid()}-")
