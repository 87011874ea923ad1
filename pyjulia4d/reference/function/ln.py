"""float64 twin of kernels/function/ln.cl: f(z) = ln z (seed 003_8ca5f9108f52d3d6.txt,
"ln"), numpy's complex function (its branch cuts)."""
import numpy as np  # noqa: F401


def cfun(z):
    return np.log(z)


def cfun_d(z):
    return 1 / z
