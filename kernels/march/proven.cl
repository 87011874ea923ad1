/* march/proven.cl: a march that steps over nothing it has not proven empty, on a lane type
 * (common/lanes.cl).
 *
 * A segment [t0, t1] of the ray holds no point of the truncated set when an enclosure of
 * the orbits of all its points (enclose/ball.cl, enclose/split.cl: enc_segment, enc_step)
 * lies outside the bailout ball at some iteration n <= max_iter: every point then has
 * |q_n| > bailout, so none is inside (POV-Ray 3.6 documentation: inside when |q_n| <=
 * bailout for n = 0 .. max_iter).  This is the interval ray tracing of Knoll, Hijazi,
 * Kensler, Schott, Hansen and Hagen (2009) with circular arithmetic for the enclosure.
 *
 * The march takes segments from near on: a proven one is passed, one that is not proven
 * is shortened, down to the floor width (far - near) / z_resolution.  The next length
 * comes from the enclosure's margin (enc_prove, PROVEN_GAIN): a failed proof shrinks the
 * segment (at least 2x, at most 64x) and a proof with margin to spare lengthens the next
 * (at most 4x); the lengths only steer the march, the proofs alone decide what is passed.  A floor segment
 * that is not proven is tested at FLOOR_POINTS points evenly across it, in order: the first
 * inside one ends the march, with it and the point before (or t0, the end of proven-empty
 * space, so outside) the certified bracket, refined by march/refine.cl; the floor
 * segment's part in front of the refined bracket is proven or counted unproven too
 * (refinement finds a crossing, not the first).  With none inside, the segment is passed
 * unproven, and the
 * pixel is unresolved.  So the first crossing lies in the bracket behind the depth or in
 * one of the unproven segments in front of it; these lie just in front of the surface
 * (where the enclosures are too wide to prove the last floor segments) or where the ray
 * passes the set closely, and a part of the set thinner than the floor could hide in
 * them.  On a hit, ``unresolved`` is the reach from the start of the first unproven
 * segment to the depth (0: the bracket is certified), so [depth - unresolved, depth +
 * width] holds the first crossing: the sum of the unproven widths would not bound the
 * error where an unproven segment lies far in front (the commutative cube's draft stated
 * a p99 of 0.28 and was 0.65 wrong).  On a miss, unresolved is the ray's unproven width.
 * At most max_steps enclosures per ray (STATUS_CAPPED after); ``samples`` counts them. */

/* Whether [t0, t1] is proven empty, for the lanes in ``todo``; *margin gets the largest
 * enc_margin over the iterations, 0 where none is positive: about how many times longer the
 * segment could have been (> 1, proven) or must be shorter (< 1) to be proven, to first order
 * in its length (the march reads every margin at or below 0 alike: shrink the most).
 * *prefix gets the largest s in [-1, 1] whose part [-1, s] of the segment (s = -1 at t0, 1 at
 * t1) some iteration's form keeps outside the bailout (enc_prefix: 1 where proven, -1 where
 * none).  Different points may leave at different iterations, so each iteration's part is
 * proven on its own, and the longest is kept. */
/* enc_start, enc_next, ENC_STEPS and enc_param: the kind's orbits (enclose/julia.cl,
 * enclose/mandelbrot.cl); enc_prefix: the algebra's enclosure piece (enclose/ball.cl,
 * enclose/split.cl), where it has one (ENC_HAS_PREFIX) */
/* ENC_GATE(e, bailout): the lanes whose form may pass a test this iteration - its margin
 * positive, the segment or a part of it outside - where the enclosure piece can tell
 * (enc_gate); the rest skip enc_outside, enc_margin and enc_prefix, which would find nothing
 * there.  Most iterations of a proof are spent with the centre inside the bailout: on the
 * default scene the march took 0.89x the time with the gate (benchmarks/speed/commit_ratio.py). */
#ifdef ENC_HAS_GATE
#define ENC_GATE(e, bailout) enc_gate(e, bailout)
#else
#define ENC_GATE(e, bailout) ((lmask)L_TRUE)
#endif
/* The radius a form must clear with j iterations left, t[min(j, LADDER_N - 1)] (t2: its
 * square, bailout2 itself at j = 0): the bailout, or where the kind's piece says its map keeps
 * norms to a power D (enclose/julia.cl ENC_LADDER_POWER) the least of it and rho_j, rho_0 =
 * bailout, rho_j = (rho_(j-1) + |c|)^(1/D) raised by LADDER_UP for the rounding of |c|, the sum
 * and the root (OpenCL's sqrt and cbrt: 3 and 2 ulps).  rho_j falls to the fixed point of x^D -
 * |c| = x (rho_7 is within 0.05 % of it on the default scene) or rises to it from a smaller
 * bailout, where the bailout itself is the least; either way t[LADDER_N - 1] holds for more
 * iterations left.  On the default scene (float64 twin, 80x60: benchmarks/studies/
 * proof_budget.py) the march then took 12.7 enclosures a ray instead of 18.0, for the same
 * pixels. */
#define LADDER_N 8
#define LADDER_UP ((real)1.0000152587890625)   /* 1 + 2^-16 */
/* t[j] = min(start, rho_j), rho_0 = start, rho_j = (rho_(j-1) + cn)^(1/power) raised by
 * LADDER_UP, and t2[j] its square (start2, the exact square of start, where that is the least) */
#if defined(ENC_LADDER_POWER) || defined(ENC_PART_LADDER_POWER)
inline void ladder_rungs(real start, real start2, real cn, int power, real *t, real *t2)
{
    real rho = start;
    for (int j = 0; j < LADDER_N; ++j) {
        if (j > 0)
            rho = (power == 2 ? sqrt(rho + cn) : cbrt(rho + cn)) * LADDER_UP;
        t[j] = fmin(start, rho);
        t2[j] = rho < start ? rho * rho : start2;
    }
}
#endif
/* pa, pb: a split algebra's per component (ENC_PART_LADDER_POWER: the least of sqrt(2)
 * bailout, which holds at once, and a_j = (a_(j-1) + |c_a|)^(1/D)) */
typedef struct {
    real t[LADDER_N], t2[LADDER_N];
#ifdef ENC_PART_LADDER_POWER
    real pa[LADDER_N], pa2[LADDER_N], pb[LADDER_N], pb2[LADDER_N];
#endif
} enc_ladder;

inline enc_ladder enc_ladder_of(julia_params jp)
{
    enc_ladder l;
    real b = sqrt(jp.bailout2);
#ifdef ENC_PART_LADDER_POWER
    real4 cp = ALG_C(jp.c);
    real a0 = (real)1.4142135623730951 * b * LADDER_UP;
    ladder_rungs(a0, a0 * a0, hypot(cp.x, cp.y), ENC_PART_LADDER_POWER, l.pa, l.pa2);
    ladder_rungs(a0, a0 * a0, hypot(cp.z, cp.w), ENC_PART_LADDER_POWER, l.pb, l.pb2);
#endif
#ifdef ENC_LADDER_POWER
    ladder_rungs(b, jp.bailout2, sqrt(DOT4(jp.c, jp.c)), ENC_LADDER_POWER, l.t, l.t2);
#else
    for (int j = 0; j < LADDER_N; ++j) {
        l.t[j] = b;
        l.t2[j] = jp.bailout2;
    }
#endif
    return l;
}

inline lmask enc_prove(quat o, quat d, lreal t0, lreal t1, lmask todo, julia_params jp, const enc_ladder *lad,
                       lreal *margin, lreal *prefix)
{
    enc_param p;
    enclosure e = enc_start(o, d, t0, t1, jp, &p);
    int steps = ENC_STEPS(jp);
    int j = min(steps, LADDER_N - 1);
    real thr = lad->t[j];
    lmask proven = todo & enc_outside(e, lad->t2[j]);
    lmask live = todo & !proven;
    lreal best = fmax(enc_margin(e, thr), (lreal)0);
#ifdef ENC_HAS_PREFIX
    lreal pre = enc_prefix(e, thr, live);
#else
    lreal pre = (lreal)-1;
#endif
    real bailout = lad->t[0];
    int n = 0;
    for (; n < steps && L_ANY(live); ++n) {
        e = enc_next(e, p, live);
        j = min(steps - n - 1, LADDER_N - 1);
        thr = lad->t[j];
        lmask near = live & ENC_GATE(e, thr);
        lmask out = 0;
        if (L_ANY(near)) {   /* the tests below, only where a form may pass one */
            out = near & enc_outside(e, lad->t2[j]);
            best = L_SEL(best, fmax(best, enc_margin(e, thr)), near);
#ifdef ENC_HAS_PREFIX
            pre = L_SEL(pre, fmax(pre, enc_prefix(e, thr, near)), near);
#endif
        }
#ifdef ENC_PART_LADDER_POWER
        lmask part_near = live & enc_gate_parts(e, lad->pa[j], lad->pb[j]);
        if (L_ANY(part_near)) {   /* each component past its own ladder */
            out |= part_near & enc_outside_parts(e, lad->pa2[j], lad->pb2[j]);
            best = L_SEL(best, fmax(best, enc_margin_parts(e, lad->pa[j], lad->pb[j])), part_near);
            pre = L_SEL(pre, fmax(pre, enc_prefix_parts(e, lad->pa[j], lad->pb[j], part_near)), part_near);
        }
#endif
        proven |= out;
        live &= (!out) & enc_hopeful(e, bailout);
    }
    COUNT_ITER(jp, n);
    *margin = best;
    *prefix = L_SEL(pre, (lreal)1, proven);
    return proven;
}

/* After a partial proof the next segment is as long as its part, or what a failed proof's
 * margin would have shrunk it to where that is longer (a part of a hair must not send the
 * march to the floor, where it passes segments unproven that a shorter try proves): on the
 * default scene (float64 twin, 80x60) the part itself took 23.7 enclosures a ray, 1.5 times
 * it 26.5, twice it 29.3, against 32.5 with no partial proofs.  Its end is pulled in by
 * PREFIX_PULL of itself, two float32 spacings, so that rounding t0 + (t1 - t0) (s + 1) / 2
 * never passes the part proven. */
#define PREFIX_PULL ((real)0.99999952316284180)   /* 1 - 2^-21 */

/* the end of the part of [t0, t1] a partial proof keeps */
inline lreal prefix_end(lreal t0, lreal t1, lreal pre)
{
    return (t0 + (t1 - t0) * ((pre + (real)1) * (real)0.5)) * PREFIX_PULL;
}

/* the first segment: an eighth of the ray, or the floor if that is longer */
#define PROVEN_FIRST ((real)0.125)
/* the next length is the last times sqrt(PROVEN_GAIN * margin): near the set the margin
 * falls about as the length's -2nd power, not its -1st (the remainder ball grows with
 * rho^2; measured on the approach to the hypercomplex sin's surface, 1.8), so the square
 * root lands near the longest provable length; with the margin itself (0.7 m) half the
 * tests on the approach failed (a length 3x too long after each proof, 4x too short after
 * each failure), and the proven march took 12-20 % more tests per ray.  The gain: enclosures
 * a ray at 0.8 / 1.2 / 1.6 (float64 twin, 80x60, the forms of enclose/ball.cl with half
 * the second-order term in the centre): the default scene 18.5 / 17.5 / 17.1, its cube
 * 30.7 / 29.6 / 29.4, at max_iter 20 28.0 / 27.2 / 27.1, the hypercomplex sin 54.2 / 53.6
 * / 55.4, the CQuat square 22.5 / 21.0 / 21.2; the exponent 0.4 or 0.6 instead of the
 * square root's, or growth up to 8x, changed these by under 2 % */
#define PROVEN_GAIN ((real)1.2)
/* the points a floor segment that is not proven is tested at, evenly to its far end: a set
 * test costs a few per cent of an enclosure, and a part of the set thinner than the floor
 * is found unless it is thinner than floor / FLOOR_POINTS (with 2, the hypercomplex sin
 * stepped over such parts on 0.1 % of its pixels: benchmarks/accuracy/pair_accuracy.py) */
#define FLOOR_POINTS 8
/* a stretch where no proof succeeds (a branch cut or pole the enclosures meet on every
 * segment, a ray grazing the surface) is crossed at a floor that doubles after every
 * FLOOR_RUN floor segments passed unproven in a row, up to FLOOR_WIDEST of the ray (its
 * FLOOR_POINTS points then 1/8000 of the ray apart, finer than the scan at 1000), and is
 * back at the preset's floor after the next proof: at the final preset's 1/200000, rays of
 * a hypercomplex acos (c = 0.057 + 0.124i + ..., max_iter 6) lying along its branch cut
 * ran unproven for a third of their length, past 65536 floor segments, and were capped */
#define FLOOR_RUN 32
#define FLOOR_WIDEST ((real)0.001)
/* A floor segment found open right after a proof - a lone near miss, where the ray passes
 * the set closer than the floor, not a grazing run - is looked at again before it is passed:
 * the march goes over it once more at a floor FINE_DIV times finer, passing what it proves
 * there, and gives up at the first fine segment it cannot prove (passing the rest of the
 * floor segment unproven, as before).  What a render states is the reach from its first
 * unproven segment to its depth, so one near miss far in front of the surface widened a
 * pixel's statement by all of that distance: on the 24 pairs' defaults at 48x36
 * (benchmarks/accuracy/pair_accuracy.py) the look narrowed the stated p99 of the hypercomplex
 * sin from 0.31 to 6.6e-4, of the cos from 0.081 to 3.4e-3 and of the quaternion cube from
 * 4.7e-3 to 2.4e-4; the sets with dust barely move (their near misses lie closer still). */
#define FINE_DIV ((real)16)
/* the finest floor the look goes to, of the ray: 2^-20, 16 float32 spacings of t at a ray of
 * length 4 (finer, t + h rounds back to t and the march stalls); the final preset's floor
 * (1/200000) is past it, so the look serves draft and normal */
#define FINE_LEAST ((real)9.5367431640625e-7)

inline lreal march_ray(quat o, quat d, lreal near, lreal far, lmask live, julia_params jp,
                       int z_resolution, int post_steps, int max_steps, lmask *status,
                       lmask *samples, lmask *flags, lreal *width, lreal *unresolved)
{
    enc_ladder lad = enc_ladder_of(jp);
    lreal span = far - near;
    lreal floor_w = span / (real)z_resolution;
    lreal h = fmax(span * PROVEN_FIRST, floor_w);
    lreal t = near, t_in = near, t_out = near, open_w = 0;
    lreal t_open = (lreal)INFINITY;   /* where the first segment passed unproven begins */
    lreal floor_here = floor_w, run = 0;   /* the floor now, unproven floor segments in a row */
    lreal widest = fmax(floor_w, span * FLOOR_WIDEST);
    lmask first = live & julia_inside(QRAY(o, d, near), jp);
    lmask active = live & !first, hit = first, miss = 0, n = 0;
    /* the finer look at a lone open floor segment: its end, the floor before it (-inf: none) */
    lreal fine_end = (lreal)-INFINITY, outer_floor = floor_w;
    for (int i = 0; i < max_steps && L_ANY(active); ++i) {
        lreal t1 = fmin(t + h, far);
        lreal margin, pre;
        lmask empty = enc_prove(o, d, t, t1, active, jp, &lad, &margin, &pre);
        n = L_SEL(n, n + 1, active);
        lmask fine = fine_end > t;
        lmask at_floor = active & !empty & (h <= floor_here);
        /* a partial proof above the floor (outside the fine look): its part passed, proven */
        lreal t_pre = prefix_end(t, t1, pre);
        lmask part = active & !empty & !fine & (h > floor_here) & (t_pre > t);
        lmask got = 0;
        if (L_ANY(at_floor)) {   /* FLOOR_POINTS points across it, in order: a thin part may hold the first */
            lmask look = at_floor;
            lreal before = t;
            for (int j = 1; j <= FLOOR_POINTS && L_ANY(look); ++j) {
                lreal tj = j == FLOOR_POINTS ? t1 : t + (t1 - t) * ((real)j / (real)FLOOR_POINTS);
                lmask in = look & julia_inside(QRAY(o, d, tj), jp);
                t_in = L_SEL(t_in, tj, in);
                t_out = L_SEL(t_out, before, in);
                got |= in;
                look &= !in;
                before = tj;
            }
        }
        lmask found_open = at_floor & !got;
        /* a lone one (run 0: a proof just before) is gone over again at the fine floor */
        lmask again = found_open & !fine & (run == (real)0) & (floor_here >= span * (FINE_LEAST * FINE_DIV));
        lmask open = found_open & !again;
        /* a fine segment left open gives the look up: the rest of its floor segment passes with it */
        lmask give_up = open & fine;
        lreal t_end = L_SEL(t1, fmax(t1, fine_end), give_up);
        open_w = L_SEL(open_w, open_w + (t_end - t), open);
        t_open = L_SEL(t_open, fmin(t_open, t), open);
        lmask proof = empty | part;
        run = L_SEL(L_SEL(run, (lreal)0, proof), run + 1, open);
        lmask wider = open & (run >= (real)FLOOR_RUN);
        floor_here = L_SEL(L_SEL(floor_here, floor_w, proof), fmin(floor_here * 2, widest), wider);
        run = L_SEL(run, (lreal)0, wider);
        hit |= got;
        lmask pass = empty | open;
        lmask done = pass & (t_end >= far);
        miss |= done;
        lreal m = L_SEL((lreal)0, margin, margin == margin);   /* NaN: no guidance */
        lreal fac = sqrt(fmax(m * PROVEN_GAIN, (lreal)0));
        lreal grow = clamp(fac, (lreal)1, (lreal)4);
        lreal shrink = clamp(fac, (lreal)(1.0 / 64), (lreal)0.5);
        h = L_SEL(h, fmin(h * grow, span), empty);
        h = L_SEL(h, fmax(h * shrink, floor_here), active & !empty & !at_floor);
        h = L_SEL(h, floor_here, open);
        h = L_SEL(h, fmax(t_pre - t, h), part);   /* h: already the shrunk try, above */
        t = L_SEL(L_SEL(t, t_pre, part), t_end, pass & !done);
        /* the fine look: begun, kept while t is short of its end, and ended (the floor back) */
        outer_floor = L_SEL(outer_floor, floor_here, again);
        fine_end = L_SEL(fine_end, t1, again);
        lmask ended = (fine | again) & !(fine_end > t);
        fine_end = L_SEL(fine_end, (lreal)-INFINITY, ended);
        floor_here = L_SEL(L_SEL(floor_here, outer_floor, ended), outer_floor / FINE_DIV, fine_end > t);
        h = L_SEL(L_SEL(h, fmax(h * shrink, floor_here), again), floor_here, give_up);
        active &= !(got | done);
    }
    *samples = L_SEL(*samples, n, live);
    *status = L_SEL(*status, L_SEL(L_SEL((lmask)STATUS_CAPPED, (lmask)STATUS_MISS, miss),
                                   (lmask)STATUS_HIT, hit), live);
    lreal w;
    lmask bracketed = hit & !first;
    lreal a = refine_bracket(o, d, t_out, t_in, bracketed, post_steps, jp, &w);
    *width = L_SEL(*width, L_SEL((lreal)0, w, bracketed), hit);
    lreal depth = L_SEL((lreal)INFINITY, L_SEL(t_in, a, bracketed), hit);
    /* refinement finds a crossing in [t, t_in], not the first: the floor segment's part in
     * front of the refined bracket, [t, a], is unproven unless a proof says otherwise.  Where
     * a segment in front was left unproven already (t_open < t), the statement reaches back to
     * it whatever this proof gives, so it is not tried. */
    lreal tail_margin, tail_pre = (lreal)-1;
    lmask tail = bracketed & (a > t) & !(t_open < t);
    lmask tail_empty = L_ANY(tail) ? enc_prove(o, d, t, a, tail, jp, &lad, &tail_margin, &tail_pre) : (lmask)0;
    /* its part a partial proof keeps is proven too */
    lreal t_from = clamp(prefix_end(t, a, tail_pre), t, fmax(a, t));
    open_w = L_SEL(open_w, open_w + (a - t_from), tail & !tail_empty);
    t_open = L_SEL(t_open, fmin(t_open, t_from), tail & !tail_empty);
    /* on a hit, the reach of what is unproven: the first crossing lies in [depth - unresolved,
     * depth + width], every point in front of t_open being proven empty; on a miss the width
     * left unproven; a capped ray adds all it did not reach */
    lreal reach = L_SEL((lreal)0, depth - t_open, t_open < depth);
    *unresolved = L_SEL(*unresolved, L_SEL(L_SEL(open_w, reach, hit), open_w + (far - t), active), live);
    return depth;
}

#ifdef RAYS_FROM_BUFFERS
/* The proof alone on given segments [t0, t1] of rays o + t d, one per work-item (the tests'
 * and benchmarks' handle on enc_prove): proven 1 / 0 and the margin. */
__kernel void prove_segments(const int n_items, __global const real4 *origins, __global const real4 *dirs,
                             __global const real *t0s, __global const real *t1s, const real4 c,
                             const int max_iter, const real bailout, __global int *proven,
                             __global real *margins, __global real *prefixes)
{
#if LANES == 1
    size_t i = get_global_id(0);
    if (i >= (size_t)n_items)
        return;
    julia_params jp = { c, bailout * bailout, (real)0, max_iter COUNTER_NONE };
    lreal m, pre;
    enc_ladder lad = enc_ladder_of(jp);
    proven[i] = enc_prove(origins[i], dirs[i], t0s[i], t1s[i], 1, jp, &lad, &m, &pre) ? 1 : 0;
    margins[i] = m;
    prefixes[i] = pre;
#endif
}
#endif
