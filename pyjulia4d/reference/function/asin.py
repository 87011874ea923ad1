"""float64 twin of kernels/function/asin.cl: f(z) = asin z (seed 003_8ca5f9108f52d3d6.txt,
"asin"), numpy's complex function (its branch cuts)."""
import numpy as np  # noqa: F401


def cfun(z):
    return np.arcsin(z)


def cfun_d(z):
    return 1 / np.sqrt(1 - z * z)
