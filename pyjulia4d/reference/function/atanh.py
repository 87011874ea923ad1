"""float64 twin of kernels/function/atanh.cl: f(z) = atanh z (seed 003_8ca5f9108f52d3d6.txt,
"atanh"), numpy's complex function (its branch cuts)."""
import numpy as np  # noqa: F401


def cfun(z):
    return np.arctanh(z)


def cfun_d(z):
    return 1 / (1 - z * z)
