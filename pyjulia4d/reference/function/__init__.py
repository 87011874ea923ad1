"""float64 twins of kernels/function/*.cl, file for file: each module has ``cfun(z)`` and
``cfun_d(z)`` on numpy complex128 arrays (pwr: ``cfun(z, p)``, ``cfun_d(z, p)``)."""
