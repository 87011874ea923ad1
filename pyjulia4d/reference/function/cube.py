"""float64 twin of kernels/function/cube.cl: f(z) = z^3 (POV-Ray 3.6 documentation,
"cube"), numpy's complex function (its branch cuts)."""
import numpy as np

from pyjulia4d.reference.enclose import disc as D

# its degree, FUNC_POWER in kernels/function/cube.cl: the registry's (fractal/registry.py)


def cfun(z):
    return z * z * z


def cfun_d(z):
    return 3 * z * z


def cfun_disc(z):
    """The disc enclosure of f (kernels/function/cube.cl, under -D ENCLOSE)."""
    with np.errstate(all="ignore"):
        return D.d_mul(D.d_sqr(z), z)


def FUNC_M2(m, rho):
    """A bound on |f''| over the disc of radius rho around m (kernels/function/cube.cl)."""
    with np.errstate(all="ignore"):
        return 6 * (np.abs(m) + rho)
