"""Twin of kernels/march/: refine.cl (the certified bracket), fixed.cl, de.cl and proven.cl
(the marches along one ray) and march.cl (every ray of an image, with clip planes)."""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from pyjulia4d.pipeline.codes import FLAG_CUT_FACE, GUARD_SHELL_MISS, GUARD_ULP_STEP, STATUS_CAPPED, STATUS_HIT, STATUS_MISS
from pyjulia4d.reference.enclose.julia import LADDER_N
from pyjulia4d.reference.formula import QUATERNION_SQR, Formula
from pyjulia4d.reference.iterate import REAL_MIN, dot4, julia_distance_formula, julia_inside, julia_level

if TYPE_CHECKING:
    from pyjulia4d.pipeline.records import MarchArgs

def refine_bracket(o, d, a, b, steps, c, max_iter, bailout, itp=True, tests=None,
                   formula: Formula = QUATERNION_SQR):
    """Narrow certified brackets [a (outside), b (inside)] on rays o + t d with ``steps``
    set tests: ITP on the level function julia_level (``itp``) or bisection (Ödegaard & Wennergren
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
    """Fixed z-resolution scan (Ödegaard & Wennergren §3): the first inside sample and the one before it
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
    # samples prove nothing between them: all of the ray in front of the depth is unproven
    unresolved = np.where(status == STATUS_HIT, t - near, far - near)
    return t, status, samples, np.zeros(n, np.int32), width, unresolved


DE_OVER_RELAX = 1.2   # over-relaxed steps (march/de.cl)


def march_de(o, d, near, far, c, max_iter, bailout, epsilon, z_resolution, post_steps, max_steps,
             itp=True, formula: Formula = QUATERNION_SQR):
    """r_{n+1} = r_n + 1.2 max(d(r_n), eps) (Hart, Sandin & Kauffman 1989 §3.2 eq. 9, over-relaxed as in Keinert et
    al. 2014 with the step taken back where two spheres leave a gap) until a point is inside (its
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
    omega, step, r_prev = np.full(n, DE_OVER_RELAX), np.zeros(n), np.zeros(n)
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
        r = np.where(escaped, dist, 0.0)
        # over-relaxed steps; a gap between the spheres takes the step back (march/de.cl)
        gap = (omega[idx] > 1) & (r + r_prev[idx] < step[idx])
        hit = ~escaped & ~gap
        got = idx[hit]
        status[got] = STATUS_HIT
        samples[got] = i + 1
        active[got] = False
        if i == 0:
            width[got] = 0.0
        else:
            bracketed[got] = True
        k, g, rk = idx[~hit], gap[~hit], r[~hit]
        dk = dist[~hit]
        shell[k] |= ~g & (dk < epsilon)
        step[k] = np.where(g, step[k] * (1 - omega[k]), np.maximum(dk, epsilon) * omega[k])
        omega[k] = np.where(g, 1.0, omega[k])
        r_prev[k] = np.where(g, r_prev[k], rk)
        t_prev[k] = np.where(g, t_prev[k], t[k])
        t_old = t[k]
        t[k] = t_old + step[k]
        rounded = t[k] == t_old   # the step rounded away: one ulp instead
        t[k[rounded]] = np.nextafter(t_old[rounded], np.inf)
        flags[k[rounded]] |= GUARD_ULP_STEP
    k = np.nonzero(bracketed)[0]
    if k.size:
        t[k], width[k] = refine_bracket(o[k], d[k], t_prev[k], t[k], post_steps, c, max_iter, bailout, itp,
                                        formula=formula)
    t[status != STATUS_HIT] = np.inf
    # the estimate is no proof for the truncated set: nothing in front is proven (march/de.cl)
    unresolved = np.where(status == STATUS_HIT, t - near, far - near)
    return t, status, samples, flags, width, unresolved


# ------------------------------------------------------------------- march/proven.cl

def enc_prove(o, d, t0, t1, c, max_iter, bailout, formula: Formula, iterations=None):
    """Per ray: whether [t0, t1] is proven empty - an enclosure of its points' orbits
    (reference/enclose/) outside the bailout ball at some n <= max_iter, or outside the
    radius that passes it within the max_iter - n iterations left (the kind's ladder) -, the
    largest enc_margin over the iterations (0 where none is positive), and the largest s in
    [-1, 1] whose part [-1, s] of the segment some iteration's enclosure keeps outside (1 where
    proven, -1 where none, or where the enclosure piece has no enc_prefix) (march/proven.cl).
    ``iterations`` (int array, optional) gets 1 (the start and its tests) plus the iterations each
    ray's form stayed live: the lane-slots it holds in a packet (benchmarks/studies/march_levers.py)."""
    K = formula.kind_enclose
    E = K if formula.own_map else formula.enclose   # a kind with a map of its own encloses all of it
    enc_prefix = getattr(E, "enc_prefix", None)
    enc_gate = getattr(E, "enc_gate", None)
    steps = K.enc_steps(max_iter)
    # the radius to clear with j iterations left (march/proven.cl enc_ladder_of)
    lad = K.ladder(c, max_iter, bailout, formula) if hasattr(K, "ladder") else None
    thr, thr2, parts = lad if lad else ([bailout] * LADDER_N, [bailout * bailout] * LADDER_N, None)
    j = min(steps, LADDER_N - 1)
    # every ray's form is stepped, the decided ones too: their growth past the float64 range
    # is an infinite radius, no proof (as in the kernel), not a warning
    with np.errstate(all="ignore"):
        e, p = K.enc_start(o, d, t0, t1, c, formula)
        proven = E.enc_outside(e, thr2[j])
        live = ~proven
        if iterations is not None:
            iterations += 1
        best = np.fmax(E.enc_margin(e, thr[j]), 0.0)
        pre = enc_prefix(e, thr[j]) if enc_prefix else np.full(len(o), -1.0)
        for n in range(steps):
            if not live.any():
                break
            e = K.enc_next(e, p, formula)
            if iterations is not None:
                iterations += live
            j = min(steps - n - 1, LADDER_N - 1)
            # only where the form may pass a test (march/proven.cl ENC_GATE)
            near = live & enc_gate(e, thr[j]) if enc_gate else live
            out = near & E.enc_outside(e, thr2[j])
            best = np.where(near, np.fmax(best, E.enc_margin(e, thr[j])), best)
            if enc_prefix:
                pre = np.where(near, np.fmax(pre, enc_prefix(e, thr[j])), pre)
            if parts:   # each component past its own ladder (kernels/enclose/split.cl)
                pa, pa2, pb, pb2 = parts
                pn = live & E.enc_gate_parts(e, pa[j], pb[j])
                out |= pn & E.enc_outside_parts(e, pa2[j], pb2[j])
                best = np.where(pn, np.fmax(best, E.enc_margin_parts(e, pa[j], pb[j])), best)
                pre = np.where(pn, np.fmax(pre, E.enc_prefix_parts(e, pa[j], pb[j])), pre)
            proven |= out
            live &= ~out & E.enc_hopeful(e, bailout)
    return proven, best, np.where(proven, 1.0, pre)


def prefix_end(t0, t1, pre):
    """The end of the part of [t0, t1] a partial proof keeps (enc_prove's prefix), pulled in by
    PREFIX_PULL of itself (march/proven.cl)."""
    return (t0 + (t1 - t0) * ((pre + 1) * 0.5)) * PREFIX_PULL


PROVEN_FIRST = 0.125
PROVEN_GAIN = 1.2
FLOOR_POINTS = 8   # the points an unproven floor segment is tested at (march/proven.cl)
FLOOR_RUN = 32     # unproven floor segments in a row that double the floor (march/proven.cl)
FLOOR_WIDEST = 0.001   # of the ray: the widest the floor grows to
FINE_DIV = 16.0        # a lone open floor segment is gone over again at a floor this much finer (march/proven.cl)
FINE_LEAST = 2.0 ** -20   # of the ray: the finest floor that look goes to (march/proven.cl)
PREFIX_PULL = 1 - 2.0 ** -21   # a partial proof's end, pulled in by 2 float32 spacings (march/proven.cl)


def march_proven(o, d, near, far, c, max_iter, bailout, epsilon, z_resolution, post_steps, max_steps,
                 itp=True, formula: Formula = QUATERNION_SQR):
    """Segments from near on, each proven empty or shortened (by the enclosure's margin) down
    to the floor (far - near) / z_resolution, where FLOOR_POINTS points to its far end are tested in
    order: the first inside ends the march with the certified bracket from the point before, none
    passes the segment unproven (march/proven.cl).  ``unresolved``: on a hit the reach from
    the first unproven segment's start to the depth, on a miss the unproven width.
    Returns (t, status, samples, flags, width, unresolved)."""
    n = len(o)
    span = far - near
    floor_w = span / z_resolution
    h = np.maximum(span * PROVEN_FIRST, floor_w)
    t, t_in, t_out = near.copy(), near.copy(), near.copy()
    open_w = np.zeros(n)
    t_open = np.full(n, np.inf)   # where the first segment passed unproven begins
    floor_here, run = floor_w.copy(), np.zeros(n)   # the floor now, unproven floor segments in a row
    widest = np.maximum(floor_w, span * FLOOR_WIDEST)
    first = julia_inside(o + near[:, None] * d, c, max_iter, bailout, formula)
    active, hit, miss = ~first, first.copy(), np.zeros(n, bool)
    count = np.zeros(n, np.int32)
    # the finer look at a lone open floor segment: its end (-inf: none), the floor before it
    fine_end, outer_floor = np.full(n, -np.inf), floor_w.copy()
    for _ in range(max_steps):
        k = np.nonzero(active)[0]
        if k.size == 0:
            break
        t1 = np.minimum(t[k] + h[k], far[k])
        empty, margin, pre = enc_prove(o[k], d[k], t[k], t1, c, max_iter, bailout, formula)
        count[k] += 1
        fine = fine_end[k] > t[k]
        at_floor = ~empty & (h[k] <= floor_here[k])
        # a partial proof above the floor: its part passed, proven (march/proven.cl)
        t_pre = prefix_end(t[k], t1, pre)
        part = ~empty & ~fine & (h[k] > floor_here[k]) & (t_pre > t[k])
        got = np.zeros(k.size, bool)
        look = at_floor.copy()
        before = t[k].copy()
        for jj in range(1, FLOOR_POINTS + 1):   # FLOOR_POINTS points to its far end, in order
            j = np.nonzero(look)[0]
            if j.size == 0:
                break
            tj = t1[j] if jj == FLOOR_POINTS else t[k[j]] + (t1[j] - t[k[j]]) * (jj / FLOOR_POINTS)
            inside = julia_inside(o[k[j]] + tj[:, None] * d[k[j]], c, max_iter, bailout, formula)
            g = j[inside]
            t_in[k[g]], t_out[k[g]] = tj[inside], before[g]
            got[g] = True
            look[g] = False
            before[j] = tj
        found_open = at_floor & ~got
        # a lone one: gone over at the fine floor, where that is no finer than FINE_LEAST of the ray
        again = found_open & ~fine & (run[k] == 0) & (floor_here[k] >= span[k] * (FINE_LEAST * FINE_DIV))
        opened = found_open & ~again
        give_up = opened & fine   # a fine segment left open: the rest of its floor segment passes too
        t_end = np.where(give_up, np.maximum(t1, fine_end[k]), t1)
        open_w[k] = np.where(opened, open_w[k] + (t_end - t[k]), open_w[k])
        t_open[k] = np.where(opened, np.minimum(t_open[k], t[k]), t_open[k])
        proof = empty | part
        run[k] = np.where(opened, run[k] + 1, np.where(proof, 0.0, run[k]))
        wider = opened & (run[k] >= FLOOR_RUN)
        floor_here[k] = np.where(wider, np.minimum(floor_here[k] * 2, widest[k]),
                                 np.where(proof, floor_w[k], floor_here[k]))
        run[k] = np.where(wider, 0.0, run[k])
        hit[k] |= got
        passed = empty | opened
        done = passed & (t_end >= far[k])
        miss[k] |= done
        mg = np.where(np.isnan(margin), 0.0, margin)
        fac = np.sqrt(np.maximum(mg * PROVEN_GAIN, 0.0))   # the margin falls about as h^-2 (march/proven.cl)
        grow, shrink = np.clip(fac, 1, 4), np.clip(fac, 1 / 64, 0.5)
        h[k] = np.where(empty, np.minimum(h[k] * grow, span[k]), h[k])
        h[k] = np.where(~empty & ~at_floor, np.maximum(h[k] * shrink, floor_here[k]), h[k])
        h[k] = np.where(opened, floor_here[k], h[k])
        h[k] = np.where(part, np.maximum(t_pre - t[k], h[k]), h[k])   # as long as the part; h: already the shrunk try
        t[k] = np.where(passed & ~done, t_end, np.where(part, t_pre, t[k]))
        # the fine look: begun, kept while t is short of its end, and ended (the floor back)
        outer_floor[k] = np.where(again, floor_here[k], outer_floor[k])
        fine_end[k] = np.where(again, t1, fine_end[k])
        ended = (fine | again) & ~(fine_end[k] > t[k])
        fine_end[k] = np.where(ended, -np.inf, fine_end[k])
        floor_here[k] = np.where(fine_end[k] > t[k], outer_floor[k] / FINE_DIV,
                                 np.where(ended, outer_floor[k], floor_here[k]))
        h[k] = np.where(give_up, floor_here[k], np.where(again, np.maximum(h[k] * shrink, floor_here[k]), h[k]))
        active[k] &= ~(got | done)
    status = np.where(hit, STATUS_HIT, np.where(miss, STATUS_MISS, STATUS_CAPPED)).astype(np.int32)
    width = np.full(n, np.inf)
    width[first] = 0.0
    depth = np.where(hit, t_in, np.inf)
    k = np.nonzero(hit & ~first)[0]
    if k.size:
        depth[k], width[k] = refine_bracket(o[k], d[k], t_out[k], t_in[k], post_steps, c, max_iter, bailout, itp,
                                            formula=formula)
        # the hit segment's part in front of the refined bracket: proven, or unproven (not tried
        # where a segment in front was left unproven: the statement reaches back to it anyway)
        j = k[(depth[k] > t[k]) & ~(t_open[k] < t[k])]
        if j.size:
            tail_empty, _, tail_pre = enc_prove(o[j], d[j], t[j], depth[j], c, max_iter, bailout, formula)
            # its part a partial proof keeps is proven too
            t_from = np.clip(prefix_end(t[j], depth[j], tail_pre), t[j], depth[j])
            open_w[j] += np.where(tail_empty, 0.0, depth[j] - t_from)
            t_open[j] = np.where(tail_empty, t_open[j], np.minimum(t_open[j], t_from))
    # on a hit the reach of what is unproven (depth - t_open), on a miss the unproven width;
    # a capped ray adds all it did not reach (march/proven.cl)
    with np.errstate(invalid="ignore"):   # inf - inf off the hits
        reach = np.where(t_open < depth, depth - t_open, 0.0)
    return depth, status, count, np.zeros(n, np.int32), width, np.where(
        active, open_w + (far - t), np.where(hit, reach, open_w))


# --------------------------------------------------------------------- rays.cl ball_span, march/march.cl

def ball_span(o, d, radius, near_set, far_set):
    """(near, far, meets): each ray o + t d (|d| = 1) within the bounding 4-ball, near clamped at
    the eye, replaced by near_set / far_set where those are >= 0 (rays.cl ball_span)."""
    b = dot4(o, d)
    # radius^2 - |o - b d|^2, not b^2 - (|o|^2 - radius^2): no cancellation for a far eye
    perp = o - b[:, None] * d
    disc = radius * radius - dot4(perp, perp)
    s = np.sqrt(np.maximum(disc, 0.0))
    near = np.maximum(-b - s, 0.0)
    far = -b + s
    if near_set >= 0:
        near = np.full_like(near, near_set)
    if far_set >= 0:
        far = np.full_like(far, far_set)
    return near, far, disc >= 0


def march(origins, dirs, args: MarchArgs, flags=None, bracket=None, formula: Formula = QUATERNION_SQR, clip=None,
          unresolved=None, cone=None):
    """march/march.cl with the same record (``args``: pipeline/plan.MarchArgs, its method,
    refinement and numbers).  Clip each ray to the bounding 4-ball (and the ``clip``
    half-spaces m . x <= e, world space: camera.clip_planes), then march; returns (depth,
    point, status, samples).  A hit
    at the first point of an interval a plane started is on its cut face: flags get
    FLAG_CUT_FACE | k << 5.
    ``flags`` (int array, optional) gets the march's guard flags (march/march.cl's flags buffer),
    ``bracket`` (float array, optional) each hit's certified bracket width (+inf elsewhere),
    ``unresolved`` (float array, optional) how far in front of each depth the space the
    march did not prove empty begins (the unproven width on a miss; 0 off the bounding
    ball).  ``cone`` = (t_lo, t_last) per ray (reference/cone.py, -D CONE_START): a ray whose
    entry is at or after t_lo starts at t_last, and is marched again from its entry where
    that first point is inside."""
    c, max_iter, bailout, epsilon = args.c, args.max_iter, args.bailout, args.epsilon
    z_resolution, post_steps, max_steps, method = args.z_resolution, args.post_steps, args.max_steps, args.method
    itp = args.refine == "itp"
    o = np.asarray(origins, np.float64)
    d = np.asarray(dirs, np.float64)
    near, far, live = ball_span(o, d, args.radius, args.near, args.far)
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
    start = near
    coned = np.zeros(len(o), bool)
    if cone is not None:
        t_lo, t_last = (np.asarray(a, np.float64) for a in cone)
        coned = live & (t_last > near) & (near >= t_lo) & (t_last < far)
        start = np.where(coned, t_last, near)
    n = len(o)
    depth = np.full(n, np.inf)
    status = np.full(n, STATUS_MISS, np.int32)
    samples = np.zeros(n, np.int32)
    k = np.nonzero(live)[0]
    if k.size:
        fn = {"fixed": march_fixed, "proven": march_proven}.get(method, march_de)
        depth[k], status[k], samples[k], fl, wd, un = fn(o[k], d[k], start[k], far[k], c, max_iter, bailout,
                                                     epsilon, z_resolution, post_steps, max_steps,
                                                     itp, formula)
        if cone is not None:
            # a first point inside: the cone's estimate was wrong for this ray (march/march.cl)
            redo = coned[k] & (status[k] == STATUS_HIT) & (wd == 0)
            j = k[redo]
            if j.size:
                depth[j], status[j], samples[j], fl2, wd[redo], un[redo] = fn(
                    o[j], d[j], near[j], far[j], c, max_iter, bailout, epsilon, z_resolution, post_steps,
                    max_steps, itp, formula)
                fl[redo] |= fl2
            moved = coned[k] & ~redo
            un[moved] += start[k][moved] - near[k][moved]
        if flags is not None:
            flags[k] |= fl
            face = (status[k] == STATUS_HIT) & (wd == 0) & (cut[k] > 0)
            flags[k[face]] |= FLAG_CUT_FACE | ((cut[k[face]] - 1) << 5)
        if bracket is not None:
            bracket[:] = np.inf
            bracket[k] = np.where(status[k] == STATUS_HIT, wd, np.inf)
        if unresolved is not None:
            unresolved[:] = 0.0
            unresolved[k] = un
    depth[status != STATUS_HIT] = np.inf
    point = np.where((status == STATUS_HIT)[:, None], o + np.where(np.isfinite(depth), depth, 0)[:, None] * d, np.nan)
    return depth, point, status, samples
