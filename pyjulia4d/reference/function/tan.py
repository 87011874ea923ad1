"""float64 twin of kernels/function/tan.cl: f(z) = tan z (POV-Ray 3.6 documentation,
"tan"), numpy's complex function (its branch cuts)."""
import numpy as np

from pyjulia4d.reference.enclose import disc as D


def cfun(z):
    return np.tan(z)


def cfun_d(z):
    return 1 + np.tan(z) ** 2


def cfun_disc(z):
    """The disc enclosure of f (kernels/function/tan.cl, under -D ENCLOSE)."""
    with np.errstate(all="ignore"):
        return D.d_tan(z)
