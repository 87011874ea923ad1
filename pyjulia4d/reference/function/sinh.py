"""float64 twin of kernels/function/sinh.cl: f(z) = sinh z (seed 003_8ca5f9108f52d3d6.txt,
"sinh"), numpy's complex function (its branch cuts)."""
import numpy as np  # noqa: F401


def cfun(z):
    return np.sinh(z)


def cfun_d(z):
    return np.cosh(z)
