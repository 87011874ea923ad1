"""Writing files atomically: a temp file beside the target, renamed over it only on success,
removed on any exception - Ctrl-C's KeyboardInterrupt and the command line's SIGTERM and
SIGHUP exceptions included - so that no partial file is ever left.  Used for images, videos,
scene files, frames, and the caches (program binaries, packet widths).

The temp file is ``.<stem>.<random><ext>`` beside the output, its stem shortened so that the
name fits the file system's name limit."""
from __future__ import annotations

import contextlib
import os
import shutil
import signal
import tempfile
import threading
from pathlib import Path
from typing import Callable, Iterator

# Room left for tempfile's random part of a name (8 characters in CPython today).
RANDOM_CHARS = 16
# Where pathconf() cannot tell: the usual Linux limits.
NAME_MAX, PATH_MAX = 255, 4096
# Deferred while a temp file is created or removed, so that no signal's exception can
# fall between creating a file and knowing its name (which would leave it behind).
_HELD = tuple(getattr(signal, s) for s in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, s))


def path_text(path: object, error: Callable[[str], Exception]) -> str:
    """A path given from Python as its text: a str, or an os.PathLike whose ``__fspath__``
    gives one.  Anything else - bytes, an int (which open() would take as a file descriptor,
    and close), None, an object whose ``__fspath__`` fails - raises ``error(what)``, the
    caller's own one-line error, told what was given: "a str or an os.PathLike, got int"."""
    raw = None
    if isinstance(path, (str, os.PathLike)):
        try:
            raw = os.fspath(path)
        except Exception:   # the object's own __fspath__ failed: not a path either way
            raw = None
    if not isinstance(raw, str):
        raise error(f"a str or an os.PathLike, got {type(path).__name__}")
    return raw


SHOWN_PATH_MOST = 240   # characters of a path a message shows; the middle of a longer one is cut


def shown_path(path: str) -> str:
    """The path as a message shows it: itself when printable, else its repr; past
    SHOWN_PATH_MOST characters its start and end around "...", so the message stays a line
    one can read."""
    return _shortened(path if path and path.isprintable() else repr(path))


def _shortened(s: str) -> str:
    """``s`` past SHOWN_PATH_MOST characters as its start and end around "..."."""
    return s if len(s) <= SHOWN_PATH_MOST else f"{s[:120]}...{s[-(SHOWN_PATH_MOST - 123):]}"


def quoted_path(path: str | Path) -> str:
    """The path in quotes: 'dir', or its repr when not printable; shortened as shown_path
    shortens it, so that a message naming it stays one line."""
    path = str(path)
    return _shortened(f"'{path}'" if path and path.isprintable() else repr(path))


def path_limit(directory: str | Path, name: str, fallback: int) -> int:
    try:
        value = os.pathconf(directory, name)
    except (OSError, ValueError):
        return fallback
    return value if value > 0 else fallback  # -1: no limit, keep the usual one


def temp_affixes(p: Path, name_max: int) -> tuple[str, str]:
    """(prefix, suffix) of the temp file for ``p``: ``.<stem>.`` and its extension, the
    stem cut so that prefix + random part + suffix fits in ``name_max`` bytes."""
    room = max(0, name_max - len(os.fsencode(p.suffix)) - 2 - RANDOM_CHARS)
    stem = p.stem[:room]
    while len(os.fsencode(stem)) > room:  # multi-byte characters: cut by bytes
        stem = stem[:-1]
    return f".{stem}.", p.suffix


@contextlib.contextmanager
def signals_held() -> Iterator[None]:
    """Run the Python handlers of SIGINT, SIGTERM and SIGHUP (Ctrl-C's KeyboardInterrupt,
    the CLI's exceptions) at the end of the block instead of inside it.

    Python runs every handler in the main thread, whichever thread the signal was
    delivered to (OpenCL's workers take some): blocking it with pthread_sigmask in this
    thread would not defer it, swapping the handlers does."""
    if threading.current_thread() is not threading.main_thread():
        yield  # only the main thread runs handlers (and may swap them)
        return
    caught: list[int] = []
    old = {}
    for s in _HELD:
        if callable(signal.getsignal(s)):
            old[s] = signal.signal(s, lambda signum, frame: caught.append(signum))
    try:
        yield
    finally:
        for s, handler in old.items():
            signal.signal(s, handler)
        if caught:
            old[caught[0]](caught[0], None)  # the first one's exception, now


def _file_mode() -> int:
    """0o666 less the umask: what a plain open() would have created."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


@contextlib.contextmanager
def atomic_write(path: str | Path) -> Iterator[Path]:
    """Yield a temp path beside ``path``; move it onto ``path`` only on success.  A ``path`` that
    is a symbolic link is written through: the file it names is replaced, beside itself, and
    the link stays (as a shell's ``>`` writes through one; a render to latest.png, a link to
    the newest picture, updates that picture)."""
    p = Path(path)
    if p.is_symlink():
        p = Path(os.path.realpath(p))
    prefix, suffix = temp_affixes(p, path_limit(p.parent, "PC_NAME_MAX", NAME_MAX))
    tmp: Path | None = None
    try:
        with signals_held():  # a signal arriving here is raised once tmp is known
            fd, name = tempfile.mkstemp(dir=p.parent, prefix=prefix, suffix=suffix)
            os.close(fd)
            tmp = Path(name)
        yield tmp
        os.chmod(tmp, _file_mode())  # mkstemp creates 0600
        os.replace(tmp, p)
    except BaseException:  # KeyboardInterrupt and SIGTERM/SIGHUP too: never leave it behind
        if tmp is not None:
            with signals_held():  # a second signal must not cut the clean-up short
                tmp.unlink(missing_ok=True)
        raise


def process_scratch(prefix: str) -> str:
    """A new folder in $TMPDIR named for this process (``prefix`` PID-...), for files that
    must all go when it ends.  First the folders of ``prefix`` whose process is gone are
    removed: one killed outright (SIGKILL) could not remove its own, nor its children, which
    end with it, their files there.  Only this user's folders, of processes that no longer
    exist; a process id taken again by another process keeps its folder until that one ends."""
    for old in Path(tempfile.gettempdir()).glob(prefix + "*"):
        pid = old.name[len(prefix):].split("-", 1)[0]
        try:
            if not pid.isdigit() or old.stat().st_uid != os.getuid():
                continue
            os.kill(int(pid), 0)   # still running (or another user's): kept
        except ProcessLookupError:
            shutil.rmtree(old, ignore_errors=True)
        except OSError:
            continue
    return tempfile.mkdtemp(prefix=f"{prefix}{os.getpid()}-")
