"""Ground truth for the accuracy benchmark: depth and normals that do
not come from the marching method under test.

Three oracles, from exact to merely converged:

* ``sphere_depth`` - c = 0: |q_n| = |p|^(2^n), so the max_iter-truncated set
  (|q_n| <= bailout for n = 0..max_iter, Ödegaard & Wennergren §2.1 eq. 5,
  POV-Ray 3.6 documentation) is the 4-ball of radius bailout^(2^-max_iter); depth is the analytic
  ray-ball entry and the normal is radial.
* ``real_c_inside`` / ``real_c_depth`` - real c = (c1, 0, 0, 0): for q = x + r u
  with u a unit pure quaternion, u^2 = -1, so span(1, u) is a copy of the complex
  numbers that q -> q^2 + c1 never leaves (Ödegaard & Wennergren eqs. 3-4).  The quaternion set
  is the complex filled Julia set of c1 turned about the real axis: (x, y, z, w) is
  inside exactly when x + i sqrt(y^2 + z^2 + w^2) is.  A float64 2D iteration with
  a fine scan and bisection along each ray gives the depth.
* ``converged_depth`` - any c: the double-precision kernel (render.float =
  "double") scanning at fixed z-resolution with many post-steps (Ödegaard & Wennergren §3 and
  §7.1 eq. 11-12), the z-resolution doubled until a further doubling moves the
  depth by less than ``tol`` on all but ``frac`` of the pixels; the depth is then
  polished in float64 numpy (bisection with ``reference.julia_inside``) because
  ``RenderResult.depth`` is stored as float32.
* ``de_depth`` - any c but 0, a second search beside the two scans above: the
  double-precision kernels' distance-estimate march with epsilon 1e-10 (four decades
  below the finest float32 setting benchmarked) and 60 ITP steps, polished the same way.
  At max_iter 20-50 the truncated set has inside runs 1e-9 to 1e-6 long in front of its
  thick surface (hairs and dust around the limit set): a scan at any practical
  resolution steps over most of them (at max_iter 50 a doubling from 128,000 to 256,000
  still moves 16-30 % of the pixels), while the estimate's steps shrink near the set.
  ``ground_truth`` keeps, per pixel, the EARLIER of the scan's and this march's crossings,
  each verified in float64 (an outside point just before it, an inside point at it):
  every verified inside point bounds the first crossing from above, so the combination
  can only move the truth closer to it.  Neither is a float32 setting under test; the
  record counts the pixels each search found first.

Ground-truth normals: radial for c = 0, otherwise the float64 analytic Jacobian
normal grad |q_n|^2 = 2 J^T q_n (Quilez (n.d.) "method 3", ``reference.normal_jacobian``)
at a point verified outside just in front of the ground-truth crossing
(``outside_points``: n is the iteration at which it escapes), projected to camera
coordinates exactly like normals/jacobian.cl.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from pyjulia4d import reference as ref
from pyjulia4d.geometry.bounds import bounding_radius
from pyjulia4d.geometry.camera import camera_frame
from pyjulia4d.opencl.executor import render
from pyjulia4d.pipeline.codes import STATUS_HIT
from pyjulia4d.scene.model import Scene
from pyjulia4d.fractal.registry import has_distance_estimate
from pyjulia4d.measure.ray_scan import bisect, first_inside, ray_interval


# ------------------------------------------------------------------ c = 0

def sphere_radius(max_iter: int, bailout: float) -> float:
    """Radius of the max_iter-truncated c = 0 set: bailout^(2^-max_iter)."""
    return float(bailout) ** (2.0 ** -int(max_iter))


def sphere_depth(origins, dirs, radius):
    """c = 0 (Ödegaard & Wennergren eq. 5 with mu = 0; tests/accuracy/test_ball.py): distance along each
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
    return ref.unit_or_zero(ref.to_camera(np.asarray(points, np.float64), frame))


# --------------------------------------------------------------- real c

def real_c_inside(points, c1, max_iter, bailout):
    """Real c = (c1, 0, 0, 0) (Ödegaard & Wennergren eqs. 3-5): (x, y, z, w) is inside exactly when
    the complex point x + i sqrt(y^2 + z^2 + w^2) stays within ``bailout`` for
    n = 0..max_iter under z -> z^2 + c1 - the same escape rule as
    ``reference.julia_inside`` (POV-Ray 3.6 documentation), iterated in float64 complex arithmetic."""
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


def real_c_depth(origins, dirs, c1, max_iter, bailout, near=None, far=None,
                 n_scan=8000, radius=None, record=None):
    """Real c = (c1, 0, 0, 0): depth along each unit ray o + t d to the first point of
    the quaternion set, via the float64 2D oracle ``real_c_inside``.

    Each ray is scanned at ``n_scan`` equal steps between ``near`` and ``far`` (default:
    its entry into and exit from the provably bounding 4-ball of
    ``bounds.bounding_radius``, the interval the march kernel scans), then the bracket
    [last outside sample, first inside sample] is bisected 60 times in float64.  The
    scan is repeated at 2 n_scan; where the two differ (a strand thinner than a step
    found only by the finer scan) the finer answer is kept, and ``record`` (a dict, if
    given) gets the number of such rays and the scans used.  +inf for a miss.
    """
    o = np.asarray(origins, np.float64)
    d = np.asarray(dirs, np.float64)
    if radius is None:
        radius = bounding_radius((c1, 0, 0, 0), bailout, max_iter)
    nr, fr_, live = ray_interval(o, d, radius)
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
        first = first_inside(inside, o[k], d[k], nr[k], fr_[k], n)
        t = np.full(len(k), np.inf)
        h = (fr_[k] - nr[k]) / n
        at0 = first == 0
        t[at0] = nr[k][at0]
        ok = first > 0
        t[ok] = bisect(inside, o[k][ok], d[k][ok], nr[k][ok] + (first[ok] - 1) * h[ok],
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


def ulp32(t):
    """Spacing of float32 numbers at |t| (at least float32's smallest normal)."""
    t = np.abs(np.asarray(t, np.float64)).astype(np.float32)
    return (np.nextafter(t, np.float32(np.inf)) - t).astype(np.float64) + 1e-38


def _refine_first(inside_fn, o, d, lo, hi, near=None, n_scan=256, steps=40, back=40):
    """A float64-verified crossing near [lo, hi]: the first inside one of n_scan + 1
    equal samples of [lo, hi], bisected against the sample before it.  Where lo itself is
    inside, the search steps back (lo - 2^k (hi - lo), k = 1..back, not before ``near``)
    to an outside point and scans from there: an inside point in front of the kernel's
    crossing means a part it stepped over, and the truth is the earlier crossing.  Returns
    (t, ok): ok where an outside sample and the inside one after it were found (t then
    lies within float64 resolution of a crossing); elsewhere t = hi."""
    n = len(lo)
    lo, hi = lo.copy(), hi.copy()
    near = np.zeros(n) if near is None else np.asarray(near, np.float64)
    t = hi.copy()
    ok = np.zeros(n, bool)
    width = hi - lo
    # lo inside: step back to an outside point
    todo = np.nonzero(inside_fn(o + lo[:, None] * d))[0]
    for k in range(1, back + 1):
        if todo.size == 0:
            break
        x = np.maximum(lo[todo] - np.ldexp(width[todo], k), near[todo])
        out = ~inside_fn(o[todo] + x[:, None] * d[todo])
        lo[todo[out]] = x[out]
        stuck = ~out & (x <= near[todo])
        todo = todo[~out & ~stuck]
    first = first_inside(inside_fn, o, d, lo, hi, n_scan)
    h = (hi - lo) / n_scan
    k = np.nonzero(first > 0)[0]
    if k.size:
        a = lo[k] + (first[k] - 1) * h[k]
        b = lo[k] + first[k] * h[k]
        t[k] = bisect(inside_fn, o[k], d[k], a, b, steps=steps)
        ok[k] = True
    return t, ok


def _polish(scene: Scene, depth32, hit, inside_fn=None):
    """Float64 refinement of a float32-stored depth from a double-precision kernel: where
    [t - delta, t + delta] (delta = 2 float32 spacings of t + 1e-9, more than float32
    rounding of the kernel's double depth) holds an inside point, the first inside one
    of 257 samples in it (after stepping back to an outside point if t - delta is inside,
    ``_refine_first``) is bisected to float64 resolution; elsewhere t is kept.  Returns
    (depth, points, verified) with verified the mask of the first case."""
    f = scene.fractal
    fr = camera_frame(scene)
    w, h = scene.image.width, scene.image.height
    o, d = ref.generate_rays(fr, w, h)
    t = depth32.ravel().astype(np.float64)
    k = np.nonzero(hit.ravel())[0]
    out = t.copy()
    verified = np.zeros(t.size, bool)
    if inside_fn is None:
        F = ref.formula_of(f)
        inside_fn = lambda p: ref.julia_inside(p, f.c, f.max_iter, f.bailout, F)
    if k.size:
        tk = t[k]
        delta = 2.0 * ulp32(tk) + 1e-9
        lo, hi = np.maximum(tk - delta, 0.0), tk + delta
        tt, ok = _refine_first(inside_fn, o[k], d[k], lo, hi)
        out[k[ok]] = tt[ok]
        verified[k[ok]] = True
    pts = np.where(hit.ravel()[:, None], o + np.where(np.isfinite(out), out, 0)[:, None] * d, np.nan)
    return out.reshape(h, w), pts.reshape(h, w, 4), verified.reshape(h, w)


def converged_depth(scene: Scene, z_start: int = 8000, post_steps: int = 20, tol: float = 1e-6,
                    frac: float = 0.002, max_z: int = 256000, confirm: int = 2,
                    device=None) -> ConvergedDepth:
    """Any c: depth from the double-precision kernel's fixed scan (Ödegaard & Wennergren §3) with
    ``post_steps`` post-steps (Ödegaard & Wennergren §7.1; eq. 12 puts the bracket at
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
    depth, pts, _ = _polish(base, r.depth, hit)
    depth = np.where(hit, depth, np.inf)
    return ConvergedDepth(depth=depth, hit=hit, points=pts, record=record, converged=converged,
                          tol=tol, frac=frac, post_steps=post_steps, confirm=confirm)


DE_EPSILON = 1e-10
DE_POST_STEPS = 60
DE_MAX_STEPS = 100000


def de_depth(scene: Scene, epsilon: float = DE_EPSILON, post_steps: int = DE_POST_STEPS,
             max_steps: int = DE_MAX_STEPS, device=None):
    """The double-precision kernels' distance-estimate march (march/de.cl) with a tiny
    ``epsilon`` and ``post_steps`` ITP steps, its depth polished in float64 (``_polish``).
    Returns (depth (+inf where no verified crossing), hit (verified crossings only),
    record): rays it hit, rays whose crossing float64 verified, capped rays, guards, time."""
    s = scene.with_overrides(["march.method=de", f"march.epsilon={epsilon}", f"march.post_steps={post_steps}",
                              "march.refine=itp", f"march.max_steps={max_steps}", "render.float=double",
                              "normals.method=jacobian"])
    t0 = time.perf_counter()
    r = render(s, device=device)
    hit = r.status == STATUS_HIT
    depth, _, ok = _polish(s, r.depth, hit)
    rec = {"epsilon": epsilon, "post_steps": post_steps, "max_steps": max_steps,
           "seconds": round(time.perf_counter() - t0, 3), "hit": int(hit.sum()), "verified": int(ok.sum()),
           "capped": r.capped, "shell_miss": r.guards.get("shell_miss", 0)}
    return np.where(ok, depth, np.inf), ok, rec


def earliest(o, d, t_scan, t_de, tol: float = 1e-6) -> tuple[np.ndarray, dict]:
    """Per ray the earlier of two verified crossings (+inf = none), and a record: rays where
    each was earlier by more than ``tol`` (a miss counting as +inf) and the largest and
    99th-percentile size of the de march's lead."""
    t_scan = np.asarray(t_scan, np.float64).ravel()
    t_de = np.asarray(t_de, np.float64).ravel()
    t = np.minimum(t_scan, t_de)
    with np.errstate(invalid="ignore"):
        lead = t_scan - t_de
    de_first = (np.isinf(t_scan) & np.isfinite(t_de)) | (np.isfinite(t_scan) & (lead > tol))
    scan_first = (np.isinf(t_de) & np.isfinite(t_scan)) | (np.isfinite(t_de) & (-lead > tol))
    both = np.isfinite(t_scan) & np.isfinite(t_de) & (lead > tol)
    rec = {"rays_hit": int(np.isfinite(t).sum()), "de_first": int(de_first.sum()),
           "scan_first": int(scan_first.sum()), "de_only": int((np.isinf(t_scan) & np.isfinite(t_de)).sum()),
           "scan_only": int((np.isinf(t_de) & np.isfinite(t_scan)).sum()),
           "de_lead_p99": float(np.percentile(lead[both], 99)) if both.any() else 0.0,
           "de_lead_max": float(lead[both].max()) if both.any() else 0.0, "tol": tol}
    return t, rec


# ------------------------------------------------------------ normals

def jacobian_normals(points, scene: Scene):
    """Float64 analytic normal (Quilez (n.d.) method 3; normals/jacobian.cl) at 4D
    points (..., 4), unit, in camera coordinates; 0 where degenerate or NaN."""
    f = scene.fractal
    fr = camera_frame(scene)
    p = np.asarray(points, np.float64)
    out = np.zeros(p.shape[:-1] + (3,))
    ok = np.all(np.isfinite(p), -1)
    if ok.any():
        g = ref.normal_jacobian(p[ok], f.c, f.max_iter, f.bailout, formula=ref.formula_of(f))
        out[ok] = ref.unit_or_zero(ref.to_camera(g, fr))
    return out


def outside_points(o, d, t, inside_fn, rel: float = 1e-12, tries: int = 8):
    """Points just in front of the crossings t (+inf: none) on rays o + t d, verified outside
    (NaN where none is found within rel * 10^tries * max(1, t)).  The surface there is the
    level set |q_n|^2 = bailout^2 of the iteration n at which these points escape, so the
    normal is taken there (as the kernels do at their depth, the bracket's outside end),
    not at the inside point, whose orbit never escapes and whose |q_N|^2 can belong to
    another level set entirely (the hypercomplex functions)."""
    t = np.asarray(t, np.float64).ravel()
    out = np.full((t.size, 4), np.nan)
    todo = np.nonzero(np.isfinite(t))[0]
    step = rel * np.maximum(1.0, t)
    for _ in range(tries):
        if todo.size == 0:
            break
        x = np.maximum(t[todo] - step[todo], 0.0)
        p = o[todo] + x[:, None] * d[todo]
        ok = ~inside_fn(p)
        out[todo[ok]] = p[ok]
        todo = todo[~ok]
        step[todo] *= 10.0
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


def is_quaternion_sqr(scene: Scene) -> bool:
    """The analytic and 2D oracles hold for the Julia sets of q -> q^2 + c over the
    quaternions only (not a Mandelbrot set, not a rotated map)."""
    f = scene.fractal
    return f.algebra == "quaternion" and f.function == "sqr" and f.kind == "julia" and f.theta == 0


def is_real_c(scene: Scene) -> bool:
    c = scene.fractal.c
    return is_quaternion_sqr(scene) and c[1] == 0 and c[2] == 0 and c[3] == 0


def ground_truth(scene: Scene, n_scan: int = 8000, de_search: bool = True, **converged_kw) -> Truth:
    """The best oracle for the scene: for the quaternion square analytic at c = 0 and the
    2D oracle at real c; else ``converged_depth`` (every algebra and function); where the
    pair has a distance estimate (``de_search``) the earlier, per pixel, of that scan's and
    ``de_depth``'s float64-verified crossings (``earliest``).  The march
    settings of ``scene`` are ignored; only the fractal, camera, slice and image matter."""
    t0 = time.perf_counter()
    f = scene.fractal
    fr = camera_frame(scene)
    w, h = scene.image.width, scene.image.height
    o, d = ref.generate_rays(fr, w, h)
    if is_quaternion_sqr(scene) and all(x == 0 for x in f.c):
        t = sphere_depth(o, d, sphere_radius(f.max_iter, f.bailout))
        hit = np.isfinite(t)
        pts = o + np.where(hit, t, 0)[:, None] * d
        n = np.where(hit[:, None], sphere_normals(pts, fr), 0.0)
        tr = Truth(t.reshape(h, w), hit.reshape(h, w), n.reshape(h, w, 3), "sphere",
                   {"radius": sphere_radius(f.max_iter, f.bailout)})
        tr.seconds = time.perf_counter() - t0
        return tr
    if is_real_c(scene):
        rec: dict = {}
        t = real_c_depth(o, d, f.c[0], f.max_iter, f.bailout, n_scan=n_scan, record=rec)
        kind = "real_c"
    else:
        cd = converged_depth(scene, **converged_kw)
        t = cd.depth.ravel()
        kind = "converged"
        rec = {"converged": cd.converged, "tol": cd.tol, "frac": cd.frac, "confirm": cd.confirm,
               "post_steps": cd.post_steps, "steps": cd.record}
    if de_search and has_distance_estimate(f):
        t_de, _, de_rec = de_depth(scene)
        t, comb = earliest(o, d, t, t_de.ravel())
        rec["de_search"] = de_rec | comb
    hit = np.isfinite(t)
    F = ref.formula_of(f)
    pts = outside_points(o, d, t, lambda p: ref.julia_inside(p, f.c, f.max_iter, f.bailout, F))
    n = jacobian_normals(pts, scene)
    tr = Truth(t.reshape(h, w), hit.reshape(h, w), n.reshape(h, w, 3), kind, rec)
    tr.seconds = time.perf_counter() - t0
    return tr
