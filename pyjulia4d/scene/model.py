"""The scene model: typed frozen dataclasses, one per [section], checked when they are
built; every key's checker and valid range is scene/ranges.py's table (CHECKS).

A scene is read from TOML (or a plain dict), then ``--set section.key=VALUE`` overrides
are applied (scene/text.py), and the result is validated: each section's fields by their
checkers (scene/checks.py), the rules across keys by scene/rules.py.  The same checks run
on a scene built in Python (the constructors, dataclasses.replace).  Every error is a
SceneError whose message starts with the dotted key it concerns; every key's valid range
is declared once, in CHECKS (valid_range words it; docs/scene-keys.md is tested against
it).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any, Iterable, Literal, Mapping, Union

from pyjulia4d.scene import rules
from pyjulia4d.scene.checks import SceneError, show, show_key, unknown_key
from pyjulia4d.scene.quality import CUSTOM, MARCH_KEYS, auto_precision, auto_values, preset_values
from pyjulia4d.scene.ranges import CHECKS, Light, Vec3, Vec4, check_section
from pyjulia4d.scene.text import override_list, parse_override, read_scene_table, toml_value

Auto = Literal["auto"]


# ---------------------------------------------------------------- sections


@dataclass(frozen=True)
class Fractal:
    """[fractal]: the Julia set of q -> f(q) + c in a 4D algebra, or (``kind``) its Mandelbrot
    set, a stack of complex Julia sets or the cubic connectedness locus (Hart, Sandin & Kauffman 1989 §5); ``theta``
    rotates the quaternion map (Hart, Sandin & Kauffman 1989 §2.3)."""

    algebra: str = "quaternion"
    function: str = "sqr"
    c: Vec4 = (-0.2, 0.8, 0.0, 0.0)
    max_iter: int = 12
    bailout: float = 4.0  # escape radius (POV-Ray's default)
    exponent: tuple[float, float] = (2.0, 0.0)  # pwr's complex exponent x + iy
    # "julia": the point is q_0, c the constant; "mandelbrot": the point is c, q_0 = 0 (the
    # critical point of q^2 and q^3), c unused (kernels/kind/mandelbrot.cl)
    kind: str = "julia"
    # the complex rotation g(q) = e^(i theta) q conjugating the map, in degrees (Hart, Sandin & Kauffman 1989
    # §2.3; kernels/kind/rotate.cl); 0 compiles the rotation out
    theta: float = 0.0
    # "julia_stack" (Hart, Sandin & Kauffman 1989 §5.1; kernels/kind/julia_stack.cl): the complex Julia sets of
    # z^2 + c(s), c(s) = c_from + s (c_to - c_from), stacked along the third coordinate u =
    # 2 s - 1 in [-1, 1] (c_from at u = -1); complex numbers as (re, im)
    c_from: tuple[float, float] = (-1.0, 0.0)
    c_to: tuple[float, float] = (-0.1, 0.75)
    # "cubic_locus" (Hart, Sandin & Kauffman 1989 §5.2; kernels/kind/cubic_locus.cl): the (a, b) = (x + i y, z + i w)
    # whose critical point +a ("plus": C+) or -a ("minus": C-) has a bounded orbit under
    # z^3 - 3 a^2 z + b, drawn within the 4-ball |(a, b)| <= locus_radius (C+ is unbounded)
    component: str = "plus"
    locus_radius: float = 2.0

    def __post_init__(self) -> None:
        check_section(self, "fractal")


@dataclass(frozen=True)
class Camera:
    """[camera]: a 4D pinhole camera; ``fov`` is the full vertical angle in degrees."""

    position: Vec4 = (1.8, 1.6, -2.2, 0.0)
    target: Vec4 = (0.0, 0.0, 0.0, 0.0)
    up: Vec4 = (0.0, 1.0, 0.0, 0.0)
    limbo: Vec4 = (0.0, 0.0, 0.0, 1.0)
    fov: float = 40.0
    # frame the set from a quick first pass (framing.py), keeping the view direction; a scene
    # read by from_dict/from_toml (or the command line) that gives no camera.position and
    # no camera.fit gets true (Scene.from_dict)
    fit: bool = False
    # with fit: the share of the picture's half-width and half-height the set may fill
    margin: float = 0.9
    # the path tracer's thin lens (shading.integrator = "path"): its radius in scene units (0:
    # a pinhole, all in focus), focused at a distance along the view axis or, "auto", on the
    # surface at the picture's centre (pipeline/path_plan.resolve_focus)
    aperture: float = 0.0
    focus: Union[float, Auto] = "auto"

    def __post_init__(self) -> None:
        check_section(self, "camera")


@dataclass(frozen=True)
class Slice:
    """[slice]: the hyperplane dot(normal, p) = distance that cuts the 4D set, turned through
    4D by ``turn``: degrees in the planes xy, xz, xw, yz, yw, zw (geometry/camera.turn_matrix)."""

    normal: Vec4 = (0.0, 0.0, 0.0, 1.0)
    distance: float = 0.0
    turn: tuple = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        check_section(self, "slice")


@dataclass(frozen=True)
class March:
    """[march]: how rays find the surface.  ``quality`` other than "custom" sets
    method, z_resolution, post_steps, epsilon and refine from a measured preset (quality.py);
    "auto", the default, takes them from the set (quality.auto_values: the proven march's
    normal preset where the set has no distance estimate, the estimate where it has one), so
    they are not given with it: a scene that gives any of them is "custom"."""

    quality: str = "auto"
    method: str = CUSTOM["method"]            # custom's defaults, written once (quality.CUSTOM)
    z_resolution: int = CUSTOM["z_resolution"]
    post_steps: int = CUSTOM["post_steps"]
    refine: str = CUSTOM["refine"]
    epsilon: float = CUSTOM["epsilon"]
    max_steps: int = 4096
    near: Union[float, Auto] = "auto"
    far: Union[float, Auto] = "auto"

    def __post_init__(self) -> None:
        check_section(self, "march")


@dataclass(frozen=True)
class Normals:
    """[normals]: how surface normals are estimated."""

    method: str = "jacobian"
    step: Union[float, Auto, Literal["pixel"]] = "auto"

    def __post_init__(self) -> None:
        check_section(self, "normals")


@dataclass(frozen=True)
class Shading:
    """[shading]: Phong shading; ``light`` is "eye" or a 4D position."""

    color: Vec3 = (0.89, 0.477, 0.147)  # linear light (sRGB (0.95, 0.72, 0.42))
    background: Vec3 = (0.0, 0.0, 0.0)
    background_gradient: tuple = ()    # stops (position, r, g, b), sRGB, top (0) to bottom (1) of the frame
    background_image: str = "none"     # an image covering the frame (pipeline/backdrop.py)
    ambient: float = 0.15
    diffuse: float = 0.92
    specular: float = 0.35
    shininess: float = 40.0
    light: Union[Vec4, Literal["eye"]] = (-2.0, 5.0, -4.0, 0.0)
    light_color: Vec3 = (1.0, 1.0, 1.0)
    light_radius: float = 0.0      # path: the key light's sphere (scene units): soft shadows; 0 a point
    light_space: str = "scene"     # light and lights' coordinates: "scene" (fixed in it) or "camera" (moving with it)
    shadow: str = "soft"           # "none" | "hard" | "soft" (shade/light.cl)
    shadow_softness: float = 16.0  # k of the penumbra min(k d / t): larger is sharper
    ao: float = 0.6                # ambient occlusion strength, 0 = off
    ao_distance: float = 0.1       # how far along the normal occlusion is sampled
    coloring: str = "flat"         # "flat" | "iteration" | "trap" | "w"
    colormap: str = "viridis"      # a matplotlib colour map (COLORMAPS)
    gradient: tuple = ()           # the user's own stops (position, r, g, b), sRGB; () the colour map
    color_offset: float = 0.0      # the colour value's map: offset + scale v, then clamped,
    color_scale: float = 1.0       # repeated or mirrored (pipeline/colormap.py)
    color_repeat: str = "clamp"
    trap: Vec4 = (0.0, 0.0, 0.0, 0.0)  # the orbit trap's point (coloring = "trap")
    fog: float = 0.0               # depth cueing: fade to the background by exp(-fog distance)
    sky: Vec3 = (1.0, 1.0, 1.0)    # colour of the ambient light (times ambient and occlusion)
    lights: tuple["Light", ...] = ()   # more lights beside ``light`` (at most MAX_LIGHTS)
    reflection: float = 0.0        # share of one mirror bounce in the colour (shade/reflect.cl); 0 = off
    # "direct": the lights, shadows and occlusion above; "path": Monte Carlo light transport
    # (kernels/path/): diffuse and glossy bounces lit by the lights and the sky
    integrator: str = "direct"
    # path: the light from every direction, times ambient and sky: "uniform", "sky" (the shipped
    # daylight, pyjulia4d/data/sky.py) or an equirectangular .exr / .hdr (pipeline/environment.py)
    environment: str = "sky"
    bounces: int = 4               # path: hits a path takes at most (1: direct light alone)
    roughness: float = 0.35        # path: the microfacet width (0 mirror-like, 1 matte)
    metallic: float = 0.0          # path: 0 a dielectric (coloured diffuse, white gloss), 1 a metal
    emission: float = 0.0          # path: the surface's own light, x its colour x (1 - its colour value)

    def __post_init__(self) -> None:
        check_section(self, "shading")


@dataclass(frozen=True)
class Image:
    """[image]: output size in pixels."""

    width: int = 640
    height: int = 480
    samples: int = 1      # rays per pixel (stratified jitter); colour and alpha are their mean
    adaptive: bool = False   # samples only where neighbours differ (antialias.py)
    bits: int = 8         # per channel of a PNG or TIFF (app/output.py); EXR is float32 always
    # a PNG's or TIFF's alpha (straight: the background taken out of edge pixels); false: opaque;
    # "auto": alpha, but opaque on a gradient or an image behind the set
    alpha: Union[bool, Literal["auto"]] = "auto"
    exr: str = "pyjulia4d"   # an EXR's channels: pyjulia4d's own, or the passes compositors read (app/exr_layout.py)
    noise: float = 0.0    # path: stop a pixel's samples once its stated noise is this low (0: take them all)
    exposure: float = 0.0   # stops of brightness applied before the tone map
    tonemap: str = "clamp"  # "clamp", "aces" or "agx" (pipeline/tonemap.py): linear light to the display
    denoise: bool = False   # path: Open Image Denoise over the whole picture (the extra pyjulia4d[denoise])

    def __post_init__(self) -> None:
        check_section(self, "image")


@dataclass(frozen=True)
class Clip:
    """[clip]: up to 4 half-spaces n . p <= offset of the scene's 3D space that cut the set
    open (each plane [nx, ny, nz, offset]; the cut face is shaded with the plane's normal)."""

    planes: tuple[tuple[float, float, float, float], ...] = ()

    def __post_init__(self) -> None:
        check_section(self, "clip")


@dataclass(frozen=True)
class Render:
    """[render]: device-side settings."""

    float: str = "auto"
    variant: str = "auto"

    def __post_init__(self) -> None:
        check_section(self, "render")


# Colour maps shading.colormap accepts: matplotlib's, named here so that a scene is checked
# without importing matplotlib (tests/kernels/test_shade.py checks each exists there).
SECTIONS: dict[str, type] = {
    "fractal": Fractal,
    "camera": Camera,
    "slice": Slice,
    "march": March,
    "normals": Normals,
    "shading": Shading,
    "image": Image,
    "clip": Clip,
    "render": Render,
}

SECTION_NAMES = tuple(SECTIONS)

def fill_preset(march: dict[str, Any], keep: set[str]) -> None:
    """Set the preset's march values for ``march["quality"]``, except the keys in ``keep``;
    for "auto", drop the others (they follow the set)."""
    if "quality" not in march:
        return
    quality = CHECKS["march"]["quality"]("march.quality", march["quality"])
    if quality == "auto":
        for k in set(MARCH_KEYS) - keep:
            march.pop(k, None)
    for k, v in preset_values(quality).items():
        if k not in keep:
            march[k] = v


@dataclass(frozen=True)
class Scene:
    """A fully validated scene; build with :meth:`default`, :meth:`from_dict` or :meth:`from_toml`."""

    fractal: Fractal = field(default_factory=Fractal)
    camera: Camera = field(default_factory=Camera)
    slice: Slice = field(default_factory=Slice)
    march: March = field(default_factory=March)
    normals: Normals = field(default_factory=Normals)
    shading: Shading = field(default_factory=Shading)
    image: Image = field(default_factory=Image)
    clip: Clip = field(default_factory=Clip)
    render: Render = field(default_factory=Render)

    def __post_init__(self) -> None:
        """The rules across keys, checked however the scene was built (from a file, a dict,
        the constructor or dataclasses.replace): each section of its type, the camera's frame,
        the algebra x function pair and the methods it can use, reflection's normals, near < far."""
        for name, kind in SECTIONS.items():
            if not isinstance(getattr(self, name), kind):
                raise SceneError(name, f"expected a pyjulia4d.scene.{kind.__name__}, got "
                                       f"{show(getattr(self, name))}")
        if self.march.quality == "auto":   # the march keys follow the set, however it was built
            object.__setattr__(self, "march", dataclasses.replace(self.march, **auto_values(self.fractal)))
        rules.check_camera(self.camera)
        rules.check_fractal(self)
        if self.shading.background_gradient and self.shading.background_image != "none":
            raise SceneError("shading.background_image", "a gradient and an image behind the set: give one "
                                                         "(shading.background_gradient = [] or background_image = \"none\")")
        if self.shading.reflection > 0 and self.normals.method == "zbuffer":
            raise SceneError("shading.reflection", "needs normals.method \"jacobian\" or \"gradient\": the "
                                                   "Z-buffer has no neighbours for reflected rays")
        m = self.march
        if not isinstance(m.near, str) and not isinstance(m.far, str) and m.far <= m.near:
            raise SceneError("march.far", f"must be greater than march.near ({m.near!r}), got {m.far!r}")

    @classmethod
    def default(cls) -> Scene:
        """The built-in scene with its camera placed (``camera.fit = false``): reproducible
        without a framing pass, which is what the tests, benchmarks and the reference compare.
        The command line's built-in scene is ``Scene.from_dict({})``, which frames the set
        (camera.fit is true whenever no camera.position is given), so the two differ in
        camera only."""
        return cls()

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], overrides: Iterable[str] = ()) -> Scene:
        """Validate ``{section: {key: value}}`` (missing keys get defaults), then apply overrides."""
        if not isinstance(data, Mapping):
            raise SceneError("scene", f"expected a table, got {show(data)}")
        raw: dict[str, dict[str, Any]] = {name: {} for name in CHECKS}
        for section, table in data.items():
            if section in ("animation", "keyframe"):   # keyframes.py reads these
                raise SceneError(section, "a keyframed scene: render its frames with "
                                          "'pyjulia4d animate' (or --frames N:N for one)")
            if section not in CHECKS:
                raise unknown_key(str(section), CHECKS)
            if not isinstance(table, Mapping):
                raise SceneError(section, f"expected a table, got {show(table)}")
            for key, value in table.items():
                if key not in CHECKS[section]:
                    raise unknown_key(f"{section}.{key}", CHECKS)
                raw[section][key] = value
        # A quality preset fills the march keys the same source does not set itself;
        # a later source (an override) wins over an earlier one.
        fill_preset(raw["march"], keep=set(raw["march"]))
        for text in override_list(overrides):
            section, key, value = parse_override(text, CHECKS)
            raw[section][key] = value
            if (section, key) == ("march", "quality"):
                fill_preset(raw["march"], keep=set())
        # "auto" (given or by default) takes its march keys from the set: a scene that gives
        # any of them chose them, so it is "custom" (its other keys take custom's defaults)
        if raw["march"].get("quality", "auto") == "auto" and set(raw["march"]) & set(MARCH_KEYS):
            raw["march"]["quality"] = "custom"
        # No camera position given: nothing says where the set is, so frame it (a default
        # camera cuts off or shrinks to a speck many sets); a given position is kept as is.
        if "position" not in raw["camera"] and "fit" not in raw["camera"]:
            raw["camera"]["fit"] = True
        return cls._build(raw)

    @classmethod
    def from_toml(cls, path: str | Path, overrides: Iterable[str] = ()) -> Scene:
        """Read a TOML scene file (at most MAX_SCENE_BYTES), then apply overrides."""
        table = read_scene_table(path)
        return cls.from_dict(table, overrides)

    @classmethod
    def _build(cls, raw: Mapping[str, Mapping[str, Any]]) -> Scene:
        # each key is checked in the order given (the first bad one is named), then again,
        # with the defaults, by the sections' __post_init__
        parts = {}
        for section, table in raw.items():
            checks = CHECKS[section]
            kwargs = {k: checks[k](f"{section}.{k}", v) for k, v in table.items()}
            parts[section] = SECTIONS[section](**kwargs)
        m = parts["march"]
        if m.quality != "custom" and any(getattr(m, k) != v for k, v in preset_values(m.quality).items()):
            # a march key set after the preset: the resolved scene says what really runs
            parts["march"] = dataclasses.replace(m, quality="custom")
        return cls(**parts)

    def with_overrides(self, overrides: Iterable[str]) -> Scene:
        """A new scene with ``section.key=VALUE`` strings applied."""
        return Scene.from_dict(self.to_dict(), overrides)

    @property
    def precision(self) -> str:
        """The kernels' precision, "single" or "double": render.float, with "auto" resolved for
        the set (quality.auto_precision; a device without fp64 or a GPU takes "single",
        opencl/executor.py)."""
        return auto_precision(self) if self.render.float == "auto" else self.render.float

    def replace(self, **changes: Any) -> Scene:
        """A new scene with typed values set by dotted key: ``replace(**{"march.post_steps": 10})``."""
        data = self.to_dict()
        for dotted, value in changes.items():
            section, _, key = dotted.partition(".")
            if section not in CHECKS or key not in CHECKS[section]:
                raise unknown_key(dotted, CHECKS)
            data[section][key] = value
        return Scene.from_dict(data)

    def to_dict(self) -> dict[str, dict[str, Any]]:
        """``{section: {key: value}}`` with vectors as lists; feeds back into :meth:`from_dict`."""
        out: dict[str, dict[str, Any]] = {}
        for section in SECTIONS:
            part = getattr(self, section)
            out[section] = {
                f.name: list(v) if isinstance(v := getattr(part, f.name), tuple) else v
                for f in fields(part)
            }
        out["shading"]["lights"] = [light.to_dict() for light in self.shading.lights]
        if self.march.quality == "auto":   # its march keys follow the set: given, they would fix them
            for k in MARCH_KEYS:
                del out["march"][k]
        return out

    def to_toml(self) -> str:
        """The fully resolved scene as TOML text (reads back with :meth:`from_toml`)."""
        lines = ["# pyjulia4d scene, fully resolved"]
        for section, table in self.to_dict().items():
            lines.append(f"\n[{section}]")
            lines.extend(f"{k} = {toml_value(v)}" for k, v in table.items())
        return "\n".join(lines) + "\n"
