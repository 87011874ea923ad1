/* algebra/commutative.cl: the naive commutative quaternion rules of
 * Odegaard & Wennergren eq. 15: i^2 = j^2 = k^2 = -1, ij = ji = k, ki = ik = j,
 * jk = kj = i, extended bilinearly: commutative, not associative ((ii)j = -j but
 * i(ij) = ik = j); "highly irregular shapes" (Odegaard & Wennergren Fig. 7).  The powers and their
 * derivatives are algebra/power.cl's. */
#define ALG_IN(p) (p)
#define ALG_C(c) (c)
#define ALG_NORM2(q) QNORM2(q)
#define ALG_DOT(a, b) QDOT(a, b)

inline quat alg_mul(quat a, quat b)
{
    return QUAT(a.x * b.x - a.y * b.y - a.z * b.z - a.w * b.w,
                a.x * b.y + a.y * b.x + a.z * b.w + a.w * b.z,
                a.x * b.z + a.z * b.x + a.y * b.w + a.w * b.y,
                a.x * b.w + a.w * b.x + a.y * b.z + a.z * b.y);
}
