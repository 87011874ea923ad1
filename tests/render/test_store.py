"""A render's host images in a file whose finished rows are let go (pipeline/store.py), and
the EXR written band by band (output.write_exr): the same pixels and the same file as in
memory, with the pages really let go and no file left behind."""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import OpenEXR
import pytest

from pyjulia4d import Scene
from pyjulia4d.app import cli
from pyjulia4d.app.output import EXR_BAND_ROWS, write_exr
from pyjulia4d.pipeline.store import IN_MEMORY, ImageStore

SMALL = ["image.width=48", "image.height=40"]


def _rss() -> int:
    """This process's resident set, bytes (Linux)."""
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def test_a_spilled_image_keeps_its_values_and_leaves_no_file(tmp_path: Path) -> None:
    store = ImageStore(tmp_path)
    a = store.empty((300, 200, 3), np.float32)
    b = store.empty((300, 200), np.int32)
    assert a.shape == (300, 200, 3) and b.shape == (300, 200)
    assert a[..., 1].flags.c_contiguous and store.mapped == 2   # channels in planes, as in memory
    rng = np.random.default_rng(1)
    want_a, want_b = rng.random(a.shape, np.float32), rng.integers(-9, 9, b.shape, np.int32)
    a[...], b[...] = want_a, want_b
    store.release(slice(0, 150))
    store.release()
    np.testing.assert_array_equal(a, want_a)     # read back from the file
    np.testing.assert_array_equal(b, want_b)
    assert list(tmp_path.iterdir()) == []         # the file never had a name


@pytest.mark.skipif(not os.path.exists("/proc/self/statm"), reason="needs Linux's /proc")
def test_released_rows_leave_the_resident_set(tmp_path: Path) -> None:
    store = ImageStore(tmp_path)
    a = store.empty((4096, 4096), np.float32)     # 64 MiB
    a[...] = 1.0
    full = _rss()
    store.release()
    assert full - _rss() > 48 * 2**20
    assert float(a[4000, 4000]) == 1.0


def test_in_memory_release_changes_nothing() -> None:
    a = IN_MEMORY.empty((10, 12, 4), np.float32)
    a[...] = 3
    IN_MEMORY.release(slice(0, 5))
    assert np.all(a == 3) and not IN_MEMORY.spills


def test_a_spilled_render_is_the_in_memory_render(tmp_path: Path) -> None:
    from pyjulia4d import render

    scene = Scene.default().with_overrides(SMALL)
    mem = render(scene, calibrate=False, tile=16)
    disk = render(scene, calibrate=False, tile=16, store=ImageStore(tmp_path))
    for name in ("color", "alpha", "depth", "bracket", "unresolved", "normal", "position", "status", "samples"):
        np.testing.assert_array_equal(getattr(disk, name), getattr(mem, name), err_msg=name)
    assert disk.counts == mem.counts and disk.guards == mem.guards
    assert list(tmp_path.iterdir()) == []


def test_exr_bands_are_the_arrays_and_release_follows_them(tmp_path: Path) -> None:
    h, w = 2 * EXR_BAND_ROWS + 7, 33
    rng = np.random.default_rng(2)
    arr = rng.standard_normal((h, w)).astype(np.float32)
    other = rng.standard_normal((h, w)).astype(np.float32)
    released: list[slice] = []
    mats = {"worldToCamera": np.arange(16, dtype=np.float32).reshape(4, 4),
            "worldToNDC": np.eye(4, dtype=np.float32)}
    write_exr(tmp_path / "x.exr", {"Z": arr, "Y": lambda rows: other[rows] * 2},
              {"pyjulia4d.scene": "a = 1\n[b]\nc = 'é'", **mats}, released.append)
    f = OpenEXR.File(str(tmp_path / "x.exr"), separate_channels=True)
    np.testing.assert_array_equal(f.channels()["Z"].pixels, arr)
    np.testing.assert_array_equal(f.channels()["Y"].pixels, other * 2)
    hdr = f.header()
    assert hdr["pyjulia4d.scene"] == "a = 1\n[b]\nc = 'é'"
    for k, m in mats.items():
        np.testing.assert_array_equal(np.asarray(hdr[k]), m)
    assert [(s.start, s.stop) for s in released] == [(0, EXR_BAND_ROWS), (EXR_BAND_ROWS, 2 * EXR_BAND_ROWS),
                                                     (2 * EXR_BAND_ROWS, h)]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.exr"]


def test_exr_channel_shapes_are_checked(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="of one shape"):
        write_exr(tmp_path / "x.exr", {"A": np.zeros((4, 5), np.float32), "B": np.zeros((4, 6), np.float32)})
    with pytest.raises(ValueError, match="need an array or a shape"):
        write_exr(tmp_path / "x.exr", {"A": lambda rows: np.zeros((1, 1))})
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("layout", ["pyjulia4d", "compositing"])
def test_the_command_spills_a_large_render_to_the_same_exr(tmp_path: Path, monkeypatch, layout: str) -> None:
    """Past SPILL_BYTES the command renders into a file and writes the EXR band by band: the
    same channels and header as the same render held in memory."""
    monkeypatch.chdir(tmp_path)
    args = ["render", "--width", "64", "--height", "48", "--set", f"image.exr={layout}"]
    assert cli.main(args + ["-o", "mem.exr"]) == 0
    used = []
    real = cli.store_for

    def small_spill(scene, outputs, out):
        monkeypatch.setattr(cli, "SPILL_BYTES", 1)
        store = real(scene, outputs, out)
        used.append(store.spills)
        return store
    monkeypatch.setattr(cli, "store_for", small_spill)
    assert cli.main(args + ["-o", "disk.exr"]) == 0
    assert used == [True]
    a, b = (OpenEXR.File(str(tmp_path / n), separate_channels=True) for n in ("mem.exr", "disk.exr"))
    assert sorted(a.channels()) == sorted(b.channels())
    for name in a.channels():
        np.testing.assert_array_equal(a.channels()[name].pixels, b.channels()[name].pixels, err_msg=name)
    ha, hb = a.header(), b.header()
    for k in ha:
        if k.startswith("pyjulia4d.") and "second" not in k and "time" not in k:
            assert ha[k] == hb[k], k
    assert sorted(p.name for p in tmp_path.iterdir()) == ["disk.exr", "mem.exr"]


def test_a_folder_without_room_keeps_the_image_in_memory(tmp_path: Path, monkeypatch) -> None:
    """A full disk would make a sparse file's first unwritable page a SIGBUS: the blocks are
    taken first, and where they cannot be the image stays in memory."""
    import errno

    def full(fd, offset, length):
        raise OSError(errno.ENOSPC, "No space left on device")
    monkeypatch.setattr(os, "posix_fallocate", full)
    store = ImageStore(tmp_path)
    a = store.empty((64, 32, 3), np.float32)
    a[...] = 2.0
    store.release()
    assert np.all(a == 2.0) and store.mapped == 0
    assert list(tmp_path.iterdir()) == []


def test_kept_memory_comes_back_only_when_no_view_is_left() -> None:
    """store.Reuse: an image's memory is kept for the next image of its size once every array
    over it is gone - not while any view (a slice, a transpose, a channel) of it lives."""
    from pyjulia4d.pipeline.store import Reuse

    keep = Reuse(keep=1 << 20)
    a = keep.empty(4096).view(np.float32).reshape(4, 16, 16).transpose(1, 2, 0)
    a[...] = 7
    where = a.__array_interface__["data"][0]
    channel = a[..., 2]
    del a
    b = keep.empty(4096)                       # the first image's channel is still in use
    assert b.__array_interface__["data"][0] != where and keep.held == 0
    assert np.all(channel == 7)
    del channel
    assert keep.held == 4096
    c = keep.empty(4096)
    assert c.__array_interface__["data"][0] == where and keep.held == 0
    del b, c
    assert keep.held == 8192
    d = keep.empty(64)                         # another size: new memory
    assert keep.held == 8192 and d.nbytes == 64


def test_kept_memory_is_bounded() -> None:
    from pyjulia4d.pipeline.store import Reuse

    keep = Reuse(keep=10_000, per_size=2)
    images = [keep.empty(4000) for _ in range(4)]
    del images
    assert keep.held == 8000                   # two of a size, within 10,000 bytes
    images = [keep.empty(3000) for _ in range(2)]
    del images
    assert keep.held == 8000                   # 11,000 would pass the bound: let go


def test_new_memory_maps_large_images_and_keeps_them() -> None:
    """store.new_memory: below MAPPED_FROM numpy's memory, from it pages mapped for the image
    alone (not numpy's, which would ask for huge pages); either is writable memory of the
    size asked, and a mapped image's memory is kept and comes back like any other."""
    import mmap

    from pyjulia4d.pipeline.store import MAPPED_FROM, Reuse, new_memory

    small, big = new_memory(4096), new_memory(MAPPED_FROM)
    assert small.nbytes == 4096 and big.nbytes == MAPPED_FROM and new_memory(0).nbytes == 0
    assert not isinstance(getattr(small.base, "obj", None), mmap.mmap)
    if hasattr(mmap, "MAP_ANONYMOUS"):
        assert isinstance(big.base.obj, mmap.mmap)
    big[::4096] = 3                            # every page writable
    assert int(big[::4096].sum()) == 3 * (MAPPED_FROM // 4096)
    keep = Reuse(keep=2 * MAPPED_FROM)
    a = keep.empty(MAPPED_FROM).view(np.float32)
    a[...] = 1.5
    where = a.__array_interface__["data"][0]
    del a
    assert keep.held == MAPPED_FROM
    b = keep.empty(MAPPED_FROM)
    assert b.__array_interface__["data"][0] == where and keep.held == 0


def test_new_zeros_are_zeros_of_the_shape_asked() -> None:
    """store.new_zeros: np.zeros, in pages of its own from MAPPED_FROM bytes on."""
    from pyjulia4d.pipeline.store import MAPPED_FROM, new_zeros

    for shape in ((0, 3), (7, 5, 3), (MAPPED_FROM // 12 + 1, 3)):
        for dtype in (np.float32, np.int32):
            z = new_zeros(shape, dtype)
            assert z.shape == shape and z.dtype == dtype and z.flags.writeable and z.flags.c_contiguous
            assert not z.any()
            if z.size:
                z.flat[-1] = 1
                assert z.sum() == 1


def test_a_later_render_leaves_an_earlier_result_alone() -> None:
    """Two results alive at once never share memory; a result rendered into kept memory is
    the same as one rendered into new memory."""
    from pyjulia4d import render

    one = render(Scene.default().with_overrides(SMALL), calibrate=False)
    kept = {k: np.array(getattr(one, k)) for k in ("color", "alpha", "depth", "normal", "status")}
    other = render(Scene.default().with_overrides(SMALL + ["fractal.c=-0.5,0.5,0,0"]), calibrate=False)
    for k, v in kept.items():
        np.testing.assert_array_equal(getattr(one, k), v, err_msg=k)
    del one, other
    again = render(Scene.default().with_overrides(SMALL), calibrate=False)   # into kept memory
    for k, v in kept.items():
        np.testing.assert_array_equal(getattr(again, k), v, err_msg=k)
