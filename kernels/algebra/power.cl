/* algebra/power.cl: q -> q^D + c in a commutative algebra given only by its product
 * alg_mul (algebra/cquat.cl, algebra/commutative.cl), D = FUNC_POWER (function/sqr.cl,
 * function/cube.cl).  Without associativity the cube needs a bracketing: (q q) q, which
 * commutativity makes equal to q (q q).  Derivatives by the product rule, commutativity
 * merging the terms: d(q q)[h] = 2 q h,  d((q q) q)[h] = (2 q h) q + (q q) h. */
#ifndef FUNC_POWER
#error "this algebra takes sqr and cube only (scene.FUNCTIONS_OF)"
#endif

#if FUNC_POWER == 2
inline quat julia_f(quat q, real4 c) { return QADD_UNIFORM(alg_mul(q, q), c); }
inline quat julia_f_jvp(quat q, quat h) { return QSCALE((lreal)2, alg_mul(q, h)); }
#else
inline quat julia_f(quat q, real4 c) { return QADD_UNIFORM(alg_mul(alg_mul(q, q), q), c); }
inline quat julia_f_jvp(quat q, quat h)
{
    return QADD(alg_mul(QSCALE((lreal)2, alg_mul(q, h)), q), alg_mul(alg_mul(q, q), h));
}
#endif
#define JULIA_GROWTH FUNC_POWER

/* enclose/ball.cl: the table's product bounds.  Each coordinate of a b is a^T P b with P a
 * signed permutation matrix (algebra/table.py's INDEX is a Latin square), so |a b| <= 2 |a| |b|,
 * and h -> m h is a matrix L_m whose rows and columns each hold the m_i once, signed: its
 * norm is at most |m|_1.  Tighter where the algebra gives ALG_OFF_GRAM2(m) = |S|_F^2, S =
 * L_m^T L_m - |m|^2 I: each column of L_m is a signed permutation of m, so S has a zero
 * diagonal, its eigenvalues sum to 0, and the largest of n numbers summing to 0 is at most
 * sqrt((n - 1) / n) times their root sum of squares:
 *     |L_m|^2 <= |m|^2 + sqrt(3/4 |S|_F^2).
 * On random m this is 5.5 % above |L_m| on average, where |m|_1 is 26 % (CQuats) and 15 %
 * (the commutative rules) above it; the proofs' remainder grows by 2 L(m) an iteration, so
 * the gain compounds along the orbit.  It is raised by ALG_LBOUND_UP for its rounding: an
 * entry of S, a difference of products, is off by at most a float32 spacing of |m|^2, which
 * moves sqrt(3/4 |S|_F^2) by at most 2.45 sqrt(6) = 6 spacings and L by 3, and the sums and
 * roots add 3 more; 2^-19 is 32 halves of a spacing. */
#define ALG_ENCLOSE_K 2
inline lreal alg_norm1(quat m) { return fabs(m.x) + fabs(m.y) + fabs(m.z) + fabs(m.w); }
#ifdef ALG_OFF_GRAM2
#define ALG_LBOUND_UP ((real)1.0000019073486328)   /* 1 + 2^-19 */
inline lreal alg_lbound(quat m)
{
    return fmin(sqrt(QNORM2(m) + sqrt((real)0.75 * ALG_OFF_GRAM2(m))) * ALG_LBOUND_UP, alg_norm1(m));
}
#else
#define alg_lbound alg_norm1
#endif
#define ALG_LBOUND(m) alg_lbound(m)
#define ALG_LBOUND_SQR(m) alg_lbound(alg_mul((m), (m)))
