"""float64 twin of kernels/kind/level.cl: the level (m2 / b2)^(D^k) - 1 of an orbit that escaped
k steps before max_iter, capped at 1e30 (k > 60 or an exponent above 69); also
reference.julia_level's, as iterate.cl computes it."""
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
