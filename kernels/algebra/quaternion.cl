/* algebra_quaternion.cl: Hamilton's quaternions, q = q1 + q2 i + q3 j + q4 k
 * with i^2 = j^2 = k^2 = -1, ij = -ji = k, jk = -kj = i, ki = -ik = j
 * (seed 000_1dc675fe64448cc1.txt, eq. 3; seed 003 basis table). */

inline real4 alg_mul(real4 a, real4 b)
{
    return (real4)(a.x * b.x - a.y * b.y - a.z * b.z - a.w * b.w,
                   a.x * b.y + a.y * b.x + a.z * b.w - a.w * b.z,
                   a.x * b.z - a.y * b.w + a.z * b.x + a.w * b.y,
                   a.x * b.w + a.y * b.z - a.z * b.y + a.w * b.x);
}

/* q^2 = (q1^2 - q2^2 - q3^2 - q4^2, 2 q1 q2, 2 q1 q3, 2 q1 q4)  (seed 000, eq. 4), on a
 * lane type (real.cl): one ray or a packet of rays. */
inline quat alg_sqr(quat q)
{
    return QUAT(q.x * q.x - q.y * q.y - q.z * q.z - q.w * q.w,
                (real)2 * q.x * q.y, (real)2 * q.x * q.z, (real)2 * q.x * q.w);
}

/* Directional derivative of q -> q^2 along h: q h + h q = 2 (q1 h1 - v.hv, q1 hv + h1 v);
 * the cross products cancel, so the Jacobian is the matrix of seed 004, method 3. */
inline quat alg_sqr_jvp(quat q, quat h)
{
    return QUAT((real)2 * (q.x * h.x - q.y * h.y - q.z * h.z - q.w * h.w),
                (real)2 * (q.x * h.y + h.x * q.y),
                (real)2 * (q.x * h.z + h.x * q.z),
                (real)2 * (q.x * h.w + h.x * q.w));
}
