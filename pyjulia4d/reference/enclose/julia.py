"""float64 twin of kernels/enclose/julia.cl: the Julia set's orbit enclosures - the segment's
points are q_0 (the algebra's enc_segment), c the scene's, max_iter steps of the algebra's
enc_step.  A kind with orbits of its own has a module of the same three names
(reference/enclose/mandelbrot.py)."""
from __future__ import annotations

import numpy as np

LADDER_N = 8
LADDER_UP = 1.0 + 2.0 ** -16


def _rungs(start, cn, D):
    """min(start, rho_j), rho_0 = start, rho_j = (rho_(j-1) + cn)^(1/D) raised by LADDER_UP, and
    their squares (kernels/march/proven.cl ladder_rungs)."""
    rho, t = start, []
    for j in range(LADDER_N):
        if j:
            rho = (rho + cn) ** (1.0 / D) * LADDER_UP
        t.append(min(start, rho))
    return t, [x * x for x in t]


def ladder(c, max_iter, bailout, F):
    """(t, t2, parts) per iterations left j = 0 .. LADDER_N - 1: the radius a form must clear
    and its square (kernels/march/proven.cl enc_ladder_of).  Where the map keeps norms to a
    power D (quaternions: ALG_LBOUND_IS_LEN, a polynomial function), |f(q) + c| >= |q|^D - |c|,
    so a point beyond rho_j, rho_0 = bailout and rho_j = (rho_(j-1) + |c|)^(1/D), passes the
    bailout within j iterations (kernels/enclose/julia.cl); t_j is the least of it and the
    bailout.  ``parts``: for a split algebra's polynomials, (pa, pa2, pb, pb2), the same per
    component from sqrt(2) bailout (|h| >= |a| / sqrt(2)), the least of that and the ladder's;
    else None."""
    b = float(bailout)
    if getattr(F.alg, "ALG_LBOUND_IS_LEN", False) and F.fn.FUNC_POWER:
        t, t2 = _rungs(b, float(np.linalg.norm(np.asarray(c, np.float64))), F.fn.FUNC_POWER)
    else:
        t, t2 = [b] * LADDER_N, [b * b] * LADDER_N
    parts = None
    if F.split and F.fn.FUNC_POWER:
        cp, a0 = F.ALG_C(np.asarray(c, np.float64)), float(np.sqrt(2.0) * b * LADDER_UP)
        parts = (*_rungs(a0, float(np.hypot(cp[0], cp[1])), F.fn.FUNC_POWER),
                 *_rungs(a0, float(np.hypot(cp[2], cp[3])), F.fn.FUNC_POWER))
    return t, t2, parts


def enc_steps(max_iter: int) -> int:
    return max_iter


def enc_start(o, d, t0, t1, c, F):
    """(the form of q_0, the parameter the steps take: c in the algebra's coordinates)."""
    return F.enclose.enc_segment(o, d, t0, t1, F), F.ALG_C(np.asarray(c, np.float64))


def enc_next(e, c, F):
    return F.enclose.enc_step(e, c, F)
