/* algebra/quaternion.cl: Hamilton's quaternions, q = q1 + q2 i + q3 j + q4 k
 * with i^2 = j^2 = k^2 = -1, ij = -ji = k, jk = -kj = i, ki = -ik = j
 * (Odegaard & Wennergren, eq. 3; POV-Ray 3.6 documentation basis table).  Quaternions take the
 * polynomial functions only (function/sqr.cl, function/cube.cl: FUNC_POWER), as in
 * POV-Ray; the iterate is kept in the point's own coordinates. */
#ifndef FUNC_POWER
#error "the quaternion algebra takes sqr and cube only (scene.FUNCTIONS_OF)"
#endif

/* The algebra's interface to iterate.cl and the normals: the iterate's coordinates
 * (here the point's own), |q|^2 and its bilinear form, c in those coordinates. */
#define ALG_IN(p) (p)
#define ALG_C(c) (c)
#define ALG_NORM2(q) QNORM2(q)
#define ALG_DOT(a, b) QDOT(a, b)

inline real4 alg_mul(real4 a, real4 b)
{
    return (real4)(a.x * b.x - a.y * b.y - a.z * b.z - a.w * b.w,
                   a.x * b.y + a.y * b.x + a.z * b.w - a.w * b.z,
                   a.x * b.z - a.y * b.w + a.z * b.x + a.w * b.y,
                   a.x * b.w + a.y * b.z - a.z * b.y + a.w * b.x);
}

/* q^2 = (q1^2 - q2^2 - q3^2 - q4^2, 2 q1 q2, 2 q1 q3, 2 q1 q4)  (Odegaard & Wennergren, eq. 4), on a
 * lane type (common/lanes.cl): one ray or a packet of rays. */
inline quat alg_sqr(quat q)
{
    return QUAT(q.x * q.x - q.y * q.y - q.z * q.z - q.w * q.w,
                (real)2 * q.x * q.y, (real)2 * q.x * q.z, (real)2 * q.x * q.w);
}

/* Directional derivative of q -> q^2 along h: q h + h q = 2 (q1 h1 - v.hv, q1 hv + h1 v);
 * the cross products cancel, so the Jacobian is the matrix of Quilez (n.d.), method 3. */
inline quat alg_sqr_jvp(quat q, quat h)
{
    return QUAT((real)2 * (q.x * h.x - q.y * h.y - q.z * h.z - q.w * h.w),
                (real)2 * (q.x * h.y + h.x * q.y),
                (real)2 * (q.x * h.z + h.x * q.z),
                (real)2 * (q.x * h.w + h.x * q.w));
}

/* q = (x, v): q^3 = (x^3 - 3 x |v|^2, (3 x^2 - |v|^2) v)  (every power of q lies in the
 * complex plane spanned by 1 and v; Quilez (n.d.)'s cubic Julia sets). */
inline quat alg_cube(quat q)
{
    lreal v2 = q.y * q.y + q.z * q.z + q.w * q.w;
    lreal s = (real)3 * q.x * q.x - v2;
    return QUAT(q.x * (q.x * q.x - (real)3 * v2), s * q.y, s * q.z, s * q.w);
}

/* d(q^3)[h] = q^2 h + q h q + h q^2, in components: with h = (a, u),
 * (3 x^2 a - 3 a |v|^2 - 6 x v.u,  (6 x a - 2 v.u) v + (3 x^2 - |v|^2) u). */
inline quat alg_cube_jvp(quat q, quat h)
{
    lreal v2 = q.y * q.y + q.z * q.z + q.w * q.w;
    lreal vu = q.y * h.y + q.z * h.z + q.w * h.w;
    lreal s = (real)3 * q.x * q.x - v2;
    lreal t = (real)6 * q.x * h.x - (real)2 * vu;
    return QUAT((real)3 * (q.x * q.x * h.x - h.x * v2) - (real)6 * q.x * vu,
                t * q.y + s * h.y, t * q.z + s * h.z, t * q.w + s * h.w);
}

/* The map f(q) + c, its derivative along h, and for the distance estimate |f'(q)|^2 as a
 * function of m2 = |q|^2: |q'_{n+1}| = D |q_n|^(D-1) |q'_n|, the quaternion norm being
 * multiplicative (Hart, Sandin & Kauffman 1989 §3.1). */
#if FUNC_POWER == 2
inline quat julia_f(quat q, real4 c) { return QADD_UNIFORM(alg_sqr(q), c); }
inline quat julia_f_jvp(quat q, quat h) { return alg_sqr_jvp(q, h); }
#define JULIA_DF2(m2) ((real)4 * (m2))
#else
inline quat julia_f(quat q, real4 c) { return QADD_UNIFORM(alg_cube(q), c); }
inline quat julia_f_jvp(quat q, quat h) { return alg_cube_jvp(q, h); }
#define JULIA_DF2(m2) ((real)9 * (m2) * (m2))
#endif
#define ALG_HAS_DE            /* march/de.cl and normals/gradient.cl may be built */
#define JULIA_GROWTH FUNC_POWER

/* enclose/ball.cl: |a b| = |a| |b| */
#define ALG_ENCLOSE_K 1
#define ALG_LBOUND(m) QLEN(m)
#define ALG_LBOUND_IS_LEN     /* enclose/ball.cl: the bound is |m| itself */
#define ALG_LBOUND_SQR(m) QNORM2(m)
