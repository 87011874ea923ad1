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

/* |L_m^T L_m - |m|^2 I|_F^2 for algebra/power.cl's bound on h -> m h: its off-diagonal
 * entries are 2 m_z m_w, 2 m_y m_w, 2 m_y m_z, 2 (m_x m_w + m_y m_z), 2 (m_x m_z + m_y m_w)
 * and 2 (m_x m_y + m_z m_w), each twice */
inline lreal alg_off_gram2(quat m)
{
    lreal a = m.z * m.w, b = m.y * m.w, c = m.y * m.z;
    lreal d = m.x * m.w + m.y * m.z, e = m.x * m.z + m.y * m.w, f = m.x * m.y + m.z * m.w;
    return (real)8 * (a * a + b * b + c * c + d * d + e * e + f * f);
}
#define ALG_OFF_GRAM2(m) alg_off_gram2(m)
