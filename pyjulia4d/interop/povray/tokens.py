"""POV-Ray scene text into tokens (the reader's input), and PovError."""
from __future__ import annotations

import math
from dataclasses import dataclass


class PovError(ValueError):
    """A POV-Ray scene this reader cannot read or map; ``str(e)`` is one line."""


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
