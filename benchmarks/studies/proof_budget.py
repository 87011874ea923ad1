"""Where a proof of the space in front of each hit spends its work, and what three ways to
prove it more cheaply could save, counted on the default scene's own rays with the float64
twin (counts of orbit evaluations and enclosures, not seconds: they do not depend on the
machine, and the kernels' times follow them).

* estimate: the distance-estimate march (reference/march.py march_de, as the kernels run it
  without the cone start): estimates per ray.  It proves nothing in front of its hits.
* proven: the proven march at the normal preset (march_proven): segment enclosures per ray,
  and for the rays that hit, how many were spent at each distance in front of the depth.
* certified balls: for a quaternion q^D + c, every point of the ball B(p, r) has its D-th
  power within (|q| + r)^D - |q|^D of q^D (the norm is multiplicative), so the ball holds no
  point of the truncated set when, for some k <= max_iter, |q_k| - r_k > bailout with
  r_{k+1} = (|q_k| + r_k)^D - |q_k|^D.  Inverting that recursion from each escaped k back to
  k = 0 gives the largest such r exactly (r_k = (|q_k|^D + m)^(1/D) - |q_k|): the best any
  ball arithmetic on the orbit can prove.  Printed: that radius over the estimate at points
  in front of the hits, and a march stepping by it (down to the preset's floor, then floor
  steps): its evaluations per ray.
* beam start: one proven march per 4x4 block of pixels along the block's centre ray, its
  segments' enclosures widened by the radius of the cone that holds the block's rays (as
  march/cone.cl's), started a little in front of the bounding ball so that every ray of the
  block begins behind it; each ray then runs the proven march from where the beam's proofs
  ended.  Printed: enclosures per pixel, the beam's share included.
* lengths known in advance (an oracle): each step the longest segment an enclosure proves,
  searched on lengths floor x 2^(k/3), until not even the floor proves (where the march finds
  the surface).  Printed: its enclosures and iterations per ray against the march's own (each
  enclosure costing 1 plus the iterations it stays live, as a packet's lanes are held:
  reference/march.py enc_prove ``iterations``): what no rule for the next length can beat.
* affine beams: one form per B x B block for the whole slab of its rays between two depths,
  with three noise symbols - along the rays and across them in x and y - so that the spread
  across the block is carried to first order as a tangent, not as a ball (affine arithmetic:
  Stolfi & de Figueiredo, "Self-Validated Numerical Methods and Applications", 1997, §3; the
  cone-widened beam above carries it as a ball).  Quaternion squares only.  The slab marches
  by the proven march's rule for its lengths; each ray then marches from the slab's end.
  Printed: iterations per ray with the beams' counted at COST_3 times a ray's per iteration,
  spread over the block's rays (a beam iterates ten quaternion products to a ray's three).

Appends a section to benchmarks/results/proof_budget.md.

    python benchmarks/studies/proof_budget.py [--size 80x60] [--beam-size 320x240] [--affine-size 640x480]
        [--affine-block 8] [--affine-stride 7]
"""
from __future__ import annotations

import importlib
import sys
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:   # the checkout: its pyjulia4d, and benchmarks/ as a package
    sys.path.insert(0, str(ROOT))

from benchmarks.lib.args import Parser, size_of  # noqa: E402
from benchmarks.lib.runlog import append_study, git_commit, utc_now  # noqa: E402

from pyjulia4d import Scene  # noqa: E402
from pyjulia4d.pipeline.plan import make_plan  # noqa: E402
from pyjulia4d.reference.algebra.quaternion import alg_cube, alg_mul, alg_sqr  # noqa: E402
from pyjulia4d.reference.enclose.julia import LADDER_N, ladder  # noqa: E402
from pyjulia4d.reference.cone import centre_rays, cone_of_pixels  # noqa: E402
from pyjulia4d.reference.formula import formula_of  # noqa: E402
from pyjulia4d.reference.iterate import julia_distance_formula  # noqa: E402
from pyjulia4d.reference.rays import generate_rays  # noqa: E402

# the module, not the function of the same name pyjulia4d.reference exports
rm = importlib.import_module("pyjulia4d.reference.march")

DISTANCES = [0, 1e-4, 1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.3, np.inf]


def setup(w: int, h: int):
    """The default scene's plan at the normal preset and its camera rays inside the ball."""
    sc = Scene.default().with_overrides([f"image.width={w}", f"image.height={h}", "march.quality=normal"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plan = make_plan(sc, "CPU", 1, force=True)
    o, d = generate_rays(plan.frame, w, h, sample=0, samples=1)
    near, far, live = rm.ball_span(o, d, plan.march.radius, plan.march.near, plan.march.far)
    return plan, formula_of(plan.fractal), o, d, near, far, live


def proven_counted(plan, F, o, d, start, far):
    """march_proven from ``start``, every enclosure it asks for recorded as (ray, t0), and the
    iterations all of them took (each 1 plus the iterations it stays live: enc_prove's)."""
    ma = plan.march
    rows = {bytes(x): i for i, x in enumerate(np.ascontiguousarray(d))}
    log: list[tuple[np.ndarray, np.ndarray]] = []
    real, iterations = rm.enc_prove, [0]

    def counted(oo, dd, t0, t1, *a, **k):
        log.append((np.array([rows[bytes(x)] for x in np.ascontiguousarray(dd)]), np.array(t0, float)))
        it = np.zeros(len(oo), int)
        got = real(oo, dd, t0, t1, *a, iterations=it, **k)
        iterations[0] += int(it.sum())
        return got

    rm.enc_prove = counted
    try:
        out = rm.march_proven(o, d, start, far, np.asarray(ma.c, float), ma.max_iter, ma.bailout, ma.epsilon,
                              ma.z_resolution, ma.post_steps, 20000, True, F)
    finally:
        rm.enc_prove = real
    ids = np.concatenate([a for a, _ in log]) if log else np.zeros(0, int)
    t0 = np.concatenate([b for _, b in log]) if log else np.zeros(0)
    return out[0], ids, t0, iterations[0]


def best_ball(p, c, max_iter, bailout, degree):
    """The largest r whose ball about each point p is proven to hold no point of the truncated
    set by the norm recursion (module docstring); 0 where the orbit never escapes."""
    q = p.copy()
    norms = [np.linalg.norm(q, axis=1)]
    mul = alg_sqr if degree == 2 else alg_cube
    with np.errstate(all="ignore"):
        for _ in range(max_iter):
            q = mul(q) + c
            norms.append(np.linalg.norm(q, axis=1))
    a = np.minimum(np.nan_to_num(np.array(norms), nan=1e100, posinf=1e100), 1e100)
    best = np.zeros(len(p))
    with np.errstate(all="ignore"):   # orbits far past the bailout: capped, as above
        return _invert(a, bailout, degree, best)


def _invert(a, bailout, degree, best):
    """best_ball's inversion from every escaped k back to k = 0 (norms ``a``, (max_iter + 1, n))."""
    max_iter = a.shape[0] - 1
    for k in range(max_iter + 1):
        m = np.where(a[k] > bailout, a[k] - bailout, 0.0)
        for j in range(k - 1, -1, -1):
            # (a + r)^D - a^D = m  <=>  r = (a^D + m)^(1/D) - a, written without the cancellation:
            # x - a = (x^D - a^D) / (x + a) for D = 2, / (x^2 + x a + a^2) for D = 3
            x = np.sqrt(a[j] ** 2 + m) if degree == 2 else np.cbrt(a[j] ** 3 + m)
            m = m / (x + a[j]) if degree == 2 else m / (x * x + x * a[j] + a[j] * a[j])
        best = np.maximum(best, np.where(a[k] > bailout, m, 0.0))
    return best


def ball_march(o, d, near, far, c, max_iter, bailout, degree, floor):
    """Steps of the best certified ball until a point is inside or the ray leaves; where the
    ball is under ``floor``, a floor step (unproven).  Evaluations per ray."""
    t, active, steps = near.copy(), np.ones(len(o), bool), np.zeros(len(o), int)
    for _ in range(20000):
        k = np.nonzero(active & (t <= far))[0]
        if k.size == 0:
            break
        r = best_ball(o[k] + t[k, None] * d[k], c, max_iter, bailout, degree)
        steps[k] += 1
        inside = r == 0
        active[k[inside]] = False
        t[k] += np.maximum(r, floor[k])
    return steps


def oracle_march(plan, F, o, d, near, far):
    """Segments each the longest an enclosure proves, of lengths floor x 2^(k/3) (module
    docstring), until not even the floor proves: enclosures and iterations per ray (only the
    proof that is kept is counted), the rays that ended so, and the p10, p50 and p90 of those
    lengths over the distance estimate where each began."""
    ma = plan.march
    c = np.asarray(ma.c, float)
    floor = (far - near) / ma.z_resolution
    t, active = near.copy(), np.ones(len(o), bool)
    enc, its, stuck = np.zeros(len(o)), np.zeros(len(o)), np.zeros(len(o), bool)
    per_estimate = []
    while active.any():
        k = np.nonzero(active)[0]
        best, cost = np.zeros(k.size), np.zeros(k.size)
        for f in 2.0 ** (np.arange(60) / 3.0):
            h = floor[k] * f
            fits = h <= (far[k] - near[k]) * 1.0001
            if not fits.any():
                break
            t1 = np.minimum(t[k] + h, far[k])
            it = np.zeros(k.size, int)
            ok = rm.enc_prove(o[k], d[k], t[k], t1, c, ma.max_iter, ma.bailout, F, iterations=it)[0] & fits
            longer = ok & (t1 - t[k] > best)
            best, cost = np.where(longer, t1 - t[k], best), np.where(longer, it, cost)
        got = best > 0
        dist = julia_distance_formula(o[k] + t[k, None] * d[k], c, ma.max_iter, ma.bailout, F)[0]
        per_estimate.append((best / dist)[got & (dist > 0)])
        enc[k] += got
        its[k] += cost
        t[k] += best
        stuck[k[~got]] = True
        active[k[~got | (t[k] >= far[k] - 1e-12)]] = False
    return enc.mean(), its.mean(), int(stuck.sum()), np.percentile(np.concatenate(per_estimate), [10, 50, 90])


COST_3 = 10 / 3   # a three-symbol iteration's quaternion products over a one-symbol one's (module docstring)


def slab_prove(o, D0, Du, Dv, ta, tb, c, max_iter, bailout, thr):
    """Whether the slab {o + tau (D0 + u Du + v Dv): tau in [ta, tb], u, v in [-1, 1]} holds no point
    of the truncated set of q^2 + c, per slab: one affine form q = m + s a + u b + v e + B(r),
    squared as enclose/ball.cl squares its one symbol - each symbol's square half in the centre
    and half in the ball, the cross terms s u (a b + b a) and the like in the ball, |J[E]| <=
    2 |m| r and the error's products with the tangents and itself, 2 (|a| + |b| + |e|) r + r^2;
    outside where the least |m + s a| over s, less |b| + |e| + r, is past the ladder's radius
    ``thr`` for the iterations left.  Returns (proven, iterations + 1, margin)."""
    tm, th = (ta + tb) / 2, (tb - ta) / 2
    m, a = o + tm[:, None] * D0, th[:, None] * D0
    b, e = tm[:, None] * Du, tm[:, None] * Dv
    r = th * (np.linalg.norm(Du, axis=1) + np.linalg.norm(Dv, axis=1))   # the products s u, s v
    n = np.linalg.norm

    def test(m, a, b, e, r, j):
        aa, ma_ = np.sum(a * a, 1), np.sum(m * a, 1)
        s = np.clip(-ma_ / np.where(aa > 0, aa, 1.0), -1, 1)
        least = n(m + s[:, None] * a, axis=1) - n(b, axis=1) - n(e, axis=1) - r
        return least > thr[j], (n(m, axis=1) - thr[j]) / (n(a, axis=1) + n(b, axis=1) + n(e, axis=1) + r)

    with np.errstate(all="ignore"):   # forms far past the bailout overflow: no proof there, as in the kernel
        proven, margin = test(m, a, b, e, r, min(max_iter, LADDER_N - 1))
        margin = np.fmax(margin, 0.0)
        live, its = ~proven, np.ones(len(ta), int)
        for it in range(max_iter):
            if not live.any():
                break
            lm, la, lb, le = (n(x, axis=1) for x in (m, a, b, e))
            cross = sum(n(alg_mul(x, y) + alg_mul(y, x), axis=1) for x, y in ((a, b), (a, e), (b, e)))
            r = 2 * (lm + la + lb + le) * r + r * r + (la ** 2 + lb ** 2 + le ** 2) / 2 + cross
            m, a, b, e = (alg_sqr(m) + c + (alg_sqr(a) + alg_sqr(b) + alg_sqr(e)) / 2,
                          alg_mul(m, a) + alg_mul(a, m), alg_mul(m, b) + alg_mul(b, m), alg_mul(m, e) + alg_mul(e, m))
            its += live
            out, mg = test(m, a, b, e, r, min(max_iter - it - 1, LADDER_N - 1))
            proven |= out & live
            margin = np.where(live, np.fmax(margin, mg), margin)
            live &= ~out & (la + lb + le + r < 2 * (lm + bailout))   # enclose/ball.cl enc_hopeful
    return proven, its, margin


def affine_beams(plan, F, w, h, block, stride):
    """Every ``stride``-th block's slab march (slab_prove, the proven march's length rule, until a
    failed try is under 1/500 of the span) and then its rays' proven marches from the slab's end:
    (rays, the beams' iterations per ray weighted by COST_3, the rays' iterations per ray from
    the slab's end, from their entry, the share of hits alike)."""
    ma, fr = plan.march, plan.frame
    c = np.asarray(ma.c, float)
    thr = ladder(c, ma.max_iter, ma.bailout, F)[0]
    ux = lambda x: (2 * (x + 0.5) / w - 1) * fr.tan_half_fov * w / h   # rays.py generate_rays
    vy = lambda y: (1 - 2 * (y + 0.5) / h) * fr.tan_half_fov
    nbx = w // block
    ids = np.arange(nbx * (h // block))[::stride]
    x0, y0 = (ids % nbx) * block, (ids // nbx) * block
    D0 = fr.forward + ((ux(x0) + ux(x0 + block - 1)) / 2)[:, None] * fr.right +         ((vy(y0) + vy(y0 + block - 1)) / 2)[:, None] * fr.up
    Du = ((ux(x0 + block - 1) - ux(x0)) / 2)[:, None] * fr.right
    Dv = ((vy(y0) - vy(y0 + block - 1)) / 2)[:, None] * fr.up
    jj, ii = np.mgrid[0:block, 0:block]
    px, py = (x0[:, None] + ii.ravel()).ravel(), (y0[:, None] + jj.ravel()).ravel()
    D = fr.forward + ux(px)[:, None] * fr.right + vy(py)[:, None] * fr.up
    blk = np.repeat(np.arange(ids.size), block * block)
    dn = np.linalg.norm(D, axis=1)
    d, o = D / dn[:, None], np.tile(fr.position, (len(D), 1))
    near, far, live = rm.ball_span(o, d, ma.radius, ma.near, ma.far)
    live &= far >= near
    lo = np.full(ids.size, np.inf)
    hi = np.full(ids.size, -np.inf)
    np.minimum.at(lo, blk[live], (near / dn)[live])
    np.maximum.at(hi, blk[live], (far / dn)[live])
    tau, step = lo.copy(), (hi - lo) * rm.PROVEN_FIRST
    active, its = np.isfinite(lo) & (hi > lo), np.zeros(ids.size)
    while active.any():
        k = np.nonzero(active)[0]
        t1 = np.minimum(tau[k] + step[k], hi[k])
        ok, it, mg = slab_prove(fr.position, D0[k], Du[k], Dv[k], tau[k], t1, c, ma.max_iter, ma.bailout, thr)
        its[k] += it
        fac = np.sqrt(np.maximum(np.nan_to_num(mg) * rm.PROVEN_GAIN, 0.0))   # march/proven.cl's steering
        tau[k] = np.where(ok, t1, tau[k])
        step[k] = np.where(ok, step[k] * np.clip(fac, 1, 4), step[k] * np.clip(fac, 1 / 64, 0.5))
        active[k[(~ok & (step[k] < (hi[k] - lo[k]) / 500)) | (t1 >= hi[k])]] = False
    start = np.clip(np.maximum(near, tau[blk] * dn), near, far)
    o, d, near, far, start = o[live], d[live], near[live], far[live], start[live]
    after = proven_counted(plan, F, o, d, start, far)[3] / len(o)
    plain = proven_counted(plan, F, o, d, near, far)[3] / len(o)
    return int(live.sum()), its.sum() * COST_3 / live.sum(), after, plain


def beam_starts(plan, F, w, h, lead):
    """(t_lo, t_last) per 4x4 block: the block's centre ray proven with widened enclosures from
    ``lead`` in front of its entry of the bounding ball; the number of enclosures."""
    ma = plan.march
    c = np.asarray(ma.c, float)
    o, d, k = centre_rays(plan.frame, w, h)
    t, far, meets = rm.ball_span(o, d, ma.radius, ma.near, ma.far)
    t = np.maximum(t - lead, 0.0)
    active = meets & (far >= t)
    t_lo = np.where(active, t, np.inf)
    span = far - t
    seg = span * rm.PROVEN_FIRST
    K, E = F.kind_enclose, F.enclose
    count = 0
    for _ in range(400):
        i = np.nonzero(active)[0]
        if i.size == 0:
            break
        t1 = np.minimum(t[i] + seg[i], far[i])
        with np.errstate(all="ignore"):
            (m, vv, r), p = K.enc_start(o[i], d[i], t[i], t1, c, F)
            e = (m, vv, r + k * t1)   # every block ray's point at parameter t lies within k t of the centre's
            ok = E.enc_outside(e, ma.bailout ** 2)
            best = E.enc_margin(e, ma.bailout)
            live = ~ok
            for _ in range(K.enc_steps(ma.max_iter)):
                if not live.any():
                    break
                e = K.enc_next(e, p, F)
                out = live & E.enc_outside(e, ma.bailout ** 2)
                best = np.where(live, np.fmax(best, E.enc_margin(e, ma.bailout)), best)
                ok |= out
                live &= ~out & E.enc_hopeful(e, ma.bailout)
        count += i.size
        fac = np.sqrt(np.maximum(np.nan_to_num(best) * rm.PROVEN_GAIN, 0.0))   # march/proven.cl's steering
        t[i] = np.where(ok, t1, t[i])
        seg[i] = np.where(ok, np.minimum(seg[i] * np.clip(fac, 1, 4), span[i]), seg[i] * np.clip(fac, 1 / 64, 0.5))
        active[i] &= (t[i] < far[i]) & (seg[i] >= 2 * k * t[i])   # a segment shorter than the beam proves little
    return (t_lo, np.where(np.isfinite(t_lo), t, -1.0)), count


def main(argv=None) -> int:
    ap = Parser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="80x60")
    ap.add_argument("--beam-size", default="320x240", help="the beam start's image (its cone depends on the pixel size)")
    ap.add_argument("--affine-size", default="640x480", help="the affine beams' image")
    ap.add_argument("--affine-block", type=int, default=8, help="the affine beams' block of pixels, a side")
    ap.add_argument("--affine-stride", type=int, default=7, help="every how many blocks an affine beam is tried")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    w, h = size_of(a.size)
    plan, F, o, d, near, far, live = setup(w, h)
    o, d, near, far = o[live], d[live], near[live], far[live]
    ma = plan.march
    c = np.asarray(ma.c, float)
    degree = 2 if plan.fractal.function == "sqr" else 3   # the default scene: a quaternion square
    de_t, _, de_n, *_ = rm.march_de(o, d, near, far, c, ma.max_iter, ma.bailout, 1e-3, 250, 4, 20000, True, F)
    depth, ids, t0, its = proven_counted(plan, F, o, d, near, far)
    hit = np.isfinite(depth)
    per_ray = np.bincount(ids, minlength=len(o))
    lines = [f"| estimate march (no proof) | {de_n.mean():.1f} estimates |",
             f"| proven march, normal preset | {per_ray.mean():.1f} enclosures ({per_ray[hit].mean():.1f} on hits, "
             f"{per_ray[~hit].mean():.1f} on misses) |"]
    gap = depth[ids] - t0
    on_hit = hit[ids]
    hist, _ = np.histogram(gap[on_hit], DISTANCES)
    spread = ", ".join(f"{lo:g}-{hi:g}: {n / hit.sum():.1f}" for lo, hi, n in zip(DISTANCES[:-1], DISTANCES[1:], hist))
    rng = np.random.default_rng(1)
    t_any = near + rng.random(len(o)) * (np.where(np.isfinite(de_t), de_t, far) - near)
    p = o + t_any[:, None] * d
    dist, escaped = julia_distance_formula(p, c, ma.max_iter, ma.bailout, F)
    ratio = (best_ball(p, c, ma.max_iter, ma.bailout, degree) / dist)[escaped & (dist > 0)]
    q = np.percentile(ratio, [5, 50, 95])
    floor = (far - near) / ma.z_resolution
    balls = ball_march(o, d, near, far, c, ma.max_iter, ma.bailout, degree, floor)
    lines.append(f"| certified balls (the best radius), then floor steps | {balls.mean():.1f} evaluations |")
    bw, bh = size_of(a.beam_size)
    bplan, _, bo, bd, bnear, bfar, blive = setup(bw, bh)
    cone, beam_count = beam_starts(bplan, F, bw, bh, lead=0.05)
    t_lo, t_last = cone_of_pixels(cone, (0, 0, bw, bh))
    start = np.where(blive & (t_last > bnear) & (bnear >= t_lo) & (t_last < bfar), t_last, bnear)
    base = proven_counted(bplan, F, bo[blive], bd[blive], bnear[blive], bfar[blive])[1].size / (bw * bh)
    bdepth, bids, _, _ = proven_counted(bplan, F, bo[blive], bd[blive], start[blive], bfar[blive])
    beamed = bids.size / (bw * bh)
    behind = (start[blive] > bnear[blive]) & np.isfinite(bdepth)
    gap_left = float(np.median((bdepth - start[blive])[behind])) if behind.any() else float("nan")
    text = [f"\n## {utc_now()}, commit {git_commit()}\n\n",
            f"`python benchmarks/studies/proof_budget.py --size {w}x{h} --beam-size {bw}x{bh} --affine-size "
            f"{a.affine_size} --affine-block {a.affine_block} --affine-stride {a.affine_stride}`: the default scene's "
            f"{len(o)} rays that meet the bounding ball, float64 twin.\n\n",
            "| march | per ray |\n| --- | --- |\n", "\n".join(lines) + "\n\n",
            f"- Proven march, enclosures per hit ray by distance in front of its depth: {spread}.\n",
            f"- Best certified ball over the distance estimate at points in front of the hits: p5 {q[0]:.2f}, "
            f"p50 {q[1]:.2f}, p95 {q[2]:.2f} (the estimate march steps 1.2 estimates).\n",
            f"- Beam start at {bw}x{bh}: {base:.1f} enclosures per pixel from the ball's entry, {beamed:.1f} after "
            f"the beam plus {beam_count / (bw * bh):.2f} for the beams ({beam_count / len(cone[0]):.1f} per block); "
            f"{np.mean(start[blive] > bnear[blive]) * 100:.0f} % of the rays started behind a beam, "
            f"the hits among them a median {gap_left:.2f} in front of their depth.\n"]
    oe, oi, stuck, q_est = oracle_march(plan, F, o, d, near, far)
    me, mi = ids.size / len(o), its / len(o)
    last = stuck * (1 + ma.max_iter) / len(o)   # the surface's floor segment, one full enclosure each
    text.append(f"- Lengths known in advance (at {w}x{h}): {oe:.1f} enclosures and {oi:.0f} iterations per ray to "
                f"where not even the floor proves ({stuck} rays; one full enclosure more for each, {last:.0f} per "
                f"ray), against the march's {me:.1f} and {mi:.0f} to its hit or exit: {(oi + last) / mi:.2f}x its "
                f"iterations. Those lengths over the distance estimate where each began: p10 {q_est[0]:.2f}, p50 "
                f"{q_est[1]:.2f}, p90 {q_est[2]:.2f}.\n")
    aw, ah = size_of(a.affine_size)
    n, beam, after, plain = affine_beams(setup(aw, ah)[0], F, aw, ah, a.affine_block, a.affine_stride)
    text.append(f"- Affine beams of {a.affine_block}x{a.affine_block} pixels at {aw}x{ah} (one block in "
                f"{a.affine_stride}, {n} rays): {beam:.1f} iterations per ray for the beams (x{COST_3:.2f}) "
                f"and {after:.1f} for the rays after them, against {plain:.1f} from the entry: "
                f"{(beam + after) / plain:.2f}x.\n")
    print("".join(text))
    append_study(a.out, "benchmarks/studies/proof_budget.py", "Where a proof of the space in front spends its work", "".join(text))
    return 0


if __name__ == "__main__":
    sys.exit(main())
