"""The scene file an import writes: TOML with the mapping's notes as comments, written
atomically beside nothing it must not overwrite; and import_pov, the whole import."""
from __future__ import annotations

import os
import stat
from pathlib import Path

import numpy as np

from pyjulia4d.interop.povray.mapping import Imported, convert
from pyjulia4d.interop.povray.reader import DEFAULT_SIZE, MAX_POV_BYTES, SceneReader
from pyjulia4d.interop.povray.tokens import PovError, tokenize
from pyjulia4d.scene.checks import SceneError
from pyjulia4d.scene.model import Scene
from pyjulia4d.scene.text import toml_value  # one TOML emitter for scenes and imports

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
           "# by `pyjulia4d import-pov` (pyjulia4d/interop/povray/mapping.py maps it key by key)."]
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
    from pyjulia4d.files import path_text, shown_path

    raw_path = path_text(path, lambda got: PovError(f"POV-Ray scene path: expected {got}"))
    where = shown_path(raw_path)
    try:
        with open(raw_path, "rb") as f:
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
    from pyjulia4d.files import path_text, shown_path

    for key, v in (("width", width), ("height", height)):   # checked before any arithmetic on them
        if v is not None:
            Scene.from_dict({"image": {key: v}})
    path = path_text(path, lambda got: PovError(f"POV-Ray scene path: expected {got}"))
    w, h = DEFAULT_SIZE if width is None and height is None else (width, height)
    if w is None or h is None:  # one given: the other keeps pyjulia4d's aspect ratio
        w = w if w is not None else max(1, round(h * DEFAULT_SIZE[0] / DEFAULT_SIZE[1]))
        h = h if h is not None else max(1, round(w * DEFAULT_SIZE[1] / DEFAULT_SIZE[0]))
    Scene.from_dict({"image": {"width": w, "height": h}})  # the same range errors as render's
    where = shown_path(os.fspath(path))
    text = read_pov(path)
    try:
        with np.errstate(all="ignore"):  # an overflow becomes a non-finite value the scene refuses
            reader = SceneReader(tokenize(text, where), where, w, h)
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
    from pyjulia4d.app.output import OutputError, check_directory
    from pyjulia4d.files import NAME_MAX, path_limit, path_text, quoted_path, shown_path

    raw = path_text(path, lambda got: OutputError(f"scene file path: expected {got}"))
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
    from pyjulia4d.app.output import write_file

    write_file(path, text)
