"""The expression part of the POV-Ray reader: token access, float and vector expressions,
``< >`` vectors, colours, the common float functions, transforms (Affine) and skipping
blocks it does not read."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from pyjulia4d.interop.povray.tokens import PovError, Tok


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


_FUNCS1 = {"abs": abs, "sqrt": math.sqrt, "sin": math.sin, "cos": math.cos, "tan": math.tan,
           "asin": math.asin, "acos": math.acos, "atan": math.atan, "sinh": math.sinh,
           "cosh": math.cosh, "tanh": math.tanh, "asinh": math.asinh, "acosh": math.acosh,
           "atanh": math.atanh, "exp": math.exp, "ln": math.log, "log": math.log10,
           "radians": math.radians, "degrees": math.degrees, "floor": math.floor,
           "ceil": math.ceil, "int": lambda v: float(int(v))}
_FUNCS2 = {"pow": math.pow, "atan2": math.atan2, "mod": math.fmod,
           "div": lambda a, b: float(int(a / b)), "min": min, "max": max}
CONSTS = {"pi": math.pi, "tau": 2 * math.pi, "true": 1.0, "yes": 1.0, "on": 1.0, "false": 0.0,
           "no": 0.0, "off": 0.0, "clock": 0.0, "clock_delta": 1.0, "frame_number": 0.0,
           "initial_frame": 0.0, "final_frame": 0.0, "initial_clock": 0.0, "final_clock": 0.0,
           "x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0), "t": (0.0, 0.0, 0.0, 1.0),
           "u": (1.0, 0.0), "v": (0.0, 1.0)}
_MEMBERS = {"x": 0, "u": 0, "red": 0, "y": 1, "v": 1, "green": 1, "z": 2, "blue": 2, "t": 3,
            "filter": 3, "transmit": 4}
COLOR_WORDS = {"color", "colour", "rgb", "rgbf", "rgbt", "rgbft", "red", "green", "blue",
                "filter", "transmit", "srgb", "srgbf", "srgbt", "srgbft", "gray", "grey"}


def is_vec(v) -> bool:
    return isinstance(v, tuple)


class ExpressionReader:
    """Tokens in, values out; the scene reader (reader.py) adds the statements."""

    def __init__(self, toks: list[Tok], where: str, width: int, height: int) -> None:
        self.toks, self.pos, self.where = toks, 0, where
        self.size = (width, height)
        self.symbols: dict[str, tuple[str, Any, int]] = {}

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
        if is_vec(a) or is_vec(b):  # POV-Ray: floats promote, vectors act per component
            n = max(len(a) if is_vec(a) else 0, len(b) if is_vec(b) else 0)
            a = tuple(a) + (0.0,) * (n - len(a)) if is_vec(a) else (a,) * n
            b = tuple(b) + (0.0,) * (n - len(b)) if is_vec(b) else (b,) * n
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
            if not is_vec(v) or _MEMBERS[name] >= len(v):
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
            if name in CONSTS:
                self.next()
                return CONSTS[name]
            if name in ("image_width", "image_height"):
                self.next()
                return float(self.size[name == "image_height"])
            if name in COLOR_WORDS:
                return self.color()
            if name in _FUNCS1 or name in _FUNCS2:
                raise self.err(f"'{name}' without '(' where a value is expected", t)
            inc = f" (files named by #include are not read: {', '.join(self.includes)})" if self.includes else ""
            raise self.err(f"unknown identifier '{name}' where a value is expected{inc}", t)
        raise self.err(f"expected a value, got {self.shown(t)}", t)

    def _float(self, v: Any, what: str) -> float:
        if is_vec(v):
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
            if name == "vlength" and len(args) == 1 and is_vec(args[0]):
                return math.sqrt(sum(x * x for x in args[0]))
            if name == "vnormalize" and len(args) == 1 and is_vec(args[0]):
                n = math.sqrt(sum(x * x for x in args[0]))
                return tuple(x / n for x in args[0])
            if name == "vdot" and len(args) == 2 and all(map(is_vec, args)):
                return sum(a * b for a, b in zip(*args))
            if name == "vcross" and len(args) == 2 and all(map(is_vec, args)):
                return tuple(float(x) for x in np.cross(np.resize(args[0], 3), np.resize(args[1], 3)))
            fn = _FUNCS1.get(name) if len(args) == 1 else _FUNCS2.get(name) if len(args) == 2 else None
            if fn is None or any(map(is_vec, args)):
                raise self.err(f"{name}() with {len(args)} argument(s) of these kinds is not supported", t)
            r = float(fn(*args))
        except (ValueError, OverflowError, ZeroDivisionError):
            raise self.err(f"{name}() of {', '.join(f'{a:g}' if not is_vec(a) else 'a vector' for a in args)}"
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
        if not is_vec(v):
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
                if is_vec(v):
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
                if is_vec(v):
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
