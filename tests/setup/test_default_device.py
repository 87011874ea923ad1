"""The remembered default device (opencl/default_device.py): the command line loads the
chosen runtime alone once the choice is remembered, picks the same device and says the same
words about it, and loads every runtime again where anything it chose from has changed."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import pyjulia4d
from pyjulia4d.opencl import default_device, runtimes

PKG_ROOT = str(Path(pyjulia4d.__file__).resolve().parent.parent)

cl = pytest.importorskip("pyopencl")


def _platforms():
    try:
        return cl.get_platforms()
    except cl.Error:
        return []


needs_opencl = pytest.mark.skipif(not _platforms(), reason="no OpenCL platform")


def _env(cache: Path, **extra: str) -> dict[str, str]:
    """The environment of a child with its own cache folder, seeded with this process's
    answers about the devices (packet widths, compilers: each found by a child of its own,
    seconds from cold) so that only the remembered default device starts afresh."""
    import shutil

    from pyjulia4d.resources import cache_dir

    cache.mkdir(parents=True, exist_ok=True)
    for name in ("lanes.json", "lanes_double.json", "compiles.json"):
        if (cache_dir() / name).is_file() and not (cache / name).exists():
            shutil.copy(cache_dir() / name, cache / name)
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [PKG_ROOT, env.get("PYTHONPATH")]))
    env.pop("OCL_ICD_VENDORS", None)   # set by this process's own registration
    env["PYJULIA4D_CACHE"] = str(cache)
    env.update(extra)
    return env


def _program(args: list[str], cwd: Path, cache: Path, **extra: str) -> subprocess.CompletedProcess[str]:
    """The program as its users run it (python -m pyjulia4d)."""
    return subprocess.run([sys.executable, "-m", "pyjulia4d", *args], cwd=cwd, env=_env(cache, **extra),
                          capture_output=True, text=True, timeout=300)


# What a process's loader shows after the program's own narrowing step: the platforms, and
# the device the default choice takes with the words said about it.
PROBE = r"""
import json, sys
from pyjulia4d.opencl import default_device, runtimes
default_device.allow()
narrowed = default_device.narrow()
from pyjulia4d.app.cli import select_device
from pyjulia4d.opencl.devices import default_reason, device_key
import pyopencl as cl
dev = select_device(None)
print(json.dumps({"narrowed": narrowed, "platforms": len(cl.get_platforms()), "device": device_key(dev),
                  "reason": default_reason(dev)}))
"""


def _probe(cache: Path, **extra: str) -> dict:
    r = subprocess.run([sys.executable, "-c", PROBE], env=_env(cache, **extra), capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


@needs_opencl
def test_every_platform_has_its_library_file() -> None:
    for p in _platforms():
        lib = default_device.platform_library(p)
        assert lib and Path(lib).is_file(), p.name


@needs_opencl
def test_the_second_command_loads_one_runtime_and_says_the_same(tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    first = _probe(cache)
    assert not first["narrowed"]
    full = first["platforms"]
    record = json.loads((cache / default_device.RECORD).read_text())
    if not record:
        pytest.skip("a runtime here shows no device: nothing is remembered (module docstring)")
    second = _probe(cache)
    assert second["narrowed"] and second["platforms"] == 1
    assert second["device"] == first["device"] and second["reason"] == first["reason"]
    assert second["platforms"] <= full
    # the user's own OCL_ICD_VENDORS stands: every runtime it names
    theirs = _probe(cache, OCL_ICD_VENDORS=runtimes.registered["folder"] or runtimes.SYSTEM_VENDORS)
    assert not theirs["narrowed"]


@needs_opencl
def test_a_changed_runtime_library_loads_every_runtime_again(tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    first = _probe(cache)
    path = cache / default_device.RECORD
    known = json.loads(path.read_text())
    if not known:
        pytest.skip("nothing remembered here")
    (key, record), = known.items()
    lib = next(iter(record["libraries"]))
    record["libraries"][lib] = [1, 2]        # as if that library had been replaced
    path.write_text(json.dumps(known))
    again = _probe(cache)
    assert not again["narrowed"] and again["platforms"] == first["platforms"]
    assert again["device"] == first["device"]
    # and remembered afresh
    assert json.loads(path.read_text())[key]["libraries"][lib] != [1, 2]


@needs_opencl
def test_the_command_renders_the_same_picture_narrowed(tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    args = ["render", "--width", "32", "--height", "24"]
    a = _program(args + ["-o", "a.png"], tmp_path, cache)
    b = _program(args + ["-o", "b.png"], tmp_path, cache)
    assert a.returncode == 0 and b.returncode == 0, a.stderr + b.stderr
    import numpy as np
    from PIL import Image

    pix = [np.asarray(Image.open(tmp_path / f)) for f in ("a.png", "b.png")]
    assert np.array_equal(pix[0], pix[1])
    said = [r.stdout.splitlines()[-1].split(" in ", 1)[1].split(" s on ", 1)[1] for r in (a, b)]
    assert said[0] == said[1]


def test_nothing_is_narrowed_unless_the_program_allows_it(tmp_path: Path, monkeypatch) -> None:
    """In-process callers (the Python interface, tests running the command line) keep every
    runtime: narrow() does nothing there, whatever is remembered."""
    monkeypatch.setitem(default_device._allowed, "on", False)
    monkeypatch.setenv("PYJULIA4D_CACHE", str(tmp_path))
    before = os.environ.get("OCL_ICD_VENDORS")
    assert default_device.narrow() is False
    assert os.environ.get("OCL_ICD_VENDORS") == before and not runtimes.narrowed


@pytest.mark.parametrize("junk", ["", "[]", "{", '{"x": 1}', json.dumps({"k": {"library": 1}})])
def test_a_damaged_record_is_ignored(tmp_path: Path, monkeypatch, junk: str) -> None:
    monkeypatch.setitem(default_device._allowed, "on", True)
    monkeypatch.setenv("PYJULIA4D_CACHE", str(tmp_path))
    (tmp_path / default_device.RECORD).write_text(junk)
    before = os.environ.get("OCL_ICD_VENDORS")
    assert default_device.narrow() is False
    assert os.environ.get("OCL_ICD_VENDORS") == before and not runtimes.narrowed


def test_a_record_of_a_gone_library_is_ignored(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setitem(default_device._allowed, "on", True)
    monkeypatch.setenv("PYJULIA4D_CACHE", str(tmp_path))
    gone = str(tmp_path / "libgone.so")
    (tmp_path / default_device.RECORD).write_text(json.dumps({default_device.icd_key(): {
        "library": gone, "device": "d", "reason": "r", "libraries": {gone: [1, 2]}}}))
    before = os.environ.get("OCL_ICD_VENDORS")
    assert default_device.narrow() is False
    assert os.environ.get("OCL_ICD_VENDORS") == before and not runtimes.narrowed


def test_library_stats_follow_the_file(tmp_path: Path) -> None:
    f = tmp_path / "lib.so"
    f.write_bytes(b"x")
    a = default_device.library_stats([f])
    f.write_bytes(b"xy")
    assert default_device.library_stats([f]) != a
    f.unlink()
    assert default_device.library_stats([f]) == {str(f): []}
