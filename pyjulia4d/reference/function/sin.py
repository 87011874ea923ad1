"""float64 twin of kernels/function/sin.cl: f(z) = sin z (POV-Ray 3.6 documentation,
"sin"), numpy's complex function (its branch cuts)."""
import numpy as np

from pyjulia4d.reference.enclose import disc as D


def cfun(z):
    return np.sin(z)


def cfun_d(z):
    return np.cos(z)


def FUNC_M2(m, rho):
    """A bound on |f''| over the disc of radius rho around m (kernels/function/sin.cl)."""
    with np.errstate(all="ignore"):
        return np.cosh(np.abs(m.imag) + rho)


FUNC_D2_SIGN = -1   # f'' = FUNC_D2_SIGN f, FUNC_M2's bound holding f''' too (kernels/function/sin.cl)


cfun_disc = D.taylor_disc(cfun, cfun_d, FUNC_M2)   # kernels/function/sin.cl, under -D ENCLOSE
