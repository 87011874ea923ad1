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


def enclose_bounds(alg_mul):
    """(K, L, L2) of kernels/algebra/power.cl for reference/enclose/ball.py: |a b| <= K |a| |b|
    with K = 2, and the norm of h -> m h at most |m|_1 (L(m)) and of h -> (m m) h at most
    |m m|_1 (L2(m)): each coordinate of a b is a^T P b with P a signed permutation."""
    def norm1(m):
        return np.sum(np.abs(m), axis=-1)
    return 2.0, norm1, lambda m: norm1(alg_mul(m, m))
