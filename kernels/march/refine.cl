/* march/refine.cl: refine a certified bracket [a, b] on a ray: o + a d verified outside the
 * truncated set, o + b d verified inside (julia_level's inside flag, the scene's own
 * definition, iterate.cl), so the surface crossing lies in [a, b].  The march returns
 * the outside end a as the depth and b - a as the bracket width: the crossing lies
 * within the width behind the depth (a thin part stepped over before a is not covered).
 * On a lane type (common/lanes.cl): lanes outside ``todo`` are left as they are.
 *
 * Bisection (-U REFINE_ITP): Odegaard & Wennergren §7.1 eq. 11, post-stepping,
 * each step halves the bracket: after n steps its width is h / 2^n (eq. 12).  Unlike the
 * seed's last step, every point is classified, so the bracket stays certified.
 *
 * ITP (-D REFINE_ITP; Oliveira & Takahashi, ACM TOMS 47(1), 2020): interpolate,
 * truncate, project on the level function F = |q_N|^2 / bailout^2 - 1 (julia_level),
 * which is smooth along the ray near the surface - Quilez 2002
 * differentiates |q_N|^2 - bailout^2 for its normal - so the regula-falsi point
 * converges superlinearly; truncation (delta = 0.2 w^2 / w0) keeps both ends moving and
 * projection (n0 = 1) bounds the worst case by bisection's plus one step: post-
 * stepping's width h / 2^steps (eq. 12) is guaranteed after at most steps + 1 set tests
 * (and two level evaluations at the ends), usually far fewer; the loop stops there.
 * Both stop early once the bracket cannot be split in the number format. */

#ifdef REFINE_ITP
/* A packet's ITP refinement between set tests: the bracket [a, b], g = -F at its ends. */
typedef struct {
    lreal a, b, ya, yb, eps, k1;
    lmask live;
} itp_state;

inline itp_state itp_start(lreal a, lreal b, lreal fa, lreal fb, lmask todo, int steps)
{
    itp_state s;
    s.a = a;
    s.b = b;
    /* g = -F: g(a) < 0 outside, g(b) >= 0 inside, the orientation ITP is stated in */
    s.ya = -fmax(fa, REAL_MIN);
    s.yb = -fmin(fb, (real)0);
    lreal w0 = b - a;
    s.eps = ldexp(w0, -(steps + 1));       /* target: b - a <= 2 eps = w0 / 2^steps */
    s.k1 = (real)0.2 / w0;
    s.live = todo & (b - a > (real)2 * s.eps);
    return s;
}

/* the point of step j; lanes whose bracket cannot be split any more leave */
inline lreal itp_point(itp_state *s, int j, int steps)
{
    lreal a = s->a, b = s->b;
    lreal xh = (real)0.5 * (a + b);
    s->live &= (xh > a) & (xh < b);           /* adjacent numbers: nothing left to split */
    lreal r = ldexp(s->eps, steps + 1 - j) - (real)0.5 * (b - a);
    lreal delta = s->k1 * (b - a) * (b - a);
    lreal xf = L_SEL(xh, (s->yb * a - s->ya * b) / (s->yb - s->ya), s->yb != s->ya);
    lreal sigma = L_SEL((lreal)-1, (lreal)1, xh >= xf);
    lreal xt = L_SEL(xh, xf + sigma * delta, delta <= fabs(xh - xf));
    lreal x = L_SEL(xh - sigma * r, xt, fabs(xt - xh) <= r);
    return L_SEL(xh, x, (x > a) & (x < b));
}

/* the set test at x: F(x) = f, inside or not */
inline void itp_take(itp_state *s, lreal x, lreal f, lmask inside)
{
    lreal y = -f;
    lmask got_in = s->live & inside, got_out = s->live & !inside;
    s->b = L_SEL(s->b, x, got_in);
    s->yb = L_SEL(s->yb, fmax(y, (real)0), got_in);
    s->a = L_SEL(s->a, x, got_out);
    s->ya = L_SEL(s->ya, fmin(y, -REAL_MIN), got_out);
    s->live &= s->b - s->a > (real)2 * s->eps;
}
#endif

inline lreal refine_bracket(quat o, quat d, lreal a, lreal b, lmask todo, int steps,
                            julia_params jp, lreal *width)
{
    if (!L_ANY(todo)) {             /* nothing bracketed: no set tests at all */
        *width = b - a;
        return a;
    }
    quat away = ORBIT_AWAY(jp);   /* where lanes not refining take their set tests (iterate.cl) */
#ifdef REFINE_ITP
    lmask inside;
    lreal fa = julia_level(QSEL(away, QRAY(o, d, a), todo), jp, &inside);
    lreal fb = julia_level(QSEL(away, QRAY(o, d, b), todo), jp, &inside);
    itp_state s = itp_start(a, b, fa, fb, todo, steps);
    for (int j = 0; j <= steps && L_ANY(s.live); ++j) {
        lreal x = itp_point(&s, j, steps);
        if (!L_ANY(s.live))
            break;
        lreal f = julia_level(QSEL(away, QRAY(o, d, x), s.live), jp, &inside);
        itp_take(&s, x, f, inside);
    }
    a = s.a;
    b = s.b;
#else
    lmask live = todo;
    for (int j = 0; j < steps && L_ANY(live); ++j) {
        lreal m = (real)0.5 * (a + b);
        live &= (m > a) & (m < b);             /* adjacent numbers: nothing left to split */
        if (!L_ANY(live))
            break;
        lmask got_in = julia_inside(QSEL(away, QRAY(o, d, m), live), jp);
        b = L_SEL(b, m, live & got_in);
        a = L_SEL(a, m, live & !got_in);
    }
#endif
    *width = b - a;
    return a;
}

#ifdef PACKET_PAIRS
/* refine_bracket of two packets, [0] and [1]: their set tests side by side (iterate.cl
 * julia_level_pair for ITP, julia_inside_pair for bisection), lane for lane the same brackets. */
inline void refine_bracket_pair(const quat *o, const quat *d, const lreal *a, const lreal *b, const lmask *todo,
                                int steps, julia_params jp, lreal *out, lreal *width)
{
    if (!L_ANY(todo[0] | todo[1])) {   /* nothing bracketed: no set tests at all */
        out[0] = a[0];
        out[1] = a[1];
        width[0] = b[0] - a[0];
        width[1] = b[1] - a[1];
        return;
    }
    quat away = ORBIT_AWAY(jp);   /* where lanes not refining take their set tests (iterate.cl) */
#ifndef REFINE_ITP
    lreal a0 = a[0], b0 = b[0], a1 = a[1], b1 = b[1];
    lmask live0 = todo[0], live1 = todo[1];
    for (int j = 0; j < steps && L_ANY(live0 | live1); ++j) {
        lreal m0 = (real)0.5 * (a0 + b0), m1 = (real)0.5 * (a1 + b1);
        live0 &= (m0 > a0) & (m0 < b0);        /* adjacent numbers: nothing left to split */
        live1 &= (m1 > a1) & (m1 < b1);
        if (!L_ANY(live0 | live1))
            break;
        lmask in0, in1;
        julia_inside_pair(QSEL(away, QRAY(o[0], d[0], m0), live0), QSEL(away, QRAY(o[1], d[1], m1), live1), jp,
                          &in0, &in1);
        b0 = L_SEL(b0, m0, live0 & in0);
        a0 = L_SEL(a0, m0, live0 & !in0);
        b1 = L_SEL(b1, m1, live1 & in1);
        a1 = L_SEL(a1, m1, live1 & !in1);
    }
    out[0] = a0;
    out[1] = a1;
    width[0] = b0 - a0;
    width[1] = b1 - a1;
#else
    lmask ia, ib;
    lreal fa0, fa1, fb0, fb1;
    julia_level_pair(QSEL(away, QRAY(o[0], d[0], a[0]), todo[0]), QSEL(away, QRAY(o[1], d[1], a[1]), todo[1]), jp,
                     &ia, &ib, &fa0, &fa1);
    julia_level_pair(QSEL(away, QRAY(o[0], d[0], b[0]), todo[0]), QSEL(away, QRAY(o[1], d[1], b[1]), todo[1]), jp,
                     &ia, &ib, &fb0, &fb1);
    itp_state s0 = itp_start(a[0], b[0], fa0, fb0, todo[0], steps);
    itp_state s1 = itp_start(a[1], b[1], fa1, fb1, todo[1], steps);
    for (int j = 0; j <= steps && L_ANY(s0.live | s1.live); ++j) {
        lreal x0 = itp_point(&s0, j, steps), x1 = itp_point(&s1, j, steps);
        if (!L_ANY(s0.live | s1.live))
            break;
        lreal f0, f1;
        julia_level_pair(QSEL(away, QRAY(o[0], d[0], x0), s0.live), QSEL(away, QRAY(o[1], d[1], x1), s1.live), jp,
                         &ia, &ib, &f0, &f1);
        itp_take(&s0, x0, f0, ia);
        itp_take(&s1, x1, f1, ib);
    }
    out[0] = s0.a;
    out[1] = s1.a;
    width[0] = s0.b - s0.a;
    width[1] = s1.b - s1.a;
#endif
}
#endif
