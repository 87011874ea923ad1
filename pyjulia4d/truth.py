"""Ground truth for the accuracy benchmark (issue 3): depth and normals that do
not come from the marching method under test.

Three oracles, from exact to merely converged:

* ``sphere_depth`` - c = 0: |q_n| = |p|^(2^n), so the max_iter-truncated set
  (|q_n| <= bailout for n = 0..max_iter, seed 000_1dc675fe64448cc1.txt §2.1 eq. 5,
  seed 003) is the 4-ball of radius bailout^(2^-max_iter); depth is the analytic
  ray-ball entry and the normal is radial.
* ``real_c_inside`` / ``real_c_depth`` - real c = (c1, 0, 0, 0): for q = x + r u
  with u a unit pure quaternion, u^2 = -1, so span(1, u) is a copy of the complex
  numbers that q -> q^2 + c1 never leaves (seed 000 eqs. 3-4).  The quaternion set
  is the complex filled Julia set of c1 turned about the real axis: (x, y, z, w) is
  inside exactly when x + i sqrt(y^2 + z^2 + w^2) is.  A float64 2D iteration with
  a fine scan and bisection along each ray gives the depth.
* ``converged_depth`` - any c: the double-precision kernel (render.float =
  "double") scanning at fixed z-resolution with many post-steps (seed 000 §3 and
  §7.1 eq. 11-12), the z-resolution doubled until a further doubling moves the
  depth by less than ``tol`` on all but ``frac`` of the pixels; the depth is then
  polished in float64 numpy (bisection with ``reference.julia_inside``) because
  ``RenderResult.depth`` is stored as float32.

Ground-truth normals: radial for c = 0, otherwise the float64 analytic Jacobian
normal grad |q_n|^2 = 2 J^T q_n (seed 004 "method 3", ``reference.normal_jacobian``)
at the ground-truth hit point, projected to camera coordinates exactly like
kernels/normals_jacobian.cl.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from . import reference as ref
from .camera import bounding_radius, camera_frame
from .render import STATUS_HIT, render
from .scene import Scene


# ------------------------------------------------------------------ c = 0

def sphere_radius(max_iter: int, bailout: float) -> float:
    """Radius of the max_iter-truncated c = 0 set: bailout^(2^-max_iter)."""
    return float(bailout) ** (2.0 ** -int(max_iter))


def sphere_depth(origins, dirs, radius):
    """c = 0 (seed 000 eq. 5 with mu = 0; tests/test_sphere.py): distance along each
    unit ray o + t d to its entry into the 4-ball |p| <= radius; +inf where the ray
    misses the ball, 0 where it starts inside."""
    o = np.asarray(origins, np.float64)
    d = np.asarray(dirs, np.float64)
    b = np.sum(o * d, -1)
    disc = b * b - (np.sum(o * o, -1) - radius ** 2)
    t_in = -b - np.sqrt(np.maximum(disc, 0.0))
    t_out = -b + np.sqrt(np.maximum(disc, 0.0))
    return np.where((disc >= 0) & (t_out >= 0), np.maximum(t_in, 0.0), np.inf)


def sphere_normals(points, frame):
    """c = 0: the radial unit normal p/|p| in camera coordinates (x right, y up, z to the eye)."""
    return ref._unit_or_zero(ref._to_camera(np.asarray(points, np.float64), frame))


# --------------------------------------------------------------- real c

def real_c_inside(points, c1, max_iter, bailout):
    """Real c = (c1, 0, 0, 0) (seed 000 eqs. 3-5): (x, y, z, w) is inside exactly when
    the complex point x + i sqrt(y^2 + z^2 + w^2) stays within ``bailout`` for
    n = 0..max_iter under z -> z^2 + c1 - the same escape rule as
    ``reference.julia_inside`` (seed 003), iterated in float64 complex arithmetic."""
    p = np.asarray(points, np.float64)
    z = p[..., 0] + 1j * np.sqrt(np.sum(p[..., 1:] ** 2, -1))
    return _complex_inside(z, float(c1), int(max_iter), float(bailout))


def _complex_inside(z, c1, max_iter, bailout):
    """|z_n| <= bailout for n = 0..max_iter, z_{n+1} = z_n^2 + c1; float64, iterating
    only the points still inside (same rule as reference.julia_inside)."""
    z = np.asarray(z, np.complex128)
    shape = z.shape
    x = np.ascontiguousarray(z.real).ravel()
    y = np.ascontiguousarray(z.imag).ravel()
    b2 = bailout * bailout
    idx = np.arange(x.size)
    for _ in range(max_iter):
        keep = x * x + y * y <= b2
        idx, x, y = idx[keep], x[keep], y[keep]
        if idx.size == 0:
            break
        x, y = x * x - y * y + c1, 2.0 * x * y
    out = np.zeros(shape, bool).ravel()
    out[idx[x * x + y * y <= b2]] = True
    return out.reshape(shape)


def _ray_interval(o, d, radius):
    b = np.sum(o * d, -1)
    disc = b * b - (np.sum(o * o, -1) - radius ** 2)
    s = np.sqrt(np.maximum(disc, 0.0))
    near = np.maximum(-b - s, 0.0)
    far = -b + s
    live = (disc >= 0) & (far >= near)
    return near, far, live


def _first_inside(inside_fn, o, d, near, far, n_scan, chunk=512):
    """Index of the first sample t_i = near + i (far - near)/n_scan, i = 0..n_scan,
    for which inside_fn is true; -1 if none.  Vectorised over rays, in chunks of
    samples, so rays that hit stop early."""
    n = len(o)
    first = np.full(n, -1, np.int64)
    h = (far - near) / n_scan
    active = np.arange(n)
    for i0 in range(0, n_scan + 1, chunk):
        if active.size == 0:
            break
        i = np.arange(i0, min(i0 + chunk, n_scan + 1))
        t = near[active, None] + i[None, :] * h[active, None]
        p = o[active, None, :] + t[..., None] * d[active, None, :]
        ins = inside_fn(p)
        got = ins.any(1)
        first[active[got]] = i0 + np.argmax(ins[got], 1)
        active = active[~got]
    return first


def _bisect(inside_fn, o, d, t_out, t_in, steps=60):
    """Shrink brackets [t_out (outside), t_in (inside)] to float64 resolution."""
    t_out, t_in = t_out.copy(), t_in.copy()
    for _ in range(steps):
        mid = 0.5 * (t_out + t_in)
        ins = inside_fn(o + mid[:, None] * d)
        t_in = np.where(ins, mid, t_in)
        t_out = np.where(ins, t_out, mid)
    return t_in


def real_c_depth(origins, dirs, c1, max_iter, bailout, near=None, far=None,
                 n_scan=8000, radius=None, record=None):
    """Real c = (c1, 0, 0, 0): depth along each unit ray o + t d to the first point of
    the quaternion set, via the float64 2D oracle ``real_c_inside``.

    Each ray is scanned at ``n_scan`` equal steps between ``near`` and ``far`` (default:
    its entry into and exit from the provably bounding 4-ball of
    ``camera.bounding_radius``, the interval the march kernel scans), then the bracket
    [last outside sample, first inside sample] is bisected 60 times in float64.  The
    scan is repeated at 2 n_scan; where the two differ (a strand thinner than a step
    found only by the finer scan) the finer answer is kept, and ``record`` (a dict, if
    given) gets the number of such rays and the scans used.  +inf for a miss.
    """
    o = np.asarray(origins, np.float64)
    d = np.asarray(dirs, np.float64)
    if radius is None:
        radius = bounding_radius((c1, 0, 0, 0), bailout, max_iter)
    nr, fr_, live = _ray_interval(o, d, radius)
    if near is not None:
        nr = np.full(len(o), float(near))
    if far is not None:
        fr_ = np.full(len(o), float(far))
    live &= fr_ >= nr
    inside = lambda p: real_c_inside(p, c1, max_iter, bailout)
    depth = np.full(len(o), np.inf)
    k = np.nonzero(live)[0]
    results = []
    for n in (n_scan, 2 * n_scan):
        first = _first_inside(inside, o[k], d[k], nr[k], fr_[k], n)
        t = np.full(len(k), np.inf)
        h = (fr_[k] - nr[k]) / n
        at0 = first == 0
        t[at0] = nr[k][at0]
        ok = first > 0
        t[ok] = _bisect(inside, o[k][ok], d[k][ok], nr[k][ok] + (first[ok] - 1) * h[ok],
                        nr[k][ok] + first[ok] * h[ok])
        results.append(t)
    coarse, fine = results
    with np.errstate(invalid="ignore"):
        same = (coarse == fine) | (np.abs(coarse - fine) <= 1e-12)
    depth[k] = fine
    if record is not None:
        record.update(n_scan=[n_scan, 2 * n_scan], rays=int(len(k)),
                      changed_on_doubling=int(np.sum(~same)))
    return depth


# ------------------------------------------------------------ any c

@dataclass
class ConvergedDepth:
    """Ground truth for a scene: float64 depth (+inf miss), hit mask, 4D hit points and
    the convergence record (one entry per z-resolution tried)."""
    depth: np.ndarray           # (H, W) float64
    hit: np.ndarray             # (H, W) bool
    points: np.ndarray          # (H, W, 4) float64, NaN on a miss
    record: list = field(default_factory=list)
    converged: bool = False
    tol: float = 0.0
    frac: float = 0.0
    post_steps: int = 0
    confirm: int = 1


def _polish(scene: Scene, depth32, hit):
    """Float64 bisection around the float32-stored depth of the double kernel:
    where [t - delta, t + delta] brackets the surface (outside, inside), bisect it
    to float64 resolution; elsewhere keep t.  delta = 1e-6 + 4e-7 t covers float32
    rounding of a depth up to ~10 scene units."""
    f = scene.fractal
    fr = camera_frame(scene)
    w, h = scene.image.width, scene.image.height
    o, d = ref.generate_rays(fr, w, h)
    t = depth32.ravel().astype(np.float64)
    k = np.nonzero(hit.ravel())[0]
    out = t.copy()
    if k.size:
        tk = t[k]
        delta = 1e-6 + 4e-7 * tk
        lo, hi = np.maximum(tk - delta, 0.0), tk + delta
        inside = lambda p: ref.julia_inside(p, f.c, f.max_iter, f.bailout)
        ok = ~inside(o[k] + lo[:, None] * d[k]) & inside(o[k] + hi[:, None] * d[k])
        j = k[ok]
        out[j] = _bisect(inside, o[j], d[j], lo[ok], hi[ok], steps=40)
    pts = np.where(hit.ravel()[:, None], o + np.where(np.isfinite(out), out, 0)[:, None] * d, np.nan)
    return out.reshape(h, w), pts.reshape(h, w, 4)


def converged_depth(scene: Scene, z_start: int = 8000, post_steps: int = 20, tol: float = 1e-6,
                    frac: float = 0.002, max_z: int = 256000, confirm: int = 2,
                    device=None) -> ConvergedDepth:
    """Any c: depth from the double-precision kernel's fixed scan (seed 000 §3) with
    ``post_steps`` post-steps (seed 000 §7.1; eq. 12 puts the bracket at
    h / 2^post_steps), z_resolution doubled from ``z_start`` until ``confirm``
    consecutive doublings each change the result by more than ``tol`` scene units (or
    hit/miss) on at most ``frac`` of the pixels, or ``max_z`` is reached.  The finer render is returned, polished in
    float64.  ``record`` lists, per z-resolution, the render time and against the
    previous one: the fraction of pixels changed (depth moved > tol or hit <-> miss),
    the fraction whose hit status flipped, and the largest change below tol."""
    base = scene.with_overrides(["march.method=fixed", f"march.post_steps={post_steps}",
                                 "render.float=double", "normals.method=jacobian"])
    record = []
    prev = None
    quiet = 0
    z = int(z_start)
    converged = False
    while True:
        s = base.with_overrides([f"march.z_resolution={z}"])
        t0 = time.perf_counter()
        r = render(s, device=device)
        entry = {"z_resolution": z, "seconds": round(time.perf_counter() - t0, 3),
                 "hit_fraction": r.hit_fraction}
        if prev is not None:
            h0, h1 = prev.status == STATUS_HIT, r.status == STATUS_HIT
            both = h0 & h1
            with np.errstate(invalid="ignore"):
                dz = np.abs(r.depth.astype(np.float64) - prev.depth.astype(np.float64))
            moved = both & (dz > tol)
            flipped = h0 != h1
            entry["changed_fraction"] = float(np.mean(moved | flipped))
            entry["flipped_fraction"] = float(np.mean(flipped))
            entry["max_change_within_tol"] = float(dz[both & ~moved].max()) if np.any(both & ~moved) else 0.0
            entry["p99_change"] = float(np.percentile(dz[both], 99)) if both.any() else 0.0
            record.append(entry)
            quiet = quiet + 1 if entry["changed_fraction"] <= frac else 0
            if quiet >= confirm:
                converged = True
                break
        else:
            record.append(entry)
        prev = r
        if 2 * z > max_z:
            break
        z *= 2
    hit = r.status == STATUS_HIT
    depth, pts = _polish(base, r.depth, hit)
    depth = np.where(hit, depth, np.inf)
    return ConvergedDepth(depth=depth, hit=hit, points=pts, record=record, converged=converged,
                          tol=tol, frac=frac, post_steps=post_steps, confirm=confirm)


# ------------------------------------------------------------ normals

def jacobian_normals(points, scene: Scene):
    """Float64 analytic normal (seed 004 method 3; kernels/normals_jacobian.cl) at 4D
    points (..., 4), unit, in camera coordinates; 0 where degenerate or NaN."""
    f = scene.fractal
    fr = camera_frame(scene)
    p = np.asarray(points, np.float64)
    out = np.zeros(p.shape[:-1] + (3,))
    ok = np.all(np.isfinite(p), -1)
    if ok.any():
        g = ref.normal_jacobian(p[ok], f.c, f.max_iter, f.bailout)
        out[ok] = ref._unit_or_zero(ref._to_camera(g, fr))
    return out


# ---------------------------------------------------------- dispatch

@dataclass
class Truth:
    """Ground truth for one scene's pixels."""
    depth: np.ndarray     # (H, W) float64, +inf on a miss
    hit: np.ndarray       # (H, W) bool
    normal: np.ndarray    # (H, W, 3) float64 unit camera coordinates, 0 on a miss
    kind: str             # "sphere", "real_c" or "converged"
    record: dict = field(default_factory=dict)
    seconds: float = 0.0


def is_real_c(scene: Scene) -> bool:
    c = scene.fractal.c
    return c[1] == 0 and c[2] == 0 and c[3] == 0


def ground_truth(scene: Scene, n_scan: int = 8000, **converged_kw) -> Truth:
    """The best oracle for the scene: analytic for c = 0, the 2D oracle for real c,
    else ``converged_depth``.  The march settings of ``scene`` are ignored; only the
    fractal, camera, slice and image matter."""
    t0 = time.perf_counter()
    f = scene.fractal
    fr = camera_frame(scene)
    w, h = scene.image.width, scene.image.height
    o, d = ref.generate_rays(fr, w, h)
    if all(x == 0 for x in f.c):
        t = sphere_depth(o, d, sphere_radius(f.max_iter, f.bailout))
        hit = np.isfinite(t)
        pts = o + np.where(hit, t, 0)[:, None] * d
        n = np.where(hit[:, None], sphere_normals(pts, fr), 0.0)
        tr = Truth(t.reshape(h, w), hit.reshape(h, w), n.reshape(h, w, 3), "sphere",
                   {"radius": sphere_radius(f.max_iter, f.bailout)})
    elif is_real_c(scene):
        rec: dict = {}
        t = real_c_depth(o, d, f.c[0], f.max_iter, f.bailout, n_scan=n_scan, record=rec)
        hit = np.isfinite(t)
        pts = np.where(hit[:, None], o + np.where(hit, t, 0)[:, None] * d, np.nan)
        n = jacobian_normals(pts, scene)
        tr = Truth(t.reshape(h, w), hit.reshape(h, w), n.reshape(h, w, 3), "real_c", rec)
    else:
        cd = converged_depth(scene, **converged_kw)
        n = jacobian_normals(cd.points, scene)
        tr = Truth(cd.depth, cd.hit, n, "converged",
                   {"converged": cd.converged, "tol": cd.tol, "frac": cd.frac, "confirm": cd.confirm,
                    "post_steps": cd.post_steps, "steps": cd.record})
    tr.seconds = time.perf_counter() - t0
    return tr
