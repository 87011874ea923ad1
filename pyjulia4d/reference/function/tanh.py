"""float64 twin of kernels/function/tanh.cl: f(z) = tanh z (seed 003_8ca5f9108f52d3d6.txt,
"tanh"), numpy's complex function (its branch cuts)."""
import numpy as np  # noqa: F401


def cfun(z):
    return np.tanh(z)


def cfun_d(z):
    return 1 - np.tanh(z) ** 2
