"""Animations: a keyframed scene (keyframes.py) rendered to numbered frames, and a video.

Ödegaard & Wennergren §6: morphing c, flying the camera, moving it along w.
Frames are whole work units on a Dask cluster or in this process (cluster.py); the
results come back here, and only this process writes files, each frame once, atomically
(output.py's temp file and rename); each frame's file - with the frame number, the
frame's resolved scene and its render report in its header - is encoded by the worker that
rendered it (output.write_image), so that the client's encoding does not bound a farm.
A run killed at any moment and started again renders only the
frames that are missing or whose recorded scene or channels differ; temporary files a
killed run left beside the frames are removed first.
"""
from __future__ import annotations

import contextlib
import math
import os
import re
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterable, Sequence

from pyjulia4d.app.output import OutputError, check_output_path, output_errors, read_header
from pyjulia4d.files import NAME_MAX, atomic_write, path_limit, path_text, shown_path, temp_affixes
from pyjulia4d.pipeline.progress import Progress
from pyjulia4d.pipeline.result import add_counts
from pyjulia4d.scene.checks import SceneError, show
from pyjulia4d.scene.keyframes import Animation

HEADER_SCENE = "pyjulia4d.scene"
HEADER_FRAME = "pyjulia4d.frame"
HEADER_OUTPUTS = "pyjulia4d.outputs"
_HASHES = re.compile(r"#+")


def check_pattern(pattern: str | os.PathLike) -> str:
    """``-o``: a frame file name with one run of '#', replaced by the zero-padded frame
    number (julia_####.png -> julia_0007.png; wider numbers keep all their digits)."""
    raw = path_text(pattern, lambda got: OutputError(f"frame pattern: expected {got}"))
    name = Path(raw).name
    runs = _HASHES.findall(name)
    if len(runs) != 1:
        got = "none" if not runs else f"{len(runs)}"
        raise OutputError(f"{shown_path(raw)}: the file name needs one run of '#' for the frame number "
                          f"(e.g. frames/julia_####.png), found {got}")
    if "#" in os.path.dirname(raw):
        raise OutputError(f"{shown_path(raw)}: '#' belongs in the file name, not the directory")
    return raw


def frame_path(pattern: str, n: int) -> Path:
    """The file of frame ``n`` (check_pattern)."""
    p = Path(pattern)
    name = _HASHES.sub(lambda m: f"{n:0{len(m.group(0))}d}", p.name)
    return p.with_name(name)


def outputs_tag(outputs) -> str:
    return "all" if outputs is None else ",".join(sorted(outputs))


def is_current(path: Path, scene_toml: str, tag: str) -> bool:
    """Whether ``path`` holds this frame: its recorded scene and channels are these."""
    hdr = read_header(path) if path.is_file() else None
    return hdr is not None and hdr.get(HEADER_SCENE) == scene_toml and hdr.get(HEADER_OUTPUTS) == tag


_TEMP = re.compile(r"[A-Za-z0-9_]{8}")


def remove_stale_temps(paths: Iterable[Path]) -> list[Path]:
    """Remove the temporary files (``.<stem>.<8 random characters><ext>``, output.atomic_write)
    that a killed run left beside these frames; returns them."""
    by_dir: dict[Path, dict[str, str]] = {}
    for p in paths:
        prefix, suffix = temp_affixes(p, path_limit(p.parent, "PC_NAME_MAX", NAME_MAX))
        by_dir.setdefault(p.parent, {})[prefix] = suffix
    removed = []
    for d, affixes in by_dir.items():
        try:
            names = os.listdir(d)
        except OSError:
            continue
        for name in names:
            if not name.startswith("."):
                continue
            for prefix, suffix in affixes.items():
                mid = name[len(prefix):len(name) - len(suffix)]
                if name.startswith(prefix) and name.endswith(suffix) and _TEMP.fullmatch(mid):
                    try:
                        os.unlink(d / name)
                        removed.append(d / name)
                    except OSError:
                        pass
                    break
    return removed


@dataclass
class Summary:
    """What an animate run did."""
    frames: range
    rendered: list[int] = field(default_factory=list)   # in the order written
    current: list[int] = field(default_factory=list)    # already on disk, up to date
    seconds: float = 0.0
    workers: set = field(default_factory=set)           # (worker, pid) pairs that rendered
    devices: set = field(default_factory=set)
    programs_built: int = 0
    capped: int = 0
    guards: dict = field(default_factory=dict)
    video_frames: int = 0
    stale_removed: int = 0


def check_frames(frames: Any) -> list[int]:
    """animate's ``frames`` from Python: whole frame numbers (range or list), each once; the
    animation's own range is checked with its scenes (Animation.scene)."""
    try:
        got = list(frames)
    except Exception:   # not iterable, or an object whose own iteration fails
        raise SceneError("frames", f"expected a list of frame numbers, got {show(frames)}") from None
    for n in got:
        if isinstance(n, bool) or not isinstance(n, int):
            raise SceneError("frames", f"expected whole frame numbers, got {show(n)}")
    if len(set(got)) != len(got):
        raise SceneError("frames", "a frame is named twice")
    return got


def _check_scenes(anim: Animation, frames: range, device: Any, force: bool, outputs) -> None:
    """Every frame's scene valid, and the work of each within workload.check's limits, before
    any renders; warnings said once each (with the number of frames that raise them)."""
    from pyjulia4d.pipeline.workload import check

    seen: dict[str, list[int]] = {}
    for n in frames:
        s = anim.scene(n)
        for t in anim.moments(n):   # a blurred frame's moments: each a valid scene too
            anim.scene_at(t, f"frame[{n}]")
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                check(s, device, force=force, outputs=outputs)
            except SceneError as e:
                raise SceneError(f"frame[{n}].{e.key}", e.reason) from None
        for w in caught:
            seen.setdefault(str(w.message), []).append(n)
    for msg, ns in seen.items():
        more = f" (frames {ns[0]}..{ns[-1]}, {len(ns)} of them)" if len(ns) > 1 else f" (frame {ns[0]})"
        warnings.warn(msg + more, RuntimeWarning, stacklevel=3)


def _frame_line(n: int, total: int, spent: float, left: float, note: str) -> str:
    return f"animate: frame {note} written, {n} of {total}, {spent:.0f} s, about {left:.0f} s left"


def animate(anim: Animation, pattern: str, frames: Sequence[int] | None = None, video: str | None = None,
            workers: int | None = None, scheduler: str | None = None, device: str | None = None,
            force: bool = False, outputs=None, progress: bool = False,
            on_written: Callable[[int, Path], None] | None = None) -> Summary:
    """Render ``frames`` (default: all) of ``anim`` to the files of ``pattern`` and, with
    ``video`` (.mp4/.webm), encode them in order at animation.fps.  Frames already on disk
    with this scene and these ``outputs`` are kept.  ``workers``/``scheduler``: where
    (distributed.cluster; workers=0 renders in this process).  Every check runs before
    any frame renders."""
    from pyjulia4d.app import cluster as distributed
    from pyjulia4d.app.video import check_video_path

    from pyjulia4d.pipeline.plan import check_flag

    t0 = time.perf_counter()
    if not isinstance(anim, Animation):
        raise SceneError("anim", f"expected an Animation (keyframes.load), got {type(anim).__name__}")
    for name, value in (("force", force), ("progress", progress)):
        check_flag(name, value)
    if on_written is not None and not callable(on_written):
        raise SceneError("on_written", f"expected None or a callable, got {type(on_written).__name__}")
    pattern = check_pattern(pattern)
    frames = range(anim.frames) if frames is None else check_frames(frames)
    summary = Summary(frames=frames)
    if workers is not None:
        workers = distributed.check_workers(workers)
    distributed.check_where(workers, scheduler)
    distributed.require_cluster(workers, scheduler)
    _check_scenes(anim, frames, distributed.check_device(device, scheduler), force, outputs)
    if video is not None:
        video = check_video_path(video)
    paths = {n: frame_path(pattern, n) for n in frames}
    made = _make_dirs({p.parent for p in paths.values()})
    try:
        _frames(anim, frames, paths, summary, video, workers, scheduler, device, force, outputs,
                progress, on_written)
    except BaseException:
        for d in reversed(made):  # only what this run created, and only while empty
            try:
                d.rmdir()
            except OSError:
                pass
        raise
    summary.seconds = time.perf_counter() - t0
    return summary


def _frames(anim, frames, paths, summary, video, workers, scheduler, device, force, outputs, progress,
            on_written) -> None:
    """animate, once the input is known good and the directories exist."""
    from pyjulia4d.app import cluster as distributed
    from pyjulia4d.app.video import video_from_files

    for p in {p.parent: p for p in paths.values()}.values():  # the longest number per directory
        check_output_path(p)
    summary.stale_removed = len(remove_stale_temps(paths.values()))
    tag = outputs_tag(outputs) + (f"; motion blur {anim.shutter:g} x {anim.motion_samples}" if anim.shutter > 0 else "")
    bar = None

    def write(n: int, result: Any, info: Any) -> None:
        """File a frame that came back: its bytes, encoded by the worker (distributed.EncodedImage)."""
        try:
            with atomic_write(paths[n]) as tmp:
                tmp.write_bytes(result.data)
        except OSError as e:
            raise OutputError(f"{paths[n]}: cannot write: {e.strerror or e}") from e
        summary.rendered.append(n)
        summary.workers.add((info.worker, info.pid))
        summary.devices.add(info.device)
        summary.programs_built += info.programs_built
        summary.capped += result.capped
        add_counts(summary.guards, result.guards)
        bar.update(1, note=str(n))
        if on_written is not None:
            on_written(n, paths[n])

    def todo_list(a: Animation) -> list:
        out = []
        for n in frames:
            if is_current(paths[n], a.scene(n).to_toml(), tag):
                summary.current.append(n)
            else:
                s = a.scene(n)
                header = {HEADER_SCENE: s.to_toml(), HEADER_FRAME: str(n), HEADER_OUTPUTS: tag}
                blur = {"moments": tuple(a.scene_at(t, f"frame[{n}]") for t in a.moments(n)),
                        "shutter": a.shutter} if a.shutter > 0 else {}
                out.append((n, s, {"outputs": outputs, "encode": (paths[n].suffix.lower(), header), **blur}))
        return out

    # without camera.fit the frames on disk are known before any cluster starts
    todo = None if anim.base.camera.fit else todo_list(anim)
    if todo == []:
        client_cm: Any = contextlib.nullcontext(None)
    else:
        client_cm = distributed.cluster(workers, scheduler, device)
    with client_cm as client, warnings.catch_warnings():
        warnings.simplefilter("ignore")  # said once each by _check_scenes
        if todo is None:  # frame the set once, from frame 0 (keyframes.load)
            f = distributed.fitted(client, anim.scene(0), device, force)
            anim = anim.with_camera(f.camera.position, f.camera.target)
            todo = todo_list(anim)
        bar = Progress(len(todo), "animate", "frame", enabled=progress, line=_frame_line, first=10.0, delay=0.0)
        try:
            distributed.render_many(client, todo, write, device=device, force=force)
        finally:
            bar.close()
    if video is not None:
        summary.video_frames = video_from_files(video, [paths[n] for n in frames], anim.fps)


def _make_dirs(dirs: Iterable[Path]) -> list[Path]:
    """Create the missing frame directories; returns those created (outermost first)."""
    made: list[Path] = []
    for d in sorted(dirs):
        missing = []
        p = d
        with output_errors(d, "cannot create the frame directory"):
            while not p.exists() and p != p.parent:
                missing.append(p)
                p = p.parent
        for m in reversed(missing):
            try:
                m.mkdir()
            except FileExistsError:
                continue
            except OSError as e:
                for x in reversed(made):
                    try:
                        x.rmdir()
                    except OSError:
                        pass
                raise OutputError(f"{shown_path(str(d))}: cannot create the frame directory: "
                                  f"{e.strerror or e}") from None
            made.append(m)
    return made


def closing_line(summary: Summary, pattern: str, video: str | None, fps: float) -> str:
    """What an animate run says when it ends (capped rays and guards never hidden)."""
    n = len(summary.rendered)
    kept = len(summary.current)
    where = ""
    if summary.devices:
        from pyjulia4d.app.cluster import rendered_where

        where = f" on {', '.join(sorted(summary.devices))} ({rendered_where(summary.workers)})"
    per = f", {summary.seconds / n:.2f} s per frame" if n else ""
    line = (f"rendered {n} frame{'s' if n != 1 else ''} to {pattern} in {summary.seconds:.2f} s{per}{where}"
            f"{f'; {kept} already up to date' if kept else ''}")
    if summary.capped:
        line += f"; {summary.capped} capped rays in all"
    fired = [f"{k} {v}" for k, v in summary.guards.items() if v]
    if fired:
        line += f"; guards fired (pixels, all frames): {', '.join(fired)}"
    if video is not None:
        line += f"; video {video} ({summary.video_frames} frames at {fps:g} fps)"
    return line


def strip(files: Sequence[str | os.PathLike], out: str | os.PathLike, columns: int | None = None) -> None:
    """A contact sheet of frame files (one row, or ``columns`` wide), written atomically as PNG."""
    import numpy as np
    from PIL import Image

    from pyjulia4d.app.video import read_frame

    out = path_text(out, lambda got: OutputError(f"contact sheet path: expected {got}"))
    imgs = [read_frame(f) for f in files]
    if not imgs:
        raise OutputError(f"{shown_path(out)}: no frames for a contact sheet")
    cols = columns or len(imgs)
    rows = math.ceil(len(imgs) / cols)
    h, w = imgs[0].shape[:2]
    sheet = np.zeros((rows * h, cols * w, 3), np.uint8)
    for i, im in enumerate(imgs):
        r, c = divmod(i, cols)
        sheet[r * h:(r + 1) * h, c * w:(c + 1) * w] = im
    with atomic_write(out) as tmp:
        Image.fromarray(sheet).save(tmp, format="PNG")
