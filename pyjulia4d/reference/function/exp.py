"""float64 twin of kernels/function/exp.cl: f(z) = e^z (POV-Ray 3.6 documentation,
"exp"), numpy's complex function (its branch cuts)."""
import numpy as np

from pyjulia4d.reference.enclose import disc as D


def cfun(z):
    return np.exp(z)


def cfun_d(z):
    return np.exp(z)


def cfun_disc(z):
    """The disc enclosure of f (kernels/function/exp.cl, under -D ENCLOSE)."""
    with np.errstate(all="ignore"):
        return D.d_exp(z)


def FUNC_M2(m, rho):
    """A bound on |f''| over the disc of radius rho around m (kernels/function/exp.cl)."""
    with np.errstate(all="ignore"):
        return np.exp(m.real + rho)


FUNC_D2_SIGN = 1   # f'' = FUNC_D2_SIGN f, FUNC_M2's bound holding f''' too (kernels/function/exp.cl)
