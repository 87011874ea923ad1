"""Where a render's host images live: in memory, or in a file whose pages are let go as rows
are done.

A render keeps up to 64 bytes a pixel on the host (every output: colour, alpha, depth, its
bracket and unresolved reach, normal, position, status, samples), 506 MiB at 3840x2160, and
its header - counts, guards, the bracket's percentiles - is known only once every tile is
in, so an EXR cannot be written while the tiles come.  ``ImageStore(folder)`` puts the
images in one unnamed file in ``folder`` (``tempfile.TemporaryFile``: O_TMPFILE on Linux,
so it never has a name, and it is gone when the process ends however it ends), mapped
shared; ``release(rows)`` tells the kernel those rows' pages are no longer needed
(``madvise(MADV_DONTNEED)``): their contents stay in the file and come back when read, and
the process holds the rows it is filing or writing, not the image.  ``ImageStore()`` keeps
them in memory, and its ``release`` does nothing; so does a spilling store whose folder has no
room for an image (it is kept in memory instead).

Each image's channels lie in planes ((C, H, W), seen as (H, W, C)), as in memory: the EXR
writer takes a channel's band without a copy.
"""
from __future__ import annotations

import mmap
import os
import tempfile
import threading
import weakref
from pathlib import Path

import numpy as np

from pyjulia4d.files import path_text
from pyjulia4d.scene.checks import SceneError

PAGE = mmap.PAGESIZE
# At and above this size an image's memory is mapped anonymous pages (``new_memory``), as numpy
# would madvise it for transparent huge pages from 4 MiB on
MAPPED_FROM = 4 << 20


def new_memory(nbytes: int) -> np.ndarray:
    """``nbytes`` of new memory (uint8), uninitialised; from 4 MiB, anonymous pages mapped
    for it alone (pre-faulted where the system can: MAP_POPULATE), not numpy's allocation.
    numpy asks the kernel for transparent huge pages for every array of 4 MiB or more
    (madvise MADV_HUGEPAGE), and where the system's huge-page defrag setting is "madvise"
    (a common default) the first touch of each such page may wait for the kernel to compact
    memory: on a 2-core Intel Xeon VM 1.15-1.29 s for 500 MiB, where plain pages took 0.20 s
    (0.165 s pre-faulted), so a 3840x2160 render keeping every output spent 1.9 s where the
    same render again in the process took 0.66 s.  An image is written once and read once;
    huge pages buy it nothing."""
    got = _mapped_pages(nbytes)
    return np.empty(nbytes, np.uint8) if got is None else got


def new_empty(shape: tuple, dtype) -> np.ndarray:
    """``np.empty(shape, dtype)`` in new_memory's pages where it is 4 MiB or more: a picture's
    levels (app/output.py)."""
    return _new_array(shape, dtype, np.empty)


def new_zeros(shape: tuple, dtype) -> np.ndarray:
    """``np.zeros(shape, dtype)`` in new_memory's pages where it is 4 MiB or more (new anonymous
    pages are zeros already): the antialiasing passes' sums and their centre image."""
    return _new_array(shape, dtype, np.zeros)


def _new_array(shape: tuple, dtype, numpys) -> np.ndarray:
    """An array of ``shape`` in _mapped_pages, else numpy's (``numpys``: np.empty or np.zeros)."""
    dtype = np.dtype(dtype)
    got = _mapped_pages(int(np.prod(shape)) * dtype.itemsize)
    return numpys(shape, dtype) if got is None else got.view(dtype).reshape(shape)


def _mapped_pages(nbytes: int) -> np.ndarray | None:
    """``nbytes`` (uint8) of anonymous private pages, pre-faulted where the system can, zero;
    None below MAPPED_FROM, or where they cannot be mapped."""
    flags = getattr(mmap, "MAP_PRIVATE", 0) | getattr(mmap, "MAP_ANONYMOUS", 0)
    if nbytes < MAPPED_FROM or not flags:
        return None
    try:
        m = mmap.mmap(-1, nbytes, flags=flags | getattr(mmap, "MAP_POPULATE", 0))
    except OSError:   # no room for it all at once, or a system without those flags
        return None
    return np.frombuffer(m, np.uint8)   # the array holds the map; unmapped when it dies


class Reuse:
    """Memory of in-memory images whose every array is gone, kept for the next images of the
    same size.  New memory costs a page fault at its first touch, page by page (2,070 faults
    in a warm 640x480 render keeping colour and alpha, 4,000-4,500 keeping every output); a
    process that renders again and again (previews, animation frames, the benchmarks) takes
    the same pages back instead.  ``keep``: the most bytes held free at once (a 640x480
    render's every output is 20 MB), and eight buffers of a size at most (a render's
    single-channel images share theirs); past that a buffer is let go as numpy would.

    Each image is a view of its own wrapper ``np.frombuffer(memoryview(raw))`` over the kept
    ``raw``: numpy points every later view's base at that wrapper (it collapses chains of
    views onto the first array whose base is not an array), so the wrapper dies, and ``raw``
    comes back, only once no view of the image is left anywhere."""

    def __init__(self, keep: int = 128 << 20, per_size: int = 8):
        self.per_size = per_size
        self.keep = keep
        self._lock = threading.Lock()   # arrays die in whatever thread drops them
        self._free: dict[int, list[np.ndarray]] = {}
        self._held = 0

    def empty(self, nbytes: int) -> np.ndarray:
        """``nbytes`` bytes (uint8), uninitialised: kept memory of that size, else new; given
        back to the keeper once no view of the returned array is left."""
        with self._lock:
            got = self._free.get(nbytes)
            raw = got.pop() if got else None
            if raw is not None:
                self._held -= nbytes
        if raw is None:
            raw = new_memory(nbytes)
        image = np.frombuffer(memoryview(raw), np.uint8)
        weakref.finalize(image, self._give, raw)
        return image

    def _give(self, raw: np.ndarray) -> None:
        n = raw.nbytes
        with self._lock:
            same = self._free.setdefault(n, [])
            if len(same) < self.per_size and self._held + n <= self.keep:
                same.append(raw)
                self._held += n

    @property
    def held(self) -> int:
        """Bytes kept free now."""
        return self._held


REUSE = Reuse()


class ImageStore:
    """Allocates a render's host images (``empty``) and lets go of finished rows (``release``)."""

    def __init__(self, folder: str | Path | None = None):
        if folder is not None:
            folder = path_text(folder, lambda got: SceneError("store", f"expected None or a folder, {got}"))
        self.folder = None if folder is None else Path(folder)
        self._maps: list[tuple[mmap.mmap, int, int, int]] = []   # (map, planes, height, bytes per row)

    @property
    def spills(self) -> bool:
        """Whether the images live in a file (else in memory)."""
        return self.folder is not None

    @property
    def mapped(self) -> int:
        """How many of its images live in the file."""
        return len(self._maps)

    def empty(self, shape: tuple, dtype) -> np.ndarray:
        """An uninitialised image of ``shape``, (H, W) or (H, W, C), its channels in planes."""
        dtype = np.dtype(dtype)
        planes = shape[2] if len(shape) == 3 else 1
        h, w = shape[0], shape[1]
        m = self._mapped(planes * h * w * dtype.itemsize) if self.folder is not None and h * w else None
        if m is None:
            a = REUSE.empty(planes * h * w * dtype.itemsize).view(dtype).reshape(planes, h, w)
        else:
            self._maps.append((m, planes, h, w * dtype.itemsize))
            a = np.frombuffer(m, dtype, planes * h * w).reshape(planes, h, w)
        return a.transpose(1, 2, 0) if len(shape) == 3 else a[0]

    def _mapped(self, size: int) -> mmap.mmap | None:
        """``size`` bytes of an unnamed file in the folder, mapped shared; None where the file
        cannot be made or its disk has no room (its blocks are taken now: a sparse file on a
        full disk would kill the process with SIGBUS at the first page it could not write),
        and the image is then kept in memory."""
        try:
            with tempfile.TemporaryFile(dir=self.folder) as f:
                os.posix_fallocate(f.fileno(), 0, size)
                return mmap.mmap(f.fileno(), size)   # keeps the file open while mapped
        except (OSError, ValueError):
            return None

    def release(self, rows: slice | None = None) -> None:
        """Let go of the pages wholly inside ``rows`` (None: all) of every image in a file."""
        for m, planes, h, row_bytes in self._maps:
            r0, r1, _ = (rows or slice(None)).indices(h)
            if r1 <= r0:
                continue
            for p in range(planes):
                start = (p * h + r0) * row_bytes
                stop = (p * h + r1) * row_bytes
                start = -(-start // PAGE) * PAGE
                stop = stop // PAGE * PAGE
                if stop > start:
                    m.madvise(mmap.MADV_DONTNEED, start, stop - start)


IN_MEMORY = ImageStore()


def spill_folder(path: str | Path) -> Path:
    """The folder an output's images spill to: the output's own (a real disk where the output
    goes; /tmp may be memory itself)."""
    return Path(os.path.dirname(os.path.abspath(os.fspath(path))) or ".")
