"""float64 twin of kernels/function/ln.cl: f(z) = ln z (POV-Ray 3.6 documentation,
"ln"), numpy's complex function (its branch cuts)."""
import numpy as np

from pyjulia4d.reference.enclose import disc as D


def cfun(z):
    return np.log(z)


def cfun_d(z):
    return 1 / z


def cfun_disc(z):
    """The disc enclosure of f (kernels/function/ln.cl, under -D ENCLOSE)."""
    with np.errstate(all="ignore"):
        return D.d_log(z)
