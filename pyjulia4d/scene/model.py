"""Scene description: typed frozen dataclasses, and every check on user input.

A scene is read from TOML (or a plain dict), then ``--set section.key=VALUE``
overrides are applied, and the result is validated in one pass. Every error is a
:class:`SceneError` whose message starts with the dotted key it concerns.  Every key
has a valid range, declared once in ``_CHECKS`` (:func:`valid_range` words it; README's
"Scene keys" table is tested against it).
"""
from __future__ import annotations

import dataclasses
import json
import math
import sys
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any, Callable, Iterable, Literal, Mapping, Union

from pyjulia4d.scene.quality import QUALITIES, preset_values

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

Vec3 = tuple[float, float, float]
Vec4 = tuple[float, float, float, float]
Auto = Literal["auto"]

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


# The 4D algebras and the iterated functions f (q -> f(q) + c) of POV-Ray's julia_fractal
# (seed 003_8ca5f9108f52d3d6.txt), in its order.  Quaternions take sqr and cube only,
# as in POV-Ray; the hypercomplex numbers take every function; Gintz's CQuats and the
# naive commutative rules (seed 000 eqs. 14, 15) sqr and cube.
ALGEBRAS = ("quaternion", "hypercomplex", "cquat", "commutative")
FUNCTIONS = ("sqr", "cube", "exp", "reciprocal", "sin", "asin", "sinh", "asinh", "cos", "acos",
             "cosh", "acosh", "tan", "atan", "tanh", "atanh", "ln", "pwr")
FUNCTIONS_OF = {"quaternion": ("sqr", "cube"), "hypercomplex": FUNCTIONS, "cquat": ("sqr", "cube"),
                "commutative": ("sqr", "cube")}
# The polynomial maps, by degree: they escape to infinity like |q|^degree, which gives the
# bounding ball and the distance estimate (camera.bounding_radius, iterate.cl).
POLYNOMIAL_DEGREE = {"sqr": 2, "cube": 3}
# fractal.kind = "mandelbrot": the critical (or asymptotic) value v of f, in the point's own
# coordinates, so that q_1 = v + c (kernels/kind/mandelbrot.cl).  0 for the powers (critical
# point 0), exp and reciprocal (the asymptotic value 0: their orbit of the singular value c);
# 1 for cos and cosh (critical point 0) and sin (pi/2); i for sinh (i pi/2), component by
# component in the hypercomplex split, where (1, 0, 0, 0) and (0, 1, 0, 0) are 1 and i in both
# components.  Functions with several singular values (tan, tanh) or none (ln, the inverse
# functions) have no one Mandelbrot set and are refused.
MANDELBROT_START = {"sqr": (0.0, 0.0, 0.0, 0.0), "cube": (0.0, 0.0, 0.0, 0.0), "exp": (0.0, 0.0, 0.0, 0.0),
                    "reciprocal": (0.0, 0.0, 0.0, 0.0), "pwr": (0.0, 0.0, 0.0, 0.0),
                    "cos": (1.0, 0.0, 0.0, 0.0), "cosh": (1.0, 0.0, 0.0, 0.0), "sin": (1.0, 0.0, 0.0, 0.0),
                    "sinh": (0.0, 1.0, 0.0, 0.0)}
# Algebras where |q^D| >= |q|^D, so that the escape bound holds: quaternions (the norm is
# multiplicative) and the hypercomplex numbers (the power mean of their two complex
# components).  CQuats and the commutative rules have zero divisors with |q^2| < |q|^2.
NORM_BOUNDED = ("quaternion", "hypercomplex")


def escape_degree(f: "Fractal") -> int | None:
    """D where |f(q)| >= |q|^D - |c| (camera.bounding_radius), else None."""
    return POLYNOMIAL_DEGREE.get(f.function) if f.algebra in NORM_BOUNDED else None


@dataclass(frozen=True)
class Fractal:
    """[fractal]: the Julia set of q -> f(q) + c in a 4D algebra, or (``kind``) its Mandelbrot
    set, a stack of complex Julia sets or the cubic connectedness locus (seed 001 §5); ``theta``
    rotates the quaternion map (seed 001 §2.3)."""

    algebra: str = "quaternion"
    function: str = "sqr"
    c: Vec4 = (-0.2, 0.8, 0.0, 0.0)
    max_iter: int = 12
    bailout: float = 4.0  # escape radius (POV-Ray's default)
    exponent: tuple[float, float] = (2.0, 0.0)  # pwr's complex exponent x + iy
    # "julia": the point is q_0, c the constant; "mandelbrot": the point is c, q_0 = 0 (the
    # critical point of q^2 and q^3), c unused (kernels/kind/mandelbrot.cl)
    kind: str = "julia"
    # the complex rotation g(q) = e^(i theta) q conjugating the map, in degrees (seed 001
    # §2.3; kernels/kind/rotate.cl); 0 compiles the rotation out
    theta: float = 0.0
    # "julia_stack" (seed 001 §5.1; kernels/kind/julia_stack.cl): the complex Julia sets of
    # z^2 + c(s), c(s) = c_from + s (c_to - c_from), stacked along the third coordinate u =
    # 2 s - 1 in [-1, 1] (c_from at u = -1); complex numbers as (re, im)
    c_from: tuple[float, float] = (-1.0, 0.0)
    c_to: tuple[float, float] = (-0.1, 0.75)
    # "cubic_locus" (seed 001 §5.2; kernels/kind/cubic_locus.cl): the (a, b) = (x + i y, z + i w)
    # whose critical point +a ("plus": C+) or -a ("minus": C-) has a bounded orbit under
    # z^3 - 3 a^2 z + b, drawn within the 4-ball |(a, b)| <= locus_radius (C+ is unbounded)
    component: str = "plus"
    locus_radius: float = 2.0

    def __post_init__(self) -> None:
        _check_section(self, "fractal")


# The kinds of set a [fractal] table describes (Fractal.kind).
KINDS = ("julia", "mandelbrot", "julia_stack", "cubic_locus")


def has_distance_estimate(f: Fractal) -> bool:
    """Whether the march may step by a distance estimate: quaternion sqr and cube, whose
    norm is multiplicative, so |q'_n| follows the orbit (seed 001 §3.1, eq. 8), and the
    hypercomplex sqr and cube, whose set is the product of two complex Julia sets with
    complex estimates (iterate.cl).  The other pairs are marched by the fixed scan
    (march.method = "auto")."""
    if f.kind in ("julia_stack", "cubic_locus"):   # none proven (seed 001 §5.1, §5.2); the stack's
        return False                                # "de" is an empirical one
    return f.algebra in ("quaternion", "hypercomplex") and f.function in POLYNOMIAL_DEGREE


def march_method(scene: "Scene") -> str:
    """march.method with "auto" resolved: "de" where the pair has a distance estimate,
    else "fixed"."""
    m = scene.march.method
    if m != "auto":
        return m
    return "de" if has_distance_estimate(scene.fractal) else "fixed"


@dataclass(frozen=True)
class Camera:
    """[camera]: a 4D pinhole camera; ``fov`` is the full vertical angle in degrees."""

    position: Vec4 = (1.8, 1.6, -2.2, 0.0)
    target: Vec4 = (0.0, 0.0, 0.0, 0.0)
    up: Vec4 = (0.0, 1.0, 0.0, 0.0)
    limbo: Vec4 = (0.0, 0.0, 0.0, 1.0)
    fov: float = 40.0
    # frame the set from a quick first pass (framing.py), keeping the view direction; a scene
    # read by from_dict/from_toml (or the command line) that gives no camera.position and
    # no camera.fit gets true (Scene.from_dict)
    fit: bool = False

    def __post_init__(self) -> None:
        _check_section(self, "camera")


@dataclass(frozen=True)
class Slice:
    """[slice]: the hyperplane dot(normal, p) = distance that cuts the 4D set."""

    normal: Vec4 = (0.0, 0.0, 0.0, 1.0)
    distance: float = 0.0

    def __post_init__(self) -> None:
        _check_section(self, "slice")


@dataclass(frozen=True)
class March:
    """[march]: how rays find the surface.  ``quality`` other than "custom" sets
    method, z_resolution, post_steps and epsilon from a measured preset (quality.py)."""

    quality: str = "custom"
    method: str = "auto"
    z_resolution: int = 250
    post_steps: int = 4
    refine: str = "itp"
    epsilon: float = 1e-3
    max_steps: int = 4096
    near: Union[float, Auto] = "auto"
    far: Union[float, Auto] = "auto"

    def __post_init__(self) -> None:
        _check_section(self, "march")


@dataclass(frozen=True)
class Normals:
    """[normals]: how surface normals are estimated."""

    method: str = "jacobian"
    step: Union[float, Auto] = "auto"

    def __post_init__(self) -> None:
        _check_section(self, "normals")


@dataclass(frozen=True)
class Shading:
    """[shading]: Phong shading; ``light`` is "eye" or a 4D position."""

    color: Vec3 = (0.89, 0.477, 0.147)  # linear light (sRGB (0.95, 0.72, 0.42))
    background: Vec3 = (0.0, 0.0, 0.0)
    ambient: float = 0.15
    diffuse: float = 0.92
    specular: float = 0.35
    shininess: float = 40.0
    light: Union[Vec4, Literal["eye"]] = (-2.0, 5.0, -4.0, 0.0)
    light_color: Vec3 = (1.0, 1.0, 1.0)
    shadow: str = "soft"           # "none" | "hard" | "soft" (shade/light.cl)
    shadow_softness: float = 16.0  # k of the penumbra min(k d / t): larger is sharper
    ao: float = 0.6                # ambient occlusion strength, 0 = off
    ao_distance: float = 0.1       # how far along the normal occlusion is sampled
    coloring: str = "flat"         # "flat" | "iteration" | "trap" | "w"
    colormap: str = "viridis"      # a matplotlib colour map (COLORMAPS)
    trap: Vec4 = (0.0, 0.0, 0.0, 0.0)  # the orbit trap's point (coloring = "trap")
    fog: float = 0.0               # depth cueing: fade to the background by exp(-fog distance)
    sky: Vec3 = (1.0, 1.0, 1.0)    # colour of the ambient light (times ambient and occlusion)
    lights: tuple["Light", ...] = ()   # more lights beside ``light`` (at most MAX_LIGHTS)
    reflection: float = 0.0        # share of one mirror bounce in the colour (shade/reflect.cl); 0 = off

    def __post_init__(self) -> None:
        _check_section(self, "shading")


@dataclass(frozen=True)
class Light:
    """One of shading.lights: a point light at ``position`` or a distant light from
    ``direction`` (towards the light; scene coordinates, like shading.light), of ``color``
    times ``intensity``.  It lights diffuse and specular terms and casts shadows as
    shading.light does (shading.shadow)."""

    position: Vec4 | None = None
    direction: Vec4 | None = None
    color: Vec3 = (1.0, 1.0, 1.0)
    intensity: float = 1.0

    def __post_init__(self) -> None:
        """Checked as a table of shading.lights is (scene._Lights)."""
        _check_light(self)

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        if self.position is not None:
            out["position"] = list(self.position)
        else:
            out["direction"] = list(self.direction or ())
        out["color"] = list(self.color)
        out["intensity"] = self.intensity
        return out


MAX_LIGHTS = 3   # shading.lights beside shading.light (kernels/shade/: EXTRA_LIGHTS)


@dataclass(frozen=True)
class Image:
    """[image]: output size in pixels."""

    width: int = 640
    height: int = 480
    samples: int = 1      # rays per pixel (stratified jitter); colour and alpha are their mean
    adaptive: bool = False   # samples only where neighbours differ (antialias.py)

    def __post_init__(self) -> None:
        _check_section(self, "image")


@dataclass(frozen=True)
class Clip:
    """[clip]: up to 4 half-spaces n . p <= offset of the scene's 3D space that cut the set
    open (each plane [nx, ny, nz, offset]; the cut face is shaded with the plane's normal)."""

    planes: tuple[tuple[float, float, float, float], ...] = ()

    def __post_init__(self) -> None:
        _check_section(self, "clip")


@dataclass(frozen=True)
class Render:
    """[render]: device-side settings."""

    float: str = "single"
    variant: str = "auto"

    def __post_init__(self) -> None:
        _check_section(self, "render")


# Colour maps shading.colormap accepts: matplotlib's, named here so that a scene is checked
# without importing matplotlib (tests/test_shade.py checks each exists there).
COLORMAPS = ("viridis", "plasma", "inferno", "magma", "cividis", "twilight", "twilight_shifted", "turbo",
             "cubehelix", "Spectral", "coolwarm", "RdYlBu", "copper", "bone", "hot", "afmhot", "ocean",
             "terrain", "gist_earth", "gnuplot2", "CMRmap", "YlOrBr", "PuBuGn", "BuPu")


# ---------------------------------------------------------------- checkers
# A checker is called as check(dotted key, raw value) and returns the normalised value;
# ``valid`` is its valid range in words, as README's "Scene keys" table shows it.
#
# Why these ranges: every value must reach the float32 kernels finite, with room for
# the arithmetic done on it there (squares of positions, products of shading weights).
# Positions and distances up to 1e6 (a camera 1e4 away is the catalogue's far case),
# so points stay below ~3e6 and their squares below 1e13; near/far up to 1e7 covers
# any ray through that region.  |c| components up to 1e3: beyond |c| = 2 the set is
# already dust.  Shading weights and colours up to 1e3 keep colour sums below ~1e10.
# Integers are OpenCL ints; max_iter and post_steps are capped where more cannot
# change a float64 render (60 post-steps already bisect below float64's spacing).

_INT_MAX = 2**31 - 1  # ints end up as OpenCL `int` kernel arguments
COORD = 1e6           # bound of positions, directions' components and slice.distance
MAX_SCENE_BYTES = 1 << 20  # scene files larger than this are refused unread


def _fmt(x: float) -> str:
    """A bound as README writes it: 1e6, 1e-3, 179.9, 0, 2147483647."""
    if isinstance(x, int):
        return str(x)
    if x != 0 and not 1e-2 <= abs(x) < 1e3:
        mantissa, exponent = f"{x:.14e}".split("e")
        return f"{mantissa.rstrip('0').rstrip('.')}e{int(exponent)}"
    return f"{x:g}"


def _show(v: Any, limit: int = 60) -> str:
    """repr(v) for an error message: one line, at most ``limit`` characters."""
    try:
        s = repr(v)
    except ValueError:  # an int of more than 4300 digits
        s = f"<an integer of ~{int(v.bit_length() * math.log10(2)) + 1} digits>"
    except RecursionError:  # a deeply nested list
        s = f"<a deeply nested {type(v).__name__}>"
    return s if len(s) <= limit else s[: limit - 3] + "..."


def _show_key(key: str) -> str:
    """A user-given key or path as it goes into a message: itself when plain, else repr."""
    return key if key and key.isprintable() and len(key) <= 80 else _show(key, 80)


@dataclass(frozen=True)
class _Range:
    """lo <= x <= hi (lo < x with ``lo_open``)."""

    lo: float
    hi: float
    lo_open: bool = False

    def __contains__(self, x: float) -> bool:
        return (self.lo < x if self.lo_open else self.lo <= x) and x <= self.hi

    def __str__(self) -> str:
        return f"{'(' if self.lo_open else '['}{_fmt(self.lo)}, {_fmt(self.hi)}]"


class _Real:
    """A finite number in a range; ints are taken as floats, -0.0 becomes 0.0."""

    verbatim = False  # an override's VALUE is parsed as numbers, not kept as text

    def __init__(self, lo: float, hi: float, lo_open: bool = False) -> None:
        self.range = _Range(lo, hi, lo_open)
        self.valid = str(self.range)

    def __call__(self, key: str, v: Any) -> float:
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise SceneError(key, f"expected a number, got {_show(v)}")
        if isinstance(v, float) and not math.isfinite(v):
            raise SceneError(key, "not a finite number")
        if v not in self.range:  # an int compares exactly, however large
            raise SceneError(key, f"must be in {self.range}, got {_show(v)}")
        return float(v) + 0.0


class _Integer:
    """An integer (not a float, not a bool) in a range."""

    verbatim = False

    def __init__(self, lo: int, hi: int) -> None:
        self.range = _Range(lo, hi)
        self.valid = f"integer in {self.range}"

    def __call__(self, key: str, v: Any) -> int:
        if isinstance(v, bool) or not isinstance(v, int):
            raise SceneError(key, f"expected an integer, got {_show(v)}")
        if v not in self.range:
            raise SceneError(key, f"must be in {self.range}, got {_show(v)}")
        return v


class _Choice:
    """One of a few words."""

    verbatim = True  # an override's VALUE is the word itself

    def __init__(self, *options: str) -> None:
        self.options = options
        quoted = [f'"{o}"' for o in options]
        self.valid = quoted[0] if len(quoted) == 1 else ", ".join(quoted[:-1]) + " or " + quoted[-1]

    def __call__(self, key: str, v: Any) -> str:
        if not isinstance(v, str) or v not in self.options:
            raise SceneError(key, f"expected one of {', '.join(map(repr, self.options))}, got {_show(v)}")
        return v


class _Vector:
    """A fixed-length list of numbers, each in [lo, hi]; a 3-vector where 4 are allowed
    gets w = 0.  ``nonzero``: a direction, any length but 0 (it is normalised by its
    largest component first, so tiny and huge lengths are both exact)."""

    verbatim = False

    def __init__(self, lengths: tuple[int, ...], lo: float, hi: float, nonzero: bool = False) -> None:
        self.lengths = lengths
        self.element = _Real(lo, hi)
        self.want = " or ".join(map(str, lengths))
        self.valid = f"{self.want} numbers in {self.element.range}" + (", not all 0" if nonzero else "")
        self.nonzero = nonzero

    def __call__(self, key: str, v: Any) -> tuple[float, ...]:
        if not isinstance(v, (list, tuple)):
            raise SceneError(key, f"expected a list of {self.want} numbers, got {_show(v)}")
        if len(v) not in self.lengths:
            raise SceneError(key, f"expected a list of {self.want} numbers, got {len(v)}")
        xs = []
        for i, item in enumerate(v):
            try:
                xs.append(self.element(key, item))
            except SceneError as e:
                raise SceneError(key, f"element {i}: {e.reason}") from None
        if len(xs) == 3 and 4 in self.lengths:
            xs.append(0.0)
        if self.nonzero and not any(xs):
            raise SceneError(key, "zero-length vector")
        return tuple(xs)


class _Bool:
    """true or false (TOML booleans; on the command line the words)."""

    verbatim = True
    valid = "true or false"

    def __call__(self, key: str, v: Any) -> bool:
        if isinstance(v, bool):
            return v
        if isinstance(v, str) and v.strip() in ("true", "false"):
            return v.strip() == "true"
        raise SceneError(key, f"expected true or false, got {_show(v)}")


class _Planes:
    """Up to 4 planes [nx, ny, nz, offset]: a list of 4-number lists (TOML) or, on the
    command line, "nx,ny,nz,offset;..." ("" or "[]": none)."""

    verbatim = True

    def __init__(self, most: int) -> None:
        self.most = most
        self.valid = (f"up to {most} planes [nx, ny, nz, offset], numbers in [-1e6, 1e6], the normal not "
                      f"all 0 (--set: nx,ny,nz,offset;...)")

    def __call__(self, key: str, v: Any) -> tuple:
        if isinstance(v, str):
            text = v.strip()
            if text in ("", "[]"):
                v = []
            else:
                v = [[_scalar(x) for x in part.split(",")] for part in text.strip("[]").split(";")]
        if not isinstance(v, (list, tuple)):
            raise SceneError(key, f"expected a list of planes [nx, ny, nz, offset], got {_show(v)}")
        if len(v) > self.most:
            raise SceneError(key, f"at most {self.most} planes, got {len(v)}")
        out = []
        for i, plane in enumerate(v):
            if not isinstance(plane, (list, tuple)) or len(plane) != 4:
                raise SceneError(key, f"plane {i}: expected [nx, ny, nz, offset], got {_show(plane)}")
            vals = []
            for j, x in enumerate(plane):
                if isinstance(x, bool) or not isinstance(x, (int, float)):
                    raise SceneError(key, f"plane {i}: element {j}: expected a number, got {_show(x)}")
                if not math.isfinite(x):
                    raise SceneError(key, f"plane {i}: element {j}: not a finite number")
                if abs(x) > COORD:
                    raise SceneError(key, f"plane {i}: element {j}: must be in [-1e6, 1e6], got {_show(x)}")
                vals.append(float(x))
            if max(abs(x) for x in vals[:3]) == 0:
                raise SceneError(key, f"plane {i}: zero normal")
            out.append(tuple(vals))
        return tuple(out)


class _Lights:
    """Up to ``most`` lights, each a table with exactly one of position / direction (3 or 4
    numbers; a direction not all 0) and optional color (3 numbers in [0, 1e3]) and intensity
    (in [0, 1e3]).  On the command line: "position x,y,z[,w] color r,g,b intensity k; direction
    x,y,z[,w] ..." ("" or "[]": none)."""

    verbatim = True
    FIELDS = ("position", "direction", "color", "intensity")

    def __init__(self, most: int) -> None:
        self.most = most
        self.valid = (f"up to {most} tables {{position = [x, y, z, w] or direction = [x, y, z, w], "
                      f"color = [r, g, b], intensity = k}} (--set: position x,y,z,w color r,g,b "
                      f"intensity k; ...)")
        self.point = _Vector((3, 4), -COORD, COORD)
        self.direction = _Vector((3, 4), -COORD, COORD, nonzero=True)
        self.color = _Vector((3,), 0.0, 1e3)
        self.intensity = _Real(0.0, 1e3)

    def _parse(self, key: str, text: str) -> list:
        lights = []
        for i, part in enumerate(text.strip("[]").split(";")):
            words = part.split()
            if len(words) % 2:
                raise SceneError(key, f"light {i}: expected pairs 'name value', got {_show(part.strip())}")
            table: dict[str, Any] = {}
            for name, value in zip(words[0::2], words[1::2]):
                table[name] = _scalar(value) if name == "intensity" else [_scalar(x) for x in value.split(",")]
            lights.append(table)
        return lights

    def __call__(self, key: str, v: Any) -> tuple:
        if isinstance(v, str):
            text = v.strip()
            v = [] if text in ("", "[]") else self._parse(key, text)
        if not isinstance(v, (list, tuple)):
            raise SceneError(key, f"expected a list of light tables, got {_show(v)}")
        if len(v) > self.most:
            raise SceneError(key, f"at most {self.most} lights (besides shading.light), got {len(v)}")
        out = []
        for i, table in enumerate(v):
            where = f"{key}[{i}]"
            if isinstance(table, Light):
                table = table.to_dict()
            if not isinstance(table, Mapping):
                raise SceneError(where, f"expected a table {{position = [...], color = [...], intensity = k}}, "
                                        f"got {_show(table)}")
            for name in table:
                if name not in self.FIELDS:
                    raise SceneError(f"{where}.{_show_key(str(name))}", "unknown key; use position or direction, "
                                                                        "color, intensity")
            if ("position" in table) == ("direction" in table):
                raise SceneError(where, "give exactly one of position and direction")
            kw: dict[str, Any] = {}
            for name, check in (("position", self.point), ("direction", self.direction), ("color", self.color),
                                ("intensity", self.intensity)):
                if name in table:
                    kw[name] = check(f"{where}.{name}", table[name])
            out.append(Light(**kw))
        return tuple(out)


class _OrWord:
    """The literal string ``word``, else what ``inner`` accepts."""

    verbatim = False

    def __init__(self, word: str, inner: Any) -> None:
        self.word = word
        self.inner = inner
        self.valid = f'"{word}" or {inner.valid}'

    def __call__(self, key: str, v: Any) -> Any:
        if isinstance(v, str):
            if v == self.word:
                return v
            raise SceneError(key, f"expected {self.valid}, got {_show(v)}")
        return self.inner(key, v)


Checker = Callable[[str, Any], Any]

_SECTIONS: dict[str, type] = {
    "fractal": Fractal,
    "camera": Camera,
    "slice": Slice,
    "march": March,
    "normals": Normals,
    "shading": Shading,
    "image": Image,
    "clip": Clip,
    "render": Render,
}

SECTION_NAMES = tuple(_SECTIONS)

# Every key's check and valid range, in one place (README's table is tested against it).
_CHECKS: dict[str, dict[str, Checker]] = {
    "fractal": {
        "algebra": _Choice(*ALGEBRAS),
        "function": _Choice(*FUNCTIONS),
        "c": _Vector((4,), -1e3, 1e3),
        "max_iter": _Integer(1, 1_000_000),
        # above ~9.6e8 single precision is refused at render time (workload.py)
        "bailout": _Real(1e-3, 1e76),
        # pwr's exponent; |x|, |y| <= 16: higher powers overflow float32 within an iteration
        "exponent": _Vector((2,), -16.0, 16.0),
        "kind": _Choice(*KINDS),
        # degrees; one turn each way (the map is periodic in theta with period 360)
        "theta": _Real(-360.0, 360.0),
        # the stack's end points: a Julia set is empty (dust) for |c| > 2, so +-4 covers all
        "c_from": _Vector((2,), -4.0, 4.0),
        "c_to": _Vector((2,), -4.0, 4.0),
        "component": _Choice("plus", "minus"),
        # the ball the unbounded C+ is drawn in; fractal.bailout must reach its maps' escape
        # radius (scene._check_locus: 4 does up to 2.19)
        "locus_radius": _Real(0.05, 16.0),
    },
    "camera": {
        "position": _Vector((3, 4), -COORD, COORD),
        "target": _Vector((3, 4), -COORD, COORD),
        "up": _Vector((3, 4), -COORD, COORD, nonzero=True),
        "limbo": _Vector((3, 4), -COORD, COORD, nonzero=True),
        "fov": _Real(1e-6, 179.9),
        "fit": _Bool(),
    },
    "slice": {
        "normal": _Vector((4,), -COORD, COORD, nonzero=True),
        "distance": _Real(-COORD, COORD),
    },
    "march": {
        "quality": _Choice(*QUALITIES),
        "method": _Choice("auto", "fixed", "de"),
        # the kernel's int loop counter: from 2^31 - 2 on refused at render time (workload.py)
        "z_resolution": _Integer(1, _INT_MAX),
        "post_steps": _Integer(0, 1000),
        "refine": _Choice("itp", "bisect"),
        "epsilon": _Real(1e-12, 1.0),
        "max_steps": _Integer(1, _INT_MAX),
        "near": _OrWord("auto", _Real(0.0, 1e7)),
        "far": _OrWord("auto", _Real(0.0, 1e7, lo_open=True)),
    },
    "normals": {
        "method": _Choice("jacobian", "gradient", "zbuffer"),
        "step": _OrWord("auto", _Real(1e-12, 1.0)),
    },
    "shading": {
        "color": _Vector((3,), 0.0, 1e3),
        "background": _Vector((3,), 0.0, 1e3),
        "ambient": _Real(0.0, 1e3),
        "diffuse": _Real(0.0, 1e3),
        "specular": _Real(0.0, 1e3),
        "shininess": _Real(1e-3, 1e4),
        "light": _OrWord("eye", _Vector((3, 4), -COORD, COORD)),
        "light_color": _Vector((3,), 0.0, 1e3),
        "shadow": _Choice("none", "hard", "soft"),
        "shadow_softness": _Real(1.0, 1e3),
        "ao": _Real(0.0, 1.0),
        "ao_distance": _Real(1e-4, 10.0),
        "coloring": _Choice("flat", "iteration", "trap", "w"),
        "colormap": _Choice(*COLORMAPS),
        "trap": _Vector((3, 4), -COORD, COORD),
        "fog": _Real(0.0, 100.0),
        "sky": _Vector((3,), 0.0, 1e3),
        "lights": _Lights(MAX_LIGHTS),
        "reflection": _Real(0.0, 1.0),
    },
    "image": {
        "width": _Integer(1, _INT_MAX),
        "height": _Integer(1, _INT_MAX),
        "samples": _Integer(1, 256),
        "adaptive": _Bool(),
    },
    "clip": {
        "planes": _Planes(4),
    },
    "render": {
        "float": _Choice("single", "double"),
        "variant": _Choice("auto", "scalar", "packet"),
    },
}


def key_names() -> list[str]:
    """Every scene key, ``section.name``, in the order of the sections and their fields."""
    return [f"{section}.{key}" for section, table in _CHECKS.items() for key in table]


def valid_range(dotted: str) -> str:
    """The valid range of a scene key in words, e.g. ``valid_range("march.epsilon")``."""
    section, _, key = dotted.partition(".")
    return _CHECKS[section][key].valid


def _check_section(part: Any, section: str) -> None:
    """Check every field of a section dataclass as a scene file's value would be (the same
    one-line SceneError naming the key), storing the normalised values (vectors as tuples of
    floats, 3-vectors given w = 0): a scene built in Python, dataclasses.replace included, is
    as valid as one read from a file."""
    checks = _CHECKS[section]
    for f in fields(part):
        value = getattr(part, f.name)
        checked = checks[f.name](f"{section}.{f.name}", value)
        if checked is not value:
            object.__setattr__(part, f.name, checked)


def _check_light(light: "Light") -> None:
    """One of shading.lights, checked as _Lights checks a table."""
    lights = _CHECKS["shading"]["lights"]
    where = "shading.lights[]"
    if (light.position is None) == (light.direction is None):
        raise SceneError(where, "give exactly one of position and direction")
    for name, check in (("position", lights.point), ("direction", lights.direction), ("color", lights.color),
                        ("intensity", lights.intensity)):
        value = getattr(light, name)
        if value is not None:
            checked = check(f"{where}.{name}", value)
            if checked is not value:
                object.__setattr__(light, name, checked)


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
    """An int, else a float, else the text itself.  Only ASCII is read as a number:
    Python's int() and float() would also take other scripts' digits."""
    s = text.strip()
    if s.lstrip("+-").isdigit() and len(s) > 4000:  # int() refuses over 4300 digits; float() -> inf
        return s
    if s.isascii():
        for conv in (int, float):
            try:
                return conv(s)
            except ValueError:
                pass
    return s


def override_key(text: str) -> str:
    """The dotted key of an override ``"section.key=VALUE"`` (stripped; not checked)."""
    return text.partition("=")[0].strip()


def _parse_override(text: str) -> tuple[str, str, Any]:
    """``"section.key=VALUE"`` -> (section, key, value typed for that key)."""
    if not isinstance(text, str):
        raise SceneError("--set", f"expected SECTION.KEY=VALUE, got {_show(text)}")
    if "=" not in text:
        shown = text.strip()
        if shown and _show_key(shown) == shown:
            raise SceneError(shown, "malformed override, expected SECTION.KEY=VALUE")
        raise SceneError("--set", f"malformed override {_show(text)}, expected SECTION.KEY=VALUE")
    dotted = override_key(text)
    raw = text.partition("=")[2]
    if not dotted:
        raise SceneError("--set", f"missing key in {_show(text)}, expected SECTION.KEY=VALUE")
    section, _, key = dotted.partition(".")
    if section not in _CHECKS or key not in _CHECKS[section]:
        raise SceneError(_show_key(dotted), "unknown key")
    s = raw.strip()
    if _CHECKS[section][key].verbatim:
        return section, key, s
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
    if isinstance(v, Light):
        v = v.to_dict()
    if isinstance(v, Mapping):   # an inline table (shading.lights)
        return "{ " + ", ".join(f"{k} = {_toml_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(f"cannot write {v!r} as TOML")


# ---------------------------------------------------------------- scene


def read_scene_table(path: str | Path) -> dict[str, Any]:
    """The TOML table of a scene file: a bounded read (/dev/zero or a stray multi-gigabyte
    file is refused, not loaded), UTF-8, every failure one SceneError naming the path
    (Scene.from_toml, keyframes.load)."""
    where = _show_key(str(path))
    try:
        with open(path, "rb") as f:
            data = f.read(MAX_SCENE_BYTES + 1)
    except (OSError, ValueError) as e:  # ValueError: a NUL in the path
        raise SceneError(where, f"cannot read: {getattr(e, 'strerror', None) or e}") from None
    if len(data) > MAX_SCENE_BYTES:
        raise SceneError(where, f"larger than {MAX_SCENE_BYTES // 2**20} MiB, not a scene file")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise SceneError(where, f"invalid TOML: not UTF-8 ({e.reason})") from None
    return scene_table_from_text(text, where)


def scene_table_from_text(text: str, where: str) -> dict[str, Any]:
    """The TOML table of a scene's text (a file's, or an image header's); every failure one
    SceneError naming ``where``."""
    try:
        return tomllib.loads(text)
    except RecursionError:
        raise SceneError(where, "invalid TOML: nested too deeply") from None
    except tomllib.TOMLDecodeError as e:
        raise SceneError(where, f"invalid TOML: {' '.join(str(e).split())}") from None
    except ValueError:  # int() of an integer of over 4300 digits
        raise SceneError(where, "invalid TOML: a number too long to read") from None


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


def _unit(v: Iterable[float]) -> list[float]:
    """v / |v|, scaled by its largest component first: no overflow or underflow."""
    v = list(v)
    m = max(abs(x) for x in v)
    v = [x / m for x in v]
    n = _norm(v)
    return [x / n for x in v]


# camera.target at least this times max(1, |position|, |target|) from camera.position:
# the float64 view direction then holds to ~2e-8 rad, finer than the smallest fov
# (1e-6 degrees); camera.py refuses below an absolute 1e-9
_MIN_VIEW_DISTANCE = 1e-8


def _check_camera(cam: Camera) -> None:
    """camera.py builds a 4D frame by Gram-Schmidt on (view direction, limbo, up):
    they must be linearly independent.  Same order and messages as camera.py."""
    if cam.target == cam.position:
        raise SceneError("camera.target", "equals camera.position")
    view = _sub(cam.target, cam.position)
    least = _MIN_VIEW_DISTANCE * max(1.0, _norm(cam.position), _norm(cam.target))
    if _norm(view) < least:
        raise SceneError("camera.target", f"closer than {least:.1e} to camera.position (1e-8 x "
                         "max(1, |position|, |target|): the view direction must hold to the "
                         "smallest fov)")
    fwd = _unit(view)
    limbo = _reject(_unit(cam.limbo), [fwd])
    if _norm(limbo) < 1e-6:
        raise SceneError("camera.limbo", "parallel to the view direction")
    up = _reject(_unit(cam.up), [fwd, _unit(limbo)])
    if _norm(up) < 1e-6:
        raise SceneError("camera.up", "parallel to the view direction or to camera.limbo")


def locus_escape_radius(radius: float) -> float:
    """The escape radius of every f_{a,b}(z) = z^3 - 3 a^2 z + b with |a|, |b| <= radius: the
    root R of R^3 - (3 radius^2 + 1) R - radius = 0, beyond which |f(z)| >= |z|^3 - 3 |a|^2 |z|
    - |b| > |z| and the orbit grows without bound (kernels/kind/cubic_locus.cl)."""
    k = 3.0 * radius * radius + 1.0
    lo, hi = math.sqrt(k), math.sqrt(k) + radius + 1.0   # g(lo) = -radius < 0 < g(hi)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid * mid * mid - k * mid - radius > 0:
            hi = mid
        else:
            lo = mid
    return hi


def _check_locus(scene: "Scene") -> None:
    """fractal.kind = "cubic_locus": the complex cubic only, no rotation, no orbit colouring,
    no estimate (fixed scan, Jacobian or zbuffer normals), and a bailout that is an escape
    radius for every map in the ball, so that the truncated set tends to the locus."""
    f, m = scene.fractal, scene.march
    if f.algebra != "quaternion" or f.function != "sqr":
        raise SceneError("fractal.kind", "cubic_locus iterates the complex cubic z^3 - 3 a^2 z + b: leave "
                         "fractal.algebra=quaternion and fractal.function=sqr")
    if f.theta != 0:
        raise SceneError("fractal.theta", "the rotation is of the quaternion map, not of the cubic locus: set 0")
    if scene.shading.coloring in ("iteration", "trap"):
        raise SceneError("shading.coloring", f"{scene.shading.coloring} follows the quaternion orbit of "
                         "fractal.c, not the cubic locus's; use flat or w")
    if m.method == "de" and m.quality == "custom":   # a preset's de: refused by name below
        raise SceneError("march.method", "no distance estimate is known for the cubic connectedness locus "
                         "(seed 001 section 5.2); use fixed or auto")
    if scene.normals.method == "gradient":
        raise SceneError("normals.method", "gradient differences a distance estimate, which the cubic locus "
                         "has none of; use jacobian or zbuffer")
    need = locus_escape_radius(f.locus_radius)
    if f.bailout < need:
        raise SceneError("fractal.bailout", f"{f.bailout!r} is below the escape radius {need:.4g} of the cubic "
                         f"maps within fractal.locus_radius={f.locus_radius!r}: set at least that")


def _check_stack(scene: "Scene") -> None:
    """fractal.kind = "julia_stack" (kernels/kind/julia_stack.cl): the complex square only, no
    rotation, colouring by the quaternion orbit or estimate-based normals; its set does not
    depend on the fourth coordinate w, so the view must stay in one hyperplane w = const (the
    bounding ball, camera.march_radius, holds the stack there only)."""
    f, cam, sl = scene.fractal, scene.camera, scene.slice
    if f.algebra != "quaternion" or f.function != "sqr":
        raise SceneError("fractal.kind", "julia_stack iterates the complex square z^2 + c: leave "
                         "fractal.algebra=quaternion and fractal.function=sqr")
    if f.theta != 0:
        raise SceneError("fractal.theta", "the rotation is of the quaternion map, not of a Julia set stack: set 0")
    if scene.shading.coloring in ("iteration", "trap"):
        raise SceneError("shading.coloring", f"{scene.shading.coloring} follows the quaternion orbit of "
                         "fractal.c, not a stack's; use flat or w")
    if scene.normals.method == "gradient":
        raise SceneError("normals.method", "gradient differences a distance estimate, which a Julia set stack "
                         "has no proven one of; use jacobian or zbuffer")
    if any(sl.normal[:3]):
        raise SceneError("slice.normal", "a Julia set stack is the same at every w: slice it by w = const "
                         "only, normal (0, 0, 0, 1)")
    if len(cam.limbo) == 4 and any(cam.limbo[:3]):
        raise SceneError("camera.limbo", "a Julia set stack is the same at every w: keep the rays in w = const, "
                         "limbo (0, 0, 0, 1)")
    pw = cam.position[3] if len(cam.position) == 4 else 0.0
    tw = cam.target[3] if len(cam.target) == 4 else 0.0
    if pw != tw:
        raise SceneError("camera.target", "a Julia set stack is the same at every w: give camera.position and "
                         "camera.target the same w")


def _check_fractal(scene: "Scene") -> None:
    """The algebra x function pairs that exist, and the methods each can use."""
    f, m = scene.fractal, scene.march
    allowed = FUNCTIONS_OF[f.algebra]
    if f.function not in allowed:
        raise SceneError("fractal.function", f"{f.function!r} is not defined for the {f.algebra} algebra "
                         f"(as in POV-Ray's julia_fractal: {' and '.join(allowed)} only); use "
                         f"fractal.algebra=hypercomplex for it")
    pair = f"{f.algebra} {f.function}"
    if f.kind == "mandelbrot":
        if f.function not in MANDELBROT_START:
            raise SceneError("fractal.kind", f"mandelbrot follows the orbit of f's one critical or asymptotic "
                             f"value; {f.function} has several or none: use one of "
                             f"{', '.join(MANDELBROT_START)}")
        if f.function == "pwr" and f.exponent[0] <= 1:
            raise SceneError("fractal.exponent", f"mandelbrot with pwr needs a critical point at 0, "
                             f"real part above 1, got {f.exponent[0]!r}")
        if f.theta != 0:
            raise SceneError("fractal.theta", "the rotation leaves a Mandelbrot set unchanged (its orbits are "
                             "the unrotated ones times e^(i theta)): set 0")
    if f.kind == "julia_stack":
        _check_stack(scene)
    if f.kind == "cubic_locus":
        _check_locus(scene)
    if f.theta != 0 and f.algebra != "quaternion":
        raise SceneError("fractal.theta", f"the rotation is defined for the quaternion algebra (seed 001 "
                         f"section 2.3), not {f.algebra}: set 0")
    if m.quality != "custom" and f.kind != "julia":
        raise SceneError("march.quality", f"the presets were measured on Julia sets; for a {f.kind} set the "
                         f"march keys (march.quality=custom)")
    if m.quality != "custom" and f.algebra != "quaternion":
        raise SceneError("march.quality", f"the presets were measured on quaternion sets; for {pair} set the "
                         f"march keys (march.quality=custom), measured in README's algebras section")
    if has_distance_estimate(f):
        return
    if m.method == "de" and f.kind != "julia_stack":   # the stack's "de": its empirical estimate
        raise SceneError("march.method", f"de needs a distance estimate, which {pair} has none of; "
                         f"use fixed or auto")
    if scene.normals.method == "gradient":
        raise SceneError("normals.method", f"gradient differences the distance estimate, which {pair} "
                         f"has none of; use jacobian or zbuffer")


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
    clip: Clip = field(default_factory=Clip)
    render: Render = field(default_factory=Render)

    def __post_init__(self) -> None:
        """The rules across keys, checked however the scene was built (from a file, a dict,
        the constructor or dataclasses.replace): each section of its type, the camera's frame,
        the algebra x function pair and the methods it can use, reflection's normals, near < far."""
        for name, kind in _SECTIONS.items():
            if not isinstance(getattr(self, name), kind):
                raise SceneError(name, f"expected a pyjulia4d.scene.{kind.__name__}, got "
                                       f"{_show(getattr(self, name))}")
        _check_camera(self.camera)
        _check_fractal(self)
        if self.shading.reflection > 0 and self.normals.method == "zbuffer":
            raise SceneError("shading.reflection", "needs normals.method \"jacobian\" or \"gradient\": the "
                                                   "Z-buffer has no neighbours for reflected rays")
        m = self.march
        if not isinstance(m.near, str) and not isinstance(m.far, str) and m.far <= m.near:
            raise SceneError("march.far", f"must be greater than march.near ({m.near!r}), got {m.far!r}")

    @classmethod
    def default(cls) -> Scene:
        """The built-in scene with its camera placed (``camera.fit = false``): reproducible
        without a framing pass, which is what the tests, benchmarks and the reference compare.
        The command line's built-in scene is ``Scene.from_dict({})``, which frames the set
        (camera.fit is true whenever no camera.position is given), so the two differ in
        camera only."""
        return cls()

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], overrides: Iterable[str] = ()) -> Scene:
        """Validate ``{section: {key: value}}`` (missing keys get defaults), then apply overrides."""
        if not isinstance(data, Mapping):
            raise SceneError("scene", f"expected a table, got {_show(data)}")
        raw: dict[str, dict[str, Any]] = {name: {} for name in _CHECKS}
        for section, table in data.items():
            if section in ("animation", "keyframe"):   # keyframes.py reads these
                raise SceneError(section, "a keyframed scene: render its frames with "
                                          "'pyjulia4d animate' (or --frames N:N for one)")
            if section not in _CHECKS:
                raise SceneError(_show_key(str(section)), "unknown key")
            if not isinstance(table, Mapping):
                raise SceneError(section, f"expected a table, got {_show(table)}")
            for key, value in table.items():
                if key not in _CHECKS[section]:
                    raise SceneError(_show_key(f"{section}.{key}"), "unknown key")
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
        # No camera position given: nothing says where the set is, so frame it (a default
        # camera cuts off or shrinks to a speck many sets); a given position is kept as is.
        if "position" not in raw["camera"] and "fit" not in raw["camera"]:
            raw["camera"]["fit"] = True
        return cls._build(raw)

    @classmethod
    def from_toml(cls, path: str | Path, overrides: Iterable[str] = ()) -> Scene:
        """Read a TOML scene file (at most MAX_SCENE_BYTES), then apply overrides."""
        table = read_scene_table(path)
        return cls.from_dict(table, overrides)

    @classmethod
    def _build(cls, raw: Mapping[str, Mapping[str, Any]]) -> Scene:
        # each key is checked in the order given (the first bad one is named), then again,
        # with the defaults, by the sections' __post_init__
        parts = {}
        for section, table in raw.items():
            checks = _CHECKS[section]
            kwargs = {k: checks[k](f"{section}.{k}", v) for k, v in table.items()}
            parts[section] = _SECTIONS[section](**kwargs)
        m = parts["march"]
        if m.quality != "custom" and any(getattr(m, k) != v for k, v in preset_values(m.quality).items()):
            # a march key set after the preset: the resolved scene says what really runs
            parts["march"] = dataclasses.replace(m, quality="custom")
        return cls(**parts)

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
        out["shading"]["lights"] = [light.to_dict() for light in self.shading.lights]
        return out

    def to_toml(self) -> str:
        """The fully resolved scene as TOML text (reads back with :meth:`from_toml`)."""
        lines = ["# pyjulia4d scene, fully resolved"]
        for section, table in self.to_dict().items():
            lines.append(f"\n[{section}]")
            lines.extend(f"{k} = {_toml_value(v)}" for k, v in table.items())
        return "\n".join(lines) + "\n"
