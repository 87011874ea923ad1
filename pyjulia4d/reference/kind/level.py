"""float64 twin of kernels/kind/level.cl: the level (m2 / b2)^(D^k) - 1 of an orbit that escaped
k steps before max_iter, capped at 1e30 (k > 60 or an exponent above 69); also
reference.julia_level's, as iterate.cl computes it.  And the rescale of the derivatives the
normals carry (common/lanes.cl L_RESCALE_DUE), which every kind's normal shares."""
from __future__ import annotations

import numpy as np


def kind_level(m2, b2, k, growth):
    """(m2 / b2)^(growth^k) - 1 for escaped orbits, 1e30 past the cap."""
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        kk = np.minimum(k, 60)
        if growth == 2:
            e = np.ldexp(np.log(m2 / b2), kk.astype(np.int32))
        else:
            e = np.log(m2 / b2) * float(growth) ** kk
        # the kernel's fmin(e, 69) takes 69 for a NaN e (an orbit gone to NaN)
        e = np.where(np.isnan(e), 69.0, e)
        return np.where((k > 60) | (e > 69), 1e30, np.expm1(np.minimum(e, 69)))


def rescale_due(s2):
    """Where a derivative carried up to scale, its largest part's squared length s2, is
    rescaled by 1 / sqrt(s2): s2 outside [1e-24, 1e24] (common/lanes.cl L_RESCALE_DUE)."""
    return (s2 > 1e24) | ((s2 < 1e-24) & (s2 > 0))


def rescale_pair(A, B, unit, live):
    """A kind's two complex derivatives (and the 1 / scale ``unit`` they are kept at) divided,
    in place, by the larger length where it is due on the live points
    (kind/julia_stack.cl, kind/cubic_locus.cl)."""
    s2 = np.maximum(np.abs(A) ** 2, np.abs(B) ** 2)
    big = live & rescale_due(s2)
    s = np.sqrt(s2[big])
    A[big] /= s
    B[big] /= s
    unit[big] /= s


def rescale_columns(J, unit=None):
    """The live points' Jacobians J (n, 4, 4), and the 1 / scale ``unit`` (n,) they are kept
    at if given, divided in place by the largest column's length where it is due
    (normals/jacobian.cl, whose KIND_MANDELBROT build carries unit); the squared lengths are
    compared before any square root is taken."""
    with np.errstate(all="ignore"):
        s2 = np.sum(J * J, axis=-1).max(axis=-1)
    big = rescale_due(s2)
    if big.any():
        s = np.sqrt(s2[big])
        J[big] /= s[:, None, None]
        if unit is not None:
            unit[big] /= s
