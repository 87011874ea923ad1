"""float64 twin of kernels/function/asinh.cl: f(z) = asinh z (POV-Ray 3.6 documentation,
"asinh"), numpy's complex function (its branch cuts)."""
import numpy as np

from pyjulia4d.reference.enclose import disc as D


def cfun(z):
    return np.arcsinh(z)


def cfun_d(z):
    return 1 / np.sqrt(z * z + 1)


def cfun_disc(z):
    """The disc enclosure of f (kernels/function/asinh.cl, under -D ENCLOSE)."""
    with np.errstate(all="ignore"):
        return D.d_asinh(z)
