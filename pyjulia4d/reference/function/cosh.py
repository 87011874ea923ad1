"""float64 twin of kernels/function/cosh.cl: f(z) = cosh z (POV-Ray 3.6 documentation,
"cosh"), numpy's complex function (its branch cuts)."""
import numpy as np

from pyjulia4d.reference.enclose import disc as D


def cfun(z):
    return np.cosh(z)


def cfun_d(z):
    return np.sinh(z)


def FUNC_M2(m, rho):
    """A bound on |f''| over the disc of radius rho around m (kernels/function/cosh.cl)."""
    with np.errstate(all="ignore"):
        return np.cosh(np.abs(m.real) + rho)


FUNC_D2_SIGN = 1   # f'' = FUNC_D2_SIGN f, FUNC_M2's bound holding f''' too (kernels/function/cosh.cl)


cfun_disc = D.taylor_disc(cfun, cfun_d, FUNC_M2)   # kernels/function/cosh.cl, under -D ENCLOSE
