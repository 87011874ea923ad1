"""float64 twin of kernels/function/asinh.cl: f(z) = asinh z (seed 003_8ca5f9108f52d3d6.txt,
"asinh"), numpy's complex function (its branch cuts)."""
import numpy as np  # noqa: F401


def cfun(z):
    return np.arcsinh(z)


def cfun_d(z):
    return 1 / np.sqrt(z * z + 1)
