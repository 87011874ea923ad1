"""float64 twin of kernels/enclose/mandelbrot.cl: the Mandelbrot kind's orbit enclosures.  The
segment's points are the parameters c(s) (the algebra's enc_segment), the orbits start at
q_1 = V + c(s) (V the critical or asymptotic value, registry MANDELBROT_START) and step
q_{n+1} = f(q_n) + c(s): the algebra's step at c = 0 plus the form of c(s) (enc_add), for
max_iter - 1 steps after the start."""
from __future__ import annotations

import numpy as np

from pyjulia4d.fractal.registry import MANDELBROT_START


def enc_steps(max_iter: int) -> int:
    return max_iter - 1


def enc_start(o, d, t0, t1, c, F):
    """(the start's form, the parameter form): q_1 = V + c(s)."""
    E = F.enclose
    p = E.enc_segment(o, d, t0, t1, F)
    v = MANDELBROT_START[F.function]
    return (E.enc_shift(p, F.ALG_C(np.asarray(v, np.float64))) if any(v) else p), p


def enc_next(e, p, F):
    E = F.enclose
    return E.enc_add(E.enc_step(e, np.zeros(4), F), p)
