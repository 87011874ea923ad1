"""Twin of kernels/iterate.cl: the inside test, the escaped-orbit level and the distance
estimates, for every algebra and function (formula.py), in float64."""
from __future__ import annotations

import numpy as np

from pyjulia4d.reference.formula import QUATERNION_SQR, Formula
from pyjulia4d.reference.kind.level import kind_level

REAL_MIN = np.finfo(np.float64).tiny


def dot4(a, b):
    """Row-wise dot products of (..., 4) arrays."""
    return np.sum(a * b, axis=-1)


def julia_inside(p, c, max_iter, bailout, formula: Formula = QUATERNION_SQR):
    """|q_n| <= bailout for n = 0..max_iter (POV-Ray 3.6 documentation; Ödegaard & Wennergren eq. 5)."""
    F = formula
    kind = F.kind_twin
    if kind is not None:   # its kernels/kind/<kind>.cl takes the name over
        return kind.inside(p, max_iter, bailout, F)
    q = F.ALG_IN(np.array(p, dtype=np.float64)).copy()
    c = F.ALG_C(np.asarray(c, np.float64))
    out = np.ones(q.shape[:-1], bool)
    b2 = bailout * bailout
    with np.errstate(all="ignore"):   # inf / NaN iterates count as escaped, as in the kernel
        for _ in range(max_iter):
            out &= F.ALG_NORM2(q) <= b2
            if not out.any():
                return out
            q[out] = F.julia_f(q[out], c)
        return out & (F.ALG_NORM2(q) <= b2)


def julia_level(p, c, max_iter, bailout, formula: Formula = QUATERNION_SQR):
    """F = |q_N|^2 / bailout^2 - 1 (N = max_iter), <= 0 exactly where julia_inside; an orbit
    escaping at n < N is extrapolated as (|q_n|^2 / b^2)^(D^(N-n)) - 1 (D = the growth
    degree), capped at 1e30 (iterate.cl; Quilez 2002).  Returns (F, inside)."""
    F = formula
    kind = F.kind_twin
    if kind is not None:
        return kind.level(p, max_iter, bailout, F)
    q = F.ALG_IN(np.array(p, dtype=np.float64)).copy()
    c = F.ALG_C(np.asarray(c, np.float64))
    b2 = bailout * bailout
    m2 = F.ALG_NORM2(q)
    n = np.zeros(m2.shape, np.int64)
    live = np.ones(m2.shape, bool)
    with np.errstate(all="ignore"):
        for _ in range(max_iter):
            live &= m2 <= b2
            if not live.any():
                break
            q[live] = F.julia_f(q[live], c)
            m2[live] = F.ALG_NORM2(q[live])
            n[live] += 1
    inside = m2 <= b2
    return np.where(inside, m2 / b2 - 1.0, kind_level(m2, b2, max_iter - n, F.growth)), inside


def julia_distance_formula(p, c, max_iter, bailout, formula: Formula = QUATERNION_SQR):
    """d = |q_n| ln|q_n| / (2|q_n'|) (Hart, Sandin & Kauffman 1989 eq. 8) at the last
    iterate, derivative carried squared and rescaled as mantissa * 2^e; returns
    (d, escaped)."""
    F = formula
    kind_estimate = getattr(F.kind_twin, "distance_formula", None)
    if kind_estimate is not None:   # a kind's own (the stack's: the empirical one, -D STACK_DE)
        return kind_estimate(p, max_iter, bailout, F)
    if F.split:
        return _split_distance_formula(p, c, max_iter, bailout, F)
    q = F.ALG_IN(np.array(p, dtype=np.float64)).copy()
    c = F.ALG_C(np.asarray(c, np.float64))
    b2 = bailout * bailout
    m2 = F.ALG_NORM2(q)
    dm2 = np.ones_like(m2)
    e = np.zeros(m2.shape, np.int64)
    live = np.ones(m2.shape, bool)
    for _ in range(max_iter):
        live &= m2 <= b2
        if not live.any():
            break
        dm2[live] *= F.JULIA_DF2(m2[live])
        big = live & (dm2 > 1e16)
        if big.any():
            mant, k = np.frexp(dm2[big])
            dm2[big] = mant
            e[big] += k
        q[live] = F.julia_f(q[live], c)
        m2[live] = F.ALG_NORM2(q[live])
    escaped = m2 > b2
    mq = np.maximum(m2, REAL_MIN)
    ratio = np.sqrt(mq / np.maximum(dm2, REAL_MIN)) * np.exp2(-(e / 2.0))
    return ratio * np.log(mq) / 4.0, escaped


def _de_value(m2, dm2, e):
    """d = |q| ln|q| / (2 |q'|) from m2, dm2 * 2^e (iterate.cl de_value)."""
    mq = np.maximum(m2, REAL_MIN)
    ratio = np.sqrt(mq / np.maximum(dm2, REAL_MIN)) * np.exp2(-(e / 2.0))
    return ratio * np.log(mq) / 4.0


def _split_distance_formula(p, c, max_iter, bailout, F: Formula):
    """The split algebra's estimate (iterate.cl, ALG_SPLIT): d = sqrt(d_a^2 + d_b^2) / sqrt(2),
    each component's complex estimate where it has escaped past 1 + |c_component|, else 0."""
    q = F.ALG_IN(np.array(p, dtype=np.float64)).copy()
    c = F.ALG_C(np.asarray(c, np.float64))
    b2 = bailout * bailout
    m2 = F.ALG_NORM2(q)
    da, db = np.ones_like(m2), np.ones_like(m2)
    ea, eb = np.zeros(m2.shape, np.int64), np.zeros(m2.shape, np.int64)
    live = np.ones(m2.shape, bool)

    def grow(dm2, e, factor, live):
        dm2[live] *= factor[live]
        big = live & (dm2 > 1e16)
        if big.any():
            mant, k = np.frexp(dm2[big])
            dm2[big] = mant
            e[big] += k

    for _ in range(max_iter):
        live &= m2 <= b2
        if not live.any():
            break
        grow(da, ea, F.alg.JULIA_DF2(q[..., 0] ** 2 + q[..., 1] ** 2, F.fn.FUNC_POWER), live)
        grow(db, eb, F.alg.JULIA_DF2(q[..., 2] ** 2 + q[..., 3] ** 2, F.fn.FUNC_POWER), live)
        q[live] = F.julia_f(q[live], c)
        m2[live] = F.ALG_NORM2(q[live])
    escaped = m2 > b2
    ma, mb = q[..., 0] ** 2 + q[..., 1] ** 2, q[..., 2] ** 2 + q[..., 3] ** 2
    ra, rb = 1 + np.hypot(c[0], c[1]), 1 + np.hypot(c[2], c[3])
    d_a = np.where(ma > ra * ra, _de_value(ma, da, ea), 0.0)
    d_b = np.where(mb > rb * rb, _de_value(mb, db, eb), 0.0)
    return np.sqrt(d_a ** 2 + d_b ** 2) / np.sqrt(2.0), escaped


def julia_distance(p, c, max_iter, bailout, formula: Formula = QUATERNION_SQR):
    """The estimate the march steps by: 0 where the point never escaped."""
    d, escaped = julia_distance_formula(p, c, max_iter, bailout, formula)
    return np.where(escaped, d, 0.0)
