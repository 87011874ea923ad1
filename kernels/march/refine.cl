/* march/refine.cl: refine a certified bracket [a, b] on a ray: o + a d verified outside the
 * truncated set, o + b d verified inside (julia_level's inside flag, the scene's own
 * definition, iterate.cl), so the surface crossing lies in [a, b].  The march returns
 * the outside end a as the depth and b - a as the bracket width: the crossing lies
 * within the width behind the depth (a thin part stepped over before a is not covered).
 * On a lane type (common/lanes.cl): lanes outside ``todo`` are left as they are.
 *
 * Bisection (-U REFINE_ITP): seed 000_1dc675fe64448cc1.txt §7.1 eq. 11, post-stepping,
 * each step halves the bracket: after n steps its width is h / 2^n (eq. 12).  Unlike the
 * seed's last step, every point is classified, so the bracket stays certified.
 *
 * ITP (-D REFINE_ITP; Oliveira & Takahashi, ACM TOMS 47(1), 2020): interpolate,
 * truncate, project on the level function F = |q_N|^2 / bailout^2 - 1 (julia_level),
 * which is smooth along the ray near the surface - seed 002_6b6c8e6b1cd19649.txt
 * differentiates |q_N|^2 - bailout^2 for its normal - so the regula-falsi point
 * converges superlinearly; truncation (delta = 0.2 w^2 / w0) keeps both ends moving and
 * projection (n0 = 1) bounds the worst case by bisection's plus one step: post-
 * stepping's width h / 2^steps (eq. 12) is guaranteed after at most steps + 1 set tests
 * (and two level evaluations at the ends), usually far fewer; the loop stops there.
 * Both stop early once the bracket cannot be split in the number format. */

inline lreal refine_bracket(quat o, quat d, lreal a, lreal b, lmask todo, int steps,
                            julia_params jp, lreal *width)
{
    if (!L_ANY(todo)) {             /* nothing bracketed: no set tests at all */
        *width = b - a;
        return a;
    }
#ifdef REFINE_ITP
    lmask inside;
    lreal fa = julia_level(QRAY(o, d, a), jp, &inside);
    lreal fb = julia_level(QRAY(o, d, b), jp, &inside);
    /* g = -F: g(a) < 0 outside, g(b) >= 0 inside, the orientation ITP is stated in */
    lreal ya = -fmax(fa, REAL_MIN), yb = -fmin(fb, (real)0);
    lreal w0 = b - a;
    lreal eps = ldexp(w0, -(steps + 1));       /* target: b - a <= 2 eps = w0 / 2^steps */
    lreal k1 = (real)0.2 / w0;
    lmask live = todo & (b - a > (real)2 * eps);
    for (int j = 0; j <= steps && L_ANY(live); ++j) {
        lreal xh = (real)0.5 * (a + b);
        live &= (xh > a) & (xh < b);           /* adjacent numbers: nothing left to split */
        if (!L_ANY(live))
            break;
        lreal r = ldexp(eps, steps + 1 - j) - (real)0.5 * (b - a);
        lreal delta = k1 * (b - a) * (b - a);
        lreal xf = L_SEL(xh, (yb * a - ya * b) / (yb - ya), yb != ya);
        lreal sigma = L_SEL((lreal)-1, (lreal)1, xh >= xf);
        lreal xt = L_SEL(xh, xf + sigma * delta, delta <= fabs(xh - xf));
        lreal x = L_SEL(xh - sigma * r, xt, fabs(xt - xh) <= r);
        x = L_SEL(xh, x, (x > a) & (x < b));
        lreal y = -julia_level(QRAY(o, d, x), jp, &inside);
        lmask got_in = live & inside, got_out = live & !inside;
        b = L_SEL(b, x, got_in);
        yb = L_SEL(yb, fmax(y, (real)0), got_in);
        a = L_SEL(a, x, got_out);
        ya = L_SEL(ya, fmin(y, -REAL_MIN), got_out);
        live &= b - a > (real)2 * eps;
    }
#else
    lmask live = todo;
    for (int j = 0; j < steps && L_ANY(live); ++j) {
        lreal m = (real)0.5 * (a + b);
        live &= (m > a) & (m < b);             /* adjacent numbers: nothing left to split */
        if (!L_ANY(live))
            break;
        lmask got_in = julia_inside(QRAY(o, d, m), jp);
        b = L_SEL(b, m, live & got_in);
        a = L_SEL(a, m, live & !got_in);
    }
#endif
    *width = b - a;
    return a;
}
