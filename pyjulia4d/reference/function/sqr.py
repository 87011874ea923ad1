"""float64 twin of kernels/function/sqr.cl: f(z) = z^2 (seed 003_8ca5f9108f52d3d6.txt,
"sqr"), numpy's complex function (its branch cuts)."""
import numpy as np  # noqa: F401

# its degree, FUNC_POWER in kernels/function/sqr.cl: the registry's (fractal/registry.py)


def cfun(z):
    return z * z


def cfun_d(z):
    return 2 * z
