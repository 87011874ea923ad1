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
from pyjulia4d.fractal.registry import MANDELBROT_START, escape_degree, march_method
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


def to_world(scene: Scene, p, direction: bool = False) -> np.ndarray:
    """Camera/light coordinates -> world: R p (+ distance n/|n| for positions)."""
    r = slice_rotation(scene.slice.normal)
    v = r @ np.asarray(p, float)
    if not direction:
        v = v + scene.slice.distance * unit(scene.slice.normal)
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


def light_position(scene: Scene) -> np.ndarray | None:
    """World position of the positioned light, or None for the light at the eye."""
    if isinstance(scene.shading.light, str):
        return None
    return to_world(scene, scene.shading.light)


def extra_lights(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """shading.lights for the kernels (shade/shade.cl, shade/light.cl): (geo, rgb), geo[j]
    the world position, or the unit world direction towards a distant light; rgb[j] its
    colour times intensity, and w = 1 for a distant light.  One inert row when there are none
    (a buffer is never empty)."""
    lights = scene.shading.lights
    geo = np.zeros((max(1, len(lights)), 4))
    rgb = np.zeros((max(1, len(lights)), 4))
    for j, light in enumerate(lights):
        if light.position is not None:
            geo[j] = to_world(scene, light.position)
        else:
            d = to_world(scene, light.direction, direction=True)
            geo[j] = d / np.linalg.norm(d)
            rgb[j, 3] = 1.0
        rgb[j, :3] = np.asarray(light.color) * light.intensity
    return geo, rgb


def bounding_radius(c, bailout: float, max_iter: int, degree: int | None = 2) -> float:
    """Radius of a 4-ball that provably holds every point with |q_n| <= bailout for
    n = 0..max_iter (the set the fixed scan finds), for q -> q^degree + c.

    With R the root of r^D - |c| = r, |q| = r > R gives |q^D + c| >= r^D - |c| > r, so
    |q_n| >= g^n(r), g(r) = r^D - |c|.  A point that stays within the bailout b after N
    steps therefore has |q_0| <= g^-N(b) = h^N(b), h(s) = (s + |c|)^(1/D), and also
    |q_0| <= b.  The bound shrinks from b towards R as N grows.  |q^D| >= |q|^D holds for
    quaternions (|q^D| = |q|^D) and for the hypercomplex numbers (the power mean of the
    split components, algebra/hypercomplex.cl).  ``degree`` None (a function that is no
    polynomial): the bailout itself, the n = 0 test, widened by 2^-20 (far above float32's
    rounding of a point's norm): such sets can fill the ball up to its sphere (tan, asin,
    reciprocal stay bounded almost everywhere), and a scan must start outside them, so that
    the hit on the sphere is bracketed and its normal is the sphere's.
    """
    if degree is None:
        return float(bailout) * (1.0 + 2.0 ** -20)
    cabs = float(np.linalg.norm(c))
    s = float(bailout)
    for _ in range(min(int(max_iter), 200)):  # h^N converges to R geometrically
        s_next = (s + cabs) ** (1.0 / degree) if degree != 2 else math.sqrt(s + cabs)
        if abs(s_next - s) < 1e-15:
            break
        s = s_next
    return min(float(bailout), s)


def mandelbrot_radius(bailout: float, max_iter: int, degree: int | None = 2, start: float = 0.0) -> float:
    """Radius of a 4-ball that provably holds every c with |q_n| <= bailout for n = 1..max_iter,
    q_1 = c, q_{n+1} = q_n^degree + c (kernels/kind/mandelbrot.cl).

    |q_1| = |c| = r <= b is needed.  With s_1 = r, s_{n+1} = s_n^D - r a lower bound of |q_n|
    (|q^D + c| >= |q|^D - |c|), and r > R = 2^(1/(D-1)) (where R^D - R = R), s_n grows with n
    and with r (ds_{n+1}/dr = D s_n^(D-1) ds_n/dr - 1 >= 1); so the c that stay within b for N
    steps have r <= max(R, r*), r* the least r >= R with some s_n > b, found by bisection
    (widened by 1e-9 relative).  ``degree`` None (no norm bound): |q_1| = |v + c| <= b
    alone, so b + |v| (``start``, the critical value's norm), widened as in bounding_radius."""
    b = float(bailout)
    if degree is None:
        return (b + float(start)) * (1.0 + 2.0 ** -20)
    R = 2.0 ** (1.0 / (degree - 1))
    if b <= R:
        return b

    def escapes(r: float) -> bool:
        s = r
        for _ in range(int(max_iter) - 1):
            s = s ** degree - r
            if s > b:
                return True
        return False

    if not escapes(b):
        return b
    lo, hi = R, b                    # lo stays within b (or is R), hi escapes
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if escapes(mid):
            hi = mid
        else:
            lo = mid
    return min(b, hi * (1.0 + 1e-9))


def stack_radius(scene: Scene) -> float:
    """Radius of a 4-ball about the origin that holds a Julia set stack (kernels/kind/
    julia_stack.cl) in the hyperplane w = w0 the view keeps to (scene/rules.check_stack): there
    |z| <= bounding_radius(max |c(u)|) (|c(u)| <= the larger end point's: the segment is
    convex), |u| <= 1 and w = w0, widened by 2^-20 so that a scan starts outside."""
    f, cam = scene.fractal, scene.camera
    cmax = max(math.hypot(*f.c_from), math.hypot(*f.c_to))
    rz = bounding_radius((cmax, 0.0, 0.0, 0.0), f.bailout, f.max_iter, 2)
    w0 = float(to_world(scene, tuple(cam.position[:3]) + ((cam.position[3],) if len(cam.position) == 4
                                                              else (0.0,)))[3])
    return math.sqrt(rz * rz + 1.0 + w0 * w0) * (1.0 + 2.0 ** -20)


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
    its kind (what a mesh of the set samples; the march widens it, march_radius)."""
    f = scene.fractal
    if f.kind == "mandelbrot":
        r = mandelbrot_radius(f.bailout, f.max_iter, escape_degree(f),
                              float(np.linalg.norm(MANDELBROT_START[f.function])))
    elif f.kind == "julia_stack":
        r = stack_radius(scene)
    elif f.kind == "cubic_locus":   # kernels/kind/cubic_locus.cl: drawn within |p| <= locus_radius,
        r = f.locus_radius * (1.0 + 2.0 ** -20)   # widened so that a scan starts outside
    else:
        r = bounding_radius(f.c, f.bailout, f.max_iter, escape_degree(f))
    return r


def clip_planes(scene: Scene) -> list[tuple[np.ndarray, float]]:
    """The [clip] half-spaces n . p <= offset (scene space, n any length) in world space: a
    unit 4D normal m and offset e with m . x <= e for the world points x = R p + distance u
    of the slice (to_world)."""
    out = []
    for nx, ny, nz, off in scene.clip.planes:
        n = np.array([nx, ny, nz, 0.0])
        ln = float(np.linalg.norm(n))
        m = to_world(scene, n / ln, direction=True)
        shift = scene.slice.distance * unit(scene.slice.normal)
        out.append((m, float(off) / ln + float(m @ shift)))
    return out
