"""Moving a 4D camera by hand (the explorer's drag, wheel and w-turn): rotations of the
camera's own orthonormal frame about its target.

The frame is Ödegaard & Wennergren §4's (geometry/camera.py): forward f from the
position to the target, limbo l and up u made orthogonal to it by Gram-Schmidt, right r =
4Dcross(f, u, l).  Each move is a rotation by an angle a in one plane of that frame, applied
to the offset of the position from the target, so the distance to the target is kept:

- ``orbit``: yaw in the plane (f, r), then pitch in the plane (f, u): the view circles the
  target within the 3D space the camera sees; limbo is untouched.
- ``turn_w``: the plane (f, l): the view direction turns through the fourth dimension, by the
  limbo vector, and limbo turns with it (Ödegaard & Wennergren §6 moves position and target along w to see
  the set at other 4D angles; this does so keeping the target).
- ``zoom``: the position slides along f, its distance to the target times a factor.

All of it runs in the scene's camera coordinates (before the slice's rotation), where
camera.position and camera.target live.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from pyjulia4d.geometry.vec4 import cross4, orthonormalise, unit
from pyjulia4d.scene.checks import COORD, SceneError
from pyjulia4d.scene.model import Camera

# A zoom never brings the camera closer than this to its target, nor takes it past the
# coordinate range scene keys allow (scene/checks.py COORD).
MIN_DISTANCE = 1e-6
# Pitch stops short of the pole (degrees): at 90 the view direction would meet the old up.
MAX_PITCH = 89.0


def frame(camera: Camera) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]:
    """(forward, right, up, limbo, distance to the target) of ``camera``."""
    p, t = np.asarray(camera.position, float), np.asarray(camera.target, float)
    f, limbo, up = orthonormalise(t - p, unit(camera.limbo), unit(camera.up))
    r = cross4(f, up, limbo)
    return f, r / np.linalg.norm(r), up, limbo, float(np.linalg.norm(t - p))


def _rotate(a: np.ndarray, b: np.ndarray, degrees: float) -> tuple[np.ndarray, np.ndarray]:
    """a, b turned by ``degrees`` in their plane (a towards b)."""
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    return c * a + s * b, -s * a + c * b


def _placed(camera: Camera, forward: np.ndarray, distance: float, **vectors: np.ndarray) -> Camera:
    """The camera at ``distance`` behind its target along ``forward``, with the given frame
    vectors, never framed again (camera.fit false: the view is the user's now)."""
    t = np.asarray(camera.target, float)
    p = t - distance * forward
    if not np.all(np.abs(p) <= COORD):
        raise SceneError("camera.position", f"would leave the coordinate range +-{COORD:g}")
    return dataclasses.replace(camera, position=tuple(float(x) for x in p), fit=False,
                               **{k: tuple(float(x) for x in v) for k, v in vectors.items()})


def orbit(camera: Camera, yaw: float, pitch: float) -> Camera:
    """Circle the target: ``yaw`` degrees about the camera's up (positive: the camera moves
    right, so the set turns left), then ``pitch`` degrees about its right (positive: the
    camera moves up), each clamped to +-MAX_PITCH for the pitch."""
    f, r, u, limbo, d = frame(camera)
    f, r = _rotate(f, r, -float(yaw))
    pitch = max(-MAX_PITCH, min(MAX_PITCH, float(pitch)))
    f, u = _rotate(f, u, -pitch)
    return _placed(camera, f, d, up=u, limbo=limbo)


def turn_w(camera: Camera, degrees: float) -> Camera:
    """Turn the view through the fourth dimension by ``degrees`` in the plane of the view
    direction and limbo, keeping the target: limbo turns with the view, up stays."""
    f, r, u, limbo, d = frame(camera)
    f, limbo = _rotate(f, limbo, -float(degrees))
    return _placed(camera, f, d, up=u, limbo=limbo)


def zoom(camera: Camera, factor: float) -> Camera:
    """Move along the view direction to ``factor`` times the distance to the target
    (below 1: closer), never closer than MIN_DISTANCE."""
    factor = float(factor)
    if not (math.isfinite(factor) and factor > 0):
        raise SceneError("zoom", f"expected a positive factor, got {factor!r}")
    f, r, u, limbo, d = frame(camera)
    return _placed(camera, f, max(MIN_DISTANCE, d * factor), up=u, limbo=limbo)
