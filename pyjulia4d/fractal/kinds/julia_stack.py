"""Julia set stacks (fractal.kind = "julia_stack", Hart, Sandin & Kauffman 1989 §5.1): the
complex Julia sets of c(u) along a segment of c, stacked along u, the same at every w
(kernels/kind/julia_stack.cl)."""
from __future__ import annotations

import math
from typing import Any

from pyjulia4d.geometry.bounds import bounding_radius
from pyjulia4d.geometry.camera import to_world
from pyjulia4d.fractal.kinds.own_map import check_own_map
from pyjulia4d.scene.checks import SceneError


def defines(scene: Any) -> tuple[str, ...]:
    """KIND_JULIA_STACK; the c-line c(u) = c_mid + u c_half, in float64 here; the empirical
    estimate's switch (STACK_DE), on request only (march.method "de")."""
    f = scene.fractal
    (r0, i0), (r1, i1) = f.c_from, f.c_to
    out = ("KIND_JULIA_STACK", f"STACK_CM_RE={(r0 + r1) / 2!r}", f"STACK_CM_IM={(i0 + i1) / 2!r}",
           f"STACK_CH_RE={(r1 - r0) / 2!r}", f"STACK_CH_IM={(i1 - i0) / 2!r}")
    return out + (("STACK_DE",) if scene.march.method == "de" else ())


def set_radius(scene: Any) -> float:
    """Radius of a 4-ball about the origin that holds a Julia set stack (kernels/kind/
    julia_stack.cl) in the hyperplane w = w0 the view keeps to (check): there
    |z| <= bounding_radius(max |c(u)|) (|c(u)| <= the larger end point's: the segment is
    convex), |u| <= 1 and w = w0, widened by 2^-20 so that a scan starts outside."""
    f, cam = scene.fractal, scene.camera
    cmax = max(math.hypot(*f.c_from), math.hypot(*f.c_to))
    rz = bounding_radius((cmax, 0.0, 0.0, 0.0), f.bailout, f.max_iter, 2)
    w0 = float(to_world(scene, tuple(cam.position[:3]) + ((cam.position[3],) if len(cam.position) == 4
                                                              else (0.0,)))[3])
    return math.sqrt(rz * rz + 1.0 + w0 * w0) * (1.0 + 2.0 ** -20)


def check(scene: Any) -> None:
    """fractal.kind = "julia_stack" (kernels/kind/julia_stack.cl): the complex square only, no
    rotation, colouring by the quaternion orbit or estimate-based normals; its set does not
    depend on the fourth coordinate w, so the view must stay in one hyperplane w = const (the
    bounding ball, camera.march_radius, holds the stack there only)."""
    cam, sl = scene.camera, scene.slice
    check_own_map(scene, "the complex square z^2 + c", "a Julia set stack", "a stack's")
    if scene.normals.method == "gradient":
        raise SceneError("normals.method", "gradient differences a distance estimate, which a Julia set stack "
                         "has no proven one of; use jacobian or zbuffer")
    if any(sl.normal[:3]):
        raise SceneError("slice.normal", "a Julia set stack is the same at every w: slice it by w = const "
                         "only, normal (0, 0, 0, 1)")
    if any(sl.turn[k] % 360 for k in (2, 4, 5)):   # xw, yw, zw
        raise SceneError("slice.turn", "a Julia set stack is the same at every w: turn it in xy, xz and yz "
                         "only (the xw, yw and zw angles whole turns)")
    if len(cam.limbo) == 4 and any(cam.limbo[:3]):
        raise SceneError("camera.limbo", "a Julia set stack is the same at every w: keep the rays in w = const, "
                         "limbo (0, 0, 0, 1)")
    pw = cam.position[3] if len(cam.position) == 4 else 0.0
    tw = cam.target[3] if len(cam.target) == 4 else 0.0
    if pw != tw:
        raise SceneError("camera.target", "a Julia set stack is the same at every w: give camera.position and "
                         "camera.target the same w")
