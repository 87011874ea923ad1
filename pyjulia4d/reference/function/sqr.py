"""float64 twin of kernels/function/sqr.cl: f(z) = z^2 (POV-Ray 3.6 documentation,
"sqr"), numpy's complex function (its branch cuts)."""
import numpy as np

from pyjulia4d.reference.enclose import disc as D

# its degree, FUNC_POWER in kernels/function/sqr.cl: the registry's (fractal/registry.py)


def cfun(z):
    return z * z


def cfun_d(z):
    return 2 * z


def cfun_disc(z):
    """The disc enclosure of f (kernels/function/sqr.cl, under -D ENCLOSE)."""
    with np.errstate(all="ignore"):
        return D.d_sqr(z)


def FUNC_M2(m, rho):
    """A bound on |f''| over the disc of radius rho around m (kernels/function/sqr.cl)."""
    with np.errstate(all="ignore"):
        return np.full(np.shape(m), 2.0)
