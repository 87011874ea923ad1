"""The checkers of scene values, and SceneError.

A checker is called as ``check(dotted key, raw value)`` and returns the normalised value,
or raises SceneError with one line naming the key; ``valid`` words its valid range, as
docs/scene-keys.md and ``pyjulia4d keys`` show it.  The table of which checker each key
has is scene/model.py's CHECKS.
"""
from __future__ import annotations

import difflib
import math
from dataclasses import dataclass
from typing import Any, Callable, Mapping

Checker = Callable[[str, Any], Any]


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


def one_line(e: BaseException) -> str:
    """An exception's message on one line (the command line's and the explorer's errors)."""
    return " ".join(str(e).splitlines()) or type(e).__name__


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

INT_MAX = 2**31 - 1  # ints end up as OpenCL `int` kernel arguments
COORD = 1e6           # bound of positions, directions' components and slice.distance

def fmt(x: float) -> str:
    """A bound as README writes it: 1e6, 1e-3, 179.9, 0, 2147483647."""
    if isinstance(x, int):
        return str(x)
    if x != 0 and not 1e-2 <= abs(x) < 1e3:
        mantissa, exponent = f"{x:.14e}".split("e")
        return f"{mantissa.rstrip('0').rstrip('.')}e{int(exponent)}"
    return f"{x:g}"


def show(v: Any, limit: int = 60) -> str:
    """repr(v) for an error message: one line, at most ``limit`` characters."""
    try:
        s = repr(v)
    except ValueError:  # an int of more than 4300 digits
        s = f"<an integer of ~{int(v.bit_length() * math.log10(2)) + 1} digits>"
    except RecursionError:  # a deeply nested list
        s = f"<a deeply nested {type(v).__name__}>"
    except Exception:  # an object whose own __repr__ fails: its type is all there is to show
        s = f"<a {type(v).__name__}>"
    return s if len(s) <= limit else s[: limit - 3] + "..."


def show_key(key: str) -> str:
    """A user-given key or path as it goes into a message: itself when plain, else repr."""
    return key if key and key.isprintable() and len(key) <= 80 else show(key, 80)


def closest(got: Any, options) -> str | None:
    """The option ``got`` was most likely meant as: the one it begins (3 letters at least),
    else the closest by difflib's ratio (at least 0.6), case ignored; None if none is."""
    if not isinstance(got, str) or not got.isprintable() or len(got) > 80:
        return None
    by_lower = {o.lower(): o for o in options}
    g = got.lower()
    begun = [o for low, o in by_lower.items() if len(g) >= 3 and low.startswith(g)]
    if len(begun) == 1:
        return begun[0]
    near = difflib.get_close_matches(g, list(by_lower), n=1, cutoff=0.6)
    return by_lower[near[0]] if near else None


def did_you_mean(got: Any, options) -> str:
    """"; did you mean 'x'?" for the option closest to ``got`` (closest), else ""."""
    near = closest(got, options)
    return f"; did you mean {near!r}?" if near is not None else ""


def unknown_key(dotted: str, checks: Mapping) -> SceneError:
    """The error for a key no section has, with the closest known one (``checks``: section ->
    key -> check): the same key in another section, else the closest key of its own section,
    else the key in the closest section."""
    section, dot, key = str(dotted).partition(".")
    near = None
    if not dot:
        near = closest(section, list(checks))
    elif section in checks:
        elsewhere = [f"{sec}.{key}" for sec, keys in checks.items() if key in keys]
        k = closest(key, list(checks[section]))
        near = elsewhere[0] if elsewhere else (f"{section}.{k}" if k is not None else None)
    else:
        sec = closest(section, list(checks))
        if sec is not None:
            k = key if key in checks[sec] else closest(key, list(checks[sec]))
            near = f"{sec}.{k}" if k is not None else sec
    return SceneError(show_key(str(dotted)), "unknown key" + (f"; did you mean {near!r}?" if near and near != dotted else ""))


def scalar(text: str) -> Any:
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


@dataclass(frozen=True)
class Range:
    """lo <= x <= hi (lo < x with ``lo_open``)."""

    lo: float
    hi: float
    lo_open: bool = False

    def __contains__(self, x: float) -> bool:
        return (self.lo < x if self.lo_open else self.lo <= x) and x <= self.hi

    def __str__(self) -> str:
        return f"{'(' if self.lo_open else '['}{fmt(self.lo)}, {fmt(self.hi)}]"


class Real:
    """A finite number in a range; ints are taken as floats, -0.0 becomes 0.0."""

    verbatim = False  # an override's VALUE is parsed as numbers, not kept as text

    def __init__(self, lo: float, hi: float, lo_open: bool = False) -> None:
        self.range = Range(lo, hi, lo_open)
        self.valid = str(self.range)

    def __call__(self, key: str, v: Any) -> float:
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise SceneError(key, f"expected a number, got {show(v)}")
        if isinstance(v, float) and not math.isfinite(v):
            raise SceneError(key, "not a finite number")
        if v not in self.range:  # an int compares exactly, however large
            raise SceneError(key, f"must be in {self.range}, got {show(v)}")
        return float(v) + 0.0


class Integer:
    """An integer (not a float, not a bool) in a range."""

    verbatim = False

    def __init__(self, lo: int, hi: int) -> None:
        self.range = Range(lo, hi)
        self.valid = f"integer in {self.range}"

    def __call__(self, key: str, v: Any) -> int:
        if isinstance(v, bool) or not isinstance(v, int):
            raise SceneError(key, f"expected an integer, got {show(v)}")
        if v not in self.range:
            raise SceneError(key, f"must be in {self.range}, got {show(v)}")
        return v


class Whole:
    """One of a few whole numbers (not floats, not bools)."""

    verbatim = False

    def __init__(self, *options: int) -> None:
        self.options = options
        self.valid = ", ".join(map(str, options[:-1])) + " or " + str(options[-1])

    def __call__(self, key: str, v: Any) -> int:
        if isinstance(v, bool) or not isinstance(v, int) or v not in self.options:
            raise SceneError(key, f"expected {self.valid}, got {show(v)}")
        return v


class Choice:
    """One of a few words."""

    verbatim = True  # an override's VALUE is the word itself

    def __init__(self, *options: str, fold_case: bool = False) -> None:
        self.options = options
        self.fold_case = fold_case   # names whose case is no part of them (the colour maps': viridis, Spectral)
        quoted = [f'"{o}"' for o in options]
        self.valid = quoted[0] if len(quoted) == 1 else ", ".join(quoted[:-1]) + " or " + quoted[-1]

    def __call__(self, key: str, v: Any) -> str:
        if self.fold_case and isinstance(v, str) and v not in self.options:
            same = [o for o in self.options if o.lower() == v.lower()]
            v = same[0] if len(same) == 1 else v
        if not isinstance(v, str) or v not in self.options:
            raise SceneError(key, f"expected one of {', '.join(map(repr, self.options))}, got {show(v)}"
                                  f"{did_you_mean(v, self.options)}")
        return v


class Stops:
    """A colour gradient of ``least`` to ``most`` stops [position, r, g, b]: positions in [0, 1]
    rising (or equal: a hard edge), sRGB colours in [0, 1]; [] for none.  On the command
    line the same TOML array of arrays."""

    verbatim = True

    def __init__(self, least: int, most: int) -> None:
        self.least, self.most = least, most
        self.valid = (f"[] or {least} to {most} stops [position, r, g, b], positions in [0, 1] rising, "
                      f"sRGB colours in [0, 1]")

    def __call__(self, key: str, v: Any) -> tuple:
        if isinstance(v, str):
            import tomllib

            text = v.strip()
            try:
                v = [] if text in ("", "[]") else tomllib.loads(f"v = {text}")["v"]
            except tomllib.TOMLDecodeError as e:
                raise SceneError(key, f"not a TOML array of stops ({' '.join(str(e).split())[:100]})") from None
        if not isinstance(v, (list, tuple)):
            raise SceneError(key, f"expected a list of stops [position, r, g, b], got {show(v)}")
        if not v:
            return ()
        if not self.least <= len(v) <= self.most:
            raise SceneError(key, f"expected {self.least} to {self.most} stops, got {len(v)}")
        out = []
        for i, stop in enumerate(v):
            where = f"{key}[{i}]"
            if not isinstance(stop, (list, tuple)) or len(stop) != 4:
                raise SceneError(where, f"expected [position, r, g, b], got {show(stop)}")
            nums = []
            for x in stop:
                if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x) or not 0 <= x <= 1:
                    raise SceneError(where, f"expected numbers in [0, 1], got {show(stop)}")
                nums.append(float(x))
            if out and nums[0] < out[-1][0]:
                raise SceneError(where, f"position {nums[0]:g} is below the stop before's {out[-1][0]:g}: "
                                        f"positions rise")
            out.append(tuple(nums))
        return tuple(out)


class Vector:
    """A fixed-length list of numbers, each in [lo, hi]; a 3-vector where 4 are allowed
    gets w = 0.  ``nonzero``: a direction, any length but 0 (it is normalised by its
    largest component first, so tiny and huge lengths are both exact)."""

    verbatim = False

    def __init__(self, lengths: tuple[int, ...], lo: float, hi: float, nonzero: bool = False) -> None:
        self.lengths = lengths
        self.element = Real(lo, hi)
        self.want = " or ".join(map(str, lengths))
        self.valid = f"{self.want} numbers in {self.element.range}" + (", not all 0" if nonzero else "")
        self.nonzero = nonzero

    def __call__(self, key: str, v: Any) -> tuple[float, ...]:
        if not isinstance(v, (list, tuple)):
            raise SceneError(key, f"expected a list of {self.want} numbers, got {show(v)}")
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


class Bool:
    """true or false (TOML booleans; on the command line the words)."""

    verbatim = True
    valid = "true or false"

    def __call__(self, key: str, v: Any) -> bool:
        if isinstance(v, bool):
            return v
        if isinstance(v, str) and v.strip() in ("true", "false"):
            return v.strip() == "true"
        raise SceneError(key, f"expected true or false, got {show(v)}")


class Planes:
    """Up to 4 planes [nx, ny, nz, offset]: a list of 4-number lists (TOML) or, on the
    command line, "nx,ny,nz,offset;..." or the same TOML array of arrays ("" or "[]": none)."""

    verbatim = True

    def __init__(self, most: int) -> None:
        self.most = most
        self.valid = (f"up to {most} planes [nx, ny, nz, offset], numbers in [-1e6, 1e6], the normal not "
                      f"all 0 (--set: nx,ny,nz,offset;... or a TOML array of arrays)")

    def __call__(self, key: str, v: Any) -> tuple:
        if isinstance(v, str):
            text = v.strip()
            if text in ("", "[]"):
                v = []
            elif text.startswith("[["):   # the scene file's TOML array of arrays
                import tomllib

                try:
                    v = tomllib.loads(f"v = {text}")["v"]
                except tomllib.TOMLDecodeError as e:
                    raise SceneError(key, f"not a TOML array of planes ({' '.join(str(e).split())[:100]})") from None
            else:
                v = [[scalar(x) for x in part.split(",")] for part in text.strip("[]").split(";")]
        if not isinstance(v, (list, tuple)):
            raise SceneError(key, f"expected a list of planes [nx, ny, nz, offset], got {show(v)}")
        if len(v) > self.most:
            raise SceneError(key, f"at most {self.most} planes, got {len(v)}")
        out = []
        for i, plane in enumerate(v):
            if not isinstance(plane, (list, tuple)) or len(plane) != 4:
                raise SceneError(key, f"plane {i}: expected [nx, ny, nz, offset], got {show(plane)}")
            vals = []
            for j, x in enumerate(plane):
                if isinstance(x, bool) or not isinstance(x, (int, float)):
                    raise SceneError(key, f"plane {i}: element {j}: expected a number, got {show(x)}")
                if not math.isfinite(x):
                    raise SceneError(key, f"plane {i}: element {j}: not a finite number")
                if abs(x) > COORD:
                    raise SceneError(key, f"plane {i}: element {j}: must be in [-1e6, 1e6], got {show(x)}")
                vals.append(float(x))
            if max(abs(x) for x in vals[:3]) == 0:
                raise SceneError(key, f"plane {i}: zero normal")
            out.append(tuple(vals))
        return tuple(out)


class Lights:
    """Up to ``most`` lights, each a table with exactly one of position / direction (3 or 4
    numbers; a direction not all 0) and optional color (3 numbers in [0, 1e3]) and intensity
    (in [0, 1e3]), and for the path tracer a radius (in [0, 1e3]: a positioned light's sphere,
    scene units; a distant one's angular radius, degrees).  On the command line: "position
    x,y,z[,w] color r,g,b intensity k radius r; direction x,y,z[,w] ..." ("" or "[]": none),
    or the scene file's TOML inline array of inline tables ("[{position = [1, 2, 3]}, ...]")."""

    verbatim = True
    FIELDS = ("position", "direction", "color", "intensity", "radius")

    def __init__(self, most: int, make: Callable[..., Any]) -> None:
        self.most = most
        self.make = make   # the light's type (scene.model.Light), built from the checked fields
        self.valid = (f"up to {most} tables {{position = [x, y, z, w] or direction = [x, y, z, w], "
                      f"color = [r, g, b], intensity = k, radius = r}} (--set: the same TOML, or position x,y,z,w "
                      f"color r,g,b intensity k radius r; ...)")
        self.point = Vector((3, 4), -COORD, COORD)
        self.direction = Vector((3, 4), -COORD, COORD, nonzero=True)
        self.color = Vector((3,), 0.0, 1e3)
        self.intensity = Real(0.0, 1e3)
        self.radius = Real(0.0, 1e3)

    def _parse(self, key: str, text: str) -> list:
        lights = []
        for i, part in enumerate(text.strip("[]").split(";")):
            words = part.split()
            if len(words) % 2:
                raise SceneError(key, f"light {i}: expected pairs 'name value', got {show(part.strip())}")
            table: dict[str, Any] = {}
            for name, value in zip(words[0::2], words[1::2]):
                table[name] = scalar(value) if name in ("intensity", "radius") else [scalar(x) for x in value.split(",")]
            lights.append(table)
        return lights

    def _toml(self, key: str, text: str) -> list:
        """The value as TOML writes it in a scene file: an inline array of inline tables."""
        import tomllib

        try:
            return tomllib.loads(f"v = {text}")["v"]
        except tomllib.TOMLDecodeError as e:
            raise SceneError(key, f"not a TOML array of light tables ({' '.join(str(e).split())[:100]})") from None

    def __call__(self, key: str, v: Any) -> tuple:
        if isinstance(v, str):
            text = v.strip()
            toml = text.startswith("[") and "{" in text
            v = [] if text in ("", "[]") else self._toml(key, text) if toml else self._parse(key, text)
        if not isinstance(v, (list, tuple)):
            raise SceneError(key, f"expected a list of light tables, got {show(v)}")
        if len(v) > self.most:
            raise SceneError(key, f"at most {self.most} lights (besides shading.light), got {len(v)}")
        out = []
        for i, table in enumerate(v):
            where = f"{key}[{i}]"
            if isinstance(table, self.make):
                table = table.to_dict()
            if not isinstance(table, Mapping):
                raise SceneError(where, f"expected a table {{position = [...], color = [...], intensity = k}}, "
                                        f"got {show(table)}")
            for name in table:
                if name not in self.FIELDS:
                    raise SceneError(f"{where}.{show_key(str(name))}", "unknown key; use position or direction, "
                                                                        "color, intensity, radius")
            if ("position" in table) == ("direction" in table):
                raise SceneError(where, "give exactly one of position and direction")
            kw: dict[str, Any] = {}
            for name, check in (("position", self.point), ("direction", self.direction), ("color", self.color),
                                ("intensity", self.intensity), ("radius", self.radius)):
                if name in table:
                    kw[name] = check(f"{where}.{name}", table[name])
            out.append(self.make(**kw))
        return tuple(out)


class ImageFile:
    """One of a few words, or the path of an image file with one of ``suffixes`` (read at
    planning, where a missing or bad file is refused the same way)."""

    verbatim = True

    def __init__(self, words: tuple[str, ...], suffixes: tuple[str, ...], what: str) -> None:
        self.words, self.suffixes = words, suffixes
        quoted = ", ".join(f'"{w}"' for w in words)
        self.valid = f"{quoted} or the path of {what} ({', '.join(suffixes)})"

    def __call__(self, key: str, v: Any) -> str:
        if not isinstance(v, str) or not v.strip():
            raise SceneError(key, f"expected {self.valid}, got {show(v)}")
        if v in self.words:
            return v
        if len(v) > 4096 or any(ch in v for ch in "\0\n\r"):
            raise SceneError(key, f"expected a file path (one line, at most 4096 characters), got {show(v)}")
        if not v.lower().endswith(self.suffixes):
            raise SceneError(key, f"expected {self.valid}, got {show(v)}")
        return v


class OrWord:
    """The literal string ``word``, else what ``inner`` accepts (another OrWord: a second word)."""

    @staticmethod
    def split(check: Any) -> tuple[tuple[str, ...], Any]:
        """A key's checker as (its words, the checker beneath them): nested OrWords' words in
        order, ((), check) for any other checker."""
        words = []
        while isinstance(check, OrWord):
            words.append(check.word)
            check = check.inner
        return tuple(words), check

    verbatim = False

    def __init__(self, word: str, inner: Any) -> None:
        self.word = word
        self.inner = inner
        self.valid = f'"{word}" or {inner.valid}'
        self.verbatim = inner.verbatim   # an override's text goes to the inner checker as it would alone

    def __call__(self, key: str, v: Any) -> Any:
        if isinstance(v, str):
            if v == self.word:
                return v
            # the inner's own words (true, false; a nested OrWord's word), read from the text
            if self.inner.verbatim or isinstance(self.inner, OrWord):
                try:
                    return self.inner(key, v)
                except SceneError:
                    pass
            raise SceneError(key, f"expected {self.valid}, got {show(v)}")
        return self.inner(key, v)
