"""float64 twin of kernels/algebra/commutative.cl: the naive commutative rules (seed 000_1dc675fe64448cc1.txt eq. 15):
i^2 = j^2 = k^2 = -1, ij = ji = k, ki = ik = j, jk = kj = i; commutative, not associative.
The product is built from the basis table itself (the kernel writes it out)."""
from __future__ import annotations

import numpy as np

from . import power

# e_i e_j = SIGN[i][j] e_INDEX[i][j] for the basis 1, i, j, k
_INDEX = [[0, 1, 2, 3], [1, 0, 3, 2], [2, 3, 0, 1], [3, 2, 1, 0]]
_SIGN = [[1, 1, 1, 1], [1, -1, 1, 1], [1, 1, -1, 1], [1, 1, 1, -1]]


def alg_mul(a, b):
    a = np.asarray(a, np.float64)
    b = np.asarray(b, np.float64)
    out = np.zeros(np.broadcast_shapes(a.shape, b.shape))
    for i in range(4):
        for j in range(4):
            out[..., _INDEX[i][j]] += _SIGN[i][j] * a[..., i] * b[..., j]
    return out


def ALG_IN(p):
    return np.asarray(p, np.float64)


ALG_C = ALG_IN


def ALG_NORM2(q):
    return np.sum(q * q, axis=-1)


def ALG_DOT(a, b):
    return np.sum(a * b, axis=-1)


def julia_f(q, c, fn):
    return power.julia_f(alg_mul, q, c, fn.FUNC_POWER)


def julia_f_jvp(q, h, fn):
    return power.julia_f_jvp(alg_mul, q, h, fn.FUNC_POWER)


ALG_HAS_DE = False
