"""float64 twin of kernels/function/asin.cl: f(z) = asin z (POV-Ray 3.6 documentation,
"asin"), numpy's complex function (its branch cuts)."""
import numpy as np

from pyjulia4d.reference.enclose import disc as D


def cfun(z):
    return np.arcsin(z)


def cfun_d(z):
    return 1 / np.sqrt(1 - z * z)


def cfun_disc(z):
    """The disc enclosure of f (kernels/function/asin.cl, under -D ENCLOSE)."""
    with np.errstate(all="ignore"):
        return D.d_times_minus_i(D.d_asinh(D.d_times_i(z)))
