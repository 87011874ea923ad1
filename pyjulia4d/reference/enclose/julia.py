"""float64 twin of kernels/enclose/julia.cl: the Julia set's orbit enclosures - the segment's
points are q_0 (the algebra's enc_segment), c the scene's, max_iter steps of the algebra's
enc_step.  A kind with orbits of its own has a module of the same three names
(reference/enclose/mandelbrot.py)."""
from __future__ import annotations

import numpy as np

LADDER_N = 8
LADDER_UP = 1.0 + 2.0 ** -16


def ladder(c, max_iter, bailout, F):
    """(t, t2) per iterations left j = 0 .. LADDER_N - 1: the radius a form must clear and its
    square (kernels/march/proven.cl enc_ladder_of).  Where the map keeps norms to a power D
    (quaternions: ALG_LBOUND_IS_LEN, a polynomial function), |f(q) + c| >= |q|^D - |c|, so a point
    beyond rho_j, rho_0 = bailout and rho_j = (rho_(j-1) + |c|)^(1/D), passes the bailout within
    j iterations (kernels/enclose/julia.cl); t_j is the least of it and the bailout."""
    D = F.fn.FUNC_POWER if getattr(F.alg, "ALG_LBOUND_IS_LEN", False) else None
    t, t2 = [float(bailout)], [float(bailout) ** 2]
    rho, cl = float(bailout), float(np.linalg.norm(np.asarray(c, np.float64)))
    for _ in range(1, LADDER_N):
        if D:
            rho = (rho + cl) ** (1.0 / D) * LADDER_UP
        t.append(min(float(bailout), rho) if D else float(bailout))
        t2.append(rho * rho if D and rho < bailout else float(bailout) ** 2)
    return t, t2


def enc_steps(max_iter: int) -> int:
    return max_iter


def enc_start(o, d, t0, t1, c, F):
    """(the form of q_0, the parameter the steps take: c in the algebra's coordinates)."""
    return F.enclose.enc_segment(o, d, t0, t1, F), F.ALG_C(np.asarray(c, np.float64))


def enc_next(e, c, F):
    return F.enclose.enc_step(e, c, F)
