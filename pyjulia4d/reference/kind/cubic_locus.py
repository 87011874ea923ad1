"""float64 twin of kernels/kind/cubic_locus.cl: the cubic connectedness locus of
Hart, Sandin & Kauffman 1989 §5.2 (eq. 19, Definitions 4-5).  The point p = (Re a, Im a, Re b,
Im b); inside when |p| <= locus_radius and |z_n| <= bailout for n = 0 .. max_iter under
z <- z^3 - 3 a^2 z + b, z_0 = +a (component "plus", C+) or -a ("minus", C-)."""
from __future__ import annotations

import numpy as np

from pyjulia4d.reference.kind.level import kind_level, rescale_pair


def _start(p, F):
    p = np.asarray(p, np.float64)
    a = p[..., 0] + 1j * p[..., 1]
    b = p[..., 2] + 1j * p[..., 3]
    sign = 1.0 if F.component == "plus" else -1.0
    return a, b, sign, np.sum(p * p, axis=-1) <= F.locus_radius ** 2


def locus_f(z, a, b):
    """f_{a,b}(z) = z (z^2 - 3 a^2) + b (the kernel's order of operations)."""
    return z * (z * z - 3 * (a * a)) + b


def locus_inside(p, max_iter, bailout, F):
    a, b, sign, ball = _start(p, F)
    z = sign * a
    b2 = bailout * bailout
    out = ball.copy()
    with np.errstate(all="ignore"):
        for _ in range(max_iter):
            out &= z.real ** 2 + z.imag ** 2 <= b2
            if not out.any():
                return out
            z[out] = locus_f(z[out], a[out], b[out])
        return out & (z.real ** 2 + z.imag ** 2 <= b2)


def locus_level(p, max_iter, bailout, F):
    """max(F_z, |p|^2 / R^2 - 1), F_z = |z_N|^2 / b^2 - 1 extrapolated past an escape with the
    cube's growth 3 (capped at 1e30).  Returns (F, inside)."""
    a, b, sign, ball = _start(p, F)
    z = sign * a
    b2 = bailout * bailout
    m2 = z.real ** 2 + z.imag ** 2
    n = np.zeros(m2.shape, np.int64)
    live = np.ones(m2.shape, bool)
    with np.errstate(all="ignore"):
        for _ in range(max_iter):
            live &= m2 <= b2
            if not live.any():
                break
            z[live] = locus_f(z[live], a[live], b[live])
            m2[live] = z[live].real ** 2 + z[live].imag ** 2
            n[live] += 1
    zin = m2 <= b2
    fz = np.where(zin, m2 / b2 - 1.0, kind_level(m2, b2, max_iter - n, 3))
    fb = np.sum(np.asarray(p, np.float64) ** 2, axis=-1) / F.locus_radius ** 2 - 1.0
    return np.maximum(fz, fb), zin & (fb <= 0)


def locus_normal(p, max_iter, bailout, F, guard=None, tiny_flag=0):
    """grad |z_N|^2 / 2 = (Re(conj z A), Re(conj z i A), Re(conj z B), Re(conj z i B)),
    A = dz/da, B = dz/db: A_0 = sign, B_0 = 0, A_{n+1} = 3 (z^2 - a^2) A - 6 a z,
    B_{n+1} = 3 (z^2 - a^2) B + 1, rescaled both ways as the kernel; the sphere's normal p
    where the orbit stays bounded past the ball."""
    a, b, sign, ball = _start(p, F)
    z = sign * a
    A = np.full(z.shape, sign, np.complex128)
    B = np.zeros_like(z)
    unit = np.ones(z.shape)
    b2 = bailout * bailout
    live = np.ones(z.shape, bool)
    with np.errstate(all="ignore"):
        for _ in range(max_iter):
            live &= z.real ** 2 + z.imag ** 2 <= b2
            if not live.any():
                break
            zl, al = z[live], a[live]
            d = 3 * (zl * zl - al * al)
            A[live] = d * A[live] - unit[live] * 6 * (al * zl)
            B[live] = d * B[live] + unit[live]
            z[live] = locus_f(zl, al, b[live])
            rescale_pair(A, B, unit, live)
    zc = np.conj(z)
    g = np.stack([(zc * A).real, (zc * 1j * A).real, (zc * B).real, (zc * 1j * B).real], axis=-1)
    cut = (z.real ** 2 + z.imag ** 2 <= b2) & ~ball
    return np.where(cut[..., None], np.asarray(p, np.float64), g)


# The twin interface the registry names (Kind.twin; reference/formula.Formula.kind_twin): what
# iterate.py, normals.py and shade.py ask of a kind.
inside, level, normal = locus_inside, locus_level, locus_normal
