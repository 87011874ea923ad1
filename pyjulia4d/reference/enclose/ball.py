"""float64 twin of kernels/enclose/ball.cl: orbit enclosures of a ray segment p(s) = m + s v,
s in [-1, 1], as affine forms q_n(s) in m_n + s v_n + B(r_n), for the algebras iterated in
the point's own coordinates (quaternions, CQuats, the commutative rules).  With rho = |v| + r,
K, L(m), L(m m) the algebra's product bounds (ALG_ENCLOSE_K, ALG_LBOUND, ALG_LBOUND_SQR):
    D = 2:  r' = 2 L(m) r + |v v| / 2 + 2 L(v) r + K r^2,  centre julia_f(m, c) + v v / 2
            (half of s^2 v v in the centre: Stolfi & de Figueiredo 1997 §3.3),
    D = 3:  r' = (L(m m) + 2 L(m)^2) r + |Q(v)| / 2 + |v^3| / 4 + 3 K L(m) (2 |v| + r) r
                 + K^2 ((|v| + r)^3 - |v|^3),  centre julia_f(m, c) + Q(v) / 2, Q(v) = julia_f_jvp(v, m)
            (s^2 and s^3 split alike: s^3 = 3 s / 4 + at most 1/4),
tangent julia_f_jvp(m, v) (+ 3 v^3 / 4 for D = 3)."""
from __future__ import annotations

import numpy as np

from pyjulia4d.reference.enclose.disc import enc_radius, least_norm, prefix_of, rounding


def _norm(q):
    return np.sqrt(np.sum(q * q, axis=-1))


def enc_segment(o, d, t0, t1, F):
    """The affine form of the points o + t d, t in [t0, t1] (per ray)."""
    tm, hw = 0.5 * (t0 + t1), 0.5 * (t1 - t0)
    m = o + tm[:, None] * d
    return m, hw[:, None] * d, enc_radius(0.0, _norm(o) + np.abs(tm) * _norm(d), rounding().sum)


def enc_step(e, c, F):
    m, v, r = e
    alg = F.alg
    K = alg.ALG_ENCLOSE_K
    with np.errstate(all="ignore"):
        s, lm = _norm(m), alg.ALG_LBOUND(m)
        sv = _norm(v)
        if F.fn.FUNC_POWER == 2:
            vv = F.julia_f(v, np.zeros(4))   # v v (the rotated map's u (u^-1 v)^2)
            rn = 2 * lm * r + 0.5 * _norm(vv) + (2 * alg.ALG_LBOUND(v) + K * r) * r
            size = K * s * s + 2 * lm * sv + K * sv * sv
            mn = F.julia_f(m, c) + 0.5 * vv
            vn = F.julia_f_jvp(m, v)
        else:
            qv, cv = F.julia_f_jvp(v, m), F.julia_f(v, np.zeros(4))   # Q(v) and v^3
            jn = alg.ALG_LBOUND_SQR(m) + 2 * lm * lm
            # the quaternions' |Q(v)| by its bound 3 |m| |v|^2 (enclose/ball.cl)
            qvl = 3 * lm * sv * sv if getattr(alg, "ALG_LBOUND_IS_LEN", False) else _norm(qv)
            rn = jn * r + 0.5 * qvl + 0.25 * _norm(cv) + (
                3 * K * lm * (2 * sv + r) + K * K * (3 * sv * sv + (3 * sv + r) * r)) * r
            size = K * K * s ** 3 + jn * sv + (3 * K * lm + K * K * sv) * sv * sv
            mn = F.julia_f(m, c) + 0.5 * qv
            vn = F.julia_f_jvp(m, v) + 0.75 * cv
        gain = 8 if F.theta != 0 else 4   # the rotated map's two more rotations (enclose/ball.cl ENC_STEP_GAIN)
        return mn, vn, enc_radius(rn, gain * size + 2 * np.linalg.norm(c), rounding().sum)


def enc_add(a, b):
    """The sum of two forms in the same s (enclose/ball.cl)."""
    (ma, va, ra), (mb, vb, rb) = a, b
    return ma + mb, va + vb, enc_radius(ra + rb, _norm(ma) + _norm(mb) + _norm(va) + _norm(vb), rounding().sum)


def enc_shift(e, k):
    """The form plus a constant k in the algebra's coordinates."""
    m, v, r = e
    k = np.asarray(k, np.float64)
    return m + k, v, enc_radius(r, _norm(m) + np.linalg.norm(k), rounding().sum)


def enc_outside(e, bailout2):
    m, v, r = e
    with np.errstate(all="ignore"):
        lo = least_norm(m, v) * (1 - rounding().sum) - r
        return (lo > 0) & (lo * lo > bailout2)


def enc_prefix(e, bailout):
    """The part [-1, s] of the segment the form keeps outside the bailout (-1: none;
    kernels/enclose/ball.cl)."""
    m, v, r = e
    return prefix_of(m, v, np.sum(m * m, axis=-1), bailout + r)


def enc_margin(e, bailout):
    m, v, r = e
    with np.errstate(all="ignore"):
        return (_norm(m) - bailout) / (_norm(v) + r)


def enc_gate(e, bailout):
    """Whether the form may pass a test (kernels/enclose/ball.cl enc_gate): |m| > bailout, or
    |m| + |v| > bailout + r."""
    m, v, r = e
    ml, vl = _norm(m), _norm(v)
    return (ml > bailout) | (ml + vl > bailout + r)


def enc_hopeful(e, bailout):
    """Whether the form may still prove the segment: an extent past twice the centre's
    distance plus the bailout only grows faster than the centre (kernels/enclose/ball.cl)."""
    m, v, r = e
    with np.errstate(all="ignore"):
        return _norm(v) + r < 2 * (_norm(m) + bailout)
