"""One explorer session: the scene a page (or a notebook) is looking at, the requests that
change it, and the files it saves - whatever carries the messages.

Requests are plain dicts, ``{"op": ..., ...}`` (the page sends them as JSON over its
WebSocket); what the session says goes to ``emit(message, data)``: a dict, and the PNG bytes
of a picture.  Every bad request is one ``{"type": "error"}`` line and changes nothing.

Requests:
- ``set``: ``values`` ``{control name: text}`` (controls.py), ``moving`` (a control still moves);
- ``orbit`` (``yaw``, ``pitch`` degrees), ``turn_w`` (``degrees``), ``zoom`` (``factor``),
  each with ``moving`` (geometry/navigate.py);
- ``refine``: the control stopped: refine the current scene to its full size;
- ``frame``: place the camera to frame the set (camera.fit: its direction kept);
- ``save_scene`` (``name``.toml), ``render_file`` (``name``.png, .tif or .exr, in a thread, with
  ``progress`` messages), ``keyframe`` (``frames`` after the last one; the first is frame 0),
  ``clear_keyframes``, ``save_animation`` (``name``.toml, ``fps``: the keyframed scene
  ``pyjulia4d animate`` renders).

Files go into the session's folder only, by plain file names (no folders, no dot files)."""
from __future__ import annotations

import dataclasses
import math
import threading
import time
from pathlib import Path
from typing import Any, Callable

from pyjulia4d.app.explore import controls
from pyjulia4d.app.output import FORMATS, check_output_path, write_file
from pyjulia4d.app.explore.loop import Picture, RenderLoop
from pyjulia4d.geometry import navigate
from pyjulia4d.geometry.vec4 import Degenerate
from pyjulia4d.scene.checks import SceneError, one_line, show
from pyjulia4d.scene.keyframes import FIXED_KEYS, INTERPOLATIONS, from_table, keyframable
from pyjulia4d.scene.model import Scene
from pyjulia4d.scene.text import scene_table_from_text, toml_value

Emit = Callable[[dict, "bytes | None"], None]
# render(scene, on_progress, whole, first_sample=0) -> RenderResult; ``whole``: the file
# render (probed, calibrated), else a stage of the loop; ``first_sample``: a path-traced
# batch's first sample (loop.path_batches)
Render = Callable[..., Any]

MAX_NAME = 200                # characters of a file name the page may give
MAX_GAP = 100_000             # frames between two keyframes
DEFAULT_GAP = 48              # two seconds at 24 frames per second
MAX_KEYFRAMES = 1000
MAX_ANGLE = 360.0             # degrees of one orbit or w-turn request
ZOOM_RANGE = (1e-3, 1e3)      # one zoom request's factor
PROGRESS_EVERY = 0.2          # seconds between progress messages of a file render
CAMERA_NAMES = tuple(n for k in ("camera.position", "camera.target", "camera.up", "camera.limbo")
                     for n in controls.CONTROLS[k].names())


class ExploreError(ValueError):
    """A request the session refuses; its message is one line naming what is wrong."""


def file_in(folder: Path, name: Any, suffixes: tuple[str, ...]) -> Path:
    """``folder/name`` for a plain file name with one of ``suffixes``: no folder part, no
    leading dot, printable, at most MAX_NAME characters."""
    if not isinstance(name, str) or not name.strip():
        raise ExploreError(f"name: expected a file name ending in {' or '.join(suffixes)}, got {show(name)}")
    if (len(name) > MAX_NAME or not name.isprintable() or any(c in name for c in "/\\\0")
            or name.startswith(".") or name != name.strip()):
        raise ExploreError(f"{show(name)}: expected a plain file name (no folders, no leading dot, at most "
                           f"{MAX_NAME} characters); files are written in {folder}")
    if Path(name).suffix.lower() not in suffixes:
        raise ExploreError(f"{show(name)}: expected a name ending in {' or '.join(suffixes)}")
    return folder / name


def _toml_path(folder: Path, name: Any) -> Path:
    """A scene file ``name`` in ``folder`` (file_in), checked as an output path is."""
    return check_output_path(file_in(folder, name, (".toml",)), (".toml",), "scene")


def _number(msg: dict, key: str, lo: float, hi: float, default: float | None = None) -> float:
    value = msg.get(key, default)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
            or not lo <= value <= hi:
        raise ExploreError(f"{key}: expected a number in [{lo:g}, {hi:g}], got {show(value)}")
    return float(value)


def animation_toml(keyframes: list[tuple[int, Scene]], fps: float, interpolation: str) -> tuple[str, list[str]]:
    """The keyframed scene file of ``keyframes`` ((frame, scene), frames increasing): the
    first keyframe's scene, an [animation] table, and one [[keyframe]] per keyframe with the
    numeric keys that differ between them (scene/keyframes.py).  Also the keys that differ
    but cannot be interpolated (words, switches): the first keyframe's value is kept."""
    base = keyframes[0][1]
    flat = [{f"{sec}.{k}": v for sec, table in s.to_dict().items() for k, v in table.items()}
            for _, s in keyframes]
    varying, kept = [], []
    for dotted, first in flat[0].items():
        if all(f.get(dotted) == first for f in flat[1:]):
            continue
        if keyframable(dotted) and dotted not in FIXED_KEYS and all(not isinstance(f.get(dotted), str)
                                                                    for f in flat):
            varying.append(dotted)
        else:
            kept.append(dotted)
    if any(k.startswith("camera.") for k in varying):   # a keyframed camera is never framed
        base = dataclasses.replace(base, camera=dataclasses.replace(base.camera, fit=False))
    lines = [base.to_toml().rstrip("\n"), "", "[animation]", f"frames = {keyframes[-1][0] + 1}",
             f"fps = {fps!r}", f"interpolation = {toml_value(interpolation)}"]
    for frame, _ in keyframes:
        lines += ["", "[[keyframe]]", f"frame = {frame}"]
    out, k = [], 0
    for line in lines:   # each [[keyframe]]'s values after its frame line
        out.append(line)
        if line.startswith("frame = "):
            out += [f"{d} = {toml_value(flat[k][d])}" for d in varying]
            k += 1
    return "\n".join(out) + "\n", kept


class Session:
    """See the module's docstring.  ``render`` renders a scene (Render); ``emit`` carries
    messages and pictures to the viewer, from any thread."""

    def __init__(self, scene: Scene, render: Render, folder: str | Path, emit: Emit) -> None:
        self.folder = Path(folder)
        self._emit = emit
        self._render = render
        self._lock = threading.Lock()
        self.scene = scene
        self.keyframes: list[tuple[int, Scene]] = []
        self._file_thread: threading.Thread | None = None
        self.loop = RenderLoop(lambda s, hook, *first: render(s, hook, False, *first), self._shown, self._failed)

    # ---------------------------------------------------------------- what the viewer sees

    def start(self) -> None:
        """The form's values and the first picture."""
        self._emit({"type": "values", "values": controls.form_values(self.scene)}, None)
        self.loop.request(self.scene, moving=False)

    def close(self) -> None:
        self.loop.close()

    def _shown(self, picture: Picture) -> None:
        with self._lock:
            adopt = (self.scene.camera.fit and not picture.scene.camera.fit
                     and picture.generation == self.loop.generation)
            if adopt:   # the framing pass placed the camera: the page's camera from now on
                self.scene = dataclasses.replace(self.scene, camera=picture.scene.camera)
        if adopt:
            self._camera_values()
        self._emit({"type": "frame", "stage": picture.stage, "generation": picture.generation,
                    "facts": picture.facts}, picture.png)

    def _failed(self, message: str) -> None:
        self._emit({"type": "error", "message": message}, None)

    def _camera_values(self) -> None:
        values = controls.form_values(self.scene)
        self._emit({"type": "values", "values": {n: values[n] for n in CAMERA_NAMES}}, None)

    def say(self, message: str) -> None:
        self._emit({"type": "status", "message": message}, None)

    # ---------------------------------------------------------------- requests

    def handle(self, msg: Any) -> None:
        """Carry out one request; a bad one is an error message, never an exception."""
        try:
            self._handle(msg)
        except (ValueError, Degenerate) as e:   # SceneError, ExploreError, OutputError
            self._emit({"type": "error", "message": one_line(e)}, None)

    def _handle(self, msg: Any) -> None:
        if not isinstance(msg, dict):
            raise ExploreError(f"request: expected an object with an op, got {show(msg)}")
        op = msg.get("op")
        moving = msg.get("moving", False)
        if not isinstance(moving, bool):
            raise ExploreError(f"moving: expected true or false, got {show(moving)}")
        if op == "set":
            with self._lock:
                self.scene = controls.apply_values(self.scene, msg.get("values"))
            self.loop.request(self.scene, moving)
        elif op in ("orbit", "turn_w", "zoom"):
            self._move(op, msg, moving)
        elif op == "refine":
            self.loop.request(self.scene, moving=False)
        elif op == "focus":
            self.focus(_number(msg, "x", 0.0, 1.0), _number(msg, "y", 0.0, 1.0))
        elif op == "frame":   # camera.fit: the first stage frames the set, and the page takes its camera
            with self._lock:
                self.scene = dataclasses.replace(self.scene, camera=dataclasses.replace(self.scene.camera, fit=True))
            self.loop.request(self.scene, moving=False)
        elif op == "save_scene":
            self.save_scene(msg.get("name"))
        elif op == "render_file":
            self.render_file(msg.get("name"))
        elif op == "keyframe":
            self.add_keyframe(int(_number(msg, "frames", 1, MAX_GAP, DEFAULT_GAP)))
        elif op == "clear_keyframes":
            self.keyframes.clear()
            self._emit({"type": "keyframes", "count": 0}, None)
        elif op == "save_animation":
            interpolation = msg.get("interpolation", "catmull-rom")
            if interpolation not in INTERPOLATIONS:
                raise ExploreError(f"interpolation: expected one of {', '.join(INTERPOLATIONS)}, got "
                                   f"{show(interpolation)}")
            self.save_animation(msg.get("name"), _number(msg, "fps", 0.1, 1000.0, 24.0), interpolation)
        else:
            raise ExploreError(f"op: unknown request {show(op)}; one of set, orbit, turn_w, zoom, refine, focus, frame, "
                               f"save_scene, render_file, keyframe, clear_keyframes, save_animation")

    def focus(self, x: float, y: float) -> None:
        """A click on the picture at (x, y), fractions of its width and height from the top
        left: the lens focused on the surface seen there (path_plan.focus_at)."""
        from pyjulia4d.geometry.camera import camera_frame
        from pyjulia4d.pipeline.path_plan import focus_at
        from pyjulia4d.pipeline.records import march_args
        with self._lock:
            sc = self.scene
            if sc.shading.integrator != "path":
                self.say('focus: the lens is the path tracer\'s (shading.integrator = "path")')
                return
            w, h = sc.image.width, sc.image.height
            px, py = min(int(x * w), w - 1), min(int(y * h), h - 1)
            focus = focus_at(sc, camera_frame(sc), march_args(sc), px, py)
            self.scene = sc.replace(**{"camera.focus": focus})
        self.say(f"focus: {focus:.4g} along the view axis (camera.focus)")
        self.loop.request(self.scene, moving=False)

    def _move(self, op: str, msg: dict, moving: bool) -> None:
        with self._lock:
            cam = self.scene.camera
            try:
                if op == "orbit":
                    cam = navigate.orbit(cam, _number(msg, "yaw", -MAX_ANGLE, MAX_ANGLE, 0.0),
                                         _number(msg, "pitch", -MAX_ANGLE, MAX_ANGLE, 0.0))
                elif op == "turn_w":
                    cam = navigate.turn_w(cam, _number(msg, "degrees", -MAX_ANGLE, MAX_ANGLE))
                else:
                    cam = navigate.zoom(cam, _number(msg, "factor", *ZOOM_RANGE))
            except Degenerate as e:
                raise ExploreError(f"camera: the view has no {e.which} direction left; set the camera by hand") \
                    from None
            self.scene = dataclasses.replace(self.scene, camera=cam)
        self._camera_values()
        self.loop.request(self.scene, moving)

    # ---------------------------------------------------------------- files

    def save_scene(self, name: Any) -> Path:
        """The current scene, fully resolved, as ``name``.toml in the folder."""
        path = _toml_path(self.folder, name)
        write_file(path, self.scene.to_toml())
        self.say(f"saved {path}")
        return path

    def render_file(self, name: Any) -> None:
        """Render the current scene at its full size into ``name`` (.png or .exr) in the
        folder, in a thread, with progress messages; one render at a time."""
        path = check_output_path(file_in(self.folder, name, FORMATS))
        if self._file_thread is not None and self._file_thread.is_alive():
            raise ExploreError("render: a render to a file is still running; wait for it")
        scene = self.scene
        self._file_thread = threading.Thread(target=self._render_file, args=(scene, path), daemon=True,
                                             name="pyjulia4d-explore-file")
        self._file_thread.start()

    def _render_file(self, scene: Scene, path: Path) -> None:
        from pyjulia4d.app.output import render_header, write_image

        last = [0.0]

        def progress(done: int, total: int) -> None:
            now = time.perf_counter()
            if now - last[0] >= PROGRESS_EVERY or done >= total:
                last[0] = now
                self._emit({"type": "progress", "name": path.name, "done": done / max(1, total)}, None)

        try:
            result = self._render(scene, progress, True)
            header, tail = render_header(scene, result)
            write_image(path, result, header)
        except ValueError as e:
            self._emit({"type": "error", "message": one_line(e)}, None)
            return
        except Exception as e:   # the page stays alive; the error is one line
            self._emit({"type": "error", "message": f"render failed: {type(e).__name__}: {one_line(e)}"}, None)
            return
        w, h = scene.image.width, scene.image.height
        self.say(f"rendered {path} ({w}x{h}) in {result.seconds:.2f} s, "
                 f"{100 * result.hit_fraction:.1f}% of pixels hit{tail}")

    def add_keyframe(self, gap: int = DEFAULT_GAP) -> int:
        """The current view as a keyframe, ``gap`` frames after the last (the first: frame 0)."""
        if len(self.keyframes) >= MAX_KEYFRAMES:
            raise ExploreError(f"keyframe: at most {MAX_KEYFRAMES} keyframes")
        frame = 0 if not self.keyframes else self.keyframes[-1][0] + gap
        if frame >= 1_000_000:
            raise ExploreError("keyframe: past the last frame an animation may have (999999)")
        self.keyframes.append((frame, self.scene))
        self._emit({"type": "keyframes", "count": len(self.keyframes), "frame": frame}, None)
        return frame

    def save_animation(self, name: Any, fps: float = 24.0, interpolation: str = "catmull-rom") -> Path:
        """The keyframes as a keyframed scene ``name``.toml in the folder (animation_toml),
        checked by reading it back as ``pyjulia4d animate`` does before it is written."""
        if len(self.keyframes) < 2:
            raise ExploreError("save animation: add at least two keyframes first")
        path = _toml_path(self.folder, name)
        text, kept = animation_toml(self.keyframes, fps, interpolation)
        try:
            from_table(scene_table_from_text(text, "the animation"))
        except SceneError as e:
            raise ExploreError(f"save animation: {one_line(e)}") from None
        write_file(path, text)
        note = f"; kept the first keyframe's {', '.join(kept)} (not interpolated)" if kept else ""
        self.say(f"saved {path}: {len(self.keyframes)} keyframes, {self.keyframes[-1][0] + 1} frames "
                 f"(render: pyjulia4d animate {path.name}){note}")
        return path
