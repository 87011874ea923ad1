"""Escape-time bounds: radii of 4-balls that provably hold a set, by the growth of the map
outside them (Hart, Sandin & Kauffman 1989 §3.1: bound first, march only inside).  Each kind
of set takes its own (fractal/kinds/)."""
from __future__ import annotations

import math

import numpy as np


def bounding_radius(c, bailout: float, max_iter: int, degree: int | None = 2) -> float:
    """Radius of a 4-ball that provably holds every point with |q_n| <= bailout for
    n = 0..max_iter (the set the fixed scan finds), for q -> q^degree + c.

    With R the root of r^D - |c| = r, |q| = r > R gives |q^D + c| >= r^D - |c| > r, so
    |q_n| >= g^n(r), g(r) = r^D - |c|.  A point that stays within the bailout b after N
    steps therefore has |q_0| <= g^-N(b) = h^N(b), h(s) = (s + |c|)^(1/D), and also
    |q_0| <= b.  The bound shrinks from b towards R as N grows.  |q^D| >= |q|^D holds for
    quaternions (|q^D| = |q|^D) and for the hypercomplex numbers (the power mean of the
    split components, algebra/hypercomplex.cl).  ``degree`` None (a function that is no
    polynomial): the bailout itself, the n = 0 test, widened by 2^-20 (far above float32's
    rounding of a point's norm): such sets can fill the ball up to its sphere (tan, asin,
    reciprocal stay bounded almost everywhere), and a scan must start outside them, so that
    the hit on the sphere is bracketed and its normal is the sphere's.
    """
    if degree is None:
        return float(bailout) * (1.0 + 2.0 ** -20)
    cabs = float(np.linalg.norm(c))
    s = float(bailout)
    for _ in range(min(int(max_iter), 200)):  # h^N converges to R geometrically
        s_next = (s + cabs) ** (1.0 / degree) if degree != 2 else math.sqrt(s + cabs)
        if abs(s_next - s) < 1e-15:
            break
        s = s_next
    return min(float(bailout), s)


def mandelbrot_radius(bailout: float, max_iter: int, degree: int | None = 2, start: float = 0.0) -> float:
    """Radius of a 4-ball that provably holds every c with |q_n| <= bailout for n = 1..max_iter,
    q_1 = c, q_{n+1} = q_n^degree + c (kernels/kind/mandelbrot.cl).

    |q_1| = |c| = r <= b is needed.  With s_1 = r, s_{n+1} = s_n^D - r a lower bound of |q_n|
    (|q^D + c| >= |q|^D - |c|), and r > R = 2^(1/(D-1)) (where R^D - R = R), s_n grows with n
    and with r (ds_{n+1}/dr = D s_n^(D-1) ds_n/dr - 1 >= 1); so the c that stay within b for N
    steps have r <= max(R, r*), r* the least r >= R with some s_n > b, found by bisection
    (widened by 1e-9 relative).  ``degree`` None (no norm bound): |q_1| = |v + c| <= b
    alone, so b + |v| (``start``, the critical value's norm), widened as in bounding_radius."""
    b = float(bailout)
    if degree is None:
        return (b + float(start)) * (1.0 + 2.0 ** -20)
    R = 2.0 ** (1.0 / (degree - 1))
    if b <= R:
        return b

    def escapes(r: float) -> bool:
        s = r
        for _ in range(int(max_iter) - 1):
            s = s ** degree - r
            if s > b:
                return True
        return False

    if not escapes(b):
        return b
    lo, hi = R, b                    # lo stays within b (or is R), hi escapes
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if escapes(mid):
            hi = mid
        else:
            lo = mid
    return min(b, hi * (1.0 + 1e-9))
