"""float64 twin of kernels/function/tanh.cl: f(z) = tanh z (POV-Ray 3.6 documentation,
"tanh"), numpy's complex function (its branch cuts)."""
import numpy as np

from pyjulia4d.reference.enclose import disc as D


def cfun(z):
    return np.tanh(z)


def cfun_d(z):
    return 1 - np.tanh(z) ** 2


def cfun_disc(z):
    """The disc enclosure of f (kernels/function/tanh.cl, under -D ENCLOSE)."""
    with np.errstate(all="ignore"):
        return D.d_tanh(z)
