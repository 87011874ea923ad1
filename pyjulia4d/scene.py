"""Scene description: typed frozen dataclasses, and every check on user input.

A scene is read from TOML (or a plain dict), then ``--set section.key=VALUE``
overrides are applied, and the result is validated in one pass. Every error is a
:class:`SceneError` whose message starts with the dotted key it concerns.
"""
from __future__ import annotations

import dataclasses
import json
import math
import sys
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any, Callable, Iterable, Literal, Mapping, Union

from .quality import QUALITIES, preset_values

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

Vec3 = tuple[float, float, float]
Vec4 = tuple[float, float, float, float]
Auto = Literal["auto"]

_INT_MAX = 2**31 - 1  # ints end up as OpenCL `int` kernel arguments


class SceneError(ValueError):
    """Invalid scene input; ``str(e)`` is ``"<dotted key>: <reason>"``.

    Raise as ``SceneError(key, reason)`` or ``SceneError("key: reason")``.
    """

    def __init__(self, key: str, reason: str | None = None) -> None:
        if reason is None:
            key, _, reason = key.partition(": ")
        super().__init__(f"{key}: {reason}")
        self.key = key
        self.reason = reason

    def __reduce__(self) -> tuple[Any, ...]:
        return (SceneError, (self.key, self.reason))


# ---------------------------------------------------------------- sections


@dataclass(frozen=True)
class Fractal:
    """[fractal]: the Julia set of z -> z^2 + c over the quaternions."""

    algebra: str = "quaternion"
    function: str = "sqr"
    c: Vec4 = (-0.2, 0.8, 0.0, 0.0)
    max_iter: int = 12
    bailout: float = 4.0  # escape radius (POV-Ray's default)


@dataclass(frozen=True)
class Camera:
    """[camera]: a 4D pinhole camera; ``fov`` is the full vertical angle in degrees."""

    position: Vec4 = (1.8, 1.6, -2.2, 0.0)
    target: Vec4 = (0.0, 0.0, 0.0, 0.0)
    up: Vec4 = (0.0, 1.0, 0.0, 0.0)
    limbo: Vec4 = (0.0, 0.0, 0.0, 1.0)
    fov: float = 40.0


@dataclass(frozen=True)
class Slice:
    """[slice]: the hyperplane dot(normal, p) = distance that cuts the 4D set."""

    normal: Vec4 = (0.0, 0.0, 0.0, 1.0)
    distance: float = 0.0


@dataclass(frozen=True)
class March:
    """[march]: how rays find the surface.  ``quality`` other than "custom" sets
    method, z_resolution, post_steps and epsilon from a measured preset (quality.py)."""

    quality: str = "custom"
    method: str = "de"
    z_resolution: int = 250
    post_steps: int = 4
    refine: str = "itp"
    epsilon: float = 1e-3
    max_steps: int = 4096
    near: Union[float, Auto] = "auto"
    far: Union[float, Auto] = "auto"


@dataclass(frozen=True)
class Normals:
    """[normals]: how surface normals are estimated."""

    method: str = "jacobian"
    step: Union[float, Auto] = "auto"


@dataclass(frozen=True)
class Shading:
    """[shading]: Phong shading; ``light`` is "eye" or a 4D position."""

    color: Vec3 = (0.95, 0.72, 0.42)
    background: Vec3 = (0.0, 0.0, 0.0)
    ambient: float = 0.08
    diffuse: float = 0.92
    specular: float = 0.35
    shininess: float = 40.0
    light: Union[Vec4, Literal["eye"]] = "eye"
    light_color: Vec3 = (1.0, 1.0, 1.0)


@dataclass(frozen=True)
class Image:
    """[image]: output size in pixels."""

    width: int = 640
    height: int = 480


@dataclass(frozen=True)
class Render:
    """[render]: device-side settings."""

    float: str = "single"


# ---------------------------------------------------------------- checkers
# A checker takes (dotted key, raw value) and returns the normalised value.

Checker = Callable[[str, Any], Any]


def _number(key: str, v: Any) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise SceneError(key, f"expected a number, got {v!r}")
    try:
        x = float(v)
    except OverflowError:
        x = math.inf
    if not math.isfinite(x):
        raise SceneError(key, "not a finite number")
    return x


def _real(pred: Callable[[float], bool] | None = None, desc: str = "") -> Checker:
    def check(key: str, v: Any) -> float:
        x = _number(key, v)
        if pred is not None and not pred(x):
            raise SceneError(key, f"must be {desc}, got {x!r}")
        return x

    return check


def _integer(minimum: int) -> Checker:
    def check(key: str, v: Any) -> int:
        if isinstance(v, bool) or not isinstance(v, int):
            raise SceneError(key, f"expected an integer, got {v!r}")
        if v < minimum:
            raise SceneError(key, f"must be >= {minimum}, got {v}")
        if v > _INT_MAX:
            raise SceneError(key, f"must be <= {_INT_MAX}, got {v}")
        return v

    return check


_TEXT_CHECKERS: set[Checker] = set()  # their override VALUE is kept verbatim


def _choice(*options: str) -> Checker:
    def check(key: str, v: Any) -> str:
        if not isinstance(v, str) or v not in options:
            raise SceneError(key, f"expected one of {', '.join(map(repr, options))}, got {v!r}")
        return v

    _TEXT_CHECKERS.add(check)
    return check


def _vector(
    lengths: tuple[int, ...],
    nonzero: bool = False,
    nonnegative: bool = False,
) -> Checker:
    """Fixed-length float vector; a 3-vector where 4 are allowed gets w = 0."""
    want = " or ".join(map(str, lengths))

    def check(key: str, v: Any) -> tuple[float, ...]:
        if not isinstance(v, (list, tuple)):
            raise SceneError(key, f"expected a list of {want} numbers, got {v!r}")
        if len(v) not in lengths:
            raise SceneError(key, f"expected a list of {want} numbers, got {len(v)}")
        xs = []
        for i, item in enumerate(v):
            try:
                xs.append(_number(key, item))
            except SceneError as e:
                raise SceneError(key, f"element {i}: {e.reason}") from None
        if len(xs) == 3 and 4 in lengths:
            xs.append(0.0)
        if nonzero and math.hypot(*xs) < 1e-12:
            raise SceneError(key, "zero-length vector")
        if nonnegative and min(xs) < 0:
            raise SceneError(key, f"components must be >= 0, got {tuple(xs)}")
        return tuple(xs)

    return check


def _or_string(word: str, inner: Checker, what: str) -> Checker:
    """Accept the literal string ``word``, else defer to ``inner``."""

    def check(key: str, v: Any) -> Any:
        if isinstance(v, str):
            if v == word:
                return v
            raise SceneError(key, f'expected "{word}" or {what}, got {v!r}')
        return inner(key, v)

    return check


def _gt0(x: float) -> bool:
    return x > 0


def _ge0(x: float) -> bool:
    return x >= 0


_SECTIONS: dict[str, type] = {
    "fractal": Fractal,
    "camera": Camera,
    "slice": Slice,
    "march": March,
    "normals": Normals,
    "shading": Shading,
    "image": Image,
    "render": Render,
}

_CHECKS: dict[str, dict[str, Checker]] = {
    "fractal": {
        "algebra": _choice("quaternion"),
        "function": _choice("sqr"),
        "c": _vector((4,)),
        "max_iter": _integer(1),
        "bailout": _real(_gt0, "> 0"),
    },
    "camera": {
        "position": _vector((3, 4)),
        "target": _vector((3, 4)),
        "up": _vector((3, 4), nonzero=True),
        "limbo": _vector((3, 4), nonzero=True),
        "fov": _real(lambda x: 0 < x < 180, "between 0 and 180 degrees (exclusive)"),
    },
    "slice": {
        "normal": _vector((4,), nonzero=True),
        "distance": _real(),
    },
    "march": {
        "quality": _choice(*QUALITIES),
        "method": _choice("fixed", "de"),
        "z_resolution": _integer(1),
        "post_steps": _integer(0),
        "refine": _choice("itp", "bisect"),
        "epsilon": _real(_gt0, "> 0"),
        "max_steps": _integer(1),
        "near": _or_string("auto", _real(_ge0, ">= 0"), "a number >= 0"),
        "far": _or_string("auto", _real(_gt0, "> 0"), "a number > 0"),
    },
    "normals": {
        "method": _choice("jacobian", "gradient", "zbuffer"),
        "step": _or_string("auto", _real(_gt0, "> 0"), "a number > 0"),
    },
    "shading": {
        "color": _vector((3,), nonnegative=True),
        "background": _vector((3,), nonnegative=True),
        "ambient": _real(_ge0, ">= 0"),
        "diffuse": _real(_ge0, ">= 0"),
        "specular": _real(_ge0, ">= 0"),
        "shininess": _real(_gt0, "> 0"),
        "light": _or_string("eye", _vector((3, 4)), "a list of 3 or 4 numbers"),
        "light_color": _vector((3,), nonnegative=True),
    },
    "image": {
        "width": _integer(1),
        "height": _integer(1),
    },
    "render": {
        "float": _choice("single", "double"),
    },
}


def _apply_quality(march: dict[str, Any], keep: set[str]) -> None:
    """Set the preset's march values for ``march["quality"]``, except the keys in ``keep``."""
    if "quality" not in march:
        return
    quality = _CHECKS["march"]["quality"]("march.quality", march["quality"])
    for k, v in preset_values(quality).items():
        if k not in keep:
            march[k] = v


# ---------------------------------------------------------------- overrides


def _scalar(text: str) -> Any:
    s = text.strip()
    for conv in (int, float):
        try:
            return conv(s)
        except ValueError:
            pass
    return s


def _parse_override(text: str) -> tuple[str, str, Any]:
    """``"section.key=VALUE"`` -> (section, key, value typed for that key)."""
    if not isinstance(text, str) or "=" not in text:
        raise SceneError(str(text), "malformed override, expected SECTION.KEY=VALUE")
    dotted, _, raw = text.partition("=")
    dotted = dotted.strip()
    section, _, key = dotted.partition(".")
    if section not in _CHECKS or key not in _CHECKS[section]:
        raise SceneError(dotted, "unknown key")
    if _CHECKS[section][key] in _TEXT_CHECKERS:
        return section, key, raw.strip()
    s = raw.strip()
    if s.startswith("[") and s.endswith("]"):
        return section, key, [_scalar(p) for p in s[1:-1].split(",")]
    if "," in s:
        return section, key, [_scalar(p) for p in s.split(",")]
    return section, key, _scalar(s)


# ---------------------------------------------------------------- TOML emitter


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return repr(v)  # shortest round-tripping form, valid TOML for finite floats
    if isinstance(v, str):
        return json.dumps(v)  # JSON string escapes are a subset of TOML's
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise TypeError(f"cannot write {v!r} as TOML")


# ---------------------------------------------------------------- scene


def _sub(a: tuple[float, ...], b: tuple[float, ...]) -> list[float]:
    return [x - y for x, y in zip(a, b)]


def _dot(a: Iterable[float], b: Iterable[float]) -> float:
    return sum(x * y for x, y in zip(a, b))


def _reject(v: list[float], basis: list[list[float]]) -> list[float]:
    """Component of v orthogonal to the orthonormal vectors in basis."""
    for e in basis:
        d = _dot(v, e)
        v = [x - d * y for x, y in zip(v, e)]
    return v


def _norm(v: Iterable[float]) -> float:
    return math.hypot(*v)


def _unit(v: list[float]) -> list[float]:
    n = _norm(v)
    return [x / n for x in v]


def _check_camera(cam: Camera) -> None:
    """camera.py builds a 4D frame by Gram-Schmidt on (view direction, limbo, up):
    they must be linearly independent.  Same order and messages as camera.py."""
    if cam.target == cam.position:
        raise SceneError("camera.target", "equals camera.position")
    fwd = _unit(_sub(cam.target, cam.position))
    limbo = _reject(list(cam.limbo), [fwd])
    if _norm(limbo) < 1e-6 * _norm(cam.limbo):
        raise SceneError("camera.limbo", "parallel to the view direction")
    up = _reject(list(cam.up), [fwd, _unit(limbo)])
    if _norm(up) < 1e-6 * _norm(cam.up):
        raise SceneError("camera.up", "parallel to the view direction or to camera.limbo")


@dataclass(frozen=True)
class Scene:
    """A fully validated scene; build with :meth:`default`, :meth:`from_dict` or :meth:`from_toml`."""

    fractal: Fractal = field(default_factory=Fractal)
    camera: Camera = field(default_factory=Camera)
    slice: Slice = field(default_factory=Slice)
    march: March = field(default_factory=March)
    normals: Normals = field(default_factory=Normals)
    shading: Shading = field(default_factory=Shading)
    image: Image = field(default_factory=Image)
    render: Render = field(default_factory=Render)

    @classmethod
    def default(cls) -> Scene:
        """The default scene."""
        return cls()

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], overrides: Iterable[str] = ()) -> Scene:
        """Validate ``{section: {key: value}}`` (missing keys get defaults), then apply overrides."""
        if not isinstance(data, Mapping):
            raise SceneError("scene", f"expected a table, got {data!r}")
        raw: dict[str, dict[str, Any]] = {name: {} for name in _CHECKS}
        for section, table in data.items():
            if section not in _CHECKS:
                raise SceneError(str(section), "unknown key")
            if not isinstance(table, Mapping):
                raise SceneError(section, f"expected a table, got {table!r}")
            for key, value in table.items():
                if key not in _CHECKS[section]:
                    raise SceneError(f"{section}.{key}", "unknown key")
                raw[section][key] = value
        # A quality preset fills the march keys the same source does not set itself;
        # a later source (an override) wins over an earlier one.
        _apply_quality(raw["march"], keep=set(raw["march"]))
        if isinstance(overrides, str):  # a lone string would be iterated per character
            overrides = [overrides]
        for text in overrides:
            section, key, value = _parse_override(text)
            raw[section][key] = value
            if (section, key) == ("march", "quality"):
                _apply_quality(raw["march"], keep=set())
        return cls._build(raw)

    @classmethod
    def from_toml(cls, path: str | Path, overrides: Iterable[str] = ()) -> Scene:
        """Read a TOML scene file, then apply overrides."""
        try:
            with open(path, "rb") as f:
                data = tomllib.load(f)
        except OSError as e:
            raise SceneError(str(path), f"cannot read: {e.strerror or e}") from None
        except tomllib.TOMLDecodeError as e:
            raise SceneError(str(path), f"invalid TOML: {e}") from None
        except UnicodeDecodeError as e:
            raise SceneError(str(path), f"invalid TOML: not UTF-8 ({e.reason})") from None
        return cls.from_dict(data, overrides)

    @classmethod
    def _build(cls, raw: Mapping[str, Mapping[str, Any]]) -> Scene:
        parts = {}
        for section, table in raw.items():
            checks = _CHECKS[section]
            kwargs = {k: checks[k](f"{section}.{k}", v) for k, v in table.items()}
            parts[section] = _SECTIONS[section](**kwargs)
        scene = cls(**parts)
        _check_camera(scene.camera)
        m = scene.march
        if m.quality != "custom" and any(getattr(m, k) != v for k, v in preset_values(m.quality).items()):
            # a march key set after the preset: the resolved scene says what really runs
            scene = dataclasses.replace(scene, march=dataclasses.replace(m, quality="custom"))
            m = scene.march
        if not isinstance(m.near, str) and not isinstance(m.far, str) and m.far <= m.near:
            raise SceneError("march.far", f"must be greater than march.near ({m.near!r}), got {m.far!r}")
        return scene

    def with_overrides(self, overrides: Iterable[str]) -> Scene:
        """A new scene with ``section.key=VALUE`` strings applied."""
        return Scene.from_dict(self.to_dict(), overrides)

    def replace(self, **changes: Any) -> Scene:
        """A new scene with typed values set by dotted key: ``replace(**{"march.post_steps": 10})``."""
        data = self.to_dict()
        for dotted, value in changes.items():
            section, _, key = dotted.partition(".")
            if section not in _CHECKS or key not in _CHECKS[section]:
                raise SceneError(dotted, "unknown key")
            data[section][key] = value
        return Scene.from_dict(data)

    def to_dict(self) -> dict[str, dict[str, Any]]:
        """``{section: {key: value}}`` with vectors as lists; feeds back into :meth:`from_dict`."""
        out: dict[str, dict[str, Any]] = {}
        for section in _SECTIONS:
            part = getattr(self, section)
            out[section] = {
                f.name: list(v) if isinstance(v := getattr(part, f.name), tuple) else v
                for f in fields(part)
            }
        return out

    def to_toml(self) -> str:
        """The fully resolved scene as TOML text (reads back with :meth:`from_toml`)."""
        lines = ["# pyjulia4d scene, fully resolved"]
        for section, table in self.to_dict().items():
            lines.append(f"\n[{section}]")
            lines.extend(f"{k} = {_toml_value(v)}" for k, v in table.items())
        return "\n".join(lines) + "\n"
