"""Import the julia_fractal of a POV-Ray 3.7 scene as a pyjulia4d scene:
``pyjulia4d import-pov FILE.pov [-o SCENE.toml]``.

POV-Ray's scene language has no Python library; this is a small hand-written tokenizer
and recursive-descent reader of the part of it a julia_fractal scene uses: ``#version``,
``#include`` (noted, never read), ``#declare``/``#local`` of floats, vectors, colours and
julia_fractals, float and vector expressions (+ - * /, parentheses, ``< >`` vectors, x y z,
pi, image_width/height, the common float functions), ``camera``, ``light_source``,
``background``, ``julia_fractal`` and ``object { ID }`` of a declared one.  Everything
else that is a ``keyword { ... }`` block (other objects, global_settings, fog, ...) is
skipped and named in a comment of the scene written; anything it cannot read or map
exactly is refused with one line, ``FILE:LINE: reason``.

What POV-Ray does, and what pyjulia4d is told (POV-Ray 3.7 source: parser.cpp
Parse_Julia_Fractal and Parse_Camera, fractal.cpp, quaternion.cpp, hypercomplex.cpp):

* ``max_iteration N`` (default 20, floored, at least 1): POV-Ray tests |q_n| for
  n = 0 .. N-1 and never looks at q_N; pyjulia4d tests n = 0 .. max_iter.  So
  fractal.max_iter = N - 1 (N = 1, a ball, has no pyjulia4d equivalent: refused).
* The escape radius: hypercomplex 4 (Exit_Value 16), but quaternion
  sqrt(R^2 + 1e-7) with R = min(2, 1 + |c| + 1e-7) (Compute_BBox), not the documented 4.
  fractal.bailout gets that value.  With both, pyjulia4d's silhouette of the documentation
  example agrees with POV-Ray's (precision 1000) on every pixel of a 160x120 image.
* ``precision P`` (default 20, at least 1): POV-Ray's march steps at least 1/P.
  pyjulia4d's march stays its own (certified, finer), made no coarser than 1/P:
  ``de`` keeps epsilon 1e-3 unless 1/P is smaller; the fixed scan's z_resolution is
  raised to 2 x (bounding radius) x P if that exceeds 250.
* ``slice <n>, d``: POV-Ray normalises n and refuses |n|^2 or |n_t| below 1e-10, as here.
  It draws the 3D point X as the 4D point (X, (d - n_xyz.X) / n_t); pyjulia4d draws its
  camera coordinates p as R p + d n/|n| (camera.slice_rotation, an isometry).  The two are
  the same map when n has only a w component (any sign, any d): exact.  Otherwise the
  hyperplane is the same, and the eye, target and light are put at the same 4D points,
  but POV-Ray's picture is the section sheared by its projection along w and
  pyjulia4d's is undistorted: a warning says so.
* Camera (the 3.5+ rules: modifiers applied in POV-Ray's fixed order, whatever their
  order in the file): POV-Ray is left-handed, x right, y up, z into the screen, and so is
  pyjulia4d's frame with limbo = +w: right = cross4(forward, up, limbo) = up x forward,
  which is POV-Ray's right (sky x direction) - no coordinate is mirrored.  POV-Ray's
  ``angle`` is horizontal and sets |direction| = |right| / (2 tan(angle/2)); its vertical
  extent is |up| / |direction|, so camera.fov = 2 atan(|up| / (2 |direction|)) exactly,
  and the horizontal extent follows from the image's width/height, which equals POV-Ray's
  when |right| / |up| = width / height (else a warning: POV-Ray stretches its pixels).  A
  left-handed ``right`` (negative, e.g. ``right -x*4/3``) mirrors POV-Ray's image: that
  is limbo = -w here.  Default camera: location 0, direction z, up y, right 1.33 x.
* ``translate``/``rotate``/``scale``/``matrix`` on the julia_fractal: the inverse is applied
  to the camera and the light (exact for rotations, translations and uniform scales,
  mirrors included; others are refused).  On the camera and the light they are applied.
* pigment { color rgb <r,g,b> } -> shading.color; finish ambient, diffuse, specular,
  roughness (shininess = 1/roughness; POV-Ray's specular is Blinn-Phong too), with
  POV-Ray 3.7's defaults (0.1, 0.6, 0, 0.05) for what a given finish leaves out;
  light_source position and colour -> shading.light (in camera coordinates),
  shading.light_color, its shadows -> shading.shadow ("hard", or "none" for
  shadowless or no_shadow), shading.ao = 0 (POV-Ray has no ambient occlusion);
  background -> shading.background.  Colours are taken as linear (POV-Ray 3.7 with
  assumed_gamma 1.0, as pyjulia4d shades).  No pigment: pyjulia4d's colour is kept
  (POV-Ray would draw the object black); no light: pyjulia4d's default lighting.
"""
from __future__ import annotations

import math
import os
import stat
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from pyjulia4d.fractal.registry import FUNCTIONS
from pyjulia4d.scene.model import Scene
from pyjulia4d.scene.checks import SceneError
from pyjulia4d.scene.text import toml_value  # one TOML emitter for scenes and imports

MAX_POV_BYTES = 8 << 20       # larger files are refused unread
POV_EPSILON = 1e-10           # POV-Ray's EPSILON (slice and camera checks)
FRACTAL_TOLERANCE = 1e-7      # fractal.cpp: added to the quaternion escape radius
POV_DEFAULT_RIGHT = 1.33      # camera.cpp Camera::Init (horizontal angle 67.38 degrees)
POV_FINISH = {"ambient": 0.1, "diffuse": 0.6, "specular": 0.0, "roughness": 0.05}
DEFAULT_SIZE = (640, 480)     # pyjulia4d's image size, used unless --width/--height


class PovError(ValueError):
    """A POV-Ray scene this reader cannot read or map; ``str(e)`` is one line."""


# ------------------------------------------------------------------------- tokens

@dataclass(frozen=True)
class Tok:
    kind: str      # "num", "id", "str", "op", "dir" (#word), "end"
    text: str
    line: int
    value: float = 0.0


_OPS = set("{}()[]<>,;=+-*/!?:.&|")


def tokenize(text: str, where: str) -> list[Tok]:
    """POV-Ray SDL tokens; // and nested /* */ comments dropped."""
    toks: list[Tok] = []
    i, n, line = 0, len(text), 1
    while i < n:
        ch = text[i]
        if ch == "\n":
            line += 1
            i += 1
        elif ch in " \t\r\f\v":
            i += 1
        elif text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            start, depth = line, 0
            while True:  # POV-Ray nests block comments
                if i >= n:
                    raise PovError(f"{where}:{start}: unterminated /* comment")
                if text.startswith("/*", i):
                    depth += 1
                    i += 2
                elif text.startswith("*/", i):
                    depth -= 1
                    i += 2
                    if depth == 0:
                        break
                else:
                    line += text[i] == "\n"
                    i += 1
        elif ch.isascii() and (ch.isdigit() or (ch == "." and i + 1 < n and text[i + 1].isascii()
                                                and text[i + 1].isdigit())):
            j = i
            while j < n and text[j].isascii() and text[j].isdigit():
                j += 1
            if j < n and text[j] == ".":
                j += 1
                while j < n and text[j].isascii() and text[j].isdigit():
                    j += 1
            if j < n and text[j] in "eE":
                k = j + 1
                if k < n and text[k] in "+-":
                    k += 1
                if k < n and text[k].isascii() and text[k].isdigit():
                    j = k
                    while j < n and text[j].isascii() and text[j].isdigit():
                        j += 1
            s = text[i:j]
            v = float(s)
            if not math.isfinite(v):
                raise PovError(f"{where}:{line}: number {s[:30]} is too large")
            toks.append(Tok("num", s, line, v))
            i = j
        elif ch.isascii() and (ch.isalpha() or ch == "_"):
            j = i
            while j < n and text[j].isascii() and (text[j].isalnum() or text[j] == "_"):
                j += 1
            toks.append(Tok("id", text[i:j], line))
            i = j
        elif ch == "#":
            j = i + 1
            while j < n and text[j] in " \t":
                j += 1
            k = j
            while k < n and text[k].isascii() and (text[k].isalnum() or text[k] == "_"):
                k += 1
            if k == j:
                raise PovError(f"{where}:{line}: '#' without a directive name")
            toks.append(Tok("dir", "#" + text[j:k], line))
            i = k
        elif ch == '"':
            j = i + 1
            while j < n and text[j] not in '"\n':
                j += 2 if text[j] == "\\" else 1
            if j >= n or text[j] != '"':
                raise PovError(f"{where}:{line}: unterminated string")
            toks.append(Tok("str", text[i + 1:j], line))
            i = j + 1
        elif ch in _OPS:
            toks.append(Tok("op", ch, line))
            i += 1
        else:
            shown = ch if ch.isprintable() else repr(ch)
            raise PovError(f"{where}:{line}: unexpected character {shown!s}")
    toks.append(Tok("end", "end of file", line))
    return toks


# ------------------------------------------------------------------ transforms

@dataclass(frozen=True)
class Affine:
    """p -> a p + t (column vectors)."""
    a: np.ndarray = field(default_factory=lambda: np.eye(3))
    t: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def then(self, other: "Affine") -> "Affine":
        """This transform followed by ``other``."""
        return Affine(other.a @ self.a, other.a @ self.t + other.t)

    def point(self, p) -> np.ndarray:
        return self.a @ np.asarray(p, float) + self.t

    def direction(self, v) -> np.ndarray:
        return self.a @ np.asarray(v, float)

    def inverse(self) -> "Affine":
        ai = np.linalg.inv(self.a)
        return Affine(ai, -ai @ self.t)


def rotation(degrees) -> np.ndarray:
    """POV-Ray's ``rotate <a, b, c>``: about x by a, then y by b, then z by c (degrees),
    as matrix.cpp Compute_Rotation_Transform (row vectors there, columns here)."""
    m = np.eye(3)
    for axis, deg in enumerate(degrees):
        r = math.radians(deg)
        c, s = math.cos(r), math.sin(r)
        i, j = [(1, 2), (2, 0), (0, 1)][axis]
        rot = np.eye(3)
        rot[i, i] = rot[j, j] = c
        rot[j, i], rot[i, j] = s, -s
        m = rot @ m
    return m


# ---------------------------------------------------------------- the reader

_FUNCS1 = {"abs": abs, "sqrt": math.sqrt, "sin": math.sin, "cos": math.cos, "tan": math.tan,
           "asin": math.asin, "acos": math.acos, "atan": math.atan, "sinh": math.sinh,
           "cosh": math.cosh, "tanh": math.tanh, "asinh": math.asinh, "acosh": math.acosh,
           "atanh": math.atanh, "exp": math.exp, "ln": math.log, "log": math.log10,
           "radians": math.radians, "degrees": math.degrees, "floor": math.floor,
           "ceil": math.ceil, "int": lambda v: float(int(v))}
_FUNCS2 = {"pow": math.pow, "atan2": math.atan2, "mod": math.fmod,
           "div": lambda a, b: float(int(a / b)), "min": min, "max": max}
_CONSTS = {"pi": math.pi, "tau": 2 * math.pi, "true": 1.0, "yes": 1.0, "on": 1.0, "false": 0.0,
           "no": 0.0, "off": 0.0, "clock": 0.0, "clock_delta": 1.0, "frame_number": 0.0,
           "initial_frame": 0.0, "final_frame": 0.0, "initial_clock": 0.0, "final_clock": 0.0,
           "x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0), "t": (0.0, 0.0, 0.0, 1.0),
           "u": (1.0, 0.0), "v": (0.0, 1.0)}
_MEMBERS = {"x": 0, "u": 0, "red": 0, "y": 1, "v": 1, "green": 1, "z": 2, "blue": 2, "t": 3,
            "filter": 3, "transmit": 4}
_COLOR_WORDS = {"color", "colour", "rgb", "rgbf", "rgbt", "rgbft", "red", "green", "blue",
                "filter", "transmit", "srgb", "srgbf", "srgbt", "srgbft", "gray", "grey"}
_ALGEBRAS = ("quaternion", "hypercomplex")
_CAMERA_TYPES = ("orthographic", "fisheye", "ultra_wide_angle", "omnimax", "panoramic", "spherical",
                 "cylinder", "mesh_camera", "user_defined")
# light_source modifiers that are read past (with a warning) and their arguments
_LIGHT_SKIP = {"spotlight": "", "cylinder": "", "parallel": "", "circular": "", "orient": "",
               "jitter": "", "area_illumination": "f?", "fade_distance": "f", "fade_power": "f",
               "radius": "f", "falloff": "f", "tightness": "f", "point_at": "v", "adaptive": "f",
               "media_interaction": "f?", "media_attenuation": "f?", "area_light": "v,v,f,f",
               "looks_like": "{", "photons": "{", "projected_through": "{"}


def _is_vec(v) -> bool:
    return isinstance(v, tuple)


@dataclass
class Julia:
    line: int
    c: tuple = ()
    algebra: str = "quaternion"
    function: str = "sqr"
    exponent: tuple = (0.0, 0.0)
    max_iteration: int = 20
    precision: float = 20.0
    slice_normal: tuple = (0.0, 0.0, 0.0, 1.0)
    slice_distance: float = 0.0
    color: tuple | None = None
    finish: dict | None = None
    transform: Affine = field(default_factory=Affine)
    no_shadow: bool = False
    given: dict = field(default_factory=dict)  # POV keyword -> its text, for comments


@dataclass
class Camera:
    line: int
    location: np.ndarray
    direction: np.ndarray
    up: np.ndarray
    right: np.ndarray
    notes: list = field(default_factory=list)


@dataclass
class Light:
    line: int
    position: np.ndarray
    color: tuple
    shadowless: bool = False


class _Reader:
    def __init__(self, toks: list[Tok], where: str, width: int, height: int) -> None:
        self.toks, self.pos, self.where = toks, 0, where
        self.size = (width, height)
        self.symbols: dict[str, tuple[str, Any, int]] = {}
        self.includes: list[str] = []
        self.julias: list[Julia] = []
        self.cameras: list[Camera] = []
        self.lights: list[Light] = []
        self.background: tuple | None = None
        self.ignored: list[str] = []
        self.warnings: list[str] = []
        self.version: float | None = None

    # -- token access
    def peek(self, k: int = 0) -> Tok:
        return self.toks[min(self.pos + k, len(self.toks) - 1)]

    def next(self) -> Tok:
        t = self.peek()
        if t.kind != "end":
            self.pos += 1
        return t

    def err(self, msg: str, tok: Tok | None = None) -> PovError:
        return PovError(f"{self.where}:{(tok or self.peek()).line}: {msg}")

    def is_op(self, text: str, k: int = 0) -> bool:
        t = self.peek(k)
        return t.kind == "op" and t.text == text

    def accept_op(self, text: str) -> bool:
        if self.is_op(text):
            self.pos += 1
            return True
        return False

    def expect_op(self, text: str, what: str) -> Tok:
        t = self.peek()
        if not self.is_op(text):
            raise self.err(f"expected '{text}' {what}, got {self.shown(t)}")
        return self.next()

    @staticmethod
    def shown(t: Tok) -> str:
        if t.kind == "end":
            return "the end of the file"
        text = t.text if len(t.text) <= 40 else t.text[:37] + "..."
        return f'"{text}"' if t.kind == "str" else f"'{text}'"

    def word(self, k: int = 0) -> str | None:
        t = self.peek(k)
        return t.text if t.kind == "id" else None

    # -- expressions: floats and vectors (tuples)
    def expr(self) -> Any:
        v = self._term()
        while self.is_op("+") or self.is_op("-"):
            op = self.next()
            v = self._arith(op, v, self._term())
        return v

    def _term(self) -> Any:
        v = self._unary()
        while self.is_op("*") or self.is_op("/"):
            op = self.next()
            v = self._arith(op, v, self._unary())
        return v

    def _unary(self) -> Any:
        if self.is_op("-"):
            self.next()
            return self._arith(Tok("op", "*", 0), -1.0, self._unary())
        if self.is_op("+"):
            self.next()
            return self._unary()
        return self._postfix(self._primary())

    def _arith(self, op: Tok, a: Any, b: Any) -> Any:
        if _is_vec(a) or _is_vec(b):  # POV-Ray: floats promote, vectors act per component
            n = max(len(a) if _is_vec(a) else 0, len(b) if _is_vec(b) else 0)
            a = tuple(a) + (0.0,) * (n - len(a)) if _is_vec(a) else (a,) * n
            b = tuple(b) + (0.0,) * (n - len(b)) if _is_vec(b) else (b,) * n
            return tuple(self._arith(op, x, y) for x, y in zip(a, b))
        if op.text == "/" and b == 0:
            raise self.err("division by zero", op)
        r = {"+": a + b, "-": a - b, "*": a * b, "/": a / b if b else 0.0}[op.text]
        if not math.isfinite(r):
            raise self.err("a number overflows", op)
        return r

    def _postfix(self, v: Any) -> Any:
        while self.is_op(".") and self.peek(1).kind == "id":
            dot = self.next()
            name = self.next().text
            if name not in _MEMBERS:
                raise self.err(f"unsupported vector member '.{name}'", dot)
            if not _is_vec(v) or _MEMBERS[name] >= len(v):
                raise self.err(f"'.{name}' of a value without that component", dot)
            v = v[_MEMBERS[name]]
        return v

    def _primary(self) -> Any:
        t = self.peek()
        if t.kind == "num":
            self.next()
            return t.value
        if self.is_op("("):
            self.next()
            v = self.expr()
            self.expect_op(")", "to close '('")
            return v
        if self.is_op("<"):
            self.next()
            comps = [self._float(self.expr(), "a vector component")]
            while self.accept_op(","):
                comps.append(self._float(self.expr(), "a vector component"))
            self.expect_op(">", "to close '<'")
            if not 2 <= len(comps) <= 5:
                raise self.err(f"a vector of {len(comps)} components", t)
            return tuple(comps)
        if t.kind == "id":
            name = t.text
            if name in _FUNCS1 or name in _FUNCS2 or name in ("vlength", "vnormalize", "vdot", "vcross"):
                if self.is_op("(", 1):
                    return self._call()
            if name in self.symbols:
                kind, value, line = self.symbols[name]
                if kind in ("float", "vector", "color"):
                    self.next()
                    return value
                raise self.err(f"identifier '{name}' (a {kind} declared at line {line}) cannot be "
                               f"evaluated here: only float, vector and colour declarations are read", t)
            if name in _CONSTS:
                self.next()
                return _CONSTS[name]
            if name in ("image_width", "image_height"):
                self.next()
                return float(self.size[name == "image_height"])
            if name in _COLOR_WORDS:
                return self.color()
            if name in _FUNCS1 or name in _FUNCS2:
                raise self.err(f"'{name}' without '(' where a value is expected", t)
            inc = f" (files named by #include are not read: {', '.join(self.includes)})" if self.includes else ""
            raise self.err(f"unknown identifier '{name}' where a value is expected{inc}", t)
        raise self.err(f"expected a value, got {self.shown(t)}", t)

    def _float(self, v: Any, what: str) -> float:
        if _is_vec(v):
            raise self.err(f"expected a number for {what}, got a vector")
        return float(v)

    def _call(self) -> Any:
        t = self.next()
        self.expect_op("(", f"after {t.text}")
        args = [self.expr()]
        while self.accept_op(","):
            args.append(self.expr())
        self.expect_op(")", f"to close {t.text}(")
        name = t.text
        try:
            if name == "vlength" and len(args) == 1 and _is_vec(args[0]):
                return math.sqrt(sum(x * x for x in args[0]))
            if name == "vnormalize" and len(args) == 1 and _is_vec(args[0]):
                n = math.sqrt(sum(x * x for x in args[0]))
                return tuple(x / n for x in args[0])
            if name == "vdot" and len(args) == 2 and all(map(_is_vec, args)):
                return sum(a * b for a, b in zip(*args))
            if name == "vcross" and len(args) == 2 and all(map(_is_vec, args)):
                return tuple(float(x) for x in np.cross(np.resize(args[0], 3), np.resize(args[1], 3)))
            fn = _FUNCS1.get(name) if len(args) == 1 else _FUNCS2.get(name) if len(args) == 2 else None
            if fn is None or any(map(_is_vec, args)):
                raise self.err(f"{name}() with {len(args)} argument(s) of these kinds is not supported", t)
            r = float(fn(*args))
        except (ValueError, OverflowError, ZeroDivisionError):
            raise self.err(f"{name}() of {', '.join(f'{a:g}' if not _is_vec(a) else 'a vector' for a in args)}"
                           f" is undefined or overflows", t) from None
        if not math.isfinite(r):
            raise self.err(f"{name}() overflows", t)
        return r

    def number(self, what: str) -> float:
        return self._float(self.expr(), what)

    def vector(self, n: int, what: str) -> tuple:
        """A vector of n components; a float promotes, a shorter vector is padded with 0."""
        t = self.peek()
        v = self.expr()
        if not _is_vec(v):
            return (float(v),) * n
        if len(v) > n:
            raise self.err(f"{what}: expected {n} components, got {len(v)}", t)
        return tuple(v) + (0.0,) * (n - len(v))

    def color(self) -> tuple:
        """COLOR: [color] (rgb V | rgbf V | rgbt V | rgbft V | red F | ... | V) ... as
        (r, g, b, filter, transmit)."""
        t = self.peek()
        if self.word() in ("color", "colour"):
            self.next()
        c = [0.0] * 5
        got = False
        while True:
            w = self.word()
            if w in ("rgb", "rgbf", "rgbt", "rgbft"):
                self.next()
                tt = self.peek()
                v = self.expr()
                slots = {"rgb": (0, 1, 2), "rgbf": (0, 1, 2, 3), "rgbt": (0, 1, 2, 4), "rgbft": (0, 1, 2, 3, 4)}[w]
                if _is_vec(v):
                    if len(v) < len(slots):
                        raise self.err(f"{w} needs {len(slots)} components, got {len(v)}", tt)
                    vals = v[:len(slots)]
                else:
                    vals = (float(v),) * len(slots)
                for i, x in zip(slots, vals):
                    c[i] = x
                got = True
            elif w in ("red", "green", "blue", "filter", "transmit"):
                self.next()
                c[_MEMBERS[w]] = self.number(w)
                got = True
            elif w in ("srgb", "srgbf", "srgbt", "srgbft", "gray", "grey"):
                raise self.err(f"colour keyword '{w}' is not supported (use rgb)")
            elif not got and (self.peek().kind == "num" or self.is_op("<") or self.is_op("(")
                              or self.is_op("-") or (w is not None and w in self.symbols)):
                tt = self.peek()
                v = self.expr()
                if _is_vec(v):
                    if len(v) < 3:
                        raise self.err(f"a colour needs 3 to 5 components, got {len(v)}", tt)
                    for i, x in enumerate(v[:5]):
                        c[i] = x
                else:
                    c[0] = c[1] = c[2] = float(v)
                got = True
            else:
                break
        if not got:
            if self.peek().kind == "id" and self.word() not in self.symbols:
                self._primary()  # an unknown identifier: its own message (includes not read)
            raise self.err(f"expected a colour, got {self.shown(self.peek())}", t)
        return tuple(float(x) for x in c)

    # -- blocks
    def skip_block(self, name: str, start: Tok) -> None:
        """Past the matching '}' of a '{' just consumed; a julia_fractal inside is refused."""
        depth = 1
        while depth:
            t = self.next()
            if t.kind == "end":
                raise self.err(f"unterminated '{name} {{' opened at line {start.line}", t)
            if t.kind == "op" and t.text in "{}":
                depth += 1 if t.text == "{" else -1
            elif t.kind == "id" and t.text == "julia_fractal":
                raise self.err(f"julia_fractal inside '{name} {{ ... }}' (line {start.line}) is not read: "
                               f"only a top-level julia_fractal, or object {{ ID }} of a declared one", t)
            elif t.kind == "id" and t.text in self.symbols and self.symbols[t.text][0] == "julia_fractal":
                raise self.err(f"the julia_fractal '{t.text}' used inside '{name} {{ ... }}' (line "
                               f"{start.line}) is not read: only a top-level object {{ {t.text} }}", t)

    def transform(self, word: str, uniform_only: bool) -> Affine:
        """The transform after translate/rotate/scale/matrix (just consumed)."""
        t = self.peek()
        if word == "translate":
            return Affine(np.eye(3), np.array(self.vector(3, "translate")))
        if word == "rotate":
            return Affine(rotation(self.vector(3, "rotate")), np.zeros(3))
        if word == "scale":
            s = self.vector(3, "scale")
            if any(v == 0 for v in s):
                raise self.err("scale by 0", t)
            if uniform_only and not (s[0] == s[1] == s[2]):
                raise self.err(f"scale <{s[0]:g}, {s[1]:g}, {s[2]:g}> on the julia_fractal is not uniform: "
                               f"it cannot be mapped exactly (only rotations, translations and uniform "
                               f"scales can, as the inverse transform of the camera)", t)
            return Affine(np.diag(s), np.zeros(3))
        # matrix < 12 numbers >, row vectors: p' = p M[0:3] + M[3]
        self.expect_op("<", "after matrix")
        vals = [self.number("a matrix entry")]
        while self.accept_op(","):
            vals.append(self.number("a matrix entry"))
        self.expect_op(">", "to close matrix <")
        if len(vals) != 12:
            raise self.err(f"matrix needs 12 numbers, got {len(vals)}", t)
        m = np.array(vals).reshape(4, 3)
        a = m[:3].T
        if abs(np.linalg.det(a)) < 1e-12:
            raise self.err("matrix is singular", t)
        if uniform_only:
            g = a.T @ a
            s2 = np.trace(g) / 3
            if not np.allclose(g, s2 * np.eye(3), rtol=0, atol=1e-9 * s2):
                raise self.err("matrix on the julia_fractal is not a rotation, translation and uniform "
                               "scale: it cannot be mapped exactly", t)
        return Affine(a, m[3].copy())

    # -- statements
    def run(self) -> None:
        while self.peek().kind != "end":
            t = self.peek()
            if t.kind == "dir":
                self.directive()
            elif t.kind == "id":
                w = t.text
                if w == "camera":
                    self.next()
                    self.camera(t)
                elif w == "light_source":
                    self.next()
                    self.light(t)
                elif w == "julia_fractal":
                    self.next()
                    self.julias.append(self.julia(t))
                elif w == "background":
                    self.next()
                    self.expect_op("{", "after background")
                    self.background = self.color()
                    self.expect_op("}", "to close background {")
                elif w == "object" and self.is_op("{", 1) and self.word(2) in self.symbols \
                        and self.symbols[self.word(2)][0] == "julia_fractal":
                    self.next()
                    self.julias.append(self.julia(t))
                elif self.is_op("{", 1):
                    self.next()
                    self.next()
                    start = self.pos
                    self.skip_block(w, t)
                    self.ignored.append(f"{w} (line {t.line})")
                    if w == "global_settings":
                        self.gamma_note(start)
                else:
                    raise self.err(f"unexpected {self.shown(t)} at the top level of the scene", t)
            else:
                raise self.err(f"unexpected {self.shown(t)} at the top level of the scene", t)

    def gamma_note(self, start: int) -> None:
        """A warning for assumed_gamma other than 1 in the global_settings just skipped."""
        for k in range(start, self.pos - 1):
            t, v = self.toks[k], self.toks[k + 1]
            if t.kind == "id" and t.text == "assumed_gamma" and v.kind == "num" and v.value != 1:
                self.warnings.append(f"{self.where}:{t.line}: assumed_gamma {v.text}: POV-Ray then shades in "
                                     f"that gamma space, pyjulia4d in linear light; the colours are taken as "
                                     f"linear and the tones differ")

    def directive(self) -> None:
        t = self.next()
        d = t.text
        if d == "#version":
            self.version = self.number("#version")
            self.accept_op(";")
            if self.version < 3.5:
                raise self.err(f"#version {self.version:g}: scenes older than 3.5 order camera modifiers "
                               f"differently; not supported", t)
        elif d == "#include":
            s = self.next()
            if s.kind != "str":
                raise self.err(f"#include needs a file name in quotes, got {self.shown(s)}", s)
            self.includes.append(s.text)
        elif d in ("#declare", "#local"):
            name = self.next()
            if name.kind != "id":
                raise self.err(f"{d} needs an identifier, got {self.shown(name)}", name)
            self.expect_op("=", f"after {d} {name.text}")
            w = self.word()
            if w == "julia_fractal":
                start = self.next()
                self.symbols[name.text] = ("julia_fractal", self.julia(start), name.line)
            elif w is not None and w not in self.symbols and w not in _COLOR_WORDS and self.is_op("{", 1):
                self.next()
                start = self.next()
                self.skip_block(w, start)
                self.symbols[name.text] = (w, None, name.line)
            else:
                v = self.expr()
                kind = "vector" if _is_vec(v) else "float"
                self.symbols[name.text] = (kind, v, name.line)
            self.accept_op(";")
        elif d == "#default":
            start = self.peek()
            self.expect_op("{", "after #default")
            self.skip_block("#default", start)
            self.ignored.append(f"#default (line {t.line})")
        else:
            raise self.err(f"unsupported directive {d} (only #version, #include, #declare, #local and "
                           f"#default are read)", t)

    def camera(self, start: Tok) -> None:
        self.expect_op("{", "after camera")
        loc, dirv, up, right, sky = (0, 0, 0), (0, 0, 1), (0, 1, 0), (POV_DEFAULT_RIGHT, 0, 0), (0, 1, 0)
        look_at = angle = None
        trans = Affine()
        notes: list[str] = []
        while not self.accept_op("}"):
            t = self.next()
            w = t.text if t.kind == "id" else None
            if w == "perspective":
                continue
            if w in _CAMERA_TYPES:
                raise self.err(f"camera type '{w}' cannot be mapped: pyjulia4d's camera is a pinhole "
                               f"(perspective)", t)
            if w == "location":
                loc = self.vector(3, w)
            elif w == "look_at":
                look_at = self.vector(3, w)
            elif w == "direction":
                dirv = self.vector(3, w)
            elif w == "up":
                up = self.vector(3, w)
            elif w == "right":
                right = self.vector(3, w)
            elif w == "sky":
                sky = self.vector(3, w)
            elif w == "angle":
                angle = self.number(w)
            elif w in ("translate", "rotate", "scale", "matrix"):
                trans = trans.then(self.transform(w, uniform_only=False))
            elif w in ("aperture", "blur_samples", "focal_point", "confidence", "variance"):
                if w == "focal_point":
                    self.vector(3, w)
                else:
                    self.number(w)
                if w == "blur_samples" and self.accept_op(","):
                    self.number(w)
                if "focal blur" not in notes:
                    notes.append("focal blur")
                    self.warnings.append(f"{self.where}:{t.line}: camera focal blur ({w}) ignored: "
                                         f"pyjulia4d's pinhole camera is always in focus")
            elif t.kind == "end":
                raise self.err(f"unterminated 'camera {{' opened at line {start.line}", t)
            else:
                raise self.err(f"camera: {self.shown(t)} cannot be mapped", t)
        loc, dirv, up, right, sky = (np.array(v, float) for v in (loc, dirv, up, right, sky))
        # POV-Ray 3.5+ Parse_Camera: right, direction, angle, up, sky, location, look_at
        if angle is not None:
            if angle < 0:
                raise self.err("camera: negative viewing angle", start)
            if angle >= 180:
                raise self.err("camera: the viewing angle has to be smaller than 180 degrees", start)
            if angle > 0:
                if np.linalg.norm(dirv) == 0:
                    raise self.err("camera: zero direction", start)
                dirv = dirv / np.linalg.norm(dirv) * (np.linalg.norm(right) / math.tan(math.radians(angle) / 2) / 2)
        if look_at is not None:
            dl, ul, rl = (float(np.linalg.norm(v)) for v in (dirv, up, right))
            handed = float(np.dot(np.cross(up, dirv), right))
            d = np.array(look_at, float) - loc
            if d @ d < POV_EPSILON:
                raise self.err("camera: location and look_at must be different", start)
            d = d / np.linalg.norm(d)
            r = np.cross(sky, d)
            if np.all(np.abs(r) < POV_EPSILON):
                r = right  # POV-Ray warns and keeps the right vector
            if np.linalg.norm(r) == 0:
                raise self.err("camera: zero right vector", start)
            r = r / np.linalg.norm(r)
            up = np.cross(d, r) * ul
            dirv = d * dl
            right = r * (rl if handed > 0 else -rl)
        self.cameras.append(Camera(start.line, trans.point(loc), trans.direction(dirv), trans.direction(up),
                                   trans.direction(right), notes))

    def light(self, start: Tok) -> None:
        self.expect_op("{", "after light_source")
        if self.word() in self.symbols and self.symbols[self.word()][0] == "light_source":
            raise self.err("a declared light_source cannot be read: write it inline")
        pos = self.vector(3, "light_source position")
        self.accept_op(",")
        col = self.color()
        trans = Affine()
        shadowless = False
        ignored: list[str] = []
        while not self.accept_op("}"):
            t = self.next()
            w = t.text if t.kind == "id" else None
            if w == "shadowless":
                shadowless = True
            elif w in ("translate", "rotate", "scale", "matrix"):
                trans = trans.then(self.transform(w, uniform_only=False))
            elif w in _LIGHT_SKIP:
                ignored.append(w)
                for arg in filter(None, _LIGHT_SKIP[w].split(",")):
                    if arg == "f" or (arg == "f?" and (
                            self.peek().kind == "num" or self.is_op("(") or self.is_op("-")
                            or self.word() in ("on", "off", "true", "false", "yes", "no"))):
                        self.number(w)
                    elif arg == "v":
                        self.vector(3, w)
                    elif arg == "{":
                        b = self.peek()
                        self.expect_op("{", f"after {w}")
                        self.skip_block(w, b)
                    self.accept_op(",")
            elif t.kind == "end":
                raise self.err(f"unterminated 'light_source {{' opened at line {start.line}", t)
            else:
                raise self.err(f"light_source: {self.shown(t)} cannot be read", t)
        if ignored:
            self.warnings.append(f"{self.where}:{start.line}: light_source {', '.join(ignored)} ignored: "
                                 f"pyjulia4d has one point light")
        self.lights.append(Light(start.line, trans.point(pos), col[:3], shadowless))

    def julia(self, start: Tok) -> Julia:
        self.expect_op("{", f"after {start.text}")
        w = self.word()
        if w in self.symbols and self.symbols[w][0] == "julia_fractal":
            self.next()
            proto: Julia = self.symbols[w][1]
            j = Julia(start.line, **{k: getattr(proto, k) for k in (
                "c", "algebra", "function", "exponent", "max_iteration", "precision", "slice_normal",
                "slice_distance", "color", "finish", "transform", "no_shadow")}, given=dict(proto.given))
        elif start.text == "object":
            raise self.err("object { ... } without a declared julia_fractal")
        else:
            j = Julia(start.line)
            j.c = self.vector(4, "the julia parameter")
        while not self.accept_op("}"):
            t = self.next()
            w = t.text if t.kind == "id" else None
            if w in _ALGEBRAS:
                j.algebra = w
            elif w in FUNCTIONS and w != "pwr":
                if self.is_op("("):
                    raise self.err(f"julia_fractal: '{w}' takes no arguments", t)
                j.function = w
            elif w == "pwr":
                self.expect_op("(", "after pwr: pwr(X, Y)")
                x = self.number("pwr's X")
                if not self.accept_op(","):
                    raise self.err("pwr needs two numbers: pwr(X, Y)")
                y = self.number("pwr's Y")
                self.expect_op(")", "to close pwr(X, Y)")
                j.function, j.exponent = "pwr", (x, y)
            elif w == "max_iteration":
                v = self.number(w)
                j.max_iteration = max(1, math.floor(v)) if v < 2**31 else 2**31
                j.given[w] = f"{v:g}"
            elif w == "precision":
                v = self.number(w)
                j.precision = max(1.0, v)
                j.given[w] = f"{v:g}"
            elif w == "slice":
                n = self.vector(4, "slice")
                if not self.accept_op(","):
                    raise self.err("slice needs a 4D normal and a distance: slice <a, b, c, d>, D")
                dist = self.number("the slice distance")
                n2 = sum(v * v for v in n)
                if abs(n2) < POV_EPSILON:
                    raise self.err("slice: the normal is zero (POV-Ray refuses it too)", t)
                if abs(n[3]) < POV_EPSILON:
                    raise self.err("slice: the normal's 4th component is zero (POV-Ray refuses it too)", t)
                norm = math.sqrt(n2)
                j.slice_normal, j.slice_distance = tuple(v / norm for v in n), dist
                j.given[w] = f"<{', '.join(f'{v:g}' for v in n)}>, {dist:g}"
            elif w in ("translate", "rotate", "scale", "matrix"):
                j.transform = j.transform.then(self.transform(w, uniform_only=True))
            elif w == "pigment":
                j.color = self.pigment(t)
            elif w == "finish":
                j.finish = self.finish(t)
            elif w == "texture":
                self.texture(t, j)
            elif w == "no_shadow":
                j.no_shadow = True  # the only object: no shadows at all
            elif w == "hollow":  # only matters for media inside; optional boolean
                if self.peek().kind == "num" or self.word() in ("on", "off", "true", "false", "yes", "no"):
                    self.expr()
            elif t.kind == "end":
                raise self.err(f"unterminated '{start.text} {{' opened at line {start.line}", t)
            elif w is not None:
                raise self.err(f"julia_fractal: unknown or unmappable keyword '{w}'", t)
            else:
                raise self.err(f"julia_fractal: unexpected {self.shown(t)}", t)
        return j

    def pigment(self, start: Tok) -> tuple:
        self.expect_op("{", "after pigment")
        w = self.word()
        if w is not None and w not in _COLOR_WORDS and w not in _CONSTS and not (
                w in self.symbols and self.symbols[w][0] in ("color", "vector", "float")):
            kind = self.symbols[w][0] if w in self.symbols else None
            what = f"the declared {kind} '{w}'" if kind else f"'{w}'"
            inc = f" (files named by #include are not read: {', '.join(self.includes)})" if self.includes else ""
            raise self.err(f"pigment {{ {w} ... }}: {what} cannot be mapped: only a plain colour "
                           f"(pigment {{ color rgb <r, g, b> }}){inc}")
        c = self.color()
        if not self.is_op("}"):
            raise self.err(f"pigment: {self.shown(self.peek())} cannot be mapped: only a plain colour")
        self.next()
        if c[3] != 0 or c[4] != 0:
            raise self.err("pigment: filter/transmit (transparency) cannot be mapped", start)
        return c[:3]

    def finish(self, start: Tok) -> dict:
        self.expect_op("{", "after finish")
        f: dict[str, float] = {}
        while not self.accept_op("}"):
            t = self.next()
            w = t.text if t.kind == "id" else None
            if w in ("ambient", "diffuse", "specular", "roughness"):
                tt = self.peek()
                v = self.expr()
                if _is_vec(v):
                    if len(set(v[:3])) != 1:
                        raise self.err(f"finish: a coloured {w} cannot be mapped", tt)
                    v = v[0]
                if w == "roughness" and v <= 0:
                    raise self.err("finish: roughness must be positive", tt)
                f[w] = float(v)
            elif w == "brilliance":
                tt = self.peek()
                if self.number(w) != 1:
                    raise self.err("finish: brilliance other than 1 cannot be mapped (pyjulia4d's diffuse "
                                   "term is Lambert's)", tt)
            elif t.kind == "end":
                raise self.err(f"unterminated 'finish {{' opened at line {start.line}", t)
            else:
                raise self.err(f"finish: {self.shown(t)} cannot be mapped (only ambient, diffuse, specular, "
                               f"roughness)", t)
        return f

    def texture(self, start: Tok, j: Julia) -> None:
        self.expect_op("{", "after texture")
        while not self.accept_op("}"):
            t = self.next()
            w = t.text if t.kind == "id" else None
            if w == "pigment":
                j.color = self.pigment(t)
            elif w == "finish":
                j.finish = self.finish(t)
            elif t.kind == "end":
                raise self.err(f"unterminated 'texture {{' opened at line {start.line}", t)
            else:
                raise self.err(f"texture: {self.shown(t)} cannot be mapped (only pigment and finish)", t)


# ---------------------------------------------------------------- the mapping

@dataclass
class Imported:
    """The scene, its TOML text (with comments) and the warnings to show."""
    scene: Scene
    toml: str
    warnings: list[str]


def pov_escape_radius(algebra: str, c) -> float:
    """POV-Ray's escape radius: sqrt(Exit_Value) of fractal.cpp Compute_BBox."""
    if algebra == "hypercomplex":
        return 4.0
    r = min(2.0, 1.0 + math.sqrt(sum(v * v for v in c)) + FRACTAL_TOLERANCE)
    return math.sqrt(r * r + FRACTAL_TOLERANCE)


class SliceMap:
    """POV-Ray's 3D fractal-space point X is the 4D point (X, (d - n_xyz.X) / n_t); the
    pyjulia4d camera coordinates of that point are R^T (Y - d n) (camera.slice_rotation)."""

    def __init__(self, normal, distance: float) -> None:
        from pyjulia4d.geometry.camera import slice_rotation

        self.n = np.asarray(normal, float)
        self.d = float(distance)
        self.r = slice_rotation(self.n)
        self.exact = bool(np.all(self.n[:3] == 0))

    def lift(self, v, point: bool) -> np.ndarray:
        v = np.asarray(v, float)
        w = ((self.d if point else 0.0) - self.n[:3] @ v) / self.n[3]
        return np.append(v, w)

    def point(self, x) -> np.ndarray:
        p = self.r.T @ (self.lift(x, True) - self.d * self.n)
        return p[:3] if self.exact else p

    def direction(self, v) -> np.ndarray:
        p = self.r.T @ self.lift(v, False)
        return p[:3] if self.exact else p


def _num(x: float) -> float:
    x = float(x) + 0.0
    return 0.0 if abs(x) < 1e-15 else x


def _vec(v) -> list[float]:
    return [_num(x) for x in v]


def convert(r: _Reader, width: int, height: int) -> tuple[dict, dict, list[str], list[str]]:
    """The scene dict, comments per dotted key, header notes and warnings."""
    where = r.where
    if not r.julias:
        declared = [n for n, s in r.symbols.items() if s[0] == "julia_fractal"]
        hint = (f" (the declared julia_fractal '{declared[0]}' is never used as object {{ {declared[0]} }})"
                if declared else "")
        raise PovError(f"{where}: no julia_fractal in the scene{hint}")
    if len(r.julias) > 1:
        raise PovError(f"{where}:{r.julias[1].line}: a second julia_fractal (the first is at line "
                       f"{r.julias[0].line}): pyjulia4d renders one")
    j = r.julias[0]
    data: dict[str, dict[str, Any]] = {}
    notes: dict[str, str] = {}
    header: list[str] = []
    warns = list(r.warnings)

    def put(key: str, value: Any, note: str | None = None) -> None:
        section, _, k = key.partition(".")
        data.setdefault(section, {})[k] = value
        if note:
            notes[key] = note

    # -- fractal
    put("fractal.algebra", j.algebra)
    if j.function not in ("sqr", "cube") and j.algebra == "quaternion":
        raise PovError(f"{where}:{j.line}: julia_fractal: quaternion takes sqr and cube only (POV-Ray: "
                       f"\"Illegal function\"); add hypercomplex for {j.function}")
    put("fractal.function", j.function)
    if j.function == "pwr":
        put("fractal.exponent", _vec(j.exponent), f"pwr({j.exponent[0]:g}, {j.exponent[1]:g})")
    put("fractal.c", _vec(j.c))
    n = j.max_iteration
    if n < 2:
        raise PovError(f"{where}:{j.line}: max_iteration {n}: POV-Ray then tests the start point only "
                       f"(a ball); pyjulia4d iterates at least once, which is POV-Ray's max_iteration 2")
    put("fractal.max_iter", n - 1,
        f"max_iteration {n}{'' if 'max_iteration' in j.given else ' (POV-Ray default)'}: POV-Ray tests "
        f"|q_n| for n = 0..{n - 1}, pyjulia4d for n = 0..max_iter")
    bail = pov_escape_radius(j.algebra, j.c)
    put("fractal.bailout", bail,
        "POV-Ray's escape radius: 4 for hypercomplex" if j.algebra == "hypercomplex" else
        "POV-Ray's quaternion escape radius sqrt(R^2 + 1e-7), R = min(2, 1 + |c| + 1e-7) "
        "(fractal.cpp), not the documented 4")

    # -- the camera, in fractal space, then in pyjulia4d camera coordinates
    inv = j.transform.inverse()
    smap = SliceMap(j.slice_normal, j.slice_distance)
    if j.slice_normal != (0.0, 0.0, 0.0, 1.0) or j.slice_distance != 0:
        put("slice.normal", _vec(j.slice_normal), f"slice {j.given.get('slice', '')} (normalised, as POV-Ray does)")
        put("slice.distance", _num(j.slice_distance))
        if not smap.exact:
            warns.append(f"{where}:{j.line}: slice normal with x/y/z components: POV-Ray draws the section "
                         f"sheared (its 3D point X is the 4D point (X, (d - n.X)/n_t)); pyjulia4d draws it "
                         f"undistorted, seen from the same 4D eye and target: the pictures differ by that shear")
            header.append("The slice normal has x/y/z components: the hyperplane, eye, target and light are "
                          "POV-Ray's; POV-Ray's picture is the section sheared by its projection along w, "
                          "this one is undistorted.")
    cam = r.cameras[-1] if r.cameras else Camera(0, np.zeros(3), np.array([0.0, 0, 1]), np.array([0.0, 1, 0]),
                                                 np.array([POV_DEFAULT_RIGHT, 0, 0]))
    if len(r.cameras) > 1:
        header.append(f"{len(r.cameras)} camera statements: the last one (line {cam.line}) is used, as in POV-Ray.")
    loc = smap.point(inv.point(cam.location))
    dirv = smap.direction(inv.direction(cam.direction))
    up = smap.direction(inv.direction(cam.up))
    right = smap.direction(inv.direction(cam.right))
    for name, v in (("direction", dirv), ("up", up), ("right", right)):
        if not np.linalg.norm(v) > 0:
            raise PovError(f"{where}:{cam.line}: camera: zero {name} vector")
    dn = dirv / np.linalg.norm(dirv)
    up_perp = up - (up @ dn) * dn
    if not np.linalg.norm(up_perp) > 1e-12 * np.linalg.norm(up):
        raise PovError(f"{where}:{cam.line}: camera: up is parallel to the view direction")
    cosines = [abs(a @ b) / (np.linalg.norm(a) * np.linalg.norm(b)) for a, b in ((dirv, up), (dirv, right), (up, right))]
    if max(cosines) > 1e-6 and smap.exact:
        warns.append(f"{where}:{cam.line}: camera vectors are not perpendicular: POV-Ray's picture is skewed; "
                     f"pyjulia4d's frame is made orthonormal (up is kept, right follows)")
    fov = math.degrees(2 * math.atan(np.linalg.norm(up_perp) / (2 * np.linalg.norm(dirv))))
    aspect = np.linalg.norm(right - (right @ dn) * dn) / np.linalg.norm(up_perp)
    if abs(aspect / (width / height) - 1) > 0.01:
        warns.append(f"{where}:{cam.line}: camera |right|/|up| = {aspect:.4g} but the image is {width}x{height} "
                     f"({width / height:.4g}): POV-Ray would stretch its pixels; pyjulia4d's are square (the "
                     f"vertical field of view matches; give --width/--height in the ratio {aspect:.4g})")
    # which way pyjulia4d's right = cross4(forward, up, limbo) points, in world coordinates
    # (limbo +w in camera coordinates is R e_w = n there), against POV-Ray's right lifted
    # onto the slice: a negative slice normal's w, or a left-handed right vector, flips it
    from pyjulia4d.geometry.vec4 import cross4

    f_w, u_w, r_w = (smap.lift(inv.direction(v), False) for v in (cam.direction, cam.up, cam.right))
    handed = float(cross4(f_w, u_w, smap.n) @ r_w)
    src = f"line {cam.line}" if cam.line else "POV-Ray's default camera: location 0, looking along +z, right 1.33 x"
    put("camera.position", _vec(loc), f"location ({src})")
    put("camera.target", _vec(loc + dirv), "location + direction (after look_at)")
    put("camera.up", _vec(up))
    if handed <= 0:
        put("camera.limbo", [0.0, 0.0, 0.0, -1.0], "so that POV-Ray's right vector is pyjulia4d's right "
            "(a left-handed right vector, or a slice normal with negative w)")
    put("camera.fov", fov, "full vertical angle: 2 atan(|up| / (2 |direction|)); POV-Ray's angle is horizontal")
    if not (np.array_equal(j.transform.a, np.eye(3)) and np.array_equal(j.transform.t, np.zeros(3))):
        header.append("The julia_fractal's transform is applied inversely to the camera and the light.")

    # -- march: POV-Ray's precision P steps at least 1/P
    from pyjulia4d.geometry.camera import march_radius

    step = 1.0 / j.precision
    prec = f"precision {j.given.get('precision', '20 (POV-Ray default)')}"
    probe = Scene.from_dict({k: dict(v) for k, v in data.items()})
    if probe.fractal.algebra == "quaternion":
        if step < probe.march.epsilon:
            put("march.epsilon", step, f"{prec}: POV-Ray's minimum step 1/P, finer than the default")
        else:
            header.append(f"{prec}: POV-Ray's march steps at least 1/P = {step:.4g}; pyjulia4d's default "
                          f"march (distance estimate, minimum step march.epsilon = {probe.march.epsilon:g}, "
                          f"certified depth) is no coarser and is kept.")
    else:
        zres = math.ceil(2 * march_radius(probe) * j.precision)
        if zres > probe.march.z_resolution:
            put("march.z_resolution", zres, f"{prec}: samples no farther apart than POV-Ray's step 1/P")
        else:
            header.append(f"{prec}: POV-Ray's march steps at least 1/P = {step:.4g}; pyjulia4d's fixed "
                          f"scan ({probe.march.z_resolution} samples across the bounding ball, at most "
                          f"{2 * march_radius(probe) / probe.march.z_resolution:.3g} apart, certified depth) "
                          f"is no coarser and is kept.")

    # -- shading
    if j.color is not None:
        put("shading.color", _vec(j.color), "pigment")
    else:
        header.append("No pigment: POV-Ray would draw the object black; pyjulia4d's default colour is kept.")
    if j.finish is not None:
        f = {**POV_FINISH, **j.finish}
        put("shading.ambient", f["ambient"], "finish (POV-Ray 3.7 defaults for what it leaves out)")
        put("shading.diffuse", f["diffuse"])
        put("shading.specular", f["specular"])
        put("shading.shininess", 1.0 / f["roughness"], "1 / roughness")
    if r.lights:
        lt = r.lights[0]
        if len(r.lights) > 1:
            warns.append(f"{where}:{r.lights[1].line}: {len(r.lights)} light sources: pyjulia4d has one light, "
                         f"the first (line {lt.line}) is used")
        put("shading.light", _vec(smap.point(inv.point(lt.position))), f"light_source (line {lt.line})")
        put("shading.light_color", _vec(lt.color))
        if lt.shadowless or j.no_shadow:
            put("shading.shadow", "none", "shadowless" if lt.shadowless else "no_shadow on the julia_fractal")
        else:
            put("shading.shadow", "hard", "POV-Ray's point light casts hard shadows")
        put("shading.ao", 0.0, "POV-Ray has no ambient occlusion (without radiosity)")
    else:
        header.append("No light_source: POV-Ray would show ambient light only; pyjulia4d's default lighting "
                      "(its light, shadows and ambient occlusion) is kept.")
    if r.background is not None:
        put("shading.background", _vec(r.background[:3]), "background")
    put("image.width", width)
    put("image.height", height)
    if r.ignored:
        header.append("Not read: " + ", ".join(r.ignored) + ".")
    if r.includes:
        header.append("#include files not read: " + ", ".join(r.includes) + ".")
    return data, notes, header, warns


def _wrap(text: str, width: int = 88) -> list[str]:
    lines, cur = [], "#"
    for word in text.split():
        if len(cur) + 1 + len(word) > width and cur != "#":
            lines.append(cur)
            cur = "#"
        cur += " " + word
    lines.append(cur)
    return lines


def to_toml(data: dict, notes: dict, header: list[str], source: str) -> str:
    out = [f"# pyjulia4d scene imported from the POV-Ray scene {source}",
           "# by `pyjulia4d import-pov` (pyjulia4d/povray.py documents the mapping)."]
    for h in header:
        out.extend(_wrap(h))
    for section, table in data.items():
        out.append(f"\n[{section}]")
        for k, v in table.items():
            line = f"{k} = {toml_value(v)}"
            note = notes.get(f"{section}.{k}")
            out.append(f"{line}  # {note}" if note else line)
    return "\n".join(out) + "\n"


def read_pov(path: str | Path) -> str:
    from pyjulia4d.app.output import shown_path

    where = shown_path(os.fspath(path))
    try:
        with open(path, "rb") as f:
            raw = f.read(MAX_POV_BYTES + 1)
    except (OSError, ValueError) as e:
        raise PovError(f"{where}: cannot read: {getattr(e, 'strerror', None) or e}") from None
    if len(raw) > MAX_POV_BYTES:
        raise PovError(f"{where}: larger than {MAX_POV_BYTES >> 20} MiB, not read")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise PovError(f"{where}: not UTF-8 text ({e.reason} at byte {e.start})") from None
    return text.removeprefix("\ufeff")


def import_pov(path: str | Path, width: int | None = None, height: int | None = None) -> Imported:
    """Read ``path`` and map its julia_fractal, camera and light to a pyjulia4d scene."""
    from pyjulia4d.app.output import shown_path

    w, h = DEFAULT_SIZE if width is None and height is None else (width, height)
    if w is None or h is None:  # one given: the other keeps pyjulia4d's aspect ratio
        w = w if w is not None else max(1, round(h * DEFAULT_SIZE[0] / DEFAULT_SIZE[1]))
        h = h if h is not None else max(1, round(w * DEFAULT_SIZE[1] / DEFAULT_SIZE[0]))
    Scene.from_dict({"image": {"width": w, "height": h}})  # the same range errors as render's
    where = shown_path(os.fspath(path))
    text = read_pov(path)
    try:
        with np.errstate(all="ignore"):  # an overflow becomes a non-finite value the scene refuses
            reader = _Reader(tokenize(text, where), where, w, h)
            reader.run()
            data, notes, header, warns = convert(reader, w, h)
            scene = Scene.from_dict(data)
    except RecursionError:
        raise PovError(f"{where}: expressions nested too deeply") from None
    except SceneError as e:
        raise PovError(f"{where}: maps to {e}") from None
    return Imported(scene, to_toml(data, notes, header, Path(os.fspath(path)).name), warns)


def check_toml_path(path: str | Path, source: str | Path) -> Path:
    """Fail before writing if ``path`` cannot take the scene file (output.check_output_path's
    checks, for .toml)."""
    from pyjulia4d.app.output import NAME_MAX, OutputError, path_limit, quoted_path, shown_path, check_directory

    raw = os.fspath(path)
    shown = shown_path(raw)
    if not raw:
        raise OutputError(f"{shown}: empty output path")
    p = Path(raw)
    if p.suffix.lower() != ".toml":
        got = quoted_path(p.suffix) if p.suffix else "'(none)'"
        raise OutputError(f"{shown}: unsupported output format {got} (use .toml)")
    if raw.endswith(("/", os.sep)):
        raise OutputError(f"{shown}: names a directory (trailing '/')")
    check_directory(shown, p.parent)
    try:
        st = os.stat(p)
    except (FileNotFoundError, ValueError):
        st = None
    except OSError as e:
        raise OutputError(f"{shown}: {e.strerror or e}") from None
    if st is not None and stat.S_ISDIR(st.st_mode):
        raise OutputError(f"{shown}: is a directory")
    try:
        same = st is not None and os.path.samefile(p, source)
    except (OSError, ValueError):
        same = False
    if same:
        raise OutputError(f"{shown}: is the POV-Ray file itself")
    name_max = path_limit(p.parent, "PC_NAME_MAX", NAME_MAX)
    if len(os.fsencode(p.name)) > name_max:
        raise OutputError(f"{shown}: file name too long ({len(os.fsencode(p.name))} bytes; this file "
                          f"system allows {name_max})")
    return p


def write_toml(path: Path, text: str) -> None:
    """Atomically (output.py's temp file beside it, renamed)."""
    from pyjulia4d.app.output import OutputError, atomic_write

    try:
        with atomic_write(path) as tmp:
            tmp.write_text(text, encoding="utf-8")
    except OSError as e:
        raise OutputError(f"{path}: cannot write: {e.strerror or e}") from None

