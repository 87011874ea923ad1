"""float64 twin of kernels/function/sinh.cl: f(z) = sinh z (seed 003_8ca5f9108f52d3d6.txt,
"sinh"), numpy's complex function (its branch cuts)."""
import numpy as np

from pyjulia4d.reference.enclose import disc as D


def cfun(z):
    return np.sinh(z)


def cfun_d(z):
    return np.cosh(z)


def cfun_disc(z):
    """The disc enclosure of f (kernels/function/sinh.cl, under -D ENCLOSE)."""
    with np.errstate(all="ignore"):
        return D.d_taylor(np.sinh(z[0]), np.abs(np.cosh(z[0])), z[1], np.cosh(np.abs(z[0].real) + z[1]))


def FUNC_M2(m, rho):
    """A bound on |f''| over the disc of radius rho around m (kernels/function/sinh.cl)."""
    with np.errstate(all="ignore"):
        return np.cosh(np.abs(m.real) + rho)
