"""float64 twin of kernels/function/tan.cl: f(z) = tan z (seed 003_8ca5f9108f52d3d6.txt,
"tan"), numpy's complex function (its branch cuts)."""
import numpy as np  # noqa: F401


def cfun(z):
    return np.tan(z)


def cfun_d(z):
    return 1 + np.tan(z) ** 2
