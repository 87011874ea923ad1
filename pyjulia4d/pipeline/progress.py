"""Progress on stderr, written once for renders, animations and the cluster's tiles: a tqdm
bar on a terminal; on a file or a pipe (a log) whole lines instead - the first after
``first`` seconds (none for work shorter than that), then at most one per ``every`` seconds,
never a carriage return; nothing when not enabled."""
from __future__ import annotations

import sys
import time
from typing import Callable


# line(n done, total, seconds so far, seconds left, note) -> the text of one progress line
LineText = Callable[[int, int, float, float, str], str]

# A stop a signal handler asked for (the command line's SIGTERM and SIGHUP), raised again at
# every update: a handler's exception that lands inside a finaliser (__del__, a weakref
# callback) is printed and dropped by Python, and the render would run on, deaf to the
# signals the handler has set to ignore.  Seen once in CI, under load: SIGHUP left a slow
# render running past the test's 30 s.
_stop: list[BaseException] = []


def request_stop(exc: BaseException) -> None:
    """Raise ``exc`` at every Progress.update from now on, until clear_stop()."""
    _stop[:] = [exc]


def clear_stop() -> None:
    _stop.clear()


class Progress:
    def __init__(self, total: int, desc: str, unit: str, enabled: bool = True, line: LineText | None = None,
                 first: float = 3.0, every: float = 10.0, unit_scale: bool = False, delay: float = 1.0,
                 hook: Callable[[int, int], None] | None = None) -> None:
        """``hook(n, total)`` is called after every update, shown or not; an exception it raises
        stops the work (explore's renders: a newer request makes the running one stale)."""
        self.total, self.n, self.enabled, self.every, self.hook = total, 0, enabled, every, hook
        self.t0 = time.perf_counter()
        self.last = self.t0 - every + first
        self.line = line or (lambda n, total, spent, left, note:
                             f"{desc}: {n} of {total} {unit}s, {spent:.0f} s, about {left:.0f} s left")
        tty = hasattr(sys.stderr, "isatty") and sys.stderr.isatty()
        if enabled and tty:
            from tqdm import tqdm   # here: its import (with importlib.metadata's) is 60 ms of start-up
        self.bar = (tqdm(total=total, unit=unit, unit_scale=unit_scale, file=sys.stderr, delay=delay,
                         leave=False, desc=desc) if enabled and tty else None)

    def update(self, k: int = 1, note: str = "") -> None:
        if _stop:
            raise _stop[0]
        self.n += k
        if self.hook is not None:
            self.hook(self.n, self.total)
        if self.bar is not None:
            self.bar.update(k)
            return
        if not self.enabled:
            return
        now = time.perf_counter()
        if now - self.last >= self.every and self.n < self.total:
            self.last = now
            left = (now - self.t0) * (self.total - self.n) / max(self.n, 1)
            # one write, newline included: a signal's exception (the command line's SIGTERM and
            # SIGHUP) raised between print's two writes would leave the line unterminated
            sys.stderr.write(self.line(self.n, self.total, now - self.t0, left, note) + "\n")
            sys.stderr.flush()

    def set_total(self, total: int) -> None:
        """A new total, once the work is known (antialiasing's adaptive passes)."""
        self.total = total
        if self.bar is not None:
            self.bar.total = total
            self.bar.refresh()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()

    def __enter__(self) -> "Progress":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def silent() -> Progress:
    """A Progress that shows nothing (the time probe's passes)."""
    return Progress(0, "", "", enabled=False)
