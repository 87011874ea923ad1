"""POV-Ray's julia_fractal, camera and light mapped onto pyjulia4d's scene keys (the rules are
the package docstring's)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from pyjulia4d.interop.povray.reader import FRACTAL_TOLERANCE, POV_DEFAULT_RIGHT, POV_FINISH, Camera, SceneReader
from pyjulia4d.scene.model import Scene
from pyjulia4d.scene.ranges import MAX_LIGHTS as MAX_EXTRA_LIGHTS   # shading.lights, besides shading.light
from pyjulia4d.interop.povray.tokens import PovError


@dataclass
class Imported:
    """The scene, its TOML text (with comments) and the warnings to show."""
    scene: Scene
    toml: str
    warnings: list[str]


def pov_escape_radius(algebra: str, c) -> float:
    """POV-Ray's escape radius: sqrt(Exit_Value) of fractal.cpp Compute_BBox."""
    if algebra == "hypercomplex":
        return 4.0
    r = min(2.0, 1.0 + math.sqrt(sum(v * v for v in c)) + FRACTAL_TOLERANCE)
    return math.sqrt(r * r + FRACTAL_TOLERANCE)


class SliceMap:
    """POV-Ray's 3D fractal-space point X is the 4D point (X, (d - n_xyz.X) / n_t); the
    pyjulia4d camera coordinates of that point are R^T (Y - d n) (camera.slice_rotation)."""

    def __init__(self, normal, distance: float) -> None:
        from pyjulia4d.geometry.camera import slice_rotation

        self.n = np.asarray(normal, float)
        self.d = float(distance)
        self.r = slice_rotation(self.n)
        self.exact = bool(np.all(self.n[:3] == 0))

    def lift(self, v, point: bool) -> np.ndarray:
        v = np.asarray(v, float)
        w = ((self.d if point else 0.0) - self.n[:3] @ v) / self.n[3]
        return np.append(v, w)

    def point(self, x) -> np.ndarray:
        p = self.r.T @ (self.lift(x, True) - self.d * self.n)
        return p[:3] if self.exact else p

    def direction(self, v) -> np.ndarray:
        p = self.r.T @ self.lift(v, False)
        return p[:3] if self.exact else p


def _num(x: float) -> float:
    x = float(x) + 0.0
    return 0.0 if abs(x) < 1e-15 else x


def _vec(v) -> list[float]:
    return [_num(x) for x in v]


class Converted:
    """What ``convert`` builds: the scene dict, a comment per dotted key, the header's notes
    and the warnings."""

    def __init__(self, warnings):
        self.data: dict[str, dict[str, Any]] = {}
        self.notes: dict[str, str] = {}
        self.header: list[str] = []
        self.warns = list(warnings)

    def put(self, key: str, value: Any, note: str | None = None) -> None:
        section, _, k = key.partition(".")
        self.data.setdefault(section, {})[k] = value
        if note:
            self.notes[key] = note


def convert(r: SceneReader, width: int, height: int) -> tuple[dict, dict, list[str], list[str]]:
    """The scene dict, comments per dotted key, header notes and warnings: the julia_fractal's
    fractal, the camera in fractal space then in pyjulia4d's camera coordinates (through the
    object's inverse transform and the slice), the march from POV-Ray's precision, and the
    shading from its pigment, finish and light."""
    where = r.where
    if not r.julias:
        declared = [n for n, s in r.symbols.items() if s[0] == "julia_fractal"]
        hint = (f" (the declared julia_fractal '{declared[0]}' is never used as object {{ {declared[0]} }})"
                if declared else "")
        raise PovError(f"{where}: no julia_fractal in the scene{hint}")
    if len(r.julias) > 1:
        raise PovError(f"{where}:{r.julias[1].line}: a second julia_fractal (the first is at line "
                       f"{r.julias[0].line}): pyjulia4d renders one")
    j = r.julias[0]
    out = Converted(r.warnings)
    inv, smap = j.transform.inverse(), SliceMap(j.slice_normal, j.slice_distance)
    map_fractal(j, where, out)
    map_camera(r, j, inv, smap, width, height, out)
    map_march(j, out)
    map_shading(r, j, inv, smap, out)
    out.put("image.width", width)
    out.put("image.height", height)
    if r.ignored:
        out.header.append("Not read: " + ", ".join(r.ignored) + ".")
    if r.includes:
        out.header.append("#include files not read: " + ", ".join(r.includes) + ".")
    return out.data, out.notes, out.header, out.warns


def map_fractal(j, where: str, out: Converted) -> None:
    """The algebra, function, c, iterations (POV-Ray tests n = 0..max_iteration - 1) and
    POV-Ray's own escape radius."""
    out.put("fractal.algebra", j.algebra)
    if j.function not in ("sqr", "cube") and j.algebra == "quaternion":
        raise PovError(f"{where}:{j.line}: julia_fractal: quaternion takes sqr and cube only (POV-Ray: "
                       f"\"Illegal function\"); add hypercomplex for {j.function}")
    out.put("fractal.function", j.function)
    if j.function == "pwr":
        out.put("fractal.exponent", _vec(j.exponent), f"pwr({j.exponent[0]:g}, {j.exponent[1]:g})")
    out.put("fractal.c", _vec(j.c))
    n = j.max_iteration
    if n < 2:
        raise PovError(f"{where}:{j.line}: max_iteration {n}: POV-Ray then tests the start point only "
                       f"(a ball); pyjulia4d iterates at least once, which is POV-Ray's max_iteration 2")
    out.put("fractal.max_iter", n - 1,
        f"max_iteration {n}{'' if 'max_iteration' in j.given else ' (POV-Ray default)'}: POV-Ray tests "
        f"|q_n| for n = 0..{n - 1}, pyjulia4d for n = 0..max_iter")
    bail = pov_escape_radius(j.algebra, j.c)
    out.put("fractal.bailout", bail,
        "POV-Ray's escape radius: 4 for hypercomplex" if j.algebra == "hypercomplex" else
        "POV-Ray's quaternion escape radius sqrt(R^2 + 1e-7), R = min(2, 1 + |c| + 1e-7) "
        "(fractal.cpp), not the documented 4")


def map_camera(r: SceneReader, j, inv, smap: SliceMap, width: int, height: int, out: Converted) -> None:
    """The slice, and the last camera statement's location, direction, up and right in fractal
    space, then in pyjulia4d's camera coordinates: position, target, up, limbo (which way
    right points) and the vertical field of view."""
    where = r.where
    if j.slice_normal != (0.0, 0.0, 0.0, 1.0) or j.slice_distance != 0:
        out.put("slice.normal", _vec(j.slice_normal), f"slice {j.given.get('slice', '')} (normalised, as POV-Ray does)")
        out.put("slice.distance", _num(j.slice_distance))
        if not smap.exact:
            out.warns.append(f"{where}:{j.line}: slice normal with x/y/z components: POV-Ray draws the section "
                         f"sheared (its 3D point X is the 4D point (X, (d - n.X)/n_t)); pyjulia4d draws it "
                         f"undistorted, seen from the same 4D eye and target: the pictures differ by that shear")
            out.header.append("The slice normal has x/y/z components: the hyperplane, eye, target and light are "
                          "POV-Ray's; POV-Ray's picture is the section sheared by its projection along w, "
                          "this one is undistorted.")
    cam = r.cameras[-1] if r.cameras else Camera(0, np.zeros(3), np.array([0.0, 0, 1]), np.array([0.0, 1, 0]),
                                                 np.array([POV_DEFAULT_RIGHT, 0, 0]))
    if len(r.cameras) > 1:
        out.header.append(f"{len(r.cameras)} camera statements: the last one (line {cam.line}) is used, as in POV-Ray.")
    loc = smap.point(inv.point(cam.location))
    dirv = smap.direction(inv.direction(cam.direction))
    up = smap.direction(inv.direction(cam.up))
    right = smap.direction(inv.direction(cam.right))
    for name, v in (("direction", dirv), ("up", up), ("right", right)):
        if not np.linalg.norm(v) > 0:
            raise PovError(f"{where}:{cam.line}: camera: zero {name} vector")
    dn = dirv / np.linalg.norm(dirv)
    up_perp = up - (up @ dn) * dn
    if not np.linalg.norm(up_perp) > 1e-12 * np.linalg.norm(up):
        raise PovError(f"{where}:{cam.line}: camera: up is parallel to the view direction")
    cosines = [abs(a @ b) / (np.linalg.norm(a) * np.linalg.norm(b)) for a, b in ((dirv, up), (dirv, right), (up, right))]
    if max(cosines) > 1e-6 and smap.exact:
        out.warns.append(f"{where}:{cam.line}: camera vectors are not perpendicular: POV-Ray's picture is skewed; "
                     f"pyjulia4d's frame is made orthonormal (up is kept, right follows)")
    fov = math.degrees(2 * math.atan(np.linalg.norm(up_perp) / (2 * np.linalg.norm(dirv))))
    aspect = np.linalg.norm(right - (right @ dn) * dn) / np.linalg.norm(up_perp)
    if abs(aspect / (width / height) - 1) > 0.01:
        out.warns.append(f"{where}:{cam.line}: camera |right|/|up| = {aspect:.4g} but the image is {width}x{height} "
                     f"({width / height:.4g}): POV-Ray would stretch its pixels; pyjulia4d's are square (the "
                     f"vertical field of view matches; give --width/--height in the ratio {aspect:.4g})")
    # which way pyjulia4d's right = cross4(forward, up, limbo) points, in world coordinates
    # (limbo +w in camera coordinates is R e_w = n there), against POV-Ray's right lifted
    # onto the slice: a negative slice normal's w, or a left-handed right vector, flips it
    from pyjulia4d.geometry.vec4 import cross4

    f_w, u_w, r_w = (smap.lift(inv.direction(v), False) for v in (cam.direction, cam.up, cam.right))
    handed = float(cross4(f_w, u_w, smap.n) @ r_w)
    src = f"line {cam.line}" if cam.line else "POV-Ray's default camera: location 0, looking along +z, right 1.33 x"
    out.put("camera.position", _vec(loc), f"location ({src})")
    out.put("camera.target", _vec(loc + dirv), "location + direction (after look_at)")
    out.put("camera.up", _vec(up))
    if handed <= 0:
        out.put("camera.limbo", [0.0, 0.0, 0.0, -1.0], "so that POV-Ray's right vector is pyjulia4d's right "
            "(a left-handed right vector, or a slice normal with negative w)")
    out.put("camera.fov", fov, "full vertical angle: 2 atan(|up| / (2 |direction|)); POV-Ray's angle is horizontal")
    if not (np.array_equal(j.transform.a, np.eye(3)) and np.array_equal(j.transform.t, np.zeros(3))):
        out.header.append("The julia_fractal's transform is applied inversely to the camera and the light.")


def map_march(j, out: Converted) -> None:
    """POV-Ray's precision P steps at least 1/P: the estimate's epsilon or the fixed scan's
    resolution made no coarser than that."""
    from pyjulia4d.geometry.camera import march_radius

    step = 1.0 / j.precision
    prec = f"precision {j.given.get('precision', '20 (POV-Ray default)')}"
    probe = Scene.from_dict({k: dict(v) for k, v in out.data.items()})
    if probe.fractal.algebra == "quaternion":
        if step < probe.march.epsilon:
            out.put("march.epsilon", step, f"{prec}: POV-Ray's minimum step 1/P, finer than the default")
        else:
            out.header.append(f"{prec}: POV-Ray's march steps at least 1/P = {step:.4g}; pyjulia4d's default "
                          f"march (distance estimate, minimum step march.epsilon = {probe.march.epsilon:g}, "
                          f"certified depth) is no coarser and is kept.")
    else:
        zres = math.ceil(2 * march_radius(probe) * j.precision)
        if zres > probe.march.z_resolution:
            out.put("march.z_resolution", zres, f"{prec}: samples no farther apart than POV-Ray's step 1/P")
        else:
            out.header.append(f"{prec}: POV-Ray's march steps at least 1/P = {step:.4g}; pyjulia4d's fixed "
                          f"scan ({probe.march.z_resolution} samples across the bounding ball, at most "
                          f"{2 * march_radius(probe) / probe.march.z_resolution:.3g} apart, certified depth) "
                          f"is no coarser and is kept.")


def map_shading(r: SceneReader, j, inv, smap: SliceMap, out: Converted) -> None:
    """The pigment, the finish (POV-Ray 3.7's defaults for what it leaves out), the first light
    source and its shadows, and the background."""
    where = r.where
    if j.color is not None:
        out.put("shading.color", _vec(j.color), "pigment")
    else:
        out.header.append("No pigment: POV-Ray would draw the object black; pyjulia4d's default colour is kept.")
    if j.finish is not None:
        f = {**POV_FINISH, **j.finish}
        out.put("shading.ambient", f["ambient"], "finish (POV-Ray 3.7 defaults for what it leaves out)")
        out.put("shading.diffuse", f["diffuse"])
        out.put("shading.specular", f["specular"])
        out.put("shading.shininess", 1.0 / f["roughness"], "1 / roughness")
        if "reflection" in f:
            out.put("shading.reflection", f["reflection"], "finish reflection")
    if r.lights:
        lt = r.lights[0]
        out.put("shading.light", _vec(smap.point(inv.point(lt.position))), f"light_source (line {lt.line})")
        out.put("shading.light_color", _vec(lt.color))
        more = r.lights[1:1 + MAX_EXTRA_LIGHTS]
        if more:   # the others as shading.lights, point lights at their places
            lines = ", ".join(str(x.line) for x in more)
            out.put("shading.lights", [{"position": _vec(smap.point(inv.point(x.position))), "color": _vec(x.color)}
                                       for x in more], f"light_source (line{'s' if len(more) > 1 else ''} {lines})")
        if len(r.lights) > 1 + MAX_EXTRA_LIGHTS:
            out.warns.append(f"{where}:{r.lights[1 + MAX_EXTRA_LIGHTS].line}: {len(r.lights)} light sources: "
                             f"pyjulia4d takes {1 + MAX_EXTRA_LIGHTS}, the first {1 + MAX_EXTRA_LIGHTS} are used")
        if lt.shadowless or j.no_shadow:
            out.put("shading.shadow", "none", "shadowless" if lt.shadowless else "no_shadow on the julia_fractal")
        else:
            out.put("shading.shadow", "hard", "POV-Ray's point light casts hard shadows")
        out.put("shading.ao", 0.0, "POV-Ray has no ambient occlusion (without radiosity)")
    else:
        out.header.append("No light_source: POV-Ray would show ambient light only; pyjulia4d's default lighting "
                      "(its light, shadows and ambient occlusion) is kept.")
    if r.background is not None:
        out.put("shading.background", _vec(r.background[:3]), "background")
