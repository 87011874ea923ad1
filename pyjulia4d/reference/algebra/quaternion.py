"""float64 twin of kernels/algebra/quaternion.cl: Hamilton's quaternions
(Ödegaard & Wennergren eq. 3; POV-Ray 3.6 documentation's basis table), sqr and cube only."""
from __future__ import annotations

import numpy as np


def _dot(a, b):
    return np.sum(a * b, axis=-1)


def ALG_IN(p):
    """The iterate's coordinates: the point's own."""
    return np.asarray(p, np.float64)


def ALG_C(c):
    return np.asarray(c, np.float64)


def ALG_NORM2(q):
    return _dot(q, q)


def ALG_DOT(a, b):
    return _dot(a, b)


def alg_mul(a, b):
    """Hamilton product (Ödegaard & Wennergren eq. 3)."""
    a1, a2, a3, a4 = np.moveaxis(a, -1, 0)
    b1, b2, b3, b4 = np.moveaxis(b, -1, 0)
    return np.stack([a1 * b1 - a2 * b2 - a3 * b3 - a4 * b4,
                     a1 * b2 + a2 * b1 + a3 * b4 - a4 * b3,
                     a1 * b3 - a2 * b4 + a3 * b1 + a4 * b2,
                     a1 * b4 + a2 * b3 - a3 * b2 + a4 * b1], axis=-1)


def alg_sqr(q):
    """q^2 (Ödegaard & Wennergren eq. 4)."""
    x, y, z, w = np.moveaxis(q, -1, 0)
    return np.stack([x * x - y * y - z * z - w * w, 2 * x * y, 2 * x * z, 2 * x * w], axis=-1)


def alg_sqr_jvp(q, h):
    """d(q^2)[h] = q h + h q."""
    x, y, z, w = np.moveaxis(q, -1, 0)
    a, b, c, d = np.moveaxis(h, -1, 0)
    return 2 * np.stack([x * a - y * b - z * c - w * d, x * b + a * y, x * c + a * z,
                         x * d + a * w], axis=-1)


def alg_cube(q):
    """q^3 = (x^3 - 3 x |v|^2, (3 x^2 - |v|^2) v)."""
    x = q[..., 0]
    v2 = _dot(q[..., 1:], q[..., 1:])
    s = 3 * x * x - v2
    return np.concatenate([(x * (x * x - 3 * v2))[..., None], s[..., None] * q[..., 1:]], axis=-1)


def alg_cube_jvp(q, h):
    """d(q^3)[h] = q^2 h + q h q + h q^2."""
    x, a = q[..., 0], h[..., 0]
    v, u = q[..., 1:], h[..., 1:]
    v2, vu = _dot(v, v), _dot(v, u)
    s = 3 * x * x - v2
    t = 6 * x * a - 2 * vu
    return np.concatenate([(3 * (x * x * a - a * v2) - 6 * x * vu)[..., None],
                           t[..., None] * v + s[..., None] * u], axis=-1)


def julia_f(q, c, fn):
    """f(q) + c for the polynomial of function module ``fn`` (FUNC_POWER 2 or 3)."""
    return (alg_sqr(q) if fn.FUNC_POWER == 2 else alg_cube(q)) + c


def julia_f_jvp(q, h, fn):
    return alg_sqr_jvp(q, h) if fn.FUNC_POWER == 2 else alg_cube_jvp(q, h)


def JULIA_DF2(m2, power):
    """|f'(q)|^2 as a function of m2 = |q|^2 for the running derivative: D^2 m2^(D-1)."""
    return 4.0 * m2 if power == 2 else 9.0 * m2 * m2


ALG_HAS_DE = True


# reference/enclose/ball.py (kernels/algebra/quaternion.cl): |a b| = |a| |b|
ALG_ENCLOSE_K = 1.0
ALG_LBOUND_IS_LEN = True   # the bound on h -> m h is |m| itself (reference/enclose/ball.py)


def ALG_LBOUND(m):
    return np.sqrt(np.sum(m * m, axis=-1))


def ALG_LBOUND_SQR(m):
    return np.sum(m * m, axis=-1)
