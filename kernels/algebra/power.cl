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
 * and h -> m h is a matrix whose rows and columns each hold the m_i once, signed: its norm
 * is at most |m|_1. */
#define ALG_ENCLOSE_K 2
inline lreal alg_norm1(quat m) { return fabs(m.x) + fabs(m.y) + fabs(m.z) + fabs(m.w); }
#define ALG_LBOUND(m) alg_norm1(m)
#define ALG_LBOUND_SQR(m) alg_norm1(alg_mul((m), (m)))
