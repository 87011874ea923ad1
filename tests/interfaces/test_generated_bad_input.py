"""Generated bad input for the command line, seeded and deterministic.

Every case is bad input: a scene file, a --set value, a flag or an output path.  For
each, ``pyjulia4d.cli.main(argv)`` must return 2 with exactly one stderr line starting
``pyjulia4d: error:`` (no warning lines either: bad input is refused before anything
could warn), print nothing on stdout, raise no numpy warning, never reach the render,
and leave the working directory (a tmp_path) as it was: no output, no temp file.
Almost all cases run in-process; a handful run through ``python -m pyjulia4d`` to show
that no traceback reaches the terminal.  SIGTERM and SIGHUP during a real render and
during the write must remove the temp file and exit with 128 + the signal number.
"""
from __future__ import annotations

import os
import random
import signal
import subprocess
import sys
import time
import types
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import pytest

import pyjulia4d
from pyjulia4d.app import cli
from pyjulia4d.scene.checks import OrWord
from pyjulia4d.scene.ranges import CHECKS

PKG_ROOT = str(Path(pyjulia4d.__file__).resolve().parent.parent)
SEED = 20261125
KEYS = [f"{s}.{k}" for s, table in CHECKS.items() for k in table]
OPTIONS = ["--output", "--width", "--height", "--set", "--device", "--force", "--help", "--verbose"]


@dataclass
class Case:
    id: str
    argv: list[str]
    files: dict[str, bytes | None] = field(default_factory=dict)  # None: a directory
    real_argv: bool = True  # can go through a real command line (no NUL, no lone surrogate)


def _check_of(key: str):
    section, _, name = key.partition(".")
    return CHECKS[section][name]


# ------------------------------------------------------------------ value generators

GARBAGE = ["", " ", "abc", "x1", "1x", "[", "]", "[1,", ",", ",,", "1,,2", "true", "false",
           "0x10", "1e", "e3", "--", "None", "null", "{}", "{a=1}", "'1'", '"1"', "1 2",
           "١٢", "１２", "½", "1\u200b", "\u202e1", "🙂", "\\n", "1;2", "\t", "NaN(0)"]
NONFINITE = ["nan", "-nan", "inf", "-inf", "+inf", "Infinity", "1e400", "-1e999"]


def _unicode(rng: random.Random, n: int) -> str:
    blocks = [(0x21, 0x7E), (0xA0, 0x24F), (0x370, 0x3FF), (0x4E00, 0x4E80), (0x1F600, 0x1F64F),
              (0x300, 0x36F), (0x200B, 0x200F), (0x202A, 0x202E), (0x1, 0x1F)]
    out = [chr(rng.randint(0xA1, 0x24F))]  # never all ASCII: never a number or a word
    for _ in range(n - 1):
        lo, hi = rng.choice(blocks)
        out.append(chr(rng.randint(lo, hi)))
    return "".join(out)


def _fmt(x) -> str:
    return repr(x) if isinstance(x, float) else str(x)


def _out_of_range(rng: random.Random, valid, integer: bool) -> list:
    """Numbers just and far outside the range ``valid`` (a scene.checks.Range)."""
    lo, hi, lo_open = valid.lo, valid.hi, valid.lo_open
    if integer:
        return [lo - 1, lo - rng.randint(2, 10**6), hi + 1, hi + rng.randint(2, 10**12), 10**rng.randint(19, 60),
                -(10**rng.randint(10, 40))]
    span = max(1.0, abs(lo), abs(hi))
    vals = [lo - span * 10 ** rng.uniform(-6, 2), hi + span * 10 ** rng.uniform(-6, 2),
            hi * 10 ** rng.uniform(1, 300) if hi > 0 else 1e300, -1e308, 1e308,
            10 ** rng.randint(309, 500)]  # an int too large for a float
    if lo_open:
        vals.append(lo)
    elif lo > 0:
        vals.append(lo / 10)
    return vals


def bad_values(rng: random.Random, key: str) -> list[str]:
    """--set values that are bad for ``key`` whatever the rest of the scene."""
    check = _check_of(key)
    kind = type(check).__name__
    words, inner = OrWord.split(check)
    inner_kind = type(inner).__name__
    vals: list[str] = []
    garbage = [g for g in GARBAGE if g.strip() not in words]
    vals += rng.sample(garbage, 3) + [_unicode(rng, rng.randint(1, 12))]
    if kind == "Bool":   # "true" and "false" (and with spaces around them) are its values
        return [v for v in vals if v.strip() not in ("true", "false")] + ["True", "yes", "1", "on"]
    if kind == "Choice":
        opts = check.options
        vals += [rng.choice(opts).upper(), rng.choice(opts)[:-1], rng.choice(opts) + "x", "1", "0"]
        # a name whose case is no part of it (the colour maps') is valid in any case
        folded = {o.lower() for o in opts} if check.fold_case else set()
        return [v for v in vals if v.strip() not in opts and v.strip().lower() not in folded]
    if kind == "Lights":   # "" and "[]" are valid (no lights)
        vals = [v for v in vals if v.strip() not in ("", "[]")]
        return vals + ["position", "position 1,2", "direction 0,0,0", "position 1,2,3 direction 1,0,0",
                       "color 1,1,1", "position 1,2,3 intensity -1", "position 1,2,3 intensity nan",
                       "position 1,2,3 color 1,1", "pos 1,2,3", ";".join(["position 1,2,3"] * 4),
                       "position 1,2,3;x"]
    if kind == "Planes":   # "" and "[]" are valid (no planes)
        vals = [v for v in vals if v.strip() not in ("", "[]")]
        return vals + ["1,0,0", "0,0,0,1", "1,0,0,nan", "1,0,0,2e6", ";".join(["1,0,0,0"] * 5), "1,0,0,0;x"]
    if kind == "Stops":   # "" and "[]" are valid (no gradient)
        vals = [v for v in vals if v.strip() not in ("", "[]")]
        return vals + ["[[0, 1, 0, 0]]", "[[0.5, 1, 0, 0], [0.2, 0, 0, 1]]", "[[0, 1, 0, 0], [1, 2, 0, 0]]",
                       "[[0, 1, 0], [1, 0, 0, 1]]", "[[0, 1, 0, 0], [1, nan, 0, 0]]", "[[0, 1, 0, 0], [1"]
    for word in words:
        vals += [word.upper(), word + "s", f"[{word}]"]
    if inner_kind == "Real":
        vals += [rng.choice(NONFINITE)] + [_fmt(v) for v in rng.sample(_out_of_range(rng, inner.range, False), 3)]
        vals += ["1,2", "[]"]
    elif inner_kind == "Integer":
        vals += [rng.choice(NONFINITE), "2.5", "1e3", "7.0", "true"]
        vals += [_fmt(v) for v in rng.sample(_out_of_range(rng, inner.range, True), 3)]
    elif inner_kind == "Vector":
        n = max(inner.lengths)
        ok = inner.element.range
        mid = _fmt((max(ok.lo, -1.0) + min(ok.hi, 1.0)) / 2 + 0.25)
        bad_elements = [rng.choice(NONFINITE), rng.choice([g for g in garbage if "," not in g])]
        bad_elements += [_fmt(v) for v in rng.sample(_out_of_range(rng, ok, False), 2)]
        for bad in bad_elements:  # one bad element among good ones
            xs = [mid] * n
            xs[rng.randrange(n)] = bad
            vals.append(",".join(xs) if rng.random() < 0.7 else "[" + ", ".join(xs) + "]")
        wrong = rng.choice([k for k in range(8) if k not in inner.lengths])
        vals.append(",".join([mid] * wrong))
        if getattr(inner, "nonzero", False):
            vals.append(",".join(rng.choice(["0", "-0.0", "0.0", "0e0"]) for _ in range(n)))
    return vals


# ------------------------------------------------------------------ case generators

def set_cases(rng: random.Random) -> list[Case]:
    cases = []
    for key in KEYS:
        for i, v in enumerate(bad_values(rng, key)):
            text = f"{key}={v}"
            extra = []
            if key in ("image.width", "image.height") and rng.random() < 0.3:
                extra = [f"--{key.split('.')[1]}", v]  # the flag form
                text = None
            argv = ["render"] + (extra if text is None else ["--set", text])
            cases.append(Case(f"set-{key}-{i}", argv))
    # bad in context: each value fine alone, the combination not
    combos = [
        ["camera.position=1,2,3,4", "camera.target=1,2,3,4"],
        ["camera.position=0,0,0", "camera.target=0,0,1e-12"],
        ["camera.position=0,0,-3", "camera.target=0,0,0", "camera.up=0,0,1"],
        ["camera.position=0,0,-3", "camera.target=0,0,0,0", "camera.limbo=0,0,5,0"],
        ["camera.up=0,0,0,1"],
        ["march.near=2", "march.far=2"],
        ["march.near=5", "march.far=1e-3"],
        ["march.quality=final", "march.quality=best"],
    ]
    for i, sets in enumerate(combos):
        cases.append(Case(f"set-combo-{i}", ["render"] + [a for s in sets for a in ("--set", s)]))
    # malformed --set texts
    for i, text in enumerate(["", "=", " = ", "noequals", ".=1", "a.b.c=1", "fractal.=1", ".c=1",
                              "fractal..c=1", "FRACTAL.C=1", "fractal.c", "=1", "image.width==3",
                              "zork.x=1", " fractal . c =1", _unicode(rng, 6) + "=1",
                              "fractal.c\x00=1", "\udcff.x=1"]):
        cases.append(Case(f"set-malformed-{i}", ["render", "--set", text],
                          real_argv="\x00" not in text and "\udcff" not in text))
    return cases


def _toml_wrong_types(key: str) -> list[str]:
    check = _check_of(key)
    kind = type(getattr(check, "inner", check)).__name__
    vals = ['"x"', "true", "1979-05-27T07:32:00Z", "1979-05-27", "07:32:00", "{ a = 1 }",
            "[[1, 2], [3]]", '"1.0"', "[]"]
    if kind in ("Real", "Integer"):
        vals += ["nan", "+inf", "-inf", "[1.0]"]
    if kind == "Integer":
        vals += ["12.0", "1e3", str(2**63), "-" + str(2**63)]
    if kind == "Vector":
        vals += ["1.0", "[nan, 0, 0, 0]", "[0, inf, 0]", "[true, 1, 1]", '["0", 0, 0, 0]']
    if kind == "Choice":
        vals = [v for v in vals if v != "[]"] + ['"FIXED"', '""', '" de "']
    if kind == "Lights":   # [] is valid (no lights)
        vals = [v for v in vals if v != "[]"] + ["[{ color = [1, 1, 1] }]", "[[1, 2, 3]]",
                                                "[{ position = [1, 2, 3], direction = [1, 0, 0] }]",
                                                "[{ position = [1, 2, 3], x = 1 }]",
                                                "[{ direction = [0, 0, 0] }]", "[{ position = [nan, 0, 0] }]"]
    if kind == "Planes":   # [] is valid (no planes)
        vals = [v for v in vals if v != "[]"] + ["[[0, 0, 0, 1]]", "[1, 2, 3, 4]", "[[1, 0, 0, nan]]",
                                                "[[1, 0, 0, true]]"]
    if kind == "Stops":   # [] is valid (no gradient)
        vals = [v for v in vals if v != "[]"] + ["[[0, 1, 0, 0]]", "[[0.5, 1, 0, 0], [0.2, 0, 0, 1]]",
                                                "[[0, 1, 0, 0], [1, true, 0, 0]]", "[0, 1, 0, 0]"]
    if kind == "Bool":     # true is a boolean key's own type
        vals = [v for v in vals if v != "true"] + ["1", '"yes"']
    return vals


def _toml_out_of_range(rng: random.Random, key: str) -> list[str]:
    """TOML literals of the right type but outside the key's range."""
    inner = OrWord.split(_check_of(key))[1]
    kind = type(inner).__name__
    if kind == "Real":
        return [_toml_float(v) for v in rng.sample(_out_of_range(rng, inner.range, False), 2)]
    if kind == "Integer":
        return [str(v) for v in rng.sample(_out_of_range(rng, inner.range, True), 2)]
    if kind == "Vector":
        ok = inner.element.range
        n = max(inner.lengths)
        out = []
        for v in rng.sample(_out_of_range(rng, ok, False), 2):
            xs = ["0.25"] * n
            xs[rng.randrange(n)] = _toml_float(v)
            out.append("[" + ", ".join(xs) + "]")
        return out
    return []


def _toml_float(v) -> str:
    return str(v) if isinstance(v, int) else repr(float(v))


def scene_cases(rng: random.Random) -> list[Case]:
    cases = []
    for key in KEYS:
        section, _, name = key.partition(".")
        vals = _toml_wrong_types(key)
        for i, v in enumerate(rng.sample(vals, min(5, len(vals)))):
            cases.append(Case(f"toml-{key}-{i}", ["render", "s.toml"],
                              {"s.toml": f"[{section}]\n{name} = {v}\n".encode()}))
        for i, v in enumerate(_toml_out_of_range(rng, key)):
            cases.append(Case(f"toml-range-{key}-{i}", ["render", "s.toml"],
                              {"s.toml": f"[{section}]\n{name} = {v}\n".encode()}))
    structural = {
        "unknown-section": b"[zork]\nx = 1\n",
        "unknown-key": b"[fractal]\nzork = 1\n",
        "top-level-scalar": b"width = 3\n",
        "section-scalar": b"fractal = 3\n",
        "section-array": b"image = [1, 2]\n",
        "array-of-tables": b"[[image]]\nwidth = 3\n",
        "key-as-table": b"[fractal.c]\nx = 1\n",
        "sub-table": b"[image.width]\nvalue = 3\n",
        "dotted-unknown": b"fractal.c.x = 1\n",
        "duplicate-key": b"[image]\nwidth = 3\nwidth = 4\n",
        "duplicate-section": b"[image]\n[image]\n",
        "unterminated-string": b'[march]\nmethod = "de\n',
        "unterminated-array": b"[fractal]\nc = [1, 2,\n",
        "missing-value": b"[image]\nwidth =\n",
        "bare-word": b"[march]\nmethod = fixed\n",
        "not-utf8": b"[image]\nwidth = 8 # \xff\xfe\n",
        "latin1-key": b"[image]\nw\xe9dth = 8\n",
        "nul-byte": b"[image]\nwidth = 8\x00\n",
        "bom": b"\xef\xbb\xbf[image]\nwidth = 8\n",
        "deep-arrays": b"[fractal]\nc = " + b"[" * 5000 + b"]" * 5000 + b"\n",
        "deep-tables": b"[fractal]\nc = " + b"{a = " * 3000 + b"1" + b"}" * 3000 + b"\n",
        "deep-but-parsed": b"[fractal]\nc = [" + b"[" * 200 + b"]" * 200 + b", 0, 0, 0]\n",
        "huge-int": b"[image]\nwidth = " + b"9" * 5000 + b"\n",
        "huge-int-float-key": b"[march]\nepsilon = " + b"1" + b"0" * 400 + b"\n",
        "huge-string": b'[march]\nmethod = "' + b"x" * 100000 + b'"\n',
        "long-key": b"[fractal]\n" + b"k" * 10000 + b" = 1\n",
        "newline-key": b'[fractal]\n"a\\nb" = 1\n',
        "empty-key": b'[fractal]\n"" = 1\n',
        "over-1MiB": b"#" * (1 << 20) + b"\n",
        "random-bytes": bytes(rng.randrange(256) for _ in range(200)),
        "neg-zero-far": b"[march]\nfar = -0.0\n",
        "near-eq-far": b"[march]\nnear = 1.0\nfar = 1\n",
        "quality-int": b"[march]\nquality = 3\n",
    }
    for name, data in structural.items():
        cases.append(Case(f"toml-{name}", ["render", "s.toml"], {"s.toml": data}))
    # truncations of a valid scene that are no longer valid TOML
    valid = (b'[fractal]\nc = [-0.8, 0.4, 0.0, 0.0]\nmax_iter = 8\n[march]\nmethod = "fixed"\n'
             b"z_resolution = 250\n")
    for i, cut in enumerate(sorted(rng.sample(range(2, len(valid) - 1), 40))):
        head = valid[:cut]
        try:
            import tomllib
            tomllib.loads(head.decode())
            continue  # still valid: not a bad case
        except Exception:
            pass
        cases.append(Case(f"toml-cut-{i}", ["render", "s.toml"], {"s.toml": head}))
    # paths that are not a readable scene file
    paths = [("missing", ["render", "missing.toml"], {}),
             ("directory", ["render", "d"], {"d": None}),
             ("dev-zero", ["render", "/dev/zero"], {}),
             ("empty-name", ["render", ""], {}),
             ("nul-in-name", ["render", "a\x00b.toml"], {}),
             ("dir-slash", ["render", "s.toml/"], {"s.toml": b"[image]\n"}),
             ("file-as-dir", ["render", "s.toml/x.toml"], {"s.toml": b"[image]\n"}),
             ("name-too-long", ["render", "n" * 300 + ".toml"], {})]
    for name, argv, files in paths:
        cases.append(Case(f"path-{name}", argv, files, real_argv="\x00" not in argv[1]))
    return cases


def flag_cases(rng: random.Random) -> list[Case]:
    cases = []
    words = ["bogus", "widht", "out", "sett", "forcee", "x", "verbose", "zork", "colour", "dpi"]
    for i, w in enumerate(words + [_unicode(rng, 5) for _ in range(4)]):
        opt = "--" + w
        if any(o.startswith(opt) for o in OPTIONS):  # argparse takes unique prefixes
            continue
        cases.append(Case(f"flag-unknown-{i}", ["render", opt]))
        cases.append(Case(f"flag-unknown-v-{i}", ["render", opt + "=1", "--width", "8"]))
    for opt in ["--width", "--height", "--set", "--device", "-o", "--output"]:
        cases.append(Case(f"flag-missing-{opt}", ["render", opt]))
    for i, v in enumerate(["abc", "-1", "0", "1.5", "1e3", "", " ", "2147483648", "10" * 30, "8,6",
                           "[8]", "nan", "inf", "٨", "8px", "0x8", _unicode(rng, 4)]):
        flag = rng.choice(["--width", "--height"])
        cases.append(Case(f"flag-size-{i}", ["render", flag, v]))
    cases += [
        Case("flag-width-twice", ["render", "--width", "8", "--set", "image.width=8"]),
        Case("flag-height-twice", ["render", "--set", "image.height=6", "--height", "7"]),
        Case("flag-no-command", []),
        Case("flag-bad-command", ["rendr"]),
        Case("flag-bad-command-2", ["ren"]),
        Case("flag-command-case", ["RENDER"]),
        Case("flag-two-scenes", ["render", "a.toml", "b.toml"]),
        Case("flag-devices-extra", ["devices", "now"]),
        Case("flag-devices-option", ["devices", "--width", "3"]),
        Case("flag-force-value", ["render", "--force=yes"]),
        Case("flag-dash-only", ["render", "-"], {}),
        Case("flag-short-unknown", ["render", "-x"]),
        Case("flag-glued", ["render", "-o"]),
    ]
    return cases


def output_cases(rng: random.Random) -> list[Case]:
    cases = []
    for i, ext in enumerate([".jpg", ".PNGX", ".tga", "", ".", ".png.bak", ".exr~", ".pn", ".toml",
                             ".png ", ". png", "." + _unicode(rng, 3)]):
        cases.append(Case(f"out-ext-{i}", ["render", "-o", "out" + ext]))
    for i in range(6):
        n = rng.randint(252, 400)
        cases.append(Case(f"out-long-{i}", ["render", "-o", "n" * n + rng.choice([".png", ".exr"])]))
    for i in range(3):
        n = rng.randint(126, 200)  # two bytes each in UTF-8
        cases.append(Case(f"out-long-utf8-{i}", ["render", "-o", "é" * n + ".png"]))
    deep = "d/.." + "/d/.." * 799  # ~4000 bytes that resolve to "."
    cases += [
        Case("out-path-too-long", ["render", "-o", deep + "/" + "n" * 100 + ".png"], {"d": None}),
        Case("out-dir-too-long", ["render", "-o", deep + "/d/.." * 30 + "/x.png"], {"d": None}),
        Case("out-missing-dir", ["render", "-o", "nowhere/x.png"]),
        Case("out-missing-deep", ["render", "-o", "a/b/c/x.exr"]),
        Case("out-file-as-dir", ["render", "-o", "f/x.png"], {"f": b""}),
        Case("out-is-dir", ["render", "-o", "d.png"], {"d.png": None}),
        Case("out-trailing-slash", ["render", "-o", "x.png/"]),
        Case("out-empty", ["render", "-o", ""]),
        Case("out-only-ext", ["render", "-o", ".png"]),
        Case("out-nul", ["render", "-o", "a\x00.png"], real_argv=False),
        Case("out-surrogate-dir", ["render", "-o", "\udcff/x.png"], real_argv=False),
    ]
    if os.path.isdir("/proc/self"):
        cases.append(Case("out-proc", ["render", "-o", "/proc/x.png"]))
    if os.geteuid() != 0:  # root may write anywhere
        cases.append(Case("out-read-only", ["render", "-o", "ro/x.png"], {"ro": None}))
    return cases


def command_cases(rng: random.Random) -> list[Case]:
    """mesh and explore: their own flags, outputs, folders and ports, and --set values."""
    cases = []
    numbers = ["abc", "", " ", "1.5", "1e3", "nan", "inf", "-1", "٨", "0x10", "8,8", "[8]", "10" * 30,
               _unicode(rng, 4)]
    for i, v in enumerate(numbers + ["7", "2049", "0"]):
        cases.append(Case(f"cmd-mesh-resolution-{i}", ["mesh", "--resolution", v]))
    for i, v in enumerate(numbers[:8] + ["1001", "-5"]):
        cases.append(Case(f"cmd-mesh-smooth-{i}", ["mesh", "--smooth", v]))
    for i, v in enumerate(["0", "-0.5", "1.5", "nan", "inf", "", "half", "1e-400", "٠.٥"]):
        cases.append(Case(f"cmd-mesh-decimate-{i}", ["mesh", "--decimate", v]))
    for i, ext in enumerate([".png", ".exr", ".jpg", "", ".stl~", ".STLX", ".gltf", ". stl", "." + _unicode(rng, 3)]):
        cases.append(Case(f"cmd-mesh-out-{i}", ["mesh", "-o", "m" + ext]))
    cases += [
        Case("cmd-mesh-out-missing-dir", ["mesh", "-o", "nowhere/m.stl"]),
        Case("cmd-mesh-out-is-dir", ["mesh", "-o", "d.stl"], {"d.stl": None}),
        Case("cmd-mesh-out-nul", ["mesh", "-o", "m\x00.stl"], real_argv=False),
        Case("cmd-mesh-scene-missing", ["mesh", "missing.toml"]),
        Case("cmd-mesh-scene-dir", ["mesh", "d.toml"], {"d.toml": None}),
        Case("cmd-mesh-slice-outside", ["mesh", "--set", "slice.distance=1e5"]),
        Case("cmd-mesh-unknown-flag", ["mesh", "--resolutoin", "8"]),
        Case("cmd-mesh-missing-value", ["mesh", "--resolution"]),
        Case("cmd-mesh-two-scenes", ["mesh", "a.toml", "b.toml"]),
        Case("cmd-mesh-walls-too-fine", ["mesh", "--walls", "--resolution", "2048"]),
        Case("cmd-mesh-walls-value", ["mesh", "--walls=yes"]),
    ]
    for i, v in enumerate(numbers + ["65536", "99999", "-0"][:-1]):
        cases.append(Case(f"cmd-explore-port-{i}", ["explore", "--no-browser", "--port", v]))
    cases += [
        Case("cmd-explore-folder-missing", ["explore", "--no-browser", "--folder", "nowhere"]),
        Case("cmd-explore-folder-file", ["explore", "--no-browser", "--folder", "f"], {"f": b"x"}),
        Case("cmd-explore-folder-nul", ["explore", "--no-browser", "--folder", "a\x00b"], real_argv=False),
        Case("cmd-explore-scene-missing", ["explore", "--no-browser", "missing.toml"]),
        Case("cmd-explore-scene-not-toml", ["explore", "--no-browser", "s.toml"], {"s.toml": b"[fractal\n"}),
        Case("cmd-explore-image-not-image", ["explore", "--no-browser", "i.png"], {"i.png": b"not a png"}),
        Case("cmd-explore-unknown-flag", ["explore", "--browser"]),
        Case("cmd-explore-missing-value", ["explore", "--port"]),
    ]
    for i in range(24):   # --set's generated bad values through both commands
        key = rng.choice(KEYS)
        value = rng.choice(bad_values(rng, key))
        command = ["mesh"] if i % 2 else ["explore", "--no-browser"]
        cases.append(Case(f"cmd-set-{i}", command + ["--set", f"{key}={value}"]))
    return cases


def all_cases() -> list[Case]:
    rng = random.Random(SEED)
    cases = set_cases(rng) + scene_cases(rng) + flag_cases(rng) + output_cases(rng)
    cases += command_cases(random.Random(SEED + 1))
    ids = [c.id for c in cases]
    assert len(ids) == len(set(ids)), "case ids must be unique"
    return cases


CASES = all_cases()


# ------------------------------------------------------------------ running a case

def _make(root: Path, files: dict[str, bytes | None]) -> None:
    for name, data in files.items():
        path = root / name
        if data is None:
            path.mkdir(mode=0o555 if name == "ro" else 0o777)
        else:
            path.write_bytes(data)


def _listing(root: Path) -> list[str]:
    return sorted(os.path.relpath(os.path.join(d, f), root)
                  for d, dirs, files in os.walk(root) for f in files + dirs)


def _render_reached(*args, **kwargs):
    raise AssertionError("bad input reached the render")


@pytest.fixture
def no_render(monkeypatch: pytest.MonkeyPatch) -> None:
    mod = types.ModuleType("pyjulia4d.opencl.executor")
    mod.render = _render_reached  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "pyjulia4d.opencl.executor", mod)
    monkeypatch.setattr(pyjulia4d, "render", mod, raising=False)
    monkeypatch.setattr(cli, "select_device", lambda spec: "fake device")
    from pyjulia4d.app import mesh
    from pyjulia4d.app.explore import run
    monkeypatch.setattr(mesh, "build_mesh", _render_reached)
    monkeypatch.setattr(run, "explore", _render_reached)


def _assert_one_error_line(err: str) -> None:
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("pyjulia4d: error: "), err
    assert "Traceback" not in err


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_bad_input_in_process(case: Case, tmp_path, monkeypatch, capsys, no_render) -> None:
    monkeypatch.chdir(tmp_path)
    _make(tmp_path, case.files)
    before = _listing(tmp_path)
    handlers = {s: signal.getsignal(s) for s in (signal.SIGTERM, signal.SIGHUP)}
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a numpy overflow warning would be a failure
        status = cli.main(case.argv)
    out, err = capsys.readouterr()
    assert status == 2, err
    _assert_one_error_line(err)
    assert out == ""
    assert _listing(tmp_path) == before
    assert {s: signal.getsignal(s) for s in handlers} == handlers  # handlers restored


def test_case_count() -> None:
    """The generator makes a few hundred cases, every group represented."""
    groups = {c.id.split("-")[0] for c in CASES}
    assert groups == {"set", "toml", "path", "flag", "out", "cmd"}
    assert 300 <= len(CASES) <= 2000, len(CASES)


@pytest.mark.parametrize("spec", ["99:99", "0:99", "-1:0", "x:y", "", ":", "no-such-device-4f2a",
                                  "🙂"])
def test_bad_device(spec: str, tmp_path, monkeypatch, capsys) -> None:
    """A bad --device is refused by the real device selection, before any render."""
    mod = types.ModuleType("pyjulia4d.opencl.executor")
    mod.render = _render_reached  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "pyjulia4d.opencl.executor", mod)
    monkeypatch.chdir(tmp_path)
    assert cli.main(["render", "--device", spec, "--width", "4", "--height", "3"]) == 2
    out, err = capsys.readouterr()
    _assert_one_error_line(err)
    assert out == "" and _listing(tmp_path) == []


# ------------------------------------------------------------------ real processes

def _env() -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [PKG_ROOT, env.get("PYTHONPATH")]))
    return env


def _run(args: list[str], cwd: Path, timeout: float = 60) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "pyjulia4d", *args], cwd=cwd, env=_env(),
                          capture_output=True, text=True, timeout=timeout)


def _subprocess_cases() -> list[Case]:
    rng = random.Random(SEED + 1)
    ok = [c for c in CASES if c.real_argv]
    picked = {c.id: c for c in rng.sample(ok, 6)}
    for name in ("flag-unknown-0", "flag-missing---width", "toml-deep-arrays", "path-dev-zero",
                 "out-long-0", "set-malformed-1", "toml-not-utf8"):
        picked[name] = next(c for c in CASES if c.id == name)
    return list(picked.values())


SUBPROCESS_CASES = _subprocess_cases()


@pytest.mark.parametrize("case", SUBPROCESS_CASES, ids=[c.id for c in SUBPROCESS_CASES])
def test_bad_input_through_the_terminal(case: Case, tmp_path) -> None:
    _make(tmp_path, case.files)
    before = _listing(tmp_path)
    p = _run(case.argv, tmp_path)
    assert p.returncode == 2, p.stderr
    _assert_one_error_line(p.stderr)
    assert p.stdout == "" and _listing(tmp_path) == before


HUGE = [["--width", "1000000000", "--height", "1", "--force"],
        ["--width", "100000", "--height", "100000", "--force"],
        ["--width", "46341", "--height", "46341", "--force"],
        ["--width", "65536", "--height", "65536"]]


@pytest.mark.parametrize("size", HUGE, ids=["x".join(s[1:4:2]) for s in HUGE])
def test_huge_images_refused(size: list[str], tmp_path) -> None:
    """Sizes whose image no host of this kind can hold (any size that fits renders, in
    tiles): refused in one line with a memory estimate, --force or not, nothing written."""
    p = _run(["render", "-o", "big.png", *size], tmp_path, timeout=60)
    assert p.returncode == 2, p.stderr
    _assert_one_error_line(p.stderr)
    assert _listing(tmp_path) == []


# ------------------------------------------------------------------ signals

def _signal_and_check(proc, sig: int, err_path: Path, out: Path) -> None:
    """Send ``sig``; the CLI must exit 128 + sig with its one line and leave ``out`` empty."""
    proc.send_signal(sig)
    proc.wait(timeout=30)
    text = err_path.read_text()
    assert proc.returncode == 128 + sig, text
    assert _last_line(text) == f"pyjulia4d: terminated by {signal.Signals(sig).name}", text
    assert "Traceback" not in text
    assert list(out.iterdir()) == []


def _default_signals() -> None:
    """In the child: SIGTERM and SIGHUP at their default action, as a terminal gives them.
    A suite run under nohup (or a CI runner that ignores SIGHUP) would otherwise hand the
    child an ignored SIGHUP, which the CLI rightly leaves ignored."""
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGHUP, signal.SIG_DFL)


def _wait_for(predicate, timeout: float) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if predicate():
            return True
        time.sleep(0.05)
    return False


def _last_line(text: str) -> str:
    # a progress bar ends in carriage returns, not newlines
    return text.rstrip("\n").split("\n")[-1].split("\r")[-1]


def _slow_render_args() -> list[str]:
    """A render of tens of seconds in small tiles (so the signal is seen within a tile)."""
    from pyjulia4d.opencl.devices import device_type, select_device
    dev = select_device(os.environ.get("PYJULIA4D_DEVICE") or None)
    if device_type(dev) == "GPU":  # ~300 x faster: full-width tiles, 20 x the samples
        return ["--width", "1024", "--height", "16384", "--set", "march.method=fixed",
                "--set", "march.z_resolution=20000"]
    # 196 tiles of 16 x 512 pixels, ~40 s in all on 2 CPU cores with packets of rays (the
    # signal comes after the first progress line, at 10 s)
    return ["--width", "16", "--height", "100000", "--set", "march.method=fixed",
            "--set", "march.z_resolution=50000"]


# SIGHUP runs the same handler as SIGTERM (app/cli.py): its real render is in the slow run
@pytest.mark.parametrize("sig", [signal.SIGTERM, pytest.param(signal.SIGHUP, marks=pytest.mark.slow)],
                         ids=["SIGTERM", "SIGHUP"])
def test_signal_during_a_real_render(sig: int, tmp_path) -> None:
    """python -m pyjulia4d, a slow render under way (its progress bar showing): the signal
    ends it with 128 + the signal number and nothing in the output directory."""
    out = tmp_path / "out"
    out.mkdir()
    err_path = tmp_path / "stderr.txt"
    args = ["render", "-o", "out/julia.png", *_slow_render_args()]
    if os.environ.get("PYJULIA4D_DEVICE"):
        args += ["--device", os.environ["PYJULIA4D_DEVICE"]]
    with open(err_path, "w") as err:
        proc = subprocess.Popen([sys.executable, "-m", "pyjulia4d", *args], cwd=tmp_path, env=_env(),
                                stdout=subprocess.PIPE, stderr=err, text=True,
                                preexec_fn=_default_signals)
    try:
        # stderr is a file, not a terminal: progress comes as whole lines ("render: N% ..."),
        # the first once the render has run for 3 s, and never a carriage return
        assert _wait_for(lambda: b"render: " in err_path.read_bytes(), 60), err_path.read_text()
        assert b"\r" not in err_path.read_bytes()
        assert proc.poll() is None, "the render finished before the signal"
        _signal_and_check(proc, sig, err_path, out)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


# A CLI whose render is a stand-in and whose PNG writer pauses once the temp file holds the
# image, so that a signal is sure to hit the write (or, with "render", the render).
_STAND_IN = r"""
import sys, time, types
import numpy as np
from PIL import Image
from pyjulia4d.app import cli

phase = sys.argv[1]

class Result:
    def __init__(self, h, w):
        self.color = np.full((h, w, 3), 0.5, np.float32)
        self.alpha = np.ones((h, w), np.float32)
        self.device_name, self.seconds, self.hit_fraction, self.capped = "stand-in", 0.1, 0.5, 0
        self.guards, self.fell_back = {}, ""

    def report(self, stated_p99=None):
        return {}, ""

def render(scene, device=None, progress=False, force=False, outputs=None, store=None, fallback=None):
    if phase == "render":
        print("rendering", file=sys.stderr, flush=True)
        time.sleep(60)
    return Result(scene.image.height, scene.image.width)

module = types.ModuleType("pyjulia4d.opencl.executor")
module.render = render
sys.modules["pyjulia4d.opencl.executor"] = module
cli.select_device = lambda spec: None
save = Image.Image.save

def slow_save(self, fp, *args, **kwargs):
    save(self, fp, *args, **kwargs)
    print("writing", file=sys.stderr, flush=True)
    time.sleep(60)

Image.Image.save = slow_save
sys.exit(cli.main(sys.argv[2:]))
"""


@pytest.mark.parametrize("phase", ["write", "render"])
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP], ids=["SIGTERM", "SIGHUP"])
def test_signal_during_the_write(sig: int, phase: str, tmp_path) -> None:
    """The signal while the temp file holds the image (or while rendering): the temp file
    is removed, status 128 + the signal number, the directory is left empty."""
    out = tmp_path / "out"
    out.mkdir()
    err_path = tmp_path / "stderr.txt"
    with open(err_path, "w") as err:
        proc = subprocess.Popen([sys.executable, "-c", _STAND_IN, phase, "render", "-o", "out/julia.png",
                                 "--width", "64", "--height", "48"],
                                cwd=tmp_path, env=_env(), stdout=subprocess.PIPE, stderr=err, text=True,
                                preexec_fn=_default_signals)
    try:
        word = "writing" if phase == "write" else "rendering"
        assert _wait_for(lambda: word in err_path.read_text(), 30), err_path.read_text()
        if phase == "write":  # the write itself is under way: its temp file is there
            [tmp] = list(out.iterdir())
            assert tmp.name.startswith(".julia.") and tmp.suffix == ".png" and tmp.stat().st_size > 0
        _signal_and_check(proc, sig, err_path, out)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_a_signal_dropped_in_a_finaliser_still_stops_the_render() -> None:
    """Python prints and drops an exception raised inside a finaliser: a SIGTERM whose
    handler runs there would leave the render running, deaf to signals.  The handler also
    asks pyjulia4d.pipeline.progress for a stop, raised at the next progress update."""
    from pyjulia4d.app import cli
    from pyjulia4d.pipeline import progress

    class Finalised:
        def __del__(self):
            cli._raise_terminated(signal.SIGTERM, None)

    old = {s: signal.getsignal(s) for s in cli._SIGNALS}
    try:
        with cli._signals_raise():
            Finalised()   # the handler's Terminated is dropped here, as in a real finaliser
            bar = progress.Progress(10, "render", "pixel", enabled=False)
            with pytest.raises(cli.Terminated):
                bar.update(1)
        bar.update(1)     # the stop ends with the block
    finally:
        for s, h in old.items():
            signal.signal(s, h)
