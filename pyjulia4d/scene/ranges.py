"""Every scene key's checker and valid range, declared once (CHECKS): what a scene file, a
--set override and a scene built in Python are each checked by (scene/model.py's sections
call check_section when they are built), and what ``pyjulia4d keys`` and docs/scene-keys.md
show (valid_range; tests/interfaces/test_scene.py holds the page to it).  A light of
shading.lights is checked here too, as its table is."""
from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any

from pyjulia4d.fractal.registry import ALGEBRAS, FUNCTIONS, KINDS
from pyjulia4d.scene.checks import (COORD, INT_MAX, Bool, Checker, Choice, ImageFile, Integer, Lights, OrWord, Planes,
                                    Real, SceneError, Stops, Vector, Whole)
from pyjulia4d.scene.quality import QUALITIES

Vec3 = tuple[float, float, float]
Vec4 = tuple[float, float, float, float]


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
    # the path tracer's soft light: a positioned light's sphere radius (scene units), a distant
    # one's angular radius (degrees; the sun's is 0.27); 0: a point, a direction
    radius: float = 0.0

    def __post_init__(self) -> None:
        """Checked as a table of shading.lights is (scene/checks.Lights)."""
        check_light(self)

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        if self.position is not None:
            out["position"] = list(self.position)
        else:
            out["direction"] = list(self.direction or ())
        out["color"] = list(self.color)
        out["intensity"] = self.intensity
        if self.radius:
            out["radius"] = self.radius
        return out


MAX_LIGHTS = 3   # shading.lights beside shading.light (kernels/shade/: EXTRA_LIGHTS)


COLORMAPS = ("viridis", "plasma", "inferno", "magma", "cividis", "twilight", "twilight_shifted", "turbo",
             "cubehelix", "Spectral", "coolwarm", "RdYlBu", "copper", "bone", "hot", "afmhot", "ocean",
             "terrain", "gist_earth", "gnuplot2", "CMRmap", "YlOrBr", "PuBuGn", "BuPu")


# Every key's check and valid range, in one place (README's table is tested against it).
CHECKS: dict[str, dict[str, Checker]] = {
    "fractal": {
        "algebra": Choice(*ALGEBRAS),
        "function": Choice(*FUNCTIONS),
        "c": Vector((4,), -1e3, 1e3),
        "max_iter": Integer(1, 1_000_000),
        # above ~9.6e8 single precision is refused at render time (workload.py)
        "bailout": Real(1e-3, 1e76),
        # pwr's exponent; |x|, |y| <= 16: higher powers overflow float32 within an iteration
        "exponent": Vector((2,), -16.0, 16.0),
        "kind": Choice(*KINDS),
        # degrees; one turn each way (the map is periodic in theta with period 360)
        "theta": Real(-360.0, 360.0),
        # the stack's end points: a Julia set is empty (dust) for |c| > 2, so +-4 covers all
        "c_from": Vector((2,), -4.0, 4.0),
        "c_to": Vector((2,), -4.0, 4.0),
        "component": Choice("plus", "minus"),
        # the ball the unbounded C+ is drawn in; fractal.bailout must reach its maps' escape
        # radius (fractal/kinds/cubic_locus.check: 4 does up to 2.19)
        "locus_radius": Real(0.05, 16.0),
    },
    "camera": {
        "position": Vector((3, 4), -COORD, COORD),
        "target": Vector((3, 4), -COORD, COORD),
        "up": Vector((3, 4), -COORD, COORD, nonzero=True),
        "limbo": Vector((3, 4), -COORD, COORD, nonzero=True),
        "fov": Real(1e-6, 179.9),
        "fit": Bool(),
        "margin": Real(0.05, 1.0),
        "aperture": Real(0.0, 1e3),
        "focus": OrWord("auto", Real(1e-6, 1e7)),
    },
    "slice": {
        "normal": Vector((4,), -COORD, COORD, nonzero=True),
        "distance": Real(-COORD, COORD),
        "turn": Vector((6,), -3600.0, 3600.0),
    },
    "march": {
        "quality": Choice(*QUALITIES),
        "method": Choice("auto", "fixed", "de", "proven"),
        # the kernel's int loop counter: from 2^31 - 2 on refused at render time (workload.py)
        "z_resolution": Integer(1, INT_MAX),
        "post_steps": Integer(0, 1000),
        "refine": Choice("itp", "bisect"),
        "epsilon": Real(1e-12, 1.0),
        "max_steps": Integer(1, INT_MAX),
        "near": OrWord("auto", Real(0.0, 1e7)),
        "far": OrWord("auto", Real(0.0, 1e7, lo_open=True)),
    },
    "normals": {
        "method": Choice("jacobian", "gradient", "zbuffer"),
        "step": OrWord("auto", OrWord("pixel", Real(1e-12, 1.0))),
    },
    "shading": {
        "color": Vector((3,), 0.0, 1e3),
        "background": Vector((3,), 0.0, 1e3),
        "background_gradient": Stops(2, 16),
        "background_image": ImageFile(("none",), (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".exr", ".hdr"),
                                      "an image, scaled to cover the frame"),
        "ambient": Real(0.0, 1e3),
        "diffuse": Real(0.0, 1e3),
        "specular": Real(0.0, 1e3),
        "shininess": Real(1e-3, 1e4),
        "light": OrWord("eye", Vector((3, 4), -COORD, COORD)),
        "light_color": Vector((3,), 0.0, 1e3),
        "light_radius": Real(0.0, 1e3),
        "light_space": Choice("scene", "camera"),
        "shadow": Choice("none", "hard", "soft"),
        "shadow_softness": Real(1.0, 1e3),
        "ao": Real(0.0, 1.0),
        "ao_distance": Real(1e-4, 10.0),
        "coloring": Choice("flat", "iteration", "trap", "w"),
        "colormap": Choice(*COLORMAPS, fold_case=True),
        "gradient": Stops(2, 16),
        "color_offset": Real(-1e3, 1e3),
        "color_scale": Real(-1e3, 1e3),
        "color_repeat": Choice("clamp", "repeat", "mirror"),
        "trap": Vector((3, 4), -COORD, COORD),
        "fog": Real(0.0, 100.0),
        "sky": Vector((3,), 0.0, 1e3),
        "lights": Lights(MAX_LIGHTS, Light),
        "reflection": Real(0.0, 1.0),
        "integrator": Choice("direct", "path"),
        "environment": ImageFile(("uniform", "sky"), (".exr", ".hdr"), "an equirectangular image, twice as wide as high"),
        "bounces": Integer(1, 64),
        "roughness": Real(0.0, 1.0),
        "metallic": Real(0.0, 1.0),
        "emission": Real(0.0, 1e3),
    },
    "image": {
        "width": Integer(1, INT_MAX),
        "height": Integer(1, INT_MAX),
        "samples": Integer(1, 65536),
        "adaptive": Bool(),
        "bits": Whole(8, 16),
        "alpha": OrWord("auto", Bool()),
        "exr": Choice("pyjulia4d", "compositing"),
        "noise": Real(0.0, 1.0),
        "exposure": Real(-20.0, 20.0),
        "tonemap": Choice("clamp", "aces", "agx"),
        "denoise": Bool(),
    },
    "clip": {
        "planes": Planes(4),
    },
    "render": {
        "float": Choice("auto", "single", "double"),
        "variant": Choice("auto", "scalar", "packet"),
    },
}


def key_names() -> list[str]:
    """Every scene key, ``section.name``, in the order of the sections and their fields."""
    return [f"{section}.{key}" for section, table in CHECKS.items() for key in table]


def valid_range(dotted: str) -> str:
    """The valid range of a scene key in words, e.g. ``valid_range("march.epsilon")``."""
    section, _, key = dotted.partition(".")
    return CHECKS[section][key].valid


def check_section(part: Any, section: str) -> None:
    """Check every field of a section dataclass as a scene file's value would be (the same
    one-line SceneError naming the key), storing the normalised values (vectors as tuples of
    floats, 3-vectors given w = 0): a scene built in Python, dataclasses.replace included, is
    as valid as one read from a file."""
    checks = CHECKS[section]
    for f in fields(part):
        value = getattr(part, f.name)
        checked = checks[f.name](f"{section}.{f.name}", value)
        if checked is not value:
            object.__setattr__(part, f.name, checked)


def check_light(light: "Light") -> None:
    """One of shading.lights, checked as Lights checks a table."""
    lights = CHECKS["shading"]["lights"]
    where = "shading.lights[]"
    if (light.position is None) == (light.direction is None):
        raise SceneError(where, "give exactly one of position and direction")
    for name, check in (("position", lights.point), ("direction", lights.direction), ("color", lights.color),
                        ("intensity", lights.intensity), ("radius", lights.radius)):
        value = getattr(light, name)
        if value is not None:
            checked = check(f"{where}.{name}", value)
            if checked is not value:
                object.__setattr__(light, name, checked)
