"""float64 twin of kernels/enclose/julia.cl: the Julia set's orbit enclosures - the segment's
points are q_0 (the algebra's enc_segment), c the scene's, max_iter steps of the algebra's
enc_step.  A kind with orbits of its own has a module of the same three names
(reference/enclose/mandelbrot.py)."""
from __future__ import annotations

import numpy as np


def enc_steps(max_iter: int) -> int:
    return max_iter


def enc_start(o, d, t0, t1, c, F):
    """(the form of q_0, the parameter the steps take: c in the algebra's coordinates)."""
    return F.enclose.enc_segment(o, d, t0, t1, F), F.ALG_C(np.asarray(c, np.float64))


def enc_next(e, c, F):
    return F.enclose.enc_step(e, c, F)
