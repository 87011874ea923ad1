"""float64 twin of kernels/function/cube.cl: f(z) = z^3 (seed 003_8ca5f9108f52d3d6.txt,
"cube"), numpy's complex function (its branch cuts)."""
import numpy as np  # noqa: F401

# its degree, FUNC_POWER in kernels/function/cube.cl: the registry's (fractal/registry.py)


def cfun(z):
    return z * z * z


def cfun_d(z):
    return 3 * z * z
