"""float64 twin of kernels/enclose/julia_stack.cl: a Julia set stack's orbit enclosures, complex
affine forms (reference/enclose/caff.py) of z_n beside c(u) = c_mid + u c_half; a segment is
also empty where all its u lie beyond the slab |u| <= 1.  enclosure = (z form, off)."""
from __future__ import annotations

import numpy as np

from pyjulia4d.reference.enclose.caff import (caff_add, caff_of, caff_sqr, segment_parts,
                                              orbit_hopeful as enc_hopeful, orbit_margin as enc_margin,
                                              orbit_outside as enc_outside)
from pyjulia4d.reference.enclose.julia import enc_steps  # noqa: F401 (z_0 .. z_max_iter, as the Julia set's)
from pyjulia4d.reference.enclose.disc import enc_radius, rounding
from pyjulia4d.reference.kind.julia_stack import c_line


def enc_start(o, d, t0, t1, c, F):
    m, v, r = segment_parts(o, d, t0, t1)
    cm, ch = c_line(F)
    sh = abs(ch)
    cform = (cm + m[:, 2] * ch, v[:, 2] * ch,
             enc_radius(sh * r, abs(cm) + 2 * sh * (np.abs(m[:, 2]) + np.abs(v[:, 2])), rounding().sum))
    off = (np.abs(m[:, 2]) - np.abs(v[:, 2]) - r) > 1
    return (caff_of(m[:, 0], m[:, 1], v[:, 0], v[:, 1], r), off), cform


def enc_next(e, c, F):
    z, off = e
    return caff_add(caff_sqr(z), c), off

