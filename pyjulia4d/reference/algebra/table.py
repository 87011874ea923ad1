"""Algebras given by their basis multiplication table (Ödegaard & Wennergren eqs. 13-15, POV-Ray 3.6 documentation):
the bilinear product of e_i e_j = SIGN[i][j] e_INDEX[i][j] over the basis 1, i, j, k, and
the coordinates of algebras iterated in the point's own (cquat.py, commutative.py)."""
from __future__ import annotations

import numpy as np

# e_i e_j is +- e_INDEX[i][j] in each of these algebras: 1 e = e, i j ~ k, i k ~ j, j k ~ i
INDEX = [[0, 1, 2, 3], [1, 0, 3, 2], [2, 3, 0, 1], [3, 2, 1, 0]]


def product(sign):
    """alg_mul for the table with these signs."""
    def alg_mul(a, b):
        a = np.asarray(a, np.float64)
        b = np.asarray(b, np.float64)
        out = np.zeros(np.broadcast_shapes(a.shape, b.shape))
        for i in range(4):
            for j in range(4):
                out[..., INDEX[i][j]] += sign[i][j] * a[..., i] * b[..., j]
        return out
    return alg_mul


def ALG_IN(p):
    """The point's own coordinates."""
    return np.asarray(p, np.float64)


ALG_C = ALG_IN


def ALG_NORM2(q):
    return np.sum(q * q, axis=-1)


def ALG_DOT(a, b):
    return np.sum(a * b, axis=-1)
