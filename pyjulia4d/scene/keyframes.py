"""Keyframed scenes: ``[[keyframe]]`` tables and an ``[animation]`` table in a scene file.

Ödegaard & Wennergren §6 animates the constant c (a sphere morphed into a Julia
set), flies the camera in x, y, z and moves position and target along w to see the set
at other 4D angles; POV-Ray 3.6 documentation (julia_fractal, slice) animates the
slice distance so that the set grows from nothing and shrinks away.  Here any numeric
scene key may be keyframed; each keyed value follows its own track through the keyframes
that set it, and holds its first (last) keyed value before (after) them.  Keys no
keyframe sets keep the scene's value.

Between keyframes i and i + 1 at frames t_i < t_(i+1), with u = (t - t_i) / (t_(i+1) - t_i):

- ``linear``:      p = p_i + u (p_(i+1) - p_i)
- ``smooth``:      the same with u replaced by the smoothstep 3u^2 - 2u^3 (eases in and
                   out of every keyframe: the motion stops at each one)
- ``catmull-rom``: the cubic Hermite curve through p_i and p_(i+1) with the Catmull-Rom
                   tangents m_i = (p_(i+1) - p_(i-1)) / (t_(i+1) - t_(i-1)) (one-sided at
                   the ends), p = h00 p_i + h10 dt m_i + h01 p_(i+1) + h11 dt m_(i+1),
                   h00 = 2u^3 - 3u^2 + 1, h10 = u^3 - 2u^2 + u, h01 = -2u^3 + 3u^2,
                   h11 = u^3 - u^2, dt = t_(i+1) - t_i: smooth velocity through the
                   keyframes (the default).

Integer keys (fractal.max_iter, ...) are rounded to the nearest integer.  When any camera
vector is keyframed, each frame's camera.limbo and camera.up are re-orthonormalised
against the view direction f = (target - position) / |target - position| in Ödegaard & Wennergren §4's
order (camera.py): limbo' = unit(limbo - (limbo.f) f), up' = unit(up - (up.f) f -
(up.limbo') limbo').  Every frame's scene is built and validated before any renders.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable, Mapping

import numpy as np

from pyjulia4d.geometry.vec4 import Degenerate, orthonormalise, unit_or_none
from pyjulia4d.scene.model import Scene
from pyjulia4d.scene.ranges import CHECKS
from pyjulia4d.scene.checks import Integer, OrWord, Real, SceneError, Vector, did_you_mean, show, show_key
from pyjulia4d.scene.text import override_key, override_list, read_scene_table


INTERPOLATIONS = ("linear", "smooth", "catmull-rom")
MAX_FRAMES = 1_000_000
MAX_FPS = 1000.0
MAX_MOTION_SAMPLES = 64
# Keys that cannot change between the frames of one sequence: a video's frames share a size.
FIXED_KEYS = ("image.width", "image.height")
CAMERA_VECTORS = ("camera.position", "camera.target", "camera.up", "camera.limbo")


def _numeric(check: Any) -> Any:
    """The numeric checker behind a scene key's checker, or None for a non-numeric key
    (a choice, a boolean, the clip planes); "eye"/"auto" words are not interpolated."""
    check = OrWord.split(check)[1]   # "auto" (or "auto" or "pixel") or a number: the number
    return check if isinstance(check, (Real, Integer, Vector)) else None


def keyframable(dotted: str) -> bool:
    """Whether ``dotted`` is a scene key that keyframes may set."""
    section, _, key = dotted.partition(".")
    check = CHECKS.get(section, {}).get(key)
    return check is not None and _numeric(check) is not None and dotted not in FIXED_KEYS


def _flatten(table: Mapping[str, Any], prefix: str = "") -> Iterable[tuple[str, Any]]:
    """{"fractal": {"c": v}} and {"fractal.c": v} both give ("fractal.c", v)."""
    for k, v in table.items():
        name = f"{prefix}{k}"
        if isinstance(v, Mapping):
            yield from _flatten(v, name + ".")
        else:
            yield name, v


@dataclass(frozen=True)
class Track:
    """One key's keyframes: frames (increasing) and values (float64, scalars or vectors)."""
    key: str
    frames: tuple[int, ...]
    values: tuple[Any, ...]
    integer: bool = False


def interpolate(frames, values, t: float, method: str) -> np.ndarray:
    """The value of the track (``frames`` increasing, ``values`` arrays) at frame ``t``
    (formulas in the module docstring)."""
    ts = [float(f) for f in frames]
    ps = [np.asarray(v, np.float64) for v in values]
    if t <= ts[0]:
        return ps[0].copy()
    if t >= ts[-1]:
        return ps[-1].copy()
    i = max(k for k in range(len(ts) - 1) if ts[k] <= t)
    t0, t1 = ts[i], ts[i + 1]
    u = (t - t0) / (t1 - t0)
    p0, p1 = ps[i], ps[i + 1]
    if method == "linear":
        return p0 + u * (p1 - p0)
    if method == "smooth":
        s = u * u * (3.0 - 2.0 * u)
        return p0 + s * (p1 - p0)

    def tangent(k: int) -> np.ndarray:
        lo, hi = max(k - 1, 0), min(k + 1, len(ts) - 1)
        return (ps[hi] - ps[lo]) / (ts[hi] - ts[lo])

    dt = t1 - t0
    u2, u3 = u * u, u * u * u
    h00, h10, h01, h11 = 2 * u3 - 3 * u2 + 1, u3 - 2 * u2 + u, -2 * u3 + 3 * u2, u3 - u2
    return h00 * p0 + h10 * dt * tangent(i) + h01 * p1 + h11 * dt * tangent(i + 1)


def orthonormal_camera(position, target, up, limbo) -> tuple[list[float], list[float]] | None:
    """(up', limbo') orthonormal to the view direction (module docstring), or None where
    the vectors are degenerate (the scene's own check then names the key)."""
    lu = unit_or_none(np.asarray(limbo, np.float64))
    uu = unit_or_none(np.asarray(up, np.float64))
    if lu is None or uu is None:
        return None
    try:
        _, limbo2, up2 = orthonormalise(np.subtract(target, position, dtype=np.float64), lu, uu)
    except Degenerate:
        return None
    return [float(x) + 0.0 for x in up2], [float(x) + 0.0 for x in limbo2]


@dataclass(frozen=True)
class Animation:
    """A base scene, the tracks of its keyed values and the [animation] settings."""
    base: Scene
    tracks: tuple[Track, ...] = ()
    frames: int = 1
    fps: float = 24.0
    interpolation: str = "catmull-rom"
    shutter: float = 0.0       # motion blur: the share of a frame's interval the shutter is open (0: none)
    motion_samples: int = 8    # moments of the shutter each blurred frame is rendered at
    _cache: dict = field(default_factory=dict, compare=False, repr=False)

    def scene(self, n: int) -> Scene:
        """Frame ``n``'s scene (0 <= n < frames), validated; errors name ``frame[n].<key>``."""
        if isinstance(n, bool) or not isinstance(n, int):
            raise SceneError("frame", f"expected a whole frame number, got {show(n)}")
        if n in self._cache:
            return self._cache[n]
        if not 0 <= n < self.frames:
            raise SceneError("--frames", f"frame {n} is outside 0..{self.frames - 1}")
        s = self.scene_at(float(n), f"frame[{n}]")
        self._cache[n] = s
        return s

    def moments(self, n: int) -> tuple[float, ...]:
        """The times frame ``n``'s motion blur samples: ``motion_samples`` moments spread
        evenly over a shutter of ``shutter`` frames centred on n (the middle of each of as
        many equal parts: t_k = n + shutter ((k + 1/2) / K - 1/2)); () without blur.  A track
        holds its first and last keyed values beyond its keyframes, as at whole frames."""
        if self.shutter <= 0:
            return ()
        k = self.motion_samples
        return tuple(n + self.shutter * ((i + 0.5) / k - 0.5) for i in range(k))

    def scene_at(self, t: float, name: str | None = None) -> Scene:
        """The scene at frame time ``t`` (fractional between frames: a motion blur's moment),
        validated; errors name ``name`` (default ``time[t]``)."""
        data = self.base.to_dict()
        for tr in self.tracks:
            v = interpolate(tr.frames, tr.values, float(t), self.interpolation)
            if tr.integer:
                value: Any = int(math.floor(float(v) + 0.5))
            elif v.ndim == 0:
                value = float(v)
            else:
                value = [float(x) for x in v]
            section, _, key = tr.key.partition(".")
            data[section][key] = value
        if any(tr.key in CAMERA_VECTORS for tr in self.tracks):
            cam = data["camera"]
            got = orthonormal_camera(cam["position"], cam["target"], cam["up"], cam["limbo"])
            if got is not None:
                cam["up"], cam["limbo"] = got
        try:
            return Scene.from_dict(data)
        except SceneError as e:
            raise SceneError(f"{name or f'time[{t:g}]'}.{e.key}", e.reason) from None

    def with_camera(self, position, target) -> "Animation":
        """The animation with camera.fit resolved: every frame keeps this position and target
        (camera.fit then false); see :func:`load` for why the set is framed once.  Each is a
        list of 3 or 4 numbers (or an array), checked by the scene's own keys."""
        vectors = {key: v.tolist() if isinstance(v, np.ndarray) else v
                   for key, v in (("camera.position", position), ("camera.target", target))}
        base = self.base.replace(**vectors, **{"camera.fit": False})
        return Animation(base, self.tracks, self.frames, self.fps, self.interpolation, self.shutter,
                         self.motion_samples)


def _animation_settings(table: Any, overrides: list[tuple[str, str]]) -> dict[str, Any]:
    """[animation]: frames (integer >= 1), fps (> 0), interpolation, shutter ([0, 1]: the share
    of a frame's interval the shutter is open, 0 no motion blur) and motion_samples (2 to
    MAX_MOTION_SAMPLES moments rendered per blurred frame); overrides (key, text) last."""
    if table is None:
        table = {}
    if not isinstance(table, Mapping):
        raise SceneError("animation", f"expected a table, got {show(table)}")
    raw = dict(table)
    for key, text in overrides:
        raw[key] = _parse_setting(key, text)
    out: dict[str, Any] = {}
    for key, value in raw.items():
        dotted = f"animation.{key}"
        if key == "frames":
            out[key] = Integer(1, MAX_FRAMES)(dotted, value)
        elif key == "fps":
            out[key] = Real(0.0, MAX_FPS, lo_open=True)(dotted, value)
        elif key == "shutter":
            out[key] = Real(0.0, 1.0)(dotted, value)
        elif key == "motion_samples":
            out[key] = Integer(2, MAX_MOTION_SAMPLES)(dotted, value)
        elif key == "interpolation":
            if value not in INTERPOLATIONS:
                raise SceneError(dotted, f"expected one of {', '.join(map(repr, INTERPOLATIONS))}, "
                                         f"got {show(value)}")
            out[key] = value
        else:
            raise SceneError(show_key(dotted), "unknown key (animation takes frames, fps, interpolation, shutter, "
                                               "motion_samples)")
    return out


def _parse_setting(key: str, text: str) -> Any:
    s = text.strip()
    if key == "interpolation":
        return s
    for conv in (int, float):
        try:
            return conv(s) if s.isascii() else s
        except ValueError:
            pass
    return s


def _tracks(keyframes: Any, dropped: set[str]) -> tuple[list[Track], int]:
    """The tracks of [[keyframe]] tables, and the last keyframe's frame (-1: none)."""
    if keyframes is None:
        return [], -1
    if not isinstance(keyframes, list):
        raise SceneError("keyframe", f"expected [[keyframe]] tables, got {show(keyframes)}")
    by_key: dict[str, list[tuple[int, Any]]] = {}
    last = -1
    for i, kf in enumerate(keyframes, start=1):
        where = f"keyframe[{i}]"
        if not isinstance(kf, Mapping):
            raise SceneError(where, f"expected a table, got {show(kf)}")
        if "frame" not in kf:
            raise SceneError(f"{where}.frame", "missing: every keyframe needs frame = N")
        frame = Integer(0, MAX_FRAMES - 1)(f"{where}.frame", kf["frame"])
        if frame <= last:
            what = "duplicated" if frame == last else "out of order"
            raise SceneError(f"{where}.frame", f"{frame} is {what} (the previous keyframe is frame "
                                                f"{last}; keyframes go in increasing frame order)")
        last = frame
        keys = [(k, v) for k, v in _flatten({k: v for k, v in kf.items() if k != "frame"})]
        if not keys:
            raise SceneError(where, "sets no scene key")
        for dotted, value in keys:
            section, _, key = dotted.partition(".")
            check = CHECKS.get(section, {}).get(key)
            name = f"{where}.{show_key(dotted)}"
            if check is None:
                raise SceneError(name, "unknown key" + did_you_mean(dotted, [f"{a}.{b}" for a, ks in CHECKS.items()
                                                                              for b in ks]))
            if dotted in FIXED_KEYS:
                raise SceneError(name, "cannot change between frames (every frame of a sequence has "
                                       "one size); set it in [image]")
            numeric = _numeric(check)
            if numeric is None or isinstance(value, str):
                raise SceneError(name, f"not numeric ({check.valid}): only numbers and vectors are "
                                       f"interpolated; set it once in [{section}]")
            value = numeric(name, value)
            by_key.setdefault(dotted, []).append((frame, value))
    tracks = []
    for dotted, pts in by_key.items():
        if dotted in dropped:
            continue
        integer = isinstance(_numeric(CHECKS[dotted.split(".")[0]][dotted.split(".")[1]]), Integer)
        tracks.append(Track(dotted, tuple(f for f, _ in pts),
                            tuple(np.asarray(v, np.float64) for _, v in pts), integer))
    return tracks, last


def load(path: str | Path, overrides: Iterable[str] = ()) -> Animation:
    """Read a scene file with [[keyframe]] tables and an [animation] table.  ``overrides``
    are ``--set`` strings: ``animation.KEY=VALUE`` sets the animation, any other the base
    scene (after the file); a scene key set by an override is no longer keyframed.

    camera.fit (true where the file gives no camera.position, Scene.from_dict) frames the
    set once, from frame 0, and every frame keeps that camera (animation.animate): framed
    per frame, the camera would jump as the set changes.  Keyframes that set
    camera.position or camera.target turn that default off; with camera.fit = true they
    are an error."""
    table = read_scene_table(path)
    return from_table(table, overrides)


def from_table(table: Mapping[str, Any], overrides: Iterable[str] = ()) -> Animation:
    """:func:`load` on a table already read (``{section: {key: value}}``)."""
    if not isinstance(table, Mapping):
        raise SceneError("scene", f"expected a table, got {show(table)}")
    overrides = override_list(overrides)
    table = dict(table)
    keyframes = table.pop("keyframe", None)
    anim_table = table.pop("animation", None)
    moved = _camera_keyed(keyframes)
    cam = table.get("camera")
    if moved and (cam is None or isinstance(cam, Mapping)) and "fit" not in (cam or {}):
        # keyframes place the camera: Scene.from_dict's "no position: fit" does not apply
        table["camera"] = {**(cam or {}), "fit": False}
    anim_over, scene_over = [], []
    for text in overrides:
        key = override_key(text) if isinstance(text, str) else ""
        if key.startswith("animation."):
            anim_over.append((key.partition(".")[2], text.partition("=")[2]))
        else:
            scene_over.append(text)
    base = Scene.from_dict(table, scene_over)
    dropped = {override_key(t) for t in scene_over}
    if base.camera.fit and moved - dropped:
        raise SceneError("camera.fit", f"true, but keyframes move {' and '.join(sorted(moved - dropped))}: "
                                       f"a keyframed camera is not framed; set camera.fit = false")
    settings = _animation_settings(anim_table, anim_over)
    tracks, last = _tracks(keyframes, dropped)
    # keyframes past the last frame shape the curve (a loop's closing keyframe: frame N = frame 0)
    frames = settings.get("frames", max(last + 1, 1))
    anim = Animation(base, tuple(tracks), frames, settings.get("fps", 24.0),
                     settings.get("interpolation", "catmull-rom"), settings.get("shutter", 0.0),
                     settings.get("motion_samples", 8))
    return anim


def _camera_keyed(keyframes: Any) -> set[str]:
    """camera.position and camera.target where any keyframe sets them (unchecked input)."""
    out: set[str] = set()
    if isinstance(keyframes, list):
        for kf in keyframes:
            if isinstance(kf, Mapping):
                out |= {k for k, _ in _flatten(kf) if k in ("camera.position", "camera.target")}
    return out


def parse_frames(text: str | None, total: int) -> range:
    """``--frames``: "A:B" (A to B inclusive), "A:" , ":B" or "N"; None: every frame."""
    if text is None:
        return range(total)
    if not isinstance(text, str):
        raise SceneError("--frames", f"expected A:B (first and last frame), got {show(text)}")
    s = text.strip()
    try:
        if ":" in s:
            a, _, b = s.partition(":")
            lo = int(a) if a.strip() else 0
            hi = int(b) if b.strip() else total - 1
        else:
            lo = hi = int(s)
    except ValueError:
        raise SceneError("--frames", f"expected A:B (first and last frame), got {show(text)}") from None
    if not 0 <= lo <= hi < total:
        raise SceneError("--frames", f"{lo}:{hi} is not within 0:{total - 1} (the animation's frames, "
                                     f"first not after last)")
    return range(lo, hi + 1)
