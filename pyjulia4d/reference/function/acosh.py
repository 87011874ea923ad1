"""float64 twin of kernels/function/acosh.cl: f(z) = acosh z (seed 003_8ca5f9108f52d3d6.txt,
"acosh"), numpy's complex function (its branch cuts)."""
import numpy as np  # noqa: F401


def cfun(z):
    return np.arccosh(z)


def cfun_d(z):
    return 1 / (np.sqrt(z - 1) * np.sqrt(z + 1))
