"""float64 twin of kernels/function/acosh.cl: f(z) = acosh z (POV-Ray 3.6 documentation,
"acosh"), numpy's complex function (its branch cuts)."""
import numpy as np

from pyjulia4d.reference.enclose import disc as D


def cfun(z):
    return np.arccosh(z)


def cfun_d(z):
    return 1 / (np.sqrt(z - 1) * np.sqrt(z + 1))


def cfun_disc(z):
    """The disc enclosure of f (kernels/function/acosh.cl, under -D ENCLOSE)."""
    with np.errstate(all="ignore"):
        return D.d_log(D.d_add(z, D.d_mul(D.d_sqrt(D.d_add_const(z, 1.0)), D.d_sqrt(D.d_add_const(z, -1.0)))))
