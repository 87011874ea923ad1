"""float64 twin of kernels/function/reciprocal.cl: f(z) = 1/z (POV-Ray 3.6 documentation,
"reciprocal"), numpy's complex function (its branch cuts)."""
import numpy as np

from pyjulia4d.reference.enclose import disc as D


def cfun(z):
    return 1 / z


def cfun_d(z):
    return -1 / (z * z)


def cfun_disc(z):
    """The disc enclosure of f (kernels/function/reciprocal.cl, under -D ENCLOSE)."""
    with np.errstate(all="ignore"):
        return D.d_recip(z)


def FUNC_M2(m, rho):
    """|f''| = 2 / |z|^3 <= 2 / (|m| - rho)^3; none (inf) where 0 is in the disc."""
    g = np.abs(m) - rho
    with np.errstate(all="ignore"):
        return np.where(g > 0, 2 / g ** 3, np.inf)
