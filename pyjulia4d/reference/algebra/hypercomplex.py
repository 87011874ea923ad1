"""float64 twin of kernels/algebra/hypercomplex.cl: the commutative hypercomplex numbers
(Ödegaard & Wennergren eq. 13; POV-Ray 3.6 documentation's basis table, with k^2 = +1), iterated
split into two complex numbers a, b on the idempotents (1 +- k)/2."""
from __future__ import annotations

import numpy as np

from pyjulia4d.reference.algebra.table import product

# POV-Ray 3.6 documentation's table: ij = ji = k, jk = kj = -i, ki = ik = -j, ii = jj = -1, kk = +1
SIGN = [[1, 1, 1, 1], [1, -1, 1, -1], [1, 1, -1, -1], [1, -1, -1, 1]]
# the product by the basis table itself (the tests hold the split to it)
alg_mul = product(SIGN)


def ALG_IN(p):
    """(x, y, z, w) -> (a.re, a.im, b.re, b.im), a = (x + w) + (y - z) i, b = (x - w) + (y + z) i."""
    p = np.asarray(p, np.float64)
    x, y, z, w = np.moveaxis(p, -1, 0)
    return np.stack([x + w, y - z, x - w, y + z], axis=-1)


def ALG_OUT(q):
    """The inverse of ALG_IN."""
    ar, ai, br, bi = np.moveaxis(np.asarray(q, np.float64), -1, 0)
    return np.stack([(ar + br) / 2, (ai + bi) / 2, (bi - ai) / 2, (ar - br) / 2], axis=-1)


ALG_C = ALG_IN


def ALG_NORM2(q):
    """|h|^2 = (|a|^2 + |b|^2) / 2."""
    return 0.5 * np.sum(q * q, axis=-1)


def ALG_DOT(u, v):
    return 0.5 * np.sum(u * v, axis=-1)


def _split(q):
    return q[..., 0] + 1j * q[..., 1], q[..., 2] + 1j * q[..., 3]


def _join(a, b):
    return np.stack([a.real, a.imag, b.real, b.imag], axis=-1)


def julia_f(q, c, fn):
    """f(h) + c = (f(a) + c_a) e1 + (f(b) + c_b) e2, fn.cfun on each component."""
    a, b = _split(q)
    with np.errstate(all="ignore"):
        return _join(fn.cfun(a), fn.cfun(b)) + c


def julia_f_jvp(q, h, fn):
    """f'(a) da e1 + f'(b) db e2."""
    a, b = _split(q)
    da, db = _split(h)
    with np.errstate(all="ignore"):
        return _join(fn.cfun_d(a) * da, fn.cfun_d(b) * db)


ALG_HAS_DE = "polynomial"   # sqr and cube: the product of two complex estimates
ALG_SPLIT = True


def JULIA_DF2(m2, power):
    """|f'(z)|^2 = D^2 |z|^(2(D-1)) for one complex component."""
    return 4.0 * m2 if power == 2 else 9.0 * m2 * m2
