"""float64 twin of kernels/function/acos.cl: f(z) = acos z (seed 003_8ca5f9108f52d3d6.txt,
"acos"), numpy's complex function (its branch cuts)."""
import numpy as np  # noqa: F401


def cfun(z):
    return np.arccos(z)


def cfun_d(z):
    return -1 / np.sqrt(1 - z * z)
