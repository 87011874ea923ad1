"""float64 twin of kernels/function/sinh.cl: f(z) = sinh z (POV-Ray 3.6 documentation,
"sinh"), numpy's complex function (its branch cuts)."""
import numpy as np

from pyjulia4d.reference.enclose import disc as D


def cfun(z):
    return np.sinh(z)


def cfun_d(z):
    return np.cosh(z)


def FUNC_M2(m, rho):
    """A bound on |f''| over the disc of radius rho around m (kernels/function/sinh.cl)."""
    with np.errstate(all="ignore"):
        return np.cosh(np.abs(m.real) + rho)


FUNC_D2_SIGN = 1   # f'' = FUNC_D2_SIGN f, FUNC_M2's bound holding f''' too (kernels/function/sinh.cl)


cfun_disc = D.taylor_disc(cfun, cfun_d, FUNC_M2)   # kernels/function/sinh.cl, under -D ENCLOSE
