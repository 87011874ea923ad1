"""Every scene key with its default, valid range and a one-line meaning: ``pyjulia4d keys``
(as Mandelbulber2's ``-L`` lists its parameters).  The defaults come from the scene
dataclasses and the ranges from the checkers (scene/model.CHECKS via valid_range), so the
list cannot drift from what is accepted; docs/scene-keys.md holds the long form, and
tests/interfaces/test_scene.py holds both to the checkers."""
from __future__ import annotations

from pyjulia4d.scene.checks import fmt
from pyjulia4d.scene.model import Scene

# One line per key: what it is, in the words of docs/scene-keys.md, shortened.
from pyjulia4d.scene.ranges import key_names, valid_range

# One line per key: what it is, in the words of docs/scene-keys.md, shortened.
MEANINGS = {
    "fractal.algebra": "the 4D algebra: quaternions, hypercomplex numbers, CQuats or the naive commutative rules",
    "fractal.function": "f in q <- f(q) + c (POV-Ray's names); all 18 for hypercomplex, sqr and cube elsewhere",
    "fractal.c": "the Julia constant c",
    "fractal.max_iter": "iterations: a point is inside when |q_n| <= bailout for n = 0..max_iter",
    "fractal.bailout": "escape radius (POV-Ray's 4); single precision refuses above ~9.6e8",
    "fractal.exponent": "pwr's complex exponent x + iy: f(q) = q^(x + iy)",
    "fractal.kind": "julia, its mandelbrot set, a julia_stack of complex Julia sets, or the cubic_locus",
    "fractal.theta": "quaternion maps: conjugate by the rotation e^(i theta) of the complex plane, degrees",
    "fractal.c_from": "julia_stack: c (re, im) at the stack's end u = -1",
    "fractal.c_to": "julia_stack: c (re, im) at the stack's end u = +1",
    "fractal.component": "cubic_locus: C+ (orbit of +a bounded) or C- (orbit of -a)",
    "fractal.locus_radius": "cubic_locus: radius of the 4-ball the unbounded locus is drawn in",
    "camera.position": "the eye; 3 numbers get w = 0",
    "camera.target": "the point looked at",
    "camera.up": "up direction (made orthogonal to the view and limbo); any length",
    "camera.limbo": "the 4th frame vector: the image plane is perpendicular to it",
    "camera.fov": "full vertical field of view, degrees",
    "camera.fit": "frame the set from a quick 96x72 first pass, keeping the view direction "
                  "(default true when no camera.position is given)",
    "camera.margin": "with fit: the share of the picture's half-width and half-height the set may fill",
    "camera.aperture": "path: the thin lens's radius in scene units; 0 is a pinhole (all sharp)",
    "camera.focus": "path: the distance along the view axis held sharp; auto = the surface at the centre",
    "slice.normal": "normal of the 3D hyperplane the camera looks into (POV-Ray's slice)",
    "slice.distance": "the hyperplane's distance from the origin",
    "slice.turn": "degrees the slice and camera turn through 4D in the planes xy, xz, xw, yz, yw, zw",
    "march.quality": "draft, normal or final: measured march presets (proven marches); custom: the march keys as "
                     "given; auto: the distance estimate where it bounds the distance (connected sets), else normal",
    "march.method": "fixed (z-resolution scan), de (distance estimate) or auto (de where it exists)",
    "march.z_resolution": "fixed: samples between near and far",
    "march.post_steps": "refinement steps of the certified depth bracket after a hit",
    "march.refine": "how post-steps refine the bracket: itp (interpolate-truncate-project) or bisect",
    "march.epsilon": "de: the minimum step",
    "march.max_steps": "de: cap on estimates per ray (capped rays are counted)",
    "march.near": "start of the march along each ray; auto = entry into the bounding ball",
    "march.far": "end of the march; auto = exit from the bounding ball",
    "normals.method": "jacobian (analytic), gradient (6-point difference of the estimate) or zbuffer",
    "normals.step": "gradient: difference step; auto = march.epsilon, at least 1e-5 (1e-8 double); "
                    "pixel = a pixel's footprint at the hit (smooth normals where the surface is rough below a pixel)",
    "shading.color": "surface colour, linear light",
    "shading.background": "colour where rays miss (alpha 0 there), linear light; fog fades toward it",
    "shading.background_gradient": "a gradient behind the set: stops [position, r, g, b] (sRGB) from the top (0) to the bottom (1) of the frame",
    "shading.background_image": "an image behind the set (PNG, JPEG, TIFF, EXR, HDR), scaled to cover the frame and centred",
    "shading.ambient": "ambient weight",
    "shading.diffuse": "Lambert weight",
    "shading.specular": "Blinn-Phong weight; 0 compiles the term out",
    "shading.shininess": "Blinn-Phong exponent",
    "shading.light": "\"eye\" (a light at the camera) or the key light's position (shading.light_space)",
    "shading.light_color": "key light colour",
    "shading.light_radius": "path: the key light's sphere radius (scene units): soft shadows; 0 a point",
    "shading.light_space": "the lights' coordinates: scene (fixed in it) or camera (x right, y up, z towards you)",
    "shading.shadow": "shadows of the set on itself: none, hard or soft",
    "shading.shadow_softness": "penumbra k in min(k d / t): larger is sharper",
    "shading.ao": "ambient occlusion strength; 0 compiles it out",
    "shading.ao_distance": "how far along the normal occlusion is sampled",
    "shading.coloring": "base colour: flat, or the colour map by iteration, orbit trap or the w coordinate",
    "shading.colormap": "the matplotlib colour map for coloring other than flat",
    "shading.gradient": "your own colour stops [position, r, g, b] (sRGB), used instead of the colour map",
    "shading.color_offset": "added to the colour value (after color_scale) before the map",
    "shading.color_scale": "the colour value times this before the map: more of the map's colours, or repeats",
    "shading.color_repeat": "a colour value past [0, 1]: clamped, repeated or mirrored",
    "shading.trap": "the orbit trap's point (coloring = trap)",
    "shading.fog": "depth cueing: fade toward the background by exp(-fog t); 0 compiles it out",
    "shading.sky": "colour of the ambient light",
    "shading.lights": "up to 3 more point or distant lights, each with its own shadows",
    "shading.reflection": "share of one mirror bounce in the colour; 0 compiles it out",
    "shading.integrator": "direct (lights, shadows, occlusion) or path (Monte Carlo light transport, its noise stated)",
    "shading.environment": "path: the light from every direction (times ambient and sky): uniform, sky (shipped daylight) or a 2:1 .exr/.hdr",
    "shading.bounces": "path: the most surface hits a path takes (1: direct light alone)",
    "shading.roughness": "path: glossy lobe width (GGX), 0 mirror-like to 1 matte",
    "shading.emission": "path: the surface's own light, x its colour x (1 - colour value): with coloring = trap, a glow where orbits pass the trap",
    "shading.metallic": "path: 0 a dielectric (white gloss), 1 a metal (gloss in the colour, no diffuse)",
    "image.width": "pixels",
    "image.height": "pixels",
    "image.samples": "rays per pixel (stratified), or paths per pixel (path); colour and alpha are their mean",
    "image.adaptive": "with samples > 1: supersample only pixels on an edge",
    "image.bits": "bits per channel of a PNG or TIFF (sRGB-encoded); EXR is float32",
    "image.alpha": "a PNG or TIFF with alpha (the set alone, clean edges) or opaque (on the background); auto: alpha, but opaque on a background gradient or image",
    "image.exr": "an EXR's channels: pyjulia4d's own, or Blender's multilayer passes (premultiplied RGBA, depth, normal, position)",
    "image.noise": "path: stop a pixel's samples once its stated noise (standard error of the luminance) is this low; 0 off",
    "image.exposure": "stops of brightness before the tone map (PNG, TIFF, video; never EXR)",
    "image.tonemap": "linear light to the display: clamp, aces (ACES 1.0 SDR through OpenColorIO) or agx",
    "image.denoise": "path: Intel's Open Image Denoise over the whole picture (pip install 'pyjulia4d[denoise]')",
    "clip.planes": "cut-away half-spaces n . p <= offset that cut the set open",
    "render.float": "auto (double where float32 stops proofs short, on CPUs with fp64), single, or double (float64 kernels, devices with cl_khr_fp64: proofs reach closer, statements tighten)",
    "render.variant": "rays per work-item of the march: scalar (one), packet (16, 8 or 4; 8 or 4 in double) or auto",
}


def _value_text(v) -> str:
    """A default as a scene file writes it: 0.15, "eye", [1.8, 1.6, -2.2, 0], [], false."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, float):   # as the ranges are written (checks.fmt), a whole float as 4.0
        text = fmt(v)
        return f"{text}.0" if text.lstrip("-").isdigit() else text
    if isinstance(v, (tuple, list)):   # components as short as they go: [-0.2, 0.8, 0, 0]
        return "[" + ", ".join(f"{x:g}" if isinstance(x, float) else _value_text(x) for x in v) + "]"
    return str(v)


def default_text(key: str) -> str:
    """The default of ``key`` (section.name) as docs/scene-keys.md writes it;
    camera.fit's depends on whether camera.position is given."""
    if key == "camera.fit":
        return "true when camera.position is not given, else false"
    section, _, name = key.partition(".")
    part = getattr(Scene.default(), section)
    return _value_text(getattr(part, name))


def rows() -> list[tuple[str, str, str, str]]:
    """(key, default, valid range, meaning) for every key, in scene order."""
    return [(k, default_text(k), valid_range(k), MEANINGS[k]) for k in key_names()]


def describe_keys(section: str | None = None) -> str:
    """The text ``pyjulia4d keys [SECTION]`` prints: one block per key, key and default on the
    first line, the valid range and the meaning indented below."""
    out = []
    for key, default, valid, meaning in rows():
        if section is not None and key.partition(".")[0] != section:
            continue
        out.append(f"{key} = {default}\n    range: {valid}\n    {meaning}")
    return "\n".join(out)

