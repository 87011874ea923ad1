"""float64 twin of kernels/enclose/cubic_locus.cl: the cubic locus's orbit enclosures, complex
affine forms (reference/enclose/caff.py) of z_n beside 3 a^2 and b, z_0 = sign a,
z_{n+1} = z_n (z_n^2 - 3 a^2) + b; a segment is also empty where all its points lie outside
the ball |p| <= locus_radius.  enclosure = (z form, off)."""
from __future__ import annotations

import numpy as np

from pyjulia4d.reference.enclose.caff import (caff_add, caff_mul, caff_of, caff_scale, caff_sqr, segment_parts,
                                              orbit_hopeful as enc_hopeful, orbit_margin as enc_margin,
                                              orbit_outside as enc_outside)
from pyjulia4d.reference.enclose.julia import enc_steps  # noqa: F401 (z_0 .. z_max_iter, as the Julia set's)
from pyjulia4d.reference.enclose.disc import least_norm, rounding


def enc_start(o, d, t0, t1, c, F):
    m, v, r = segment_parts(o, d, t0, t1)
    a = caff_of(m[:, 0], m[:, 1], v[:, 0], v[:, 1], r)
    a3 = caff_scale(3.0, caff_sqr(a))
    b = caff_of(m[:, 2], m[:, 3], v[:, 2], v[:, 3], r)
    least = least_norm(m, v) * (1 - rounding().sum) - r
    off = (least > 0) & (least * least > F.locus_radius ** 2)
    sign = 1.0 if F.component == "plus" else -1.0
    return (caff_scale(sign, a), off), (a3, b)


def enc_next(e, p, F):
    z, off = e
    a3, b = p
    w = caff_add(caff_sqr(z), caff_scale(-1.0, a3))
    return caff_add(caff_mul(z, w), b), off

