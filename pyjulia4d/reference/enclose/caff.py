"""float64 twin of kernels/enclose/caff.cl: complex affine forms (m, v, r) in one real symbol
s in [-1, 1], holding every m + s v + e with |e| <= r; products put s^2 v1 v2 as v1 v2 / 2
into the centre and |v1 v2| / 2 into the radius, and every radius is raised for the
rounding of the centre and tangent (ENC_ROUND of the terms' sizes)."""
from __future__ import annotations

import numpy as np

from pyjulia4d.reference.enclose.disc import enc_radius, least_norm, prefix_of, rounding


def caff_of(mx, my, vx, vy, r):
    """Two reals m + s v as one complex form."""
    return mx + 1j * my, vx + 1j * vy, r


def caff_add(a, b):
    (ma, va, ra), (mb, vb, rb) = a, b
    return ma + mb, va + vb, enc_radius(ra + rb, np.abs(ma) + np.abs(mb) + np.abs(va) + np.abs(vb), rounding().sum)


def caff_scale(k, a):
    m, v, r = a
    sk = np.abs(k)
    return k * m, k * v, enc_radius(sk * r, 2 * sk * (np.abs(m) + np.abs(v)), rounding().sum)


def caff_mul(a, b):
    (m1, v1, r1), (m2, v2, r2) = a, b
    a1, b1, a2, b2 = np.abs(m1), np.abs(v1), np.abs(m2), np.abs(v2)
    with np.errstate(all="ignore"):
        m = m1 * m2 + 0.5 * (v1 * v2)
        v = m1 * v2 + v1 * m2
        r = 0.5 * b1 * b2 + (a1 + b1) * r2 + (a2 + b2) * r1 + r1 * r2
        return m, v, enc_radius(r, 4 * (a1 * a2 + b1 * b2 + a1 * b2 + b1 * a2), rounding().sum)


def caff_sqr(a):
    return caff_mul(a, a)


def caff_margin(z, bailout):
    m, v, r = z
    with np.errstate(all="ignore"):
        return (np.abs(m) - bailout) / (np.abs(v) + r)


def caff_outside(z, bailout2):
    m, v, r = z
    with np.errstate(all="ignore"):
        lo = least_norm(np.stack([m.real, m.imag], -1), np.stack([v.real, v.imag], -1)) * (1 - rounding().sum) - r
        return (lo > 0) & (lo * lo > bailout2)


def caff_prefix(z, bailout):
    """The part [-1, s] of the segment the form keeps beyond ``bailout`` (-1: none;
    kernels/enclose/caff.cl)."""
    m, v, r = z
    mq, vq = np.stack([m.real, m.imag], -1), np.stack([v.real, v.imag], -1)
    return prefix_of(mq, vq, np.sum(mq * mq, axis=-1), bailout + r)


def caff_hopeful(z, bailout):
    m, v, r = z
    with np.errstate(all="ignore"):
        return np.abs(v) + r < 2 * (np.abs(m) + bailout)


def segment_parts(o, d, t0, t1):
    """A ray segment's midpoint m, half-extent v (per ray, 4 coordinates) and the rounding
    radius of its points (enclose/ball.cl enc_segment's)."""
    tm, hw = 0.5 * (t0 + t1), 0.5 * (t1 - t0)
    m, v = o + tm[:, None] * d, hw[:, None] * d
    r = enc_radius(0.0, np.linalg.norm(o, axis=-1) + np.abs(tm) * np.linalg.norm(d, axis=-1), rounding().sum)
    return m, v, r


# The enclosure (z form, off) of a kind that iterates a complex map of its own
# (reference/enclose/julia_stack.py, cubic_locus.py): off proves the segment empty by itself.
def orbit_outside(e, bailout2):
    return e[1] | caff_outside(e[0], bailout2)


def orbit_margin(e, bailout):
    return caff_margin(e[0], bailout)


def orbit_hopeful(e, bailout):
    return caff_hopeful(e[0], bailout)
