"""camera.fit: frame the set from a quick low-resolution pass, keeping the view direction
(Ödegaard & Wennergren §4 finds near and far the same way: from what a first pass sees).

The pass looks along the scene's view direction at the whole bounding ball (96 x 72 rays,
depth and position only).  The camera then looks along the same direction at a target on
the viewed hyperplane, moved across the view until the hits' extents in the picture lie
evenly about its centre, from the smallest distance at which every hit lies within
camera.margin (90 % by default) of the half-width and half-height of the picture - a wider
camera.fov comes nearer, a narrower one stands back, the set filling the same share - but
no nearer than where half a pixel of the pass fills the view (what the pass cannot resolve;
a set seen as a single hit is framed at that distance); both turned back into the scene's
(slice) coordinates.  A pass that hits nothing leaves the camera alone.
"""
from __future__ import annotations

import math

import numpy as np

from pyjulia4d.geometry.camera import camera_frame, march_radius, slice_map
from pyjulia4d.scene.checks import COORD, SceneError
from pyjulia4d.scene.model import Scene

PROBE = (96, 72)
CENTRE_ROUNDS = 4   # the centring's rounds: each halves what perspective left off centre, or better


def to_scene(scene: Scene, x) -> np.ndarray:
    """World point -> scene (slice) coordinates: the inverse of camera.to_world."""
    r, offset = slice_map(scene)
    return r.T @ (np.asarray(x, float) - offset)


def _within_reach(scene: Scene, eye: np.ndarray, radius: float, what: str) -> None:
    """A camera at ``eye`` (world coordinates) must be a valid camera.position (every
    component within +-COORD): else the set is too large to frame, which comes of its
    bound - the bailout where the pair has no polynomial escape bound (bounds.bounding_radius)
    - not of a key the user set; refused with one line naming fractal.bailout."""
    pos = to_scene(scene, eye)
    if np.all(np.abs(pos) <= COORD):
        return
    f = scene.fractal
    raise SceneError("fractal.bailout", f"camera.fit: {what} would need a camera {float(np.max(np.abs(pos))):.3g} "
                     f"from the origin, beyond camera.position's range [-1e6, 1e6], to frame the "
                     f"{f.algebra} {f.function} set within its bound of radius {radius:.3g} "
                     f"(fractal.bailout={f.bailout!r}); lower fractal.bailout, or give camera.position")


def fit_camera(scene: Scene, render_fn) -> tuple[Scene, dict]:
    """The scene with camera.position and camera.target refitted (camera.fit then false),
    and a record of the pass.  ``render_fn(scene, outputs)`` renders (executor.render)."""
    fr = camera_frame(scene)
    radius = march_radius(scene)
    tan_v = fr.tan_half_fov
    tan_h = tan_v * scene.image.width / scene.image.height
    half = math.atan(min(tan_v, tan_h))
    d0 = 1.2 * radius / math.sin(half)
    # the bounding ball is about the world origin (camera.march_radius); the camera sees the
    # 3D hyperplane through its eye spanned by right, up and forward (the slice, Ödegaard & Wennergren
    # §4), so the pass looks at the point of that hyperplane nearest the ball's centre
    rel = -np.asarray(fr.position, float)
    centre = np.asarray(fr.position, float) + sum((rel @ v) * v for v in (fr.right, fr.up, fr.forward))
    eye = centre - d0 * fr.forward
    _within_reach(scene, eye, radius, "the first pass")
    w, h = PROBE
    probe = scene.replace(**{"camera.position": [float(v) for v in to_scene(scene, eye)],
                             "camera.target": [float(v) for v in to_scene(scene, centre)],
                             "camera.fit": False, "image.width": w, "image.height": h,
                             "image.samples": 1})
    res = render_fn(probe, ["position"])
    pts = res.position[np.all(np.isfinite(res.position), axis=-1)].astype(np.float64)
    record = {"probe_hits": int(len(pts)), "probe_size": f"{w}x{h}"}
    if len(pts) == 0:
        return scene.replace(**{"camera.fit": False}), record
    c = pts.mean(axis=0)
    # back onto the viewed hyperplane exactly (the hits are float32)
    c = centre + sum(((c - centre) @ v) * v for v in (fr.right, fr.up, fr.forward))
    # the pass sees the set to within one of its pixels: no nearer than where half a probe
    # pixel at the hits' depth fills the view (one hit or a few together would otherwise
    # put the camera on its target, a camera with no direction)
    half_pixel = float(np.max((pts - eye) @ fr.forward)) * tan_v / PROBE[1]
    margin = scene.camera.margin

    def distance(c: np.ndarray) -> float:
        """The nearest camera distance from c that holds every hit within the margin."""
        rel = pts - c
        x, y, z = rel @ fr.right, rel @ fr.up, rel @ fr.forward
        return max(float(np.max(np.abs(x) / (margin * tan_h) - z)), float(np.max(np.abs(y) / (margin * tan_v) - z)),
                   half_pixel / (margin * min(tan_v, tan_h)), 1e-6)

    dist = distance(c)
    for _ in range(CENTRE_ROUNDS):   # centred in the picture: the hits' extents even about the middle
        rel = pts - c
        depth = rel @ fr.forward + dist
        u, v = (rel @ fr.right) / depth, (rel @ fr.up) / depth
        mid_u, mid_v = 0.5 * (u.max() + u.min()), 0.5 * (v.max() + v.min())
        c = c + dist * (mid_u * fr.right + mid_v * fr.up)
        dist = distance(c)
    pos = c - dist * fr.forward
    _within_reach(scene, pos, radius, "the framed camera")
    record.update(distance=dist, target=[float(v) for v in c])
    fitted = scene.replace(**{"camera.position": [float(v) for v in to_scene(scene, pos)],
                              "camera.target": [float(v) for v in to_scene(scene, c)],
                              "camera.fit": False})
    return fitted, record
