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
from pathlib import Path

import numpy as np

PAGE = mmap.PAGESIZE


class ImageStore:
    """Allocates a render's host images (``empty``) and lets go of finished rows (``release``)."""

    def __init__(self, folder: str | Path | None = None):
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
            a = np.empty((planes, h, w), dtype)
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
