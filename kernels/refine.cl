/* refine.cl: refine a certified bracket [a, b] on a ray: o + a d verified outside the
 * truncated set, o + b d verified inside (julia_level's inside flag, the scene's own
 * definition, iterate.cl), so the surface crossing lies in [a, b].  The march returns
 * the outside end a as the depth and b - a as the bracket width: the crossing lies
 * within the width behind the depth (a thin part stepped over before a is not covered).
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

inline real refine_bracket(real4 o, real4 d, real a, real b, int steps, julia_params jp,
                           real *width)
{
#ifdef REFINE_ITP
    int inside;
    real fa = julia_level(o + a * d, jp, &inside);
    real fb = julia_level(o + b * d, jp, &inside);
    /* g = -F: g(a) < 0 outside, g(b) >= 0 inside, the orientation ITP is stated in */
    real ya = -fmax(fa, REAL_MIN), yb = -fmin(fb, (real)0);
    real w0 = b - a;
    real eps = ldexp(w0, -(steps + 1));        /* target: b - a <= 2 eps = w0 / 2^steps */
    real k1 = (real)0.2 / w0;
    for (int j = 0; j <= steps && b - a > (real)2 * eps; ++j) {
        real xh = (real)0.5 * (a + b);
        if (!(xh > a && xh < b))
            break;                              /* adjacent numbers: nothing left to split */
        real r = ldexp(eps, steps + 1 - j) - (real)0.5 * (b - a);
        real delta = k1 * (b - a) * (b - a);
        real xf = yb != ya ? (yb * a - ya * b) / (yb - ya) : xh;
        real sigma = xh >= xf ? (real)1 : (real)-1;
        real xt = delta <= fabs(xh - xf) ? xf + sigma * delta : xh;
        real x = fabs(xt - xh) <= r ? xt : xh - sigma * r;
        if (!(x > a && x < b))
            x = xh;
        real y = -julia_level(o + x * d, jp, &inside);
        if (inside) {
            b = x;
            yb = fmax(y, (real)0);
        } else {
            a = x;
            ya = fmin(y, -REAL_MIN);
        }
    }
#else
    for (int j = 0; j < steps; ++j) {
        real m = (real)0.5 * (a + b);
        if (!(m > a && m < b))
            break;                              /* adjacent numbers: nothing left to split */
        if (julia_inside(o + m * d, jp))
            b = m;
        else
            a = m;
    }
#endif
    *width = b - a;
    return a;
}
