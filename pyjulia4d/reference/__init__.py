"""Float64 numpy twin of the OpenCL kernels, function for function.

Each name here is the name of a kernel function or kernel in kernels/*.cl, with
the same formula, the same loop bounds and the same guards, vectorised over a
batch of points or rays instead of one per work-item.  It is slow and exact to
float64: the tests hold the kernels to it, and it can render a small scene.  The
algebras and functions mirror kernels/algebra/ and kernels/function/ file for file
(reference/algebra/, reference/function/), assembled by reference/formula.py; every
function taking ``formula`` defaults to the quaternion square.
"""
from __future__ import annotations

import time

import numpy as np

from pyjulia4d.geometry.camera import Frame, camera_frame, clip_planes, light_position, march_radius
from pyjulia4d.pipeline.codes import (GUARD_JACOBIAN_TINY, GUARD_NORMAL_FALLBACK, GUARD_SHELL_MISS, GUARD_ULP_STEP, STATUS_CAPPED,
                     STATUS_HIT, STATUS_MISS)
from pyjulia4d.pipeline.plan import fog_start, gradient_step, light_parameters
from pyjulia4d.pipeline.result import RenderResult, count_guards
from pyjulia4d.scene.model import Scene
from pyjulia4d.fractal.registry import march_method

REAL_MIN = np.finfo(np.float64).tiny
from pyjulia4d.pipeline.codes import FLAG_CUT_FACE  # noqa: E402  (kernels/codes.cl)


def _dot(a, b):
    return np.sum(a * b, axis=-1)


# ------------------------------------ algebra/*.cl, function/*.cl (formula.py)
# The quaternion square's pieces stay importable here (ref.alg_mul, ref.alg_sqr, ...).
from pyjulia4d.reference.algebra.quaternion import alg_mul, alg_sqr, alg_sqr_jvp  # noqa: E402,F401
from pyjulia4d.reference.formula import QUATERNION_SQR, Formula, formula_of  # noqa: E402,F401
from pyjulia4d.pipeline import colormap  # noqa: E402
from pyjulia4d.reference.kind import mandelbrot as _mandelbrot  # noqa: E402
from pyjulia4d.reference.kind.level import kind_level  # noqa: E402
from pyjulia4d.reference.kind import julia_stack as _stack  # noqa: E402
from pyjulia4d.reference.kind import cubic_locus as _locus  # noqa: E402


# ------------------------------------------------------------------ iterate.cl

def julia_inside(p, c, max_iter, bailout, formula: Formula = QUATERNION_SQR):
    """|q_n| <= bailout for n = 0..max_iter (seed 003; seed 000 eq. 5)."""
    F = formula
    if F.kind == "mandelbrot":   # kernels/kind/mandelbrot.cl takes the name over
        return _mandelbrot.mandel_inside(p, max_iter, bailout, F)
    if F.kind == "julia_stack":  # kernels/kind/julia_stack.cl likewise
        return _stack.stack_inside(p, max_iter, bailout, F)
    if F.kind == "cubic_locus":  # kernels/kind/cubic_locus.cl likewise
        return _locus.locus_inside(p, max_iter, bailout, F)
    q = F.ALG_IN(np.array(p, dtype=np.float64)).copy()
    c = F.ALG_C(np.asarray(c, np.float64))
    out = np.ones(q.shape[:-1], bool)
    b2 = bailout * bailout
    with np.errstate(all="ignore"):   # inf / NaN iterates count as escaped, as in the kernel
        for _ in range(max_iter):
            out &= F.ALG_NORM2(q) <= b2
            if not out.any():
                return out
            q[out] = F.julia_f(q[out], c)
        return out & (F.ALG_NORM2(q) <= b2)


def julia_level(p, c, max_iter, bailout, formula: Formula = QUATERNION_SQR):
    """F = |q_N|^2 / bailout^2 - 1 (N = max_iter), <= 0 exactly where julia_inside; an orbit
    escaping at n < N is extrapolated as (|q_n|^2 / b^2)^(D^(N-n)) - 1 (D = the growth
    degree), capped at 1e30 (iterate.cl; seed 002).  Returns (F, inside)."""
    F = formula
    if F.kind == "mandelbrot":
        return _mandelbrot.mandel_level(p, max_iter, bailout, F)
    if F.kind == "julia_stack":
        return _stack.stack_level(p, max_iter, bailout, F)
    if F.kind == "cubic_locus":
        return _locus.locus_level(p, max_iter, bailout, F)
    q = F.ALG_IN(np.array(p, dtype=np.float64)).copy()
    c = F.ALG_C(np.asarray(c, np.float64))
    b2 = bailout * bailout
    m2 = F.ALG_NORM2(q)
    n = np.zeros(m2.shape, np.int64)
    live = np.ones(m2.shape, bool)
    with np.errstate(all="ignore"):
        for _ in range(max_iter):
            live &= m2 <= b2
            if not live.any():
                break
            q[live] = F.julia_f(q[live], c)
            m2[live] = F.ALG_NORM2(q[live])
            n[live] += 1
    inside = m2 <= b2
    return np.where(inside, m2 / b2 - 1.0, kind_level(m2, b2, max_iter - n, F.growth)), inside


def julia_distance_formula(p, c, max_iter, bailout, formula: Formula = QUATERNION_SQR):
    """d = |q_n| ln|q_n| / (2|q_n'|) (seed 001_01b4b6353b5280e3.txt eq. 8) at the last
    iterate, derivative carried squared and rescaled as mantissa * 2^e; returns
    (d, escaped)."""
    F = formula
    if F.kind == "mandelbrot":
        return _mandelbrot.mandel_distance_formula(p, max_iter, bailout, F)
    if F.kind == "julia_stack":   # the empirical estimate (-D STACK_DE)
        return _stack.stack_distance_formula(p, max_iter, bailout, F)
    if F.split:
        return _split_distance_formula(p, c, max_iter, bailout, F)
    q = F.ALG_IN(np.array(p, dtype=np.float64)).copy()
    c = F.ALG_C(np.asarray(c, np.float64))
    b2 = bailout * bailout
    m2 = F.ALG_NORM2(q)
    dm2 = np.ones_like(m2)
    e = np.zeros(m2.shape, np.int64)
    live = np.ones(m2.shape, bool)
    for _ in range(max_iter):
        live &= m2 <= b2
        if not live.any():
            break
        dm2[live] *= F.JULIA_DF2(m2[live])
        big = live & (dm2 > 1e16)
        if big.any():
            mant, k = np.frexp(dm2[big])
            dm2[big] = mant
            e[big] += k
        q[live] = F.julia_f(q[live], c)
        m2[live] = F.ALG_NORM2(q[live])
    escaped = m2 > b2
    mq = np.maximum(m2, REAL_MIN)
    ratio = np.sqrt(mq / np.maximum(dm2, REAL_MIN)) * np.exp2(-(e / 2.0))
    return ratio * np.log(mq) / 4.0, escaped


def _de_value(m2, dm2, e):
    """d = |q| ln|q| / (2 |q'|) from m2, dm2 * 2^e (iterate.cl de_value)."""
    mq = np.maximum(m2, REAL_MIN)
    ratio = np.sqrt(mq / np.maximum(dm2, REAL_MIN)) * np.exp2(-(e / 2.0))
    return ratio * np.log(mq) / 4.0


def _split_distance_formula(p, c, max_iter, bailout, F: Formula):
    """The split algebra's estimate (iterate.cl, ALG_SPLIT): d = sqrt(d_a^2 + d_b^2) / sqrt(2),
    each component's complex estimate where it has escaped past 1 + |c_component|, else 0."""
    q = F.ALG_IN(np.array(p, dtype=np.float64)).copy()
    c = F.ALG_C(np.asarray(c, np.float64))
    b2 = bailout * bailout
    m2 = F.ALG_NORM2(q)
    da, db = np.ones_like(m2), np.ones_like(m2)
    ea, eb = np.zeros(m2.shape, np.int64), np.zeros(m2.shape, np.int64)
    live = np.ones(m2.shape, bool)

    def grow(dm2, e, factor, live):
        dm2[live] *= factor[live]
        big = live & (dm2 > 1e16)
        if big.any():
            mant, k = np.frexp(dm2[big])
            dm2[big] = mant
            e[big] += k

    for _ in range(max_iter):
        live &= m2 <= b2
        if not live.any():
            break
        grow(da, ea, F.alg.JULIA_DF2(q[..., 0] ** 2 + q[..., 1] ** 2, F.fn.FUNC_POWER), live)
        grow(db, eb, F.alg.JULIA_DF2(q[..., 2] ** 2 + q[..., 3] ** 2, F.fn.FUNC_POWER), live)
        q[live] = F.julia_f(q[live], c)
        m2[live] = F.ALG_NORM2(q[live])
    escaped = m2 > b2
    ma, mb = q[..., 0] ** 2 + q[..., 1] ** 2, q[..., 2] ** 2 + q[..., 3] ** 2
    ra, rb = 1 + np.hypot(c[0], c[1]), 1 + np.hypot(c[2], c[3])
    d_a = np.where(ma > ra * ra, _de_value(ma, da, ea), 0.0)
    d_b = np.where(mb > rb * rb, _de_value(mb, db, eb), 0.0)
    return np.sqrt(d_a ** 2 + d_b ** 2) / np.sqrt(2.0), escaped


def julia_distance(p, c, max_iter, bailout, formula: Formula = QUATERNION_SQR):
    """The estimate the march steps by: 0 where the point never escaped."""
    d, escaped = julia_distance_formula(p, c, max_iter, bailout, formula)
    return np.where(escaped, d, 0.0)


# ------------------------------------------------------------------- march/refine.cl

def refine_bracket(o, d, a, b, steps, c, max_iter, bailout, itp=True, tests=None,
                   formula: Formula = QUATERNION_SQR):
    """Narrow certified brackets [a (outside), b (inside)] on rays o + t d with ``steps``
    set tests: ITP on the level function julia_level (``itp``) or bisection (seed 000
    §7.1 eq. 11-12, every point classified); both stop where the bracket cannot be split.
    Both guarantee width <= (b - a) / 2^steps, ITP with at most one more set test.
    Returns (a, b - a): the outside end is the depth, the crossing lies within the width
    behind it (march/refine.cl).  ``tests`` (int array, optional) gets the set tests each ray took
    (ITP's two end-point level evaluations not counted)."""
    a = np.array(a, np.float64)
    b = np.array(b, np.float64)
    pt = lambda k, t: o[k] + t[:, None] * d[k]
    if itp:
        k = np.arange(len(a))
        fa, _ = julia_level(pt(k, a), c, max_iter, bailout, formula)
        fb, _ = julia_level(pt(k, b), c, max_iter, bailout, formula)
        ya, yb = -np.maximum(fa, REAL_MIN), -np.minimum(fb, 0.0)
        w0 = b - a
        eps = np.ldexp(w0, -(steps + 1))
        k1 = 0.2 / np.where(w0 > 0, w0, 1.0)
    live = np.ones(len(a), bool)
    for j in range(steps + 1 if itp else steps):
        if itp:
            live &= b - a > 2 * eps
        xh = 0.5 * (a + b)
        live &= (xh > a) & (xh < b)
        k = np.nonzero(live)[0]
        if k.size == 0:
            break
        if tests is not None:
            tests[k] += 1
        if itp:
            ak, bk, yak, ybk, xhk = a[k], b[k], ya[k], yb[k], xh[k]
            r = np.ldexp(eps[k], steps + 1 - j) - 0.5 * (bk - ak)
            delta = k1[k] * (bk - ak) ** 2
            with np.errstate(invalid="ignore", divide="ignore"):
                xf = np.where(ybk != yak, (ybk * ak - yak * bk) / (ybk - yak), xhk)
            sigma = np.where(xhk >= xf, 1.0, -1.0)
            xt = np.where(delta <= np.abs(xhk - xf), xf + sigma * delta, xhk)
            x = np.where(np.abs(xt - xhk) <= r, xt, xhk - sigma * r)
            x = np.where((x > ak) & (x < bk), x, xhk)
            f, ins = julia_level(pt(k, x), c, max_iter, bailout, formula)
            y = -f
            b[k] = np.where(ins, x, bk)
            yb[k] = np.where(ins, np.maximum(y, 0.0), ybk)
            a[k] = np.where(ins, ak, x)
            ya[k] = np.where(ins, yak, np.minimum(y, -REAL_MIN))
        else:
            x = xh[k]
            ins = julia_inside(pt(k, x), c, max_iter, bailout, formula)
            b[k] = np.where(ins, x, b[k])
            a[k] = np.where(ins, a[k], x)
    return a, b - a


# ---------------------------------------------------- march/fixed.cl / march/de.cl

def march_fixed(o, d, near, far, c, max_iter, bailout, epsilon, z_resolution, post_steps, max_steps,
                itp=True, formula: Formula = QUATERNION_SQR):
    """Fixed z-resolution scan (seed 000 §3): the first inside sample and the one before it
    are the certified bracket, refined by refine_bracket; a hit at the first sample is near
    itself, width 0.  Returns (t, status, samples, flags, width)."""
    n = len(o)
    h = (far - near) / z_resolution
    t = np.full(n, np.inf)
    width = np.full(n, np.inf)
    status = np.full(n, STATUS_MISS, np.int32)
    samples = np.full(n, z_resolution + 1, np.int32)
    first = np.zeros(n, bool)
    active = np.ones(n, bool)
    for i in range(z_resolution + 1):
        idx = np.nonzero(active)[0]
        if idx.size == 0:
            break
        ti = near[idx] + i * h[idx]
        inside = julia_inside(o[idx] + ti[:, None] * d[idx], c, max_iter, bailout, formula)
        got = idx[inside]
        t[got] = ti[inside]
        status[got] = STATUS_HIT
        samples[got] = i + 1
        first[got] = i == 0
        active[got] = False
    width[first] = 0.0
    k = np.nonzero((status == STATUS_HIT) & ~first)[0]
    if k.size:
        # the kernel's t_prev is near + (i - 1) h, computed as such (not t - h)
        t_prev = near[k] + (samples[k] - 2) * h[k]
        t[k], width[k] = refine_bracket(o[k], d[k], t_prev, t[k], post_steps, c, max_iter, bailout, itp,
                                        formula=formula)
    return t, status, samples, np.zeros(n, np.int32), width


def march_de(o, d, near, far, c, max_iter, bailout, epsilon, z_resolution, post_steps, max_steps,
             itp=True, formula: Formula = QUATERNION_SQR):
    """r_{n+1} = r_n + max(d(r_n), eps) (seed 001 §3.2 eq. 9) until a point is inside (its
    orbit never escaped); with the previous point, the certified bracket refined by
    refine_bracket.  A step that rounds away (t + step == t) becomes one ulp of t
    (GUARD_ULP_STEP); a ray that came within epsilon by the estimate and never got inside
    is a miss flagged GUARD_SHELL_MISS (march/de.cl).  Returns (t, status, samples, flags, width)."""
    n = len(o)
    t = near.copy()
    t_prev = near.copy()
    width = np.full(n, np.inf)
    status = np.full(n, STATUS_CAPPED, np.int32)
    samples = np.full(n, max_steps, np.int32)
    flags = np.zeros(n, np.int32)
    shell = np.zeros(n, bool)
    active = np.ones(n, bool)
    bracketed = np.zeros(n, bool)
    for i in range(max_steps):
        idx = np.nonzero(active)[0]
        if idx.size == 0:
            break
        out = t[idx] > far[idx]
        gone = idx[out]
        status[gone] = STATUS_MISS
        samples[gone] = i
        flags[gone[shell[gone]]] |= GUARD_SHELL_MISS
        active[gone] = False
        idx = idx[~out]
        dist, escaped = julia_distance_formula(o[idx] + t[idx, None] * d[idx], c, max_iter, bailout, formula)
        hit = ~escaped
        got = idx[hit]
        status[got] = STATUS_HIT
        samples[got] = i + 1
        active[got] = False
        if i == 0:
            width[got] = 0.0
        else:
            bracketed[got] = True
        k = idx[~hit]
        shell[k] |= dist[~hit] < epsilon
        t_prev[k] = t[k]
        t[k] = t[k] + np.maximum(dist[~hit], epsilon)
        stall = k[t[k] == t_prev[k]]
        t[stall] = np.nextafter(t_prev[stall], np.inf)
        flags[stall] |= GUARD_ULP_STEP
    k = np.nonzero(bracketed)[0]
    if k.size:
        t[k], width[k] = refine_bracket(o[k], d[k], t_prev[k], t[k], post_steps, c, max_iter, bailout, itp,
                                        formula=formula)
    t[status != STATUS_HIT] = np.inf
    return t, status, samples, flags, width


# --------------------------------------------------------------------- march/march.cl

def march(origins, dirs, c, max_iter, bailout, epsilon, radius, near_set, far_set,
          z_resolution, post_steps, max_steps, method, flags=None, refine="itp", bracket=None,
          formula: Formula = QUATERNION_SQR, clip=None):
    """Clip each ray to the bounding 4-ball (and the ``clip`` half-spaces m . x <= e, world
    space: camera.clip_planes), then march; returns (depth, point, status, samples).  A hit
    at the first point of an interval a plane started is on its cut face: flags get
    FLAG_CUT_FACE | k << 5.
    ``flags`` (int array, optional) gets the march's guard flags (march/march.cl's flags buffer),
    ``bracket`` (float array, optional) each hit's certified bracket width (+inf elsewhere)."""
    o = np.asarray(origins, np.float64)
    d = np.asarray(dirs, np.float64)
    b = _dot(o, d)
    # radius^2 - |o - b d|^2, not b^2 - (|o|^2 - radius^2): no cancellation for a far eye (march/march.cl)
    perp = o - b[:, None] * d
    disc = radius * radius - _dot(perp, perp)
    s = np.sqrt(np.maximum(disc, 0.0))
    near = np.maximum(-b - s, 0.0)
    far = -b + s
    if near_set >= 0:
        near = np.full_like(near, near_set)
    if far_set >= 0:
        far = np.full_like(far, far_set)
    live = disc >= 0
    cut = np.zeros(len(o), np.int64)      # 1 + the plane that set near (march.cl, -D CLIP)
    for k, (m, off) in enumerate(clip or ()):
        dn, on = d @ m, o @ m - off
        with np.errstate(divide="ignore", invalid="ignore"):
            tp = -on / dn
        far = np.where(dn > 0, np.minimum(far, tp), far)
        raise_ = (dn < 0) & (tp > near)
        near = np.where(raise_, tp, near)
        cut = np.where(raise_, k + 1, cut)
        live &= ~((dn == 0) & (on > 0))
    live &= far >= near
    n = len(o)
    depth = np.full(n, np.inf)
    status = np.full(n, STATUS_MISS, np.int32)
    samples = np.zeros(n, np.int32)
    k = np.nonzero(live)[0]
    if k.size:
        fn = march_fixed if method == "fixed" else march_de
        depth[k], status[k], samples[k], fl, wd = fn(o[k], d[k], near[k], far[k], c, max_iter, bailout,
                                                     epsilon, z_resolution, post_steps, max_steps,
                                                     refine == "itp", formula)
        if flags is not None:
            flags[k] |= fl
            face = (status[k] == STATUS_HIT) & (wd == 0) & (cut[k] > 0)
            flags[k[face]] |= FLAG_CUT_FACE | ((cut[k[face]] - 1) << 5)
        if bracket is not None:
            bracket[:] = np.inf
            bracket[k] = np.where(status[k] == STATUS_HIT, wd, np.inf)
    depth[status != STATUS_HIT] = np.inf
    point = np.where((status == STATUS_HIT)[:, None], o + np.where(np.isfinite(depth), depth, 0)[:, None] * d, np.nan)
    return depth, point, status, samples


# ---------------------------------------------------------------------- rays.cl

def sample_hash(x, y, s):
    """rays.cl sample_hash on uint32 arrays."""
    M = 0xFFFFFFFF
    x, y, s = (np.asarray(a, np.uint64) for a in (x, y, s))
    h = ((x * 73856093) & M) ^ ((y * 19349663) & M) ^ ((s * 83492791) & M)
    h = (h ^ 61) ^ (h >> 16)
    h = (h * 9) & M
    h ^= h >> 4
    h = (h * 0x27D4EB2D) & M
    h ^= h >> 15
    return h


def sample_offset(x, y, k: int, n: int):
    """Sample k of n in each pixel (rays.cl sample_offset): (ox, oy) in [0, 1)^2."""
    if n <= 1:
        return np.full(np.shape(x), 0.5), np.full(np.shape(x), 0.5)
    g = int(np.ceil(np.sqrt(np.float32(n))))
    h1 = sample_hash(x, y, 2 * k)
    h2 = sample_hash(x, y, 2 * k + 1)
    return ((k % g + (h1 >> 8).astype(np.float64) / 16777216.0) / g,
            (k // g + (h2 >> 8).astype(np.float64) / 16777216.0) / g)


def generate_rays(frame: Frame, width: int, height: int, x0: int = 0, y0: int = 0,
                  tile_w: int | None = None, tile_h: int | None = None, sample: int = 0, samples: int = 1):
    """Pinhole 4D camera (seed 000 §4): returns (origins, dirs), row-major, row 0 on top,
    for the tile of tile_w x tile_h pixels at (x0, y0) (default: the whole image), through
    sample ``sample`` of ``samples`` of each pixel (its centre for one)."""
    tw = width - x0 if tile_w is None else tile_w
    th = height - y0 if tile_h is None else tile_h
    y, x = np.mgrid[y0:y0 + th, x0:x0 + tw]
    ox, oy = sample_offset(x.ravel(), y.ravel(), sample, samples)
    aspect = width / height
    u = (2 * (x.ravel() + ox) / width - 1) * frame.tan_half_fov * aspect
    v = (1 - 2 * (y.ravel() + oy) / height) * frame.tan_half_fov
    d = frame.forward + u[:, None] * frame.right + v[:, None] * frame.up
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return np.tile(frame.position, (tw * th, 1)), d


# --------------------------------------------------------- normals_*.cl

def _to_camera(g, frame: Frame):
    return np.stack([g @ frame.right, g @ frame.up, -(g @ frame.forward)], axis=-1)


def _unit_or_zero(n):
    """Normalise, 0 where degenerate (used by truth.py; the normals kernels use
    to_camera_unit, which never returns 0 on a hit)."""
    l = np.linalg.norm(n, axis=-1, keepdims=True)
    ok = (l > 0) & np.isfinite(l)
    return np.where(ok, n / np.where(ok, l, 1), 0.0)


def to_camera_unit(n, guard=None):
    """Normalise (the caller projects with _to_camera); a zero or non-finite vector becomes
    the view axis (0, 0, 1), flagged GUARD_NORMAL_FALLBACK in ``guard``
    (normals/jacobian.cl / normals/gradient.cl)."""
    l = np.linalg.norm(n, axis=-1, keepdims=True)
    ok = (l > 0) & np.isfinite(l)
    if guard is not None:
        guard |= np.where(ok[..., 0], 0, GUARD_NORMAL_FALLBACK)
    return np.where(ok, n / np.where(ok, l, 1), np.array([0.0, 0.0, 1.0]))


def normal_jacobian(p, c, max_iter, bailout, guard=None, formula: Formula = QUATERNION_SQR):
    """grad |q_n|^2 = 2 J^T q_n with J carried by the chain rule (seed 004 method 3).
    J is rescaled both ways (no underflow on orbits drawn to an attracting cycle), and the
    iteration stops while q is a normal number, |q|^2 >= sqrt(REAL_MIN): inside points of
    c ~ 0 go to exactly 0 otherwise, and the normal with them (GUARD_JACOBIAN_TINY)."""
    F = formula
    if F.kind == "mandelbrot":   # normals/jacobian.cl, -D KIND_MANDELBROT
        return _mandelbrot.mandel_normal_jacobian(p, max_iter, bailout, F, guard, GUARD_JACOBIAN_TINY)
    if F.kind == "julia_stack":  # KIND_NORMAL: kind/julia_stack.cl stack_normal
        return _stack.stack_normal(p, max_iter, bailout, F, guard, GUARD_JACOBIAN_TINY)
    if F.kind == "cubic_locus":  # KIND_NORMAL: kind/cubic_locus.cl locus_normal
        return _locus.locus_normal(p, max_iter, bailout, F, guard, GUARD_JACOBIAN_TINY)
    q = F.ALG_IN(np.array(p, np.float64)).copy()
    c = F.ALG_C(np.asarray(c, np.float64))
    # J[..., k, :] = column k, in the algebra's coordinates: ALG_IN of the unit vectors
    J = np.broadcast_to(F.ALG_IN(np.eye(4)), q.shape[:-1] + (4, 4)).copy()
    live = np.ones(q.shape[:-1], bool)
    tiny = np.zeros(q.shape[:-1], bool)
    for _ in range(max_iter):
        m2 = F.ALG_NORM2(q)
        live &= m2 <= bailout * bailout
        stop = live & (m2 < np.sqrt(REAL_MIN))
        tiny |= stop
        live &= ~stop
        if not live.any():
            break
        ql = q[live]
        with np.errstate(all="ignore"):
            J[live] = F.julia_f_jvp(np.broadcast_to(ql[:, None, :], J[live].shape), J[live])
            q[live] = F.julia_f(ql, c)
            s = np.linalg.norm(J[live], axis=-1).max(axis=-1)
        big = (s > 1e12) | ((s < 1e-12) & (s > 0))
        if big.any():
            Jl = J[live]
            Jl[big] /= s[big][:, None, None]
            J[live] = Jl
    if guard is not None:
        guard |= np.where(tiny, GUARD_JACOBIAN_TINY, 0)
    with np.errstate(all="ignore"):
        return F.ALG_DOT(J, q[..., None, :])


def normals_jacobian(point, status, c, max_iter, bailout, frame: Frame, guard=None,
                     formula: Formula = QUATERNION_SQR):
    """Unit normals of the hits, 0 elsewhere; ``guard`` (int array, optional) gets the flags."""
    out = np.zeros(point.shape[:-1] + (3,))
    hit = status == STATUS_HIT
    if hit.any():
        g = np.zeros(int(hit.sum()), np.int64)
        out[hit] = to_camera_unit(_to_camera(normal_jacobian(point[hit], c, max_iter, bailout, g, formula), frame), g)
        if guard is not None:
            guard[hit] |= g
    return out


def de_field(p, c, max_iter, bailout, formula: Formula = QUATERNION_SQR):
    return julia_distance_formula(p, c, max_iter, bailout, formula)[0]


def normal_gradient(p, c, max_iter, bailout, h, frame: Frame, formula: Formula = QUATERNION_SQR):
    """6-point central difference of the estimate (seed 001 §4.1.2 eq. 15) along the camera axes."""
    f = lambda x: de_field(x, c, max_iter, bailout, formula)
    r, u, w = frame.right, frame.up, frame.forward
    return np.stack([f(p + h * r) - f(p - h * r), f(p + h * u) - f(p - h * u),
                     f(p - h * w) - f(p + h * w)], axis=-1)


def normals_gradient(point, status, c, max_iter, bailout, h, frame: Frame, guard=None,
                     formula: Formula = QUATERNION_SQR):
    out = np.zeros(point.shape[:-1] + (3,))
    hit = status == STATUS_HIT
    if hit.any():
        g = np.zeros(int(hit.sum()), np.int64)
        with np.errstate(invalid="ignore"):
            out[hit] = to_camera_unit(normal_gradient(point[hit], c, max_iter, bailout, h, frame, formula), g)
        if guard is not None:
            guard[hit] |= g
    return out


def normals_zbuffer(point, depth, status, width, height, frame: Frame, guard=None):
    """Plane through the hit and its neighbours' hits (seed 000 §5.1, seed 001 §4.1.1);
    per axis the central difference where both neighbours' depth jumps are within a
    factor 2, else the one-sided difference with the smaller jump, else the image axis."""
    P = _to_camera(np.nan_to_num(point.reshape(height, width, 4)) - frame.position, frame)
    Z = depth.reshape(height, width)
    H = (status == STATUS_HIT).reshape(height, width)

    def shifted(a, dy, dx, fill):
        out = np.full_like(a, fill)
        ys = slice(max(dy, 0), height + min(dy, 0))
        yd = slice(max(-dy, 0), height + min(-dy, 0))
        xs = slice(max(dx, 0), width + min(dx, 0))
        xd = slice(max(-dx, 0), width + min(-dx, 0))
        out[yd, xd] = a[ys, xs]
        return out

    def tangent(da, db, axis):
        # neighbour a at offset da (the "-1" side), b at db (the "+1" side)
        ok_a, ok_b = shifted(H, *da, False), shifted(H, *db, False)
        za, zb = shifted(Z, *da, np.inf), shifted(Z, *db, np.inf)
        both = ok_a & ok_b
        with np.errstate(invalid="ignore"):  # inf - inf where neither hit: masked below
            ja, jb = np.abs(za - Z), np.abs(zb - Z)
        central = both & (np.maximum(ja, jb) <= 2 * np.minimum(ja, jb))
        a_wins = both & (ja < jb)
        ok_a_final = ok_a & (~both | a_wins)
        ok_b_final = ok_b & (~both | ~a_wins)
        pa, pb = shifted(P, *da, 0.0), shifted(P, *db, 0.0)
        t = np.broadcast_to(np.asarray(axis, float), P.shape).copy()
        t = np.where(ok_a_final[..., None], P - pa, t)
        t = np.where(ok_b_final[..., None], pb - P, t)
        return np.where(central[..., None], 0.5 * (pb - pa), t)

    tx = tangent((0, -1), (0, 1), (1, 0, 0))   # left, right
    ty = tangent((1, 0), (-1, 0), (0, 1, 0))   # row below, row above (image y grows down)
    n = np.cross(tx, ty)
    view = -P
    n = np.where((_dot(n, view) < 0)[..., None], -n, n)
    l = np.linalg.norm(n, axis=-1, keepdims=True)
    bad = ~((l > 0) & np.isfinite(l))
    n = np.where(bad, view, n)
    # the hit is the eye itself (camera inside the set): the view axis (normals/zbuffer.cl)
    lv = np.linalg.norm(n, axis=-1, keepdims=True)
    n = np.where(bad & ~((lv > 0) & np.isfinite(lv)), np.array([0.0, 0.0, 1.0]), n)
    n = n / np.linalg.norm(n, axis=-1, keepdims=True)
    if guard is not None:
        guard |= np.where((bad[..., 0] & H).ravel(), GUARD_NORMAL_FALLBACK, 0)
    return np.where(H[..., None], n, 0.0).reshape(-1, 3)


# --------------------------------------------------------------------- shade.cl

def clip_normals(flags, status, frame: Frame, planes, normal):
    """march/clip.cl: hits on a cut face take their plane's normal (camera coordinates)."""
    face = (status == STATUS_HIT) & ((np.asarray(flags) & FLAG_CUT_FACE) != 0)
    if not face.any():
        return normal
    out = normal.copy()
    k = (np.asarray(flags)[face] >> 5) & 3
    m = np.array([planes[i][0] for i in k])
    out[face] = _unit_or_zero(_to_camera(m, frame))
    return out


# -------------------------------------------------------------------- pipeline

def flag_edges(color, alpha, threshold: float):
    """Twin of antialias.flag_edges, written apart: (H, W) bool, True where some pixel of the
    3 x 3 neighbourhood (clipped to the image) differs from the centre by more than
    ``threshold`` in alpha or in a channel of the sRGB-encoded colour."""
    v = np.concatenate([colormap.linear_to_srgb(np.nan_to_num(np.asarray(color, np.float64))),
                        np.nan_to_num(np.asarray(alpha, np.float64))[..., None]], axis=-1)
    h, w = v.shape[:2]
    p = np.pad(v, ((1, 1), (1, 1), (0, 0)), mode="edge")   # an edge copy never differs
    out = np.zeros((h, w), bool)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            out |= np.abs(p[1 + dy:1 + dy + h, 1 + dx:1 + dx + w] - v).max(axis=-1) > threshold
    return out


def render(scene: Scene) -> RenderResult:
    """The whole pipeline in float64 numpy (slow: for small images).  With image.samples = S
    > 1 the colour and alpha are the mean of S more passes through stratified samples of
    each pixel (rays.cl sample_offset); everything else comes from the pixel centres.  With
    image.adaptive, only the pixels flag_edges flags in the centre pass take that mean.
    camera.fit frames the set as render.render does (framing.py), from a float64 first
    pass: the camera may differ from the kernels' in its last bits (their pass is float32),
    so compare with ``reference.render(result.scene)`` for the kernels' own camera."""
    t0 = time.perf_counter()
    if scene.camera.fit:
        from pyjulia4d.pipeline.framing import fit_camera
        scene, _ = fit_camera(scene, lambda s, outs: render(s))
    frame = camera_frame(scene)
    w, h = scene.image.width, scene.image.height
    sh = scene.shading

    def one_pass(sample: int, samples: int):
        f, m = scene.fractal, scene.march
        F = formula_of(f)
        origins, dirs = generate_rays(frame, w, h, sample=sample, samples=samples)
        near = -1.0 if m.near == "auto" else float(m.near)
        far = -1.0 if m.far == "auto" else float(m.far)
        guard = np.zeros(len(origins), np.int64)
        bracket = np.full(len(origins), np.inf)
        depth, point, status, smp = march(origins, dirs, f.c, f.max_iter, f.bailout, m.epsilon,
                                          march_radius(scene), near, far, m.z_resolution,
                                          m.post_steps, m.max_steps, march_method(scene), guard, m.refine,
                                          bracket, F, planes)
        if scene.normals.method == "jacobian":
            normal = normals_jacobian(point, status, f.c, f.max_iter, f.bailout, frame, guard, F)
        elif scene.normals.method == "gradient":
            step = gradient_step(scene)
            normal = normals_gradient(point, status, f.c, f.max_iter, f.bailout, step, frame, guard, F)
        else:
            normal = normals_zbuffer(point, depth, status, w, h, frame, guard)
        normal = clip_normals(guard, status, frame, planes, normal)
        refl = None
        if sh.reflection > 0:   # shade/reflect.cl: one mirror bounce, marched like a camera ray
            from pyjulia4d.reference.shade import reflect_color, reflect_rays
            radius = march_radius(scene)
            o2, d2 = reflect_rays(point, normal, status, frame, light_parameters(scene, radius)["bias"], radius)
            g2 = np.zeros(len(o2), np.int64)
            _, p2, s2, _ = march(o2, d2, f.c, f.max_iter, f.bailout, m.epsilon, radius, near, far,
                                 m.z_resolution, m.post_steps, m.max_steps, march_method(scene), g2, m.refine,
                                 None, F, planes)
            if scene.normals.method == "jacobian":
                n2 = normals_jacobian(p2, s2, f.c, f.max_iter, f.bailout, frame, g2, F)
            else:
                n2 = normals_gradient(p2, s2, f.c, f.max_iter, f.bailout, gradient_step(scene), frame, g2, F)
            n2 = clip_normals(g2, s2, frame, planes, n2)
            refl = reflect_color(s2, n2, p2, d2, frame, light_position(scene), sh.color, sh.background,
                                 sh.light_color, sh.sky, sh.ambient, sh.diffuse)
        from pyjulia4d.reference.shade import extra_visibility_of_scene, light_terms_of_scene, shade
        terms = light_terms_of_scene(scene, point, normal, status, bracket, F)
        lut = colormap.table(sh.colormap) if sh.coloring != "flat" else None
        from pyjulia4d.geometry.camera import extra_lights
        geo, rgb = extra_lights(scene) if sh.lights else (None, None)
        rgba = shade(status, normal, point, frame, light_position(scene), sh.color, sh.background,
                     sh.light_color, sh.ambient, sh.diffuse, sh.specular, sh.shininess, terms, lut,
                     sh.fog, fog_start(frame.position, march_radius(scene)), sh.sky, geo, rgb,
                     extra_visibility_of_scene(scene, point, normal, status, F), refl, sh.reflection)
        return rgba, depth, point, status, smp, normal, guard, bracket

    planes = clip_planes(scene)
    rgba, depth, point, status, smp, normal, guard, bracket = one_pass(0, 1)
    S = scene.image.samples
    if S > 1:
        mean = np.mean([one_pass(k, S)[0] for k in range(S)], axis=0)
        if scene.image.adaptive:   # antialias.py: the flagged pixels alone take the mean
            from pyjulia4d.pipeline.antialias import THRESHOLD
            flags = flag_edges(rgba[:, :3].reshape(h, w, 3), rgba[:, 3].reshape(h, w), THRESHOLD).ravel()
            mean = np.where(flags[:, None], mean, rgba)
        rgba = mean
    res = RenderResult(color=rgba[:, :3].reshape(h, w, 3), alpha=rgba[:, 3].reshape(h, w),
                       depth=depth.reshape(h, w), normal=normal.reshape(h, w, 3),
                       position=point.reshape(h, w, 4), status=status.reshape(h, w),
                       samples=smp.reshape(h, w), bracket=bracket.reshape(h, w),
                       device_name="numpy float64 reference", scene=scene,
                       guards=count_guards(status, depth, guard))
    res.seconds = res.kernel_seconds = time.perf_counter() - t0
    return res


from pyjulia4d.reference.shade import light_terms, reflect_color, reflect_rays, shade  # noqa: E402,F401  (kernels/shade/)
