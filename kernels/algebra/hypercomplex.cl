/* algebra/hypercomplex.cl: the commutative hypercomplex numbers of Gintz and POV-Ray,
 * h = x + y i + z j + w k with i^2 = j^2 = -1, k^2 = +1, ij = ji = k, jk = kj = -i,
 * ki = ik = -j (Odegaard & Wennergren eq. 13; POV-Ray 3.6 documentation's basis table, whose
 * "kk = -1" contradicts its own ij = k, ijk = 1: k^2 = ijij = i^2 j^2 = +1).
 *
 * The idempotents e1 = (1 + k)/2, e2 = (1 - k)/2 (e1^2 = e1, e2^2 = e2, e1 e2 = 0) split
 * h = a e1 + b e2 into two complex numbers, with j = -ik:
 *     a = (x + w) + (y - z) i,   b = (x - w) + (y + z) i,   |h|^2 = (|a|^2 + |b|^2) / 2,
 * and products act on each component: (h g) = (a a') e1 + (b b') e2.  So any complex
 * function lifts as f(h) = f(a) e1 + f(b) e2, its derivative as the multiplication by
 * f'(a) e1 + f'(b) e2, and the Julia set of f(h) + c is the product of the complex
 * filled Julia sets of f(a) + c_a and f(b) + c_b.  The iterate is kept split:
 * quat (a.re, a.im, b.re, b.im). */

inline quat ALG_IN(quat p) { return QUAT(p.x + p.w, p.y - p.z, p.x - p.w, p.y + p.z); }
inline real4 ALG_C(real4 c) { return (real4)(c.x + c.w, c.y - c.z, c.x - c.w, c.y + c.z); }
#define ALG_NORM2(q) ((real)0.5 * QNORM2(q))
#define ALG_DOT(u, v) ((real)0.5 * QDOT(u, v))

/* f(h) + c on the split iterate: cfun (function/<name>.cl) on each component */
inline quat julia_f(quat q, real4 c)
{
    cplx a = cfun(C(q.x, q.y)), b = cfun(C(q.z, q.w));
    return QUAT(a.re + c.x, a.im + c.y, b.re + c.z, b.im + c.w);
}

/* d f(h)[dh] = f'(a) da e1 + f'(b) db e2 */
inline quat julia_f_jvp(quat q, quat h)
{
    cplx a = c_mul(cfun_d(C(q.x, q.y)), C(h.x, h.y));
    cplx b = c_mul(cfun_d(C(q.z, q.w)), C(h.z, h.w));
    return QUAT(a.re, a.im, b.re, b.im);
}

#define ALG_SPLIT            /* iterate.cl: the distance estimate of a product of two sets */
#ifdef FUNC_POWER
#define JULIA_GROWTH FUNC_POWER
#define ALG_HAS_DE           /* the polynomials: sqr, cube (iterate.cl) */
#if FUNC_POWER == 2
#define JULIA_DF2(m2) ((real)4 * (m2))     /* |f'(z)|^2 = D^2 |z|^(2(D-1)) per component */
#else
#define JULIA_DF2(m2) ((real)9 * (m2) * (m2))
#endif
#else
#define JULIA_GROWTH 2   /* only shapes the level function's extrapolation (iterate.cl) */
#endif
