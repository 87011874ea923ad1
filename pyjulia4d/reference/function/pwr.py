"""float64 twin of kernels/function/pwr.cl: f(z) = z^p = exp(p log z), p = x + iy the
scene's fractal.exponent (seed 003_8ca5f9108f52d3d6.txt, "pwr(x, y)"); 0^p = 0, as the kernel."""
import numpy as np


def cfun(z, p):
    with np.errstate(all="ignore"):
        r = np.exp(p * np.log(z))
    return np.where(z == 0, 0, r)


def cfun_d(z, p):
    with np.errstate(all="ignore"):
        r = p * np.exp((p - 1) * np.log(z))
    return np.where(z == 0, 0, r)
