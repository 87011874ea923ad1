"""float64 twin of kernels/function/atan.cl: f(z) = atan z (seed 003_8ca5f9108f52d3d6.txt,
"atan"), numpy's complex function (its branch cuts)."""
import numpy as np  # noqa: F401


def cfun(z):
    return np.arctan(z)


def cfun_d(z):
    return 1 / (1 + z * z)
