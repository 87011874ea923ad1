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

Appends a section to benchmarks/results/proof_budget.md.

    python benchmarks/studies/proof_budget.py [--size 80x60] [--beam-size 320x240]
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
from pyjulia4d.reference.algebra.quaternion import alg_cube, alg_sqr  # noqa: E402
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
    """march_proven from ``start``, every enclosure it asks for recorded as (ray, t0)."""
    ma = plan.march
    rows = {bytes(x): i for i, x in enumerate(np.ascontiguousarray(d))}
    log: list[tuple[np.ndarray, np.ndarray]] = []
    real = rm.enc_prove

    def counted(oo, dd, t0, t1, *a, **k):
        log.append((np.array([rows[bytes(x)] for x in np.ascontiguousarray(dd)]), np.array(t0, float)))
        return real(oo, dd, t0, t1, *a, **k)

    rm.enc_prove = counted
    try:
        out = rm.march_proven(o, d, start, far, np.asarray(ma.c, float), ma.max_iter, ma.bailout, ma.epsilon,
                              ma.z_resolution, ma.post_steps, 20000, True, F)
    finally:
        rm.enc_prove = real
    ids = np.concatenate([a for a, _ in log]) if log else np.zeros(0, int)
    t0 = np.concatenate([b for _, b in log]) if log else np.zeros(0)
    return out[0], ids, t0


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
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    a = ap.parse_args(argv)
    w, h = size_of(a.size)
    plan, F, o, d, near, far, live = setup(w, h)
    o, d, near, far = o[live], d[live], near[live], far[live]
    ma = plan.march
    c = np.asarray(ma.c, float)
    degree = 2 if plan.fractal.function == "sqr" else 3   # the default scene: a quaternion square
    de_t, _, de_n, *_ = rm.march_de(o, d, near, far, c, ma.max_iter, ma.bailout, 1e-3, 250, 4, 20000, True, F)
    depth, ids, t0 = proven_counted(plan, F, o, d, near, far)
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
    bdepth, bids, _ = proven_counted(bplan, F, bo[blive], bd[blive], start[blive], bfar[blive])
    beamed = bids.size / (bw * bh)
    behind = (start[blive] > bnear[blive]) & np.isfinite(bdepth)
    gap_left = float(np.median((bdepth - start[blive])[behind])) if behind.any() else float("nan")
    text = [f"\n## {utc_now()}, commit {git_commit()}\n\n",
            f"`python benchmarks/studies/proof_budget.py --size {w}x{h} --beam-size {bw}x{bh}`: the default scene's "
            f"{len(o)} rays that meet the bounding ball, float64 twin.\n\n",
            "| march | per ray |\n| --- | --- |\n", "\n".join(lines) + "\n\n",
            f"- Proven march, enclosures per hit ray by distance in front of its depth: {spread}.\n",
            f"- Best certified ball over the distance estimate at points in front of the hits: p5 {q[0]:.2f}, "
            f"p50 {q[1]:.2f}, p95 {q[2]:.2f} (the estimate march steps 1.2 estimates).\n",
            f"- Beam start at {bw}x{bh}: {base:.1f} enclosures per pixel from the ball's entry, {beamed:.1f} after "
            f"the beam plus {beam_count / (bw * bh):.2f} for the beams ({beam_count / len(cone[0]):.1f} per block); "
            f"{np.mean(start[blive] > bnear[blive]) * 100:.0f} % of the rays started behind a beam, "
            f"the hits among them a median {gap_left:.2f} in front of their depth.\n"]
    print("".join(text))
    append_study(a.out, "benchmarks/studies/proof_budget.py", "Where a proof of the space in front spends its work", "".join(text))
    return 0


if __name__ == "__main__":
    sys.exit(main())
