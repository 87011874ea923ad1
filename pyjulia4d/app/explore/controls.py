"""The explorer's controls: which scene keys the page (and the notebook) offers, how each is
drawn, and the two conversions between a scene and its controls' values.

Every control is a plain form element named by its scene key; a vector's components are
``KEY[i]`` (``fractal.c[0]``).  Values travel as text, as a form holds them, and are read the
way ``--set`` reads them (scene/text.py's scalar), then checked by the scene itself: a bad
value is the scene's own one-line SceneError, naming ``KEY[i]``.  A slider beside a number
field is only a helper that types into it: its range is a comfortable span, not the key's
valid range (``pyjulia4d keys`` lists those)."""
from __future__ import annotations

import html
import re
from dataclasses import dataclass
from typing import Any, Mapping

from pyjulia4d.fractal.registry import ALGEBRAS, FUNCTIONS_OF, KINDS
from pyjulia4d.scene.checks import Choice, SceneError, scalar, show, show_key
from pyjulia4d.scene.model import Scene
from pyjulia4d.scene.ranges import CHECKS, valid_range
from pyjulia4d.scene.text import parse_override, toml_value
from pyjulia4d.scene.quality import QUALITIES

# At most this many values in one change, and this long each (a form has about 60).
MAX_VALUES = 200
MAX_VALUE_CHARS = 100
MAX_TEXT_CHARS = 1000   # a text control's (16 colour stops, a long path)


@dataclass(frozen=True)
class Control:
    """One scene key on the page: ``size`` components (0: a scalar), a ``widget`` ("number",
    "select", "checkbox", or "text": the value as typed, such as a TOML array of colour stops
    or a file's path), and for numbers a slider's span and step."""

    key: str
    label: str
    size: int = 0
    widget: str = "number"
    lo: float = 0.0
    hi: float = 1.0
    step: float = 0.01
    slider: bool = True

    def names(self) -> list[str]:
        """The form element names: the key, or ``key[i]`` per component."""
        return [self.key] if self.size == 0 else [f"{self.key}[{i}]" for i in range(self.size)]

    def choices(self) -> tuple[str, ...]:
        check = CHECKS[self.key.split(".")[0]][self.key.split(".")[1]]
        return check.options if isinstance(check, Choice) else ()


# The page's groups of controls, in order (the issue of what an explorer must offer: c, the
# iteration, algebra, function, exponent and kind; the slice; the camera; the quality preset
# and the basic shading keys; the image).
GROUPS: tuple[tuple[str, tuple[Control, ...]], ...] = (
    ("Fractal", (
        Control("fractal.c", "c", 4, lo=-2.0, hi=2.0, step=0.001),
        Control("fractal.max_iter", "iterations", lo=1, hi=64, step=1),
        Control("fractal.algebra", "algebra", widget="select"),
        Control("fractal.function", "function", widget="select"),
        Control("fractal.exponent", "exponent (pwr)", 2, lo=-8.0, hi=8.0, step=0.01),
        Control("fractal.kind", "kind", widget="select"),
        Control("fractal.theta", "theta (degrees)", lo=-180.0, hi=180.0, step=0.5),
    )),
    ("Slice", (
        Control("slice.normal", "normal", 4, lo=-1.0, hi=1.0, step=0.01),
        Control("slice.distance", "distance", lo=-2.0, hi=2.0, step=0.001),
        Control("slice.turn", "turn (degrees: xy, xz, xw, yz, yw, zw)", 6, lo=-180.0, hi=180.0, step=0.5),
    )),
    ("Camera", (
        Control("camera.position", "position", 4, slider=False, step=0.001),
        Control("camera.target", "target", 4, slider=False, step=0.001),
        Control("camera.up", "up", 4, slider=False, step=0.001),
        Control("camera.limbo", "limbo", 4, slider=False, step=0.001),
        Control("camera.fov", "field of view", lo=5.0, hi=120.0, step=0.5),
    )),
    ("Quality", (
        Control("march.quality", "quality", widget="select"),
        Control("image.width", "width", slider=False, step=1),
        Control("image.height", "height", slider=False, step=1),
        Control("image.samples", "samples per pixel", lo=1, hi=16, step=1),
        Control("render.float", "precision", widget="select"),
    )),
    ("Shading", (
        Control("shading.color", "colour (linear)", 3, lo=0.0, hi=1.0, step=0.01),
        Control("shading.ambient", "ambient", lo=0.0, hi=1.0),
        Control("shading.diffuse", "diffuse", lo=0.0, hi=1.5),
        Control("shading.specular", "specular", lo=0.0, hi=1.5),
        Control("shading.shininess", "shininess", lo=1.0, hi=200.0, step=1.0),
        Control("shading.shadow", "shadow", widget="select"),
        Control("shading.shadow_softness", "shadow softness", lo=1.0, hi=64.0, step=0.5),
        Control("shading.ao", "occlusion", lo=0.0, hi=1.0),
        Control("shading.ao_distance", "occlusion distance", lo=0.01, hi=0.5, step=0.005),
        Control("shading.fog", "fog", lo=0.0, hi=5.0),
        Control("shading.coloring", "colouring", widget="select"),
        Control("shading.colormap", "colour map", widget="select"),
        Control("shading.color_offset", "colour offset", lo=-1.0, hi=1.0, step=0.01),
        Control("shading.color_scale", "colour scale", lo=-8.0, hi=8.0, step=0.05),
        Control("shading.color_repeat", "colour repeat", widget="select"),
        Control("shading.gradient", "colour ramp [[pos, r, g, b], ...] (sRGB)", widget="text", slider=False),
        Control("shading.trap", "orbit trap", 4, lo=-2.0, hi=2.0, step=0.01),
        Control("shading.reflection", "reflection", lo=0.0, hi=1.0),
        Control("shading.background", "background (linear)", 3, lo=0.0, hi=1.0, step=0.01),
        Control("shading.background_gradient", "background gradient, top to bottom", widget="text", slider=False),
        Control("shading.background_image", "background image (a path)", widget="text", slider=False),
    )),
    ("Light", (
        Control("shading.light", "key light (x, y, z, w or eye)", widget="text", slider=False),
        Control("shading.light_color", "key light colour", 3, lo=0.0, hi=2.0, step=0.01),
        Control("shading.light_radius", "key light radius (path)", lo=0.0, hi=1.0, step=0.01),
        Control("shading.lights", "more lights (TOML)", widget="text", slider=False),
        Control("shading.light_space", "lights move with", widget="select"),
        Control("shading.sky", "sky (linear)", 3, lo=0.0, hi=2.0, step=0.01),
        Control("shading.integrator", "integrator", widget="select"),
        Control("shading.environment", "environment (sky, uniform or a path)", widget="text", slider=False),
        Control("shading.bounces", "bounces (path)", lo=1, hi=8, step=1),
        Control("shading.roughness", "roughness (path)", lo=0.0, hi=1.0),
        Control("shading.metallic", "metallic (path)", lo=0.0, hi=1.0),
        Control("shading.emission", "glow (path)", lo=0.0, hi=5.0),
        Control("camera.aperture", "lens aperture (path)", lo=0.0, hi=0.3, step=0.001),
        Control("image.exposure", "exposure (stops)", lo=-4.0, hi=4.0, step=0.1),
        Control("image.tonemap", "tone map", widget="select"),
    )),
)

CONTROLS: dict[str, Control] = {c.key: c for _, group in GROUPS for c in group}
_NAME = re.compile(r"^([a-z_]+\.[a-z_0-9]+)(?:\[(\d)\])?$")


def form_values(scene: Scene) -> dict[str, str]:
    """Every control's value for ``scene``, as the form shows it."""
    data = scene.to_dict()
    out = {}
    for key, c in CONTROLS.items():
        section, name = key.split(".")
        value = data[section].get(name, getattr(getattr(scene, section), name))
        if c.size:
            out.update({f"{key}[{i}]": _text(v) for i, v in enumerate(value)})
        else:
            out[key] = _text(value)
    return out


def _text(v: Any) -> str:
    if isinstance(v, (list, tuple)):   # a text control's vector, colour stops or lights: TOML, as --set takes them
        return toml_value([float(x) if isinstance(x, int) and not isinstance(x, bool) else x for x in v])
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v)
    return str(v)


def apply_values(scene: Scene, values: Any) -> Scene:
    """``scene`` with the form's ``{name: text}`` values set, checked as a scene file's are.
    One SceneError, naming the control, for a value the scene refuses or a name that is no
    control; the scene is unchanged then."""
    if not isinstance(values, Mapping):
        raise SceneError("values", f"expected an object of control names and values, got {show(values)}")
    if len(values) > MAX_VALUES:
        raise SceneError("values", f"{len(values)} values in one change; at most {MAX_VALUES}")
    data = scene.to_dict()
    given: dict[str, str] = {}
    for name, text in values.items():
        m = _NAME.match(name) if isinstance(name, str) else None
        control = CONTROLS.get(m.group(1)) if m else None
        if control is None or (m.group(2) is None) != (control.size == 0) or \
                (m.group(2) is not None and int(m.group(2)) >= control.size):
            raise SceneError(show_key(str(name)), "no such control")
        if not isinstance(text, str):
            raise SceneError(name, f"expected the field's text, got {show(text)}")
        most = MAX_TEXT_CHARS if control.widget == "text" else MAX_VALUE_CHARS
        if len(text) > most:
            raise SceneError(name, f"longer than {most} characters")
        section, key = control.key.split(".")
        # a text control's value is read as --set reads it (a vector, a word, TOML stops, a path)
        value = parse_override(f"{control.key}={text}", CHECKS)[2] if control.widget == "text" else scalar(text)
        if control.widget == "checkbox":
            value = {"true": True, "false": False}.get(text.strip(), value)
        if m.group(2) is not None:
            i = int(m.group(2))
            vector = list(data[section].get(key, getattr(getattr(scene, section), key)))
            vector[i] = value
            value = vector
        if section == "march" and key == "quality":
            data["march"] = {"quality": value}   # a preset sets its march keys (Scene.from_dict)
        else:
            data[section][key] = value
        given[control.key] = name
    if "camera.position" in given or "camera.target" in given:
        data["camera"]["fit"] = False   # a camera placed by hand is not framed again
    try:
        return Scene.from_dict(data)
    except SceneError as e:
        raise SceneError(_component_key(e, given), e.reason) from None


def _component_key(e: SceneError, given: Mapping[str, str]) -> str:
    """The control behind a SceneError: ``fractal.c: element 1: ...`` -> ``fractal.c[1]``."""
    m = re.match(r"element (\d+): (.*)$", e.reason)
    if e.key in given and m and e.key in CONTROLS and CONTROLS[e.key].size:
        e.reason = m.group(2)
        return f"{e.key}[{m.group(1)}]"
    return e.key


def form_html(scene: Scene) -> str:
    """The form's fieldsets for ``scene``: every control a named element, its valid range in
    its title; a number with a slider span gets a slider (``data-for`` its field) beside it."""
    values = form_values(scene)
    parts = []
    for title, group in GROUPS:
        rows = []
        for c in group:
            tip = html.escape(f"{c.key}: {valid_range(c.key)}", quote=True)
            fields = []
            for name in c.names():
                esc = html.escape(name, quote=True)
                if c.widget == "select":
                    choices = options(c, scene)
                    opts = "".join(f'<option value="{html.escape(o, quote=True)}"'
                                   f'{" selected" if o == values[name] else ""}>{html.escape(o)}</option>'
                                   for o in choices)
                    fields.append(f'<select name="{esc}" id="{esc}" title="{tip}">{opts}</select>')
                    continue
                if c.widget == "text":
                    fields.append(f'<input type="text" name="{esc}" id="{esc}" spellcheck="false" '
                                  f'value="{html.escape(values[name], quote=True)}" title="{tip}">')
                    continue
                fields.append(f'<input type="number" name="{esc}" id="{esc}" step="any" '
                              f'value="{html.escape(values[name], quote=True)}" title="{tip}">')
                if c.slider:
                    fields.append(f'<input type="range" data-for="{esc}" min="{c.lo}" max="{c.hi}" '
                                  f'step="{c.step}" value="{html.escape(values[name], quote=True)}" '
                                  f'aria-label="{esc} slider">')
            cls = "fields" if c.slider or c.widget != "number" else "fields plain"
            rows.append(f'<div class="row"><label for="{html.escape(c.names()[0], quote=True)}">'
                        f'{html.escape(c.label)}</label><span class="{cls}">{"".join(fields)}</span></div>')
        parts.append(f'<fieldset><legend>{html.escape(title)}</legend>{"".join(rows)}</fieldset>')
    return "\n".join(parts)


def options(c: Control, scene: Scene) -> tuple[str, ...]:
    """A select's choices: the functions of the scene's algebra for the function (the page
    changes them with the algebra), the key's own choices otherwise."""
    if c.key == "fractal.algebra":
        return tuple(ALGEBRAS)
    if c.key == "fractal.kind":
        return tuple(KINDS)
    if c.key == "march.quality":
        return tuple(QUALITIES)
    if c.key == "fractal.function":
        return tuple(FUNCTIONS_OF[scene.fractal.algebra])
    return c.choices()
