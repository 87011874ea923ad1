"""Tile buffers kept between a process's renders.

A render's tile runner holds two slots of device buffers (about 100 bytes a pixel of a
512 x 512 tile; the host reads them through maps), and a CPU device's buffers are host memory.
Made afresh for every render, their pages were faulted in and zeroed by the kernel each time:
a quarter of the CPU time of a warm 640x480 render on Intel's runtime (perf, cpu-clock
samples in the kernel's page-fault and page-clearing code).  The explorer, animations and
the Python interface render again and again in one process, so a runner gives its slots
back when it is done (``give``) and the next runner of the same shapes takes them (``take``).
A set is held by one runner at a time, so concurrent renders (a Dask worker's threads) never
share one; at most KEEP sets are kept, the oldest dropped.
"""
from __future__ import annotations

import threading
from collections import OrderedDict
from typing import Any, Hashable

KEEP = 4

_lock = threading.Lock()
_free: "OrderedDict[Hashable, list[Any]]" = OrderedDict()


def take(key: Hashable) -> Any | None:
    """A set of slots given back under ``key``, now this caller's; None if there is none."""
    with _lock:
        sets = _free.get(key)
        if not sets:
            return None
        item = sets.pop()
        if not sets:
            del _free[key]
        return item


def give(key: Hashable, item: Any) -> None:
    """Keep ``item`` for the next ``take(key)``; beyond KEEP sets the oldest are dropped."""
    with _lock:
        _free.setdefault(key, []).append(item)
        _free.move_to_end(key)
        while sum(len(v) for v in _free.values()) > KEEP:
            oldest = next(iter(_free))
            _free[oldest].pop(0)
            if not _free[oldest]:
                del _free[oldest]


def clear() -> None:
    """Drop every kept set (their memory goes with the last reference)."""
    with _lock:
        _free.clear()
