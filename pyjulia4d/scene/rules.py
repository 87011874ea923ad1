"""The rules across keys a scene must satisfy, however it was built (Scene.__post_init__):
the camera's frame, the algebra x function pair and the methods it can use, and the
kinds' own conditions.  Each failure is one SceneError naming the key to change."""
from __future__ import annotations

from typing import Any

import numpy as np

from pyjulia4d.fractal.registry import FUNCTIONS_OF, KINDS_TABLE, has_distance_estimate, kind_hooks
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


def check_fractal(scene: Any) -> None:
    """The algebra x function pairs that exist, and the methods each can use."""
    f, m = scene.fractal, scene.march
    allowed = FUNCTIONS_OF[f.algebra]
    if f.function not in allowed:
        raise SceneError("fractal.function", f"{f.function!r} is not defined for the {f.algebra} algebra "
                         f"(as in POV-Ray's julia_fractal: {' and '.join(allowed)} only); use "
                         f"fractal.algebra=hypercomplex for it")
    pair = f"{f.algebra} {f.function}"
    kind_hooks(f.kind).check(scene)   # the kind's own rules (fractal/kinds/<kind>.py)
    if f.theta != 0 and f.algebra != "quaternion":
        raise SceneError("fractal.theta", f"the rotation is defined for the quaternion algebra (Hart, Sandin & Kauffman 1989 "
                         f"section 2.3), not {f.algebra}: set 0")
    if has_distance_estimate(f):
        return
    if m.method == "de" and not KINDS_TABLE[f.kind].empirical_estimate:
        raise SceneError("march.method", f"de needs a distance estimate, which {pair} has none of; "
                         f"use fixed or auto")
    if scene.normals.method == "gradient":
        raise SceneError("normals.method", f"gradient differences the distance estimate, which {pair} "
                         f"has none of; use jacobian or zbuffer")



