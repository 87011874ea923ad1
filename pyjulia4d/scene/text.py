"""Scene text in and out: reading a scene file's TOML (bounded, UTF-8), ``--set
section.key=VALUE`` overrides typed for their key, and the TOML emitter of resolved scenes.
No scene model here: the key table (scene.model.checks) is passed in."""
from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any, Mapping

from pyjulia4d.files import path_text
from pyjulia4d.scene.checks import SceneError, scalar, show, show_key, unknown_key

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

MAX_SCENE_BYTES = 1 << 20  # scene files larger than this are refused unread


def override_key(text: str) -> str:
    """The dotted key of an override ``"section.key=VALUE"`` (stripped; not checked)."""
    return text.partition("=")[0].strip()


def override_list(overrides: Any) -> list:
    """Overrides given from Python as a list (one string is one override, not its letters);
    SceneError where they cannot be iterated (each is checked by parse_override)."""
    if isinstance(overrides, str):
        return [overrides]
    try:
        return list(overrides)
    except Exception:   # not iterable, or an object whose own iteration fails
        raise SceneError("overrides", f"expected a list of SECTION.KEY=VALUE texts, got {show(overrides)}") from None


def parse_override(text: str, checks: Mapping[str, Mapping[str, Any]]) -> tuple[str, str, Any]:
    """``"section.key=VALUE"`` -> (section, key, value typed for that key), the keys and their
    checkers from ``checks`` (scene.model.checks)."""
    if not isinstance(text, str):
        raise SceneError("--set", f"expected SECTION.KEY=VALUE, got {show(text)}")
    if "=" not in text:
        shown = text.strip()
        if shown and show_key(shown) == shown:
            raise SceneError(shown, "malformed override, expected SECTION.KEY=VALUE")
        raise SceneError("--set", f"malformed override {show(text)}, expected SECTION.KEY=VALUE")
    dotted = override_key(text)
    raw = text.partition("=")[2]
    if not dotted:
        raise SceneError("--set", f"missing key in {show(text)}, expected SECTION.KEY=VALUE")
    section, _, key = dotted.partition(".")
    if section not in checks or key not in checks[section]:
        raise unknown_key(dotted, checks)
    s = raw.strip()
    if checks[section][key].verbatim:
        return section, key, s
    if s.startswith("[") and s.endswith("]"):
        return section, key, [scalar(p) for p in s[1:-1].split(",")]
    if "," in s:
        return section, key, [scalar(p) for p in s.split(",")]
    return section, key, scalar(s)


def toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return repr(v)  # shortest round-tripping form, valid TOML for finite floats
    if isinstance(v, str):
        return json.dumps(v)  # JSON string escapes are a subset of TOML's
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if hasattr(v, "to_dict"):   # one of shading.lights (scene.model.Light)
        v = v.to_dict()
    if isinstance(v, Mapping):   # an inline table (shading.lights)
        return "{ " + ", ".join(f"{k} = {toml_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(f"cannot write {v!r} as TOML")


def read_scene_table(path: str | Path) -> dict[str, Any]:
    """The TOML table of a scene file: a bounded read (/dev/zero or a stray multi-gigabyte
    file is refused, not loaded), UTF-8, every failure one SceneError naming the path
    (Scene.from_toml, keyframes.load)."""
    raw = path_text(path, lambda got: SceneError("scene", f"expected the path of a scene file, {got}"))
    where = show_key(raw)
    try:
        with open(raw, "rb") as f:
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
