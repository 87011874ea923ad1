/* algebra/cquat.cl: Gintz's complexified quaternions (CQuats), q = q1 + q2 i + q3 j + q4 k
 * with i^2 = -1, j^2 = k^2 = +1, ij = ji = -k, ki = ik = -j, jk = kj = i
 * (Odegaard & Wennergren eq. 14), extended bilinearly: commutative, not
 * associative ((ii)j = -j but i(ij) = j), with zero divisors ((1 + j)(1 - j) = 0).
 * Its Julia sets have "square angles and often square holes" (Odegaard & Wennergren §8).  The powers
 * and their derivatives are algebra/power.cl's. */
#define ALG_IN(p) (p)
#define ALG_C(c) (c)
#define ALG_NORM2(q) QNORM2(q)
#define ALG_DOT(a, b) QDOT(a, b)

inline quat alg_mul(quat a, quat b)
{
    return QUAT(a.x * b.x - a.y * b.y + a.z * b.z + a.w * b.w,
                a.x * b.y + a.y * b.x + a.z * b.w + a.w * b.z,
                a.x * b.z + a.z * b.x - a.y * b.w - a.w * b.y,
                a.x * b.w + a.w * b.x - a.y * b.z - a.z * b.y);
}
