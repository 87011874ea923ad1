/* iterate.cl: the escape-time iteration and the distance estimate, on a lane type
 * (real.cl: one ray, or a packet of rays whose finished lanes are frozen).
 *
 * A point p is inside when |q_n| <= bailout for n = 0 .. max_iter, with q_0 = p and
 * q_{n+1} = f(q_n) + c (seed 003: "none of the vectors in the sequence escapes";
 * seed 000 §2.1, eq. 5).  The algebra piece (algebra/<name>.cl) supplies the map, the
 * iterate's coordinates (ALG_IN, ALG_C) and its norm (ALG_NORM2). */

inline lmask julia_inside(quat p, julia_params jp)
{
    quat q = ALG_IN(p);
    real4 c = ALG_C(jp.c);
    lmask live = ALG_NORM2(q) <= jp.bailout2;
    int n = 0;
    for (; n < jp.max_iter && L_ANY(live); ++n) {
        q = QSEL(q, julia_f(q, c), live);
        live = ALG_NORM2(q) <= jp.bailout2;
    }
    COUNT_ITER(jp, n);
    return live;
}

/* The level function of the truncated set (march/refine.cl): F = |q_N|^2 / bailout^2 - 1 at
 * N = max_iter, <= 0 exactly when the point is inside (*inside, the same test as
 * julia_inside).  With bailout >= the escape radius every |q_n| > bailout stays so, so
 * the set is {F <= 0} and its surface the level set F = 0 of a polynomial in the
 * point (seed 002_6b6c8e6b1cd19649.txt).  An orbit that escapes at n < N is not iterated
 * on (it would overflow); |q_N|^2 is extrapolated as (|q_n|^2)^(D^(N-n)), the growth of
 * q^D for large q (D = JULIA_GROWTH; 2 for functions that are no polynomial), and capped
 * at 1e30: only the interpolation uses the value, never the inside test. */
inline lreal julia_level(quat p, julia_params jp, lmask *inside)
{
    quat q = ALG_IN(p);
    real4 c = ALG_C(jp.c);
    lreal m2 = ALG_NORM2(q);
    lmask live = m2 <= jp.bailout2;
    lmask steps = 0;                /* iterations done, per lane */
    int n = 0;
    for (; n < jp.max_iter && L_ANY(live); ++n) {
        q = QSEL(q, julia_f(q, c), live);
        m2 = ALG_NORM2(q);
        steps = L_SEL(steps, steps + 1, live);
        live = m2 <= jp.bailout2;
    }
    COUNT_ITER(jp, n);
    *inside = m2 <= jp.bailout2;
    lmask k = jp.max_iter - steps;
#if JULIA_GROWTH == 2
    lreal e = ldexp(log(m2 / jp.bailout2), min(k, 60));
#else
    lreal e = log(m2 / jp.bailout2) * pow((lreal)JULIA_GROWTH, convert_lreal(min(k, 60)));
#endif
    lreal out = L_SEL(expm1(fmin(e, (real)69)), (lreal)1e30, (k > 60) | (e > (real)69));
    return L_SEL(out, m2 / jp.bailout2 - (real)1, *inside);
}

#ifdef ALG_HAS_DE
/* Distance-estimate formula d = |q_n| ln|q_n| / (2 |q_n'|)  (seed 001 §3.1, eq. 8)
 * evaluated at the last iterate, whether or not it escaped.  The derivative is
 * carried squared, so the loop needs no sqrt: |q'_{n+1}|^2 = 4 |q_n|^2 |q'_n|^2, and
 * d = sqrt(m2 / dm2) ln(m2) / 4.  Where |q'| would overflow, it is carried as a
 * mantissa times 2^e (ldexp), so the estimate stays finite at any max_iter.
 * Sets *escaped.  This is the smooth field the gradient normal differentiates. */
inline lreal julia_distance_formula(quat p, julia_params jp, lmask *escaped)
{
    quat q = ALG_IN(p);
    real4 c = ALG_C(jp.c);
    lreal m2 = ALG_NORM2(q);
    lreal dm2 = (lreal)1;
    lmask e = 0;                    /* dm2 is really dm2 * 2^e */
    lmask live = m2 <= jp.bailout2;
    int n = 0;
    for (; n < jp.max_iter && L_ANY(live); ++n) {
        dm2 = L_SEL(dm2, dm2 * JULIA_DF2(m2), live);
        lmask big = live & (dm2 > (real)1e16);
        if (L_ANY(big)) {           /* rescale long before float32 overflows (3e38) */
            lmask k;
            lreal mant = frexp(dm2, &k);
            dm2 = L_SEL(dm2, mant, big);
            e = L_SEL(e, e + k, big);
        }
        q = QSEL(q, julia_f(q, c), live);
        m2 = ALG_NORM2(q);
        live = m2 <= jp.bailout2;
    }
    COUNT_ITER(jp, n);
    *escaped = m2 > jp.bailout2;
    /* q_n = 0 exactly makes ln -> -inf; the smallest normal number keeps it finite */
    lreal mq = fmax(m2, REAL_MIN);
    lreal ratio = ldexp(sqrt(mq / fmax(dm2, REAL_MIN)), -e / 2);
    ratio = L_SEL(ratio, ratio * (real)0.70710678118654752, (e & 1) != 0);
    /* the 1/2 of the lower bound G / (2 |G'|) (Koebe), whatever the degree */
    return ratio * log(mq) / (real)4;
}

/* The distance estimate the march steps by: 0 inside (the point never escaped). */
inline lreal julia_distance(quat p, julia_params jp)
{
    lmask escaped;
    lreal d = julia_distance_formula(p, jp, &escaped);
    return L_SEL((lreal)0, d, escaped);
}
#endif  /* ALG_HAS_DE */
