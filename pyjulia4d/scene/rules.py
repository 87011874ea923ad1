"""The rules across keys a scene must satisfy, however it was built (Scene.__post_init__):
the camera's frame, the algebra x function pair and the methods it can use, and the
kinds' own conditions.  Each failure is one SceneError naming the key to change."""
from __future__ import annotations

from typing import Any

import numpy as np

from pyjulia4d.fractal.registry import FUNCTIONS_OF, MANDELBROT_START, has_distance_estimate, locus_escape_radius
from pyjulia4d.geometry.vec4 import Degenerate, norm, orthonormalise, unit
from pyjulia4d.scene.checks import SceneError


# camera.target at least this times max(1, |position|, |target|) from camera.position:
# the float64 view direction then holds to ~2e-8 rad, finer than the smallest fov
# (1e-6 degrees); camera.py refuses below an absolute 1e-9
_MIN_VIEW_DISTANCE = 1e-8


def check_camera(cam: Any) -> None:
    """geometry/camera.py builds a 4D frame by Gram-Schmidt on (view direction, limbo, up):
    they must be linearly independent (geometry/vec4.orthonormalise, here with the angle
    threshold 1e-6).  Same order and messages as the camera."""
    if cam.target == cam.position:
        raise SceneError("camera.target", "equals camera.position")
    view = np.subtract(cam.target, cam.position)
    least = _MIN_VIEW_DISTANCE * max(1.0, norm(cam.position), norm(cam.target))
    if norm(view) < least:
        raise SceneError("camera.target", f"closer than {least:.1e} to camera.position (1e-8 x "
                         "max(1, |position|, |target|): the view direction must hold to the "
                         "smallest fov)")
    try:
        orthonormalise(view, unit(cam.limbo), unit(cam.up), tiny=1e-6)
    except Degenerate as e:
        raise SceneError(f"camera.{e.which}", "parallel to the view direction" if e.which == "limbo" else
                         "parallel to the view direction or to camera.limbo") from None


def check_locus(scene: Any) -> None:
    """fractal.kind = "cubic_locus": the complex cubic only, no rotation, no orbit colouring,
    no estimate (fixed scan, Jacobian or zbuffer normals), and a bailout that is an escape
    radius for every map in the ball, so that the truncated set tends to the locus."""
    f, m = scene.fractal, scene.march
    if f.algebra != "quaternion" or f.function != "sqr":
        raise SceneError("fractal.kind", "cubic_locus iterates the complex cubic z^3 - 3 a^2 z + b: leave "
                         "fractal.algebra=quaternion and fractal.function=sqr")
    if f.theta != 0:
        raise SceneError("fractal.theta", "the rotation is of the quaternion map, not of the cubic locus: set 0")
    if scene.shading.coloring in ("iteration", "trap"):
        raise SceneError("shading.coloring", f"{scene.shading.coloring} follows the quaternion orbit of "
                         "fractal.c, not the cubic locus's; use flat or w")
    if m.method == "de" and m.quality == "custom":   # a preset's de: refused by name below
        raise SceneError("march.method", "no distance estimate is known for the cubic connectedness locus "
                         "(Hart, Sandin & Kauffman 1989 section 5.2); use fixed or auto")
    if scene.normals.method == "gradient":
        raise SceneError("normals.method", "gradient differences a distance estimate, which the cubic locus "
                         "has none of; use jacobian or zbuffer")
    need = locus_escape_radius(f.locus_radius)
    if f.bailout < need:
        raise SceneError("fractal.bailout", f"{f.bailout!r} is below the escape radius {need:.4g} of the cubic "
                         f"maps within fractal.locus_radius={f.locus_radius!r}: set at least that")


def check_stack(scene: Any) -> None:
    """fractal.kind = "julia_stack" (kernels/kind/julia_stack.cl): the complex square only, no
    rotation, colouring by the quaternion orbit or estimate-based normals; its set does not
    depend on the fourth coordinate w, so the view must stay in one hyperplane w = const (the
    bounding ball, camera.march_radius, holds the stack there only)."""
    f, cam, sl = scene.fractal, scene.camera, scene.slice
    if f.algebra != "quaternion" or f.function != "sqr":
        raise SceneError("fractal.kind", "julia_stack iterates the complex square z^2 + c: leave "
                         "fractal.algebra=quaternion and fractal.function=sqr")
    if f.theta != 0:
        raise SceneError("fractal.theta", "the rotation is of the quaternion map, not of a Julia set stack: set 0")
    if scene.shading.coloring in ("iteration", "trap"):
        raise SceneError("shading.coloring", f"{scene.shading.coloring} follows the quaternion orbit of "
                         "fractal.c, not a stack's; use flat or w")
    if scene.normals.method == "gradient":
        raise SceneError("normals.method", "gradient differences a distance estimate, which a Julia set stack "
                         "has no proven one of; use jacobian or zbuffer")
    if any(sl.normal[:3]):
        raise SceneError("slice.normal", "a Julia set stack is the same at every w: slice it by w = const "
                         "only, normal (0, 0, 0, 1)")
    if len(cam.limbo) == 4 and any(cam.limbo[:3]):
        raise SceneError("camera.limbo", "a Julia set stack is the same at every w: keep the rays in w = const, "
                         "limbo (0, 0, 0, 1)")
    pw = cam.position[3] if len(cam.position) == 4 else 0.0
    tw = cam.target[3] if len(cam.target) == 4 else 0.0
    if pw != tw:
        raise SceneError("camera.target", "a Julia set stack is the same at every w: give camera.position and "
                         "camera.target the same w")


def check_fractal(scene: Any) -> None:
    """The algebra x function pairs that exist, and the methods each can use."""
    f, m = scene.fractal, scene.march
    allowed = FUNCTIONS_OF[f.algebra]
    if f.function not in allowed:
        raise SceneError("fractal.function", f"{f.function!r} is not defined for the {f.algebra} algebra "
                         f"(as in POV-Ray's julia_fractal: {' and '.join(allowed)} only); use "
                         f"fractal.algebra=hypercomplex for it")
    pair = f"{f.algebra} {f.function}"
    if f.kind == "mandelbrot":
        if f.function not in MANDELBROT_START:
            raise SceneError("fractal.kind", f"mandelbrot follows the orbit of f's one critical or asymptotic "
                             f"value; {f.function} has several or none: use one of "
                             f"{', '.join(MANDELBROT_START)}")
        if f.function == "pwr" and f.exponent[0] <= 1:
            raise SceneError("fractal.exponent", f"mandelbrot with pwr needs a critical point at 0, "
                             f"real part above 1, got {f.exponent[0]!r}")
        if f.theta != 0:
            raise SceneError("fractal.theta", "the rotation leaves a Mandelbrot set unchanged (its orbits are "
                             "the unrotated ones times e^(i theta)): set 0")
    if f.kind == "julia_stack":
        check_stack(scene)
    if f.kind == "cubic_locus":
        check_locus(scene)
    if f.theta != 0 and f.algebra != "quaternion":
        raise SceneError("fractal.theta", f"the rotation is defined for the quaternion algebra (Hart, Sandin & Kauffman 1989 "
                         f"section 2.3), not {f.algebra}: set 0")
    if has_distance_estimate(f):
        return
    if m.method == "de" and f.kind != "julia_stack":   # the stack's "de": its empirical estimate
        raise SceneError("march.method", f"de needs a distance estimate, which {pair} has none of; "
                         f"use fixed or auto")
    if scene.normals.method == "gradient":
        raise SceneError("normals.method", f"gradient differences the distance estimate, which {pair} "
                         f"has none of; use jacobian or zbuffer")


