"""float64 twin of kernels/function/atanh.cl: f(z) = atanh z (POV-Ray 3.6 documentation,
"atanh"), numpy's complex function (its branch cuts)."""
import numpy as np

from pyjulia4d.reference.enclose import disc as D


def cfun(z):
    return np.arctanh(z)


def cfun_d(z):
    return 1 / (1 - z * z)


def cfun_disc(z):
    """The disc enclosure of f (kernels/function/atanh.cl, under -D ENCLOSE)."""
    with np.errstate(all="ignore"):
        return D.d_atanh(z)
