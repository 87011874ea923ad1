"""float64 twin of kernels/function/sin.cl: f(z) = sin z (seed 003_8ca5f9108f52d3d6.txt,
"sin"), numpy's complex function (its branch cuts)."""
import numpy as np  # noqa: F401


def cfun(z):
    return np.sin(z)


def cfun_d(z):
    return np.cos(z)
