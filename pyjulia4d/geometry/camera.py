"""The 4D camera frame, the slice transform and the bounding sphere.

Host-side set-up only (a handful of 4-vectors per scene); the per-pixel ray
generation is the kernel ``generate_rays`` in kernels/rays.cl and its twin
``reference.generate_rays``.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from pyjulia4d.geometry.vec4 import Degenerate, cross4, orthonormalise, unit
from pyjulia4d.fractal.registry import kind_hooks, march_method
from pyjulia4d.scene.model import Scene
from pyjulia4d.scene.checks import SceneError


def slice_rotation(normal) -> np.ndarray:
    """The rotation R with R e_w = n/|n| that turns in the plane of e_w and n only.

    Camera coordinates are mapped to the world by p = R p_cam + distance n/|n|, so a
    3D camera (w = 0, limbo = e_w) looks into the hyperplane n.p = distance: POV-Ray's
    slice (POV-Ray 3.6 documentation).  Unlike POV-Ray, which keeps x, y, z and
    solves for w, this map is an isometry: the section is seen undistorted and a
    normal with zero w-component is allowed.  Read-only, made once per normal (a render's
    plan maps five vectors by it: 0.2 ms made anew each time).
    """
    return _rotation(tuple(float(x) for x in np.ravel(normal)))


@functools.lru_cache(maxsize=64)
def _rotation(normal: tuple[float, ...]) -> np.ndarray:
    n = unit(normal)
    e = np.array([0.0, 0.0, 0.0, 1.0])
    cos = float(n @ e)
    if 1.0 + cos < 1e-12:  # n = -e_w: flip w only; x, y, z (the view) are unchanged
        r = np.diag([1.0, 1.0, 1.0, -1.0])
    else:
        k = np.outer(n, e) - np.outer(e, n)  # generator of the rotation in span(e, n)
        r = np.eye(4) + k + (k @ k) / (1.0 + cos)
    r.setflags(write=False)
    return r


@dataclass(frozen=True)
class Frame:
    """World-space pinhole camera: every ray starts at position, looks along
    normalize(forward + u right + v up)."""
    position: np.ndarray
    forward: np.ndarray
    right: np.ndarray
    up: np.ndarray
    tan_half_fov: float


# the planes of slice.turn, in its order: xy, xz, xw, yz, yw, zw
TURN_PLANES = ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3))


def turn_matrix(turn) -> np.ndarray:
    """The 4D rotation of slice.turn: G = G_zw G_yw G_yz G_xw G_xz G_xy, each G_ab turning
    axis a towards axis b by its angle in degrees (a' = a cos - b sin, b' = a sin + b cos), the
    xy turn first.  Read-only, made once per turn."""
    return _turn(tuple(float(x) for x in np.ravel(turn)))


@functools.lru_cache(maxsize=64)
def _turn(turn: tuple[float, ...]) -> np.ndarray:
    g = np.eye(4)
    for (a, b), deg in zip(TURN_PLANES, turn):
        if deg:
            c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
            r = np.eye(4)
            r[a, a], r[a, b], r[b, a], r[b, b] = c, -s, s, c
            g = r @ g
    g.setflags(write=False)
    return g


def slice_map(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """(R, offset): scene coordinates p -> world R p + offset.  R = G S, S the rotation that
    takes e_w to the slice's normal (slice_rotation), G slice.turn's (turn_matrix); offset =
    G distance n/|n|.  The camera and the lights ride along: the picture turns through 4D."""
    g = turn_matrix(scene.slice.turn)
    return g @ slice_rotation(scene.slice.normal), g @ (scene.slice.distance * unit(scene.slice.normal))


def to_world(scene: Scene, p, direction: bool = False) -> np.ndarray:
    """Camera/light coordinates -> world: R p (+ the offset for positions): slice_map."""
    r, offset = slice_map(scene)
    v = r @ np.asarray(p, float)
    if not direction:
        v = v + offset
    return v


def camera_frame(scene: Scene) -> Frame:
    """Orthonormal frame of Ödegaard & Wennergren §4: forward from position to target; limbo and up
    made orthogonal to it (Gram-Schmidt); right = 4Dcross(forward, up, limbo), so the
    image plane is perpendicular to limbo.  limbo = e_w with w = 0 everywhere drops the
    fourth dimension; any other choice makes the rays travel in w."""
    cam = scene.camera
    pos = to_world(scene, cam.position)
    # directions are normalised before use: any non-zero length is valid (scene/checks.py)
    try:
        fwd, limbo, up = orthonormalise(to_world(scene, cam.target) - pos,
                                        to_world(scene, unit(cam.limbo), direction=True),
                                        to_world(scene, unit(cam.up), direction=True))
    except Degenerate as e:
        key, what = {"forward": ("camera.target", "equals camera.position"),
                     "limbo": ("camera.limbo", "parallel to the view direction"),
                     "up": ("camera.up", "parallel to the view direction or to camera.limbo")}[e.which]
        raise SceneError(key, what) from None
    right = cross4(fwd, up, limbo)
    right /= np.linalg.norm(right)
    return Frame(pos, fwd, right, up, math.tan(math.radians(cam.fov) / 2.0))


def light_to_world(scene: Scene, frame: Frame | None, p, direction: bool = False) -> np.ndarray:
    """A light's position or direction in world space: given in the scene's coordinates
    (shading.light_space = "scene", to_world), or in the camera's (``frame``: x right, y up,
    z towards the viewer, w along the camera's fourth axis; a position from the eye)."""
    if scene.shading.light_space != "camera":
        return to_world(scene, p, direction)
    fr = frame if frame is not None else camera_frame(scene)
    q = np.zeros(4)
    q[:len(p)] = np.asarray(p, float)
    fourth = cross4(fr.right, fr.up, fr.forward)
    fourth /= np.linalg.norm(fourth)
    if fourth @ to_world(scene, unit(scene.camera.limbo), direction=True) < 0:
        fourth = -fourth
    v = q[0] * fr.right + q[1] * fr.up - q[2] * fr.forward + q[3] * fourth
    return v if direction else fr.position + v


def light_position(scene: Scene, frame: Frame | None = None) -> np.ndarray | None:
    """World position of the positioned light, or None for the light at the eye."""
    if isinstance(scene.shading.light, str):
        return None
    return light_to_world(scene, frame, scene.shading.light)


def extra_lights(scene: Scene, frame: Frame | None = None) -> tuple[np.ndarray, np.ndarray]:
    """shading.lights for the kernels (shade/shade.cl, shade/light.cl): (geo, rgb), geo[j]
    the world position, or the unit world direction towards a distant light; rgb[j] its
    colour times intensity, and w = 1 for a distant light.  One inert row when there are none
    (a buffer is never empty)."""
    lights = scene.shading.lights
    geo = np.zeros((max(1, len(lights)), 4))
    rgb = np.zeros((max(1, len(lights)), 4))
    for j, light in enumerate(lights):
        if light.position is not None:
            geo[j] = light_to_world(scene, frame, light.position)
        else:
            d = light_to_world(scene, frame, light.direction, direction=True)
            geo[j] = d / np.linalg.norm(d)
            rgb[j, 3] = 1.0
        rgb[j, :3] = np.asarray(light.color) * light.intensity
    return geo, rgb


def march_radius(scene: Scene) -> float:
    """Bounding radius for the march: the set's (set_radius), plus 4 epsilon for the
    distance-estimate method, whose d < epsilon shell lies outside the set and whose
    estimate is low by at most a factor of about 4 (Koebe 1/4 theorem)."""
    r = set_radius(scene)
    if march_method(scene) == "de":
        r += 4.0 * scene.march.epsilon
    return r


def set_radius(scene: Scene) -> float:
    """Radius of a 4-ball about the origin that holds the scene's set: the escape-time bound of
    its kind (fractal/kinds/<kind>.py set_radius; what a mesh of the set samples; the march
    widens it, march_radius)."""
    return kind_hooks(scene.fractal.kind).set_radius(scene)


def clip_planes(scene: Scene) -> list[tuple[np.ndarray, float]]:
    """The [clip] half-spaces n . p <= offset (scene space, n any length) in world space: a
    unit 4D normal m and offset e with m . x <= e for the world points x = R p + distance u
    of the slice (to_world)."""
    out = []
    for nx, ny, nz, off in scene.clip.planes:
        n = np.array([nx, ny, nz, 0.0])
        ln = float(np.linalg.norm(n))
        m = to_world(scene, n / ln, direction=True)
        shift = slice_map(scene)[1]
        out.append((m, float(off) / ln + float(m @ shift)))
    return out
