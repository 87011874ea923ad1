/* iterate.cl: the escape-time iteration and the distance estimate.
 *
 * A point p is inside when |q_n| <= bailout for n = 0 .. max_iter, with q_0 = p and
 * q_{n+1} = f(q_n) (seed 003: "none of the vectors in the sequence escapes";
 * seed 000 §2.1, eq. 5). */

inline int julia_inside(real4 p, julia_params jp)
{
    real4 q = p;
    for (int n = 0; n < jp.max_iter; ++n) {
        if (dot(q, q) > jp.bailout2) {
            COUNT_ITER(jp, n);
            return 0;
        }
        q = julia_f(q, jp.c);
    }
    COUNT_ITER(jp, jp.max_iter);
    return dot(q, q) <= jp.bailout2;
}

/* The level function of the truncated set (refine.cl): F = |q_N|^2 / bailout^2 - 1 at
 * N = max_iter, <= 0 exactly when the point is inside (*inside, the same test as
 * julia_inside).  With bailout >= the escape radius every |q_n| > bailout stays so, so
 * the set is {F <= 0} and its surface the level set F = 0 of a polynomial in the
 * point (seed 002_6b6c8e6b1cd19649.txt).  An orbit that escapes at n < N is not iterated
 * on (it would overflow); |q_N|^2 is extrapolated as (|q_n|^2)^(2^(N-n)), the growth of
 * q^2 for large q, and capped at 1e30: only the interpolation uses the value. */
inline real julia_level(real4 p, julia_params jp, int *inside)
{
    real4 q = p;
    real m2 = dot(q, q);
    int n = 0;
    for (; n < jp.max_iter && m2 <= jp.bailout2; ++n) {
        q = julia_f(q, jp.c);
        m2 = dot(q, q);
    }
    COUNT_ITER(jp, n);
    *inside = m2 <= jp.bailout2;
    if (*inside)
        return m2 / jp.bailout2 - (real)1;
    int k = jp.max_iter - n;
    real l = log(m2 / jp.bailout2);
    if (k > 60)
        return (real)1e30;
    real e = ldexp(l, k);
    return e > (real)69 ? (real)1e30 : expm1(e);
}

/* Distance-estimate formula d = |q_n| ln|q_n| / (2 |q_n'|)  (seed 001 §3.1, eq. 8)
 * evaluated at the last iterate, whether or not it escaped.  The derivative is
 * carried squared, so the loop needs no sqrt: |q'_{n+1}|^2 = 4 |q_n|^2 |q'_n|^2, and
 * d = sqrt(m2 / dm2) ln(m2) / 4.  Where |q'| would overflow, it is carried as a
 * mantissa times 2^e (ldexp), so the estimate stays finite at any max_iter.
 * Sets *escaped.  This is the smooth field the gradient normal differentiates. */
inline real julia_distance_formula(real4 p, julia_params jp, int *escaped)
{
    real4 q = p;
    real m2 = dot(q, q);
    real dm2 = (real)1;
    int e = 0;                      /* dm2 is really dm2 * 2^e */
    int n = 0;
    for (; n < jp.max_iter; ++n) {
        if (m2 > jp.bailout2)
            break;
        dm2 *= JULIA_DF2(m2);
        if (dm2 > (real)1e16) {     /* rescale long before float32 overflows (3e38) */
            int k;
            dm2 = frexp(dm2, &k);
            e += k;
        }
        q = julia_f(q, jp.c);
        m2 = dot(q, q);
    }
    COUNT_ITER(jp, n);
    *escaped = m2 > jp.bailout2;
    /* q_n = 0 exactly makes ln -> -inf; the smallest normal number keeps it finite */
    real mq = fmax(m2, REAL_MIN);
    real ratio = ldexp(sqrt(mq / fmax(dm2, REAL_MIN)), -e / 2);
    if (e & 1)
        ratio *= (real)0.70710678118654752;
    return ratio * log(mq) / ((real)2 * JULIA_DEGREE);
}

/* The distance estimate the march steps by: 0 inside (the point never escaped). */
inline real julia_distance(real4 p, julia_params jp)
{
    int escaped;
    real d = julia_distance_formula(p, jp, &escaped);
    return escaped ? d : (real)0;
}
