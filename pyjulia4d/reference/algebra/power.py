"""float64 twin of kernels/algebra/power.cl: q^D + c in a commutative algebra given by its
product alg_mul (cquat.py, commutative.py); the cube bracketed (q q) q."""
from __future__ import annotations

import numpy as np


def julia_f(alg_mul, q, c, power):
    qq = alg_mul(q, q)
    return (qq if power == 2 else alg_mul(qq, q)) + c


def julia_f_jvp(alg_mul, q, h, power):
    if power == 2:
        return 2 * alg_mul(q, h)
    return alg_mul(2 * alg_mul(q, h), q) + alg_mul(alg_mul(q, q), h)


def maps(alg_mul):
    """(julia_f(q, c, fn), julia_f_jvp(q, h, fn)) of an algebra with product alg_mul."""
    return (lambda q, c, fn: julia_f(alg_mul, q, c, fn.FUNC_POWER),
            lambda q, h, fn: julia_f_jvp(alg_mul, q, h, fn.FUNC_POWER))


LBOUND_UP = 1 + 2.0 ** -19   # kernels/algebra/power.cl ALG_LBOUND_UP
BASIS = np.eye(4)


def product_matrix(alg_mul, m):
    """The matrix of h -> m h (..., 4, 4), column j the product with the j-th basis vector."""
    m = np.asarray(m, np.float64)
    return np.stack([alg_mul(m, np.broadcast_to(BASIS[j], m.shape)) for j in range(4)], axis=-1)


def enclose_bounds(alg_mul):
    """(K, L, L2) of kernels/algebra/power.cl for reference/enclose/ball.py: |a b| <= K |a| |b|
    with K = 2 (each coordinate of a b is a^T P b with P a signed permutation), the norm of
    h -> m h at most L(m) = min(sqrt(|m|^2 + sqrt(3/4 |S|_F^2)), |m|_1), S = L_m^T L_m - |m|^2 I,
    and of h -> (m m) h at most L(m m).  S comes from the product itself here (the matrix
    L_m column by column), where the kernel writes each algebra's |S|_F^2 out."""
    def norm1(m):
        return np.sum(np.abs(m), axis=-1)

    def lbound(m):
        m = np.asarray(m, np.float64)
        L = product_matrix(alg_mul, m)
        n2 = np.sum(m * m, axis=-1)
        S = np.einsum("...ij,...ik->...jk", L, L) - n2[..., None, None] * BASIS
        with np.errstate(all="ignore"):
            return np.fmin(np.sqrt(n2 + np.sqrt(0.75 * np.sum(S * S, axis=(-2, -1)))) * LBOUND_UP, norm1(m))

    return 2.0, lbound, lambda m: lbound(alg_mul(m, m))
