"""float64 twin of kernels/function/reciprocal.cl: f(z) = 1/z (seed 003_8ca5f9108f52d3d6.txt,
"reciprocal"), numpy's complex function (its branch cuts)."""
import numpy as np  # noqa: F401


def cfun(z):
    return 1 / z


def cfun_d(z):
    return -1 / (z * z)
