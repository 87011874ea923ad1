"""The statement part of the POV-Ray reader: #version, #include, #declare, camera,
light_source, background, julia_fractal and its pigment, finish and texture."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from pyjulia4d.fractal.registry import FUNCTIONS
from pyjulia4d.interop.povray.expressions import COLOR_WORDS, CONSTS, Affine, ExpressionReader, is_vec
from pyjulia4d.interop.povray.tokens import Tok

MAX_POV_BYTES = 8 << 20       # larger files are refused unread
POV_EPSILON = 1e-10           # POV-Ray's EPSILON (slice and camera checks)
FRACTAL_TOLERANCE = 1e-7      # fractal.cpp: added to the quaternion escape radius
POV_DEFAULT_RIGHT = 1.33      # camera.cpp Camera::Init (horizontal angle 67.38 degrees)
POV_FINISH = {"ambient": 0.1, "diffuse": 0.6, "specular": 0.0, "roughness": 0.05}
DEFAULT_SIZE = (640, 480)     # pyjulia4d's image size, used unless --width/--height

_ALGEBRAS = ("quaternion", "hypercomplex")
_CAMERA_TYPES = ("orthographic", "fisheye", "ultra_wide_angle", "omnimax", "panoramic", "spherical",
                 "cylinder", "mesh_camera", "user_defined")
# light_source modifiers that are read past (with a warning) and their arguments
_LIGHT_SKIP = {"spotlight": "", "cylinder": "", "parallel": "", "circular": "", "orient": "",
               "jitter": "", "area_illumination": "f?", "fade_distance": "f", "fade_power": "f",
               "radius": "f", "falloff": "f", "tightness": "f", "point_at": "v", "adaptive": "f",
               "media_interaction": "f?", "media_attenuation": "f?", "area_light": "v,v,f,f",
               "looks_like": "{", "photons": "{", "projected_through": "{"}


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


class SceneReader(ExpressionReader):
    """A julia_fractal scene's statements, read into Julia, Camera and Light records."""

    def __init__(self, toks: list[Tok], where: str, width: int, height: int) -> None:
        super().__init__(toks, where, width, height)
        self.includes: list[str] = []
        self.julias: list[Julia] = []
        self.cameras: list[Camera] = []
        self.lights: list[Light] = []
        self.background: tuple | None = None
        self.ignored: list[str] = []
        self.warnings: list[str] = []
        self.version: float | None = None

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
            elif w is not None and w not in self.symbols and w not in COLOR_WORDS and self.is_op("{", 1):
                self.next()
                start = self.next()
                self.skip_block(w, start)
                self.symbols[name.text] = (w, None, name.line)
            else:
                v = self.expr()
                kind = "vector" if is_vec(v) else "float"
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
                                 f"pyjulia4d's lights are points and suns")
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
        if w is not None and w not in COLOR_WORDS and w not in CONSTS and not (
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
                if is_vec(v):
                    if len(set(v[:3])) != 1:
                        raise self.err(f"finish: a coloured {w} cannot be mapped", tt)
                    v = v[0]
                if w == "roughness" and v <= 0:
                    raise self.err("finish: roughness must be positive", tt)
                f[w] = float(v)
            elif w == "reflection":   # a mirror share: pyjulia4d's one bounce (shading.reflection)
                tt = self.peek()
                if self.peek().text == "{":
                    raise self.err("finish: a reflection block cannot be mapped (give reflection a number)", tt)
                v = self.expr()
                if is_vec(v):
                    if len(set(v[:3])) != 1:
                        raise self.err("finish: a coloured reflection cannot be mapped", tt)
                    v = v[0]
                if not 0.0 <= float(v) <= 1.0:
                    raise self.err("finish: reflection must lie in [0, 1]", tt)
                f["reflection"] = float(v)
            elif w == "brilliance":
                tt = self.peek()
                if self.number(w) != 1:
                    raise self.err("finish: brilliance other than 1 cannot be mapped (pyjulia4d's diffuse "
                                   "term is Lambert's)", tt)
            elif t.kind == "end":
                raise self.err(f"unterminated 'finish {{' opened at line {start.line}", t)
            else:
                raise self.err(f"finish: {self.shown(t)} cannot be mapped (only ambient, diffuse, specular, "
                               f"roughness, reflection)", t)
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
