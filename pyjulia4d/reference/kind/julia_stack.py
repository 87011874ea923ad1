"""float64 twin of kernels/kind/julia_stack.cl: a stack of complex Julia sets (
Hart, Sandin & Kauffman 1989 §5.1).  The point p = (x, y, u, w): z_0 = x + i y,
c(u) = c_mid + u c_half (c_from at u = -1, c_to at u = +1), |u| <= 1, w ignored; inside when
|z_n| <= bailout for n = 0 .. max_iter under z <- z^2 + c(u)."""
from __future__ import annotations

import numpy as np

from pyjulia4d.reference.kind.level import kind_level, rescale_pair

REAL_MIN = np.finfo(np.float64).tiny


def c_line(F):
    """(c_mid, c_half) as complex numbers from the Formula's c_from, c_to."""
    c0, c1 = complex(*F.c_from), complex(*F.c_to)
    return (c0 + c1) / 2, (c1 - c0) / 2


def _start(p, F):
    p = np.asarray(p, np.float64)
    cm, ch = c_line(F)
    return p[..., 0] + 1j * p[..., 1], cm + p[..., 2] * ch, p[..., 2]


def stack_inside(p, max_iter, bailout, F):
    z, c, u = _start(p, F)
    b2 = bailout * bailout
    out = np.abs(u) <= 1
    with np.errstate(all="ignore"):
        for _ in range(max_iter):
            out &= z.real ** 2 + z.imag ** 2 <= b2
            if not out.any():
                return out
            z[out] = z[out] ** 2 + c[out]
        return out & (z.real ** 2 + z.imag ** 2 <= b2)


def stack_level(p, max_iter, bailout, F):
    """max(F_z, |u| - 1), F_z = |z_N|^2 / b^2 - 1 extrapolated past an escape (growth 2,
    capped at 1e30) as reference.julia_level.  Returns (F, inside)."""
    z, c, u = _start(p, F)
    b2 = bailout * bailout
    m2 = z.real ** 2 + z.imag ** 2
    n = np.zeros(m2.shape, np.int64)
    live = np.ones(m2.shape, bool)
    with np.errstate(all="ignore"):
        for _ in range(max_iter):
            live &= m2 <= b2
            if not live.any():
                break
            z[live] = z[live] ** 2 + c[live]
            m2[live] = z[live].real ** 2 + z[live].imag ** 2
            n[live] += 1
    zin = m2 <= b2
    fz = np.where(zin, m2 / b2 - 1.0, kind_level(m2, b2, max_iter - n, 2))
    fu = np.abs(u) - 1.0
    return np.maximum(fz, fu), zin & (fu <= 0)


def stack_normal(p, max_iter, bailout, F, guard=None, tiny_flag=0):
    """grad |z_N|^2 / 2 = (Re(conj z A), Re(conj z i A), Re(conj z B), 0), A_{n+1} = 2 z A,
    B_{n+1} = 2 z B + c_half (A_0 = 1, B_0 = 0), the kernel's underflow stop; the cap's
    normal (0, 0, sign u, 0) where z stays bounded but |u| > 1."""
    z, c, u = _start(p, F)
    _, ch = c_line(F)
    A = np.ones_like(z)
    B = np.zeros_like(z)
    unit = np.ones(z.shape)
    b2 = bailout * bailout
    live = np.ones(z.shape, bool)
    tiny = np.zeros(z.shape, bool)
    with np.errstate(all="ignore"):
        for _ in range(max_iter):
            m2 = z.real ** 2 + z.imag ** 2
            live &= m2 <= b2
            stop = live & (m2 < np.sqrt(REAL_MIN))
            tiny |= stop
            live &= ~stop
            if not live.any():
                break
            zl = z[live]
            A[live] = 2 * zl * A[live]
            B[live] = 2 * zl * B[live] + unit[live] * ch
            z[live] = zl * zl + c[live]
            rescale_pair(A, B, unit, live)
    if guard is not None:
        guard |= np.where(tiny, tiny_flag, 0)
    cap = (z.real ** 2 + z.imag ** 2 <= b2) & (np.abs(u) > 1)
    zc = np.conj(z)
    g = np.stack([(zc * A).real, (zc * 1j * A).real, (zc * B).real, np.zeros(z.shape)], axis=-1)
    capn = np.stack([np.zeros(z.shape), np.zeros(z.shape), np.sign(u), np.zeros(z.shape)], axis=-1)
    return np.where(cap[..., None], capn, g)


def stack_distance_formula(p, max_iter, bailout, F):
    """The empirical estimate (march.method = "de"): d = |z_n| ln|z_n| / (2 sqrt(|A|^2 + |B|^2))
    with |A_{n+1}| = 2 |z| |A|, |B_{n+1}| <= 2 |z| |B| + |c_half|; inside the slab where z
    escaped that d, outside the slab max(d or 0, |u| - 1), 0 elsewhere.  Returns (d, escaped)."""
    z, c, u = _start(p, F)
    _, ch = c_line(F)
    b2 = bailout * bailout
    m2 = z.real ** 2 + z.imag ** 2
    ga = np.ones(m2.shape)
    gb = np.zeros(m2.shape)
    live = np.ones(m2.shape, bool)
    with np.errstate(over="ignore", invalid="ignore"):
        for _ in range(max_iter):
            live &= m2 <= b2
            if not live.any():
                break
            r2 = 2 * np.sqrt(m2[live])
            gb[live] = r2 * gb[live] + abs(ch)
            ga[live] = r2 * ga[live]
            z[live] = z[live] ** 2 + c[live]
            m2[live] = z[live].real ** 2 + z[live].imag ** 2
    slab = np.abs(u) <= 1
    zout = m2 > b2
    mq = np.maximum(m2, REAL_MIN)
    with np.errstate(divide="ignore", invalid="ignore"):
        d = np.sqrt(mq) / np.maximum(np.hypot(ga, gb), REAL_MIN) * np.log(mq) / 4.0
    du = np.abs(u) - 1.0
    out = np.where(slab & zout, d, np.maximum(np.where(zout, d, 0.0), du))
    return out, zout | ~slab


# The twin interface the registry names (Kind.twin; reference/formula.Formula.kind_twin): what
# iterate.py, normals.py and shade.py ask of a kind.
inside, level, distance_formula, normal = stack_inside, stack_level, stack_distance_formula, stack_normal
