"""float64 twin of kernels/algebra/commutative.cl: the naive commutative rules (Ödegaard & Wennergren eq. 15):
i^2 = j^2 = k^2 = -1, ij = ji = k, ki = ik = j, jk = kj = i; commutative, not associative.
The product is built from the basis table itself (the kernel writes it out)."""
from __future__ import annotations

from pyjulia4d.reference.algebra import power
from pyjulia4d.reference.algebra.table import ALG_C, ALG_DOT, ALG_IN, ALG_NORM2, product  # noqa: F401 (the algebra's interface)

SIGN = [[1, 1, 1, 1], [1, -1, 1, 1], [1, 1, -1, 1], [1, 1, 1, -1]]
alg_mul = product(SIGN)
julia_f, julia_f_jvp = power.maps(alg_mul)


ALG_HAS_DE = False
ALG_ENCLOSE_K, ALG_LBOUND, ALG_LBOUND_SQR = power.enclose_bounds(alg_mul)   # reference/enclose/ball.py
