"""float64 twin of kernels/function/atan.cl: f(z) = atan z (POV-Ray 3.6 documentation,
"atan"), numpy's complex function (its branch cuts)."""
import numpy as np

from pyjulia4d.reference.enclose import disc as D


def cfun(z):
    return np.arctan(z)


def cfun_d(z):
    return 1 / (1 + z * z)


def cfun_disc(z):
    """The disc enclosure of f (kernels/function/atan.cl, under -D ENCLOSE)."""
    with np.errstate(all="ignore"):
        return D.d_times_minus_i(D.d_atanh(D.d_times_i(z)))
