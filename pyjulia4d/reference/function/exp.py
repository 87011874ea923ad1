"""float64 twin of kernels/function/exp.cl: f(z) = e^z (seed 003_8ca5f9108f52d3d6.txt,
"exp"), numpy's complex function (its branch cuts)."""
import numpy as np  # noqa: F401


def cfun(z):
    return np.exp(z)


def cfun_d(z):
    return np.exp(z)
