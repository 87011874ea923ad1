"""Proofs of empty space along a ray, in float64 interval arithmetic: the reference of a march
that never steps over the set.

A segment o + t d, t in [t0, t1], holds no point of the max_iter-truncated set when an
enclosure of the orbits of all its points leaves the bailout ball at some iteration
n <= max_iter: every point then has |q_n| > bailout, so none is inside (seed
003_8ca5f9108f52d3d6.txt: inside when |q_n| <= bailout for n = 0..max_iter).  The
enclosure is a box (an interval per coordinate of the algebra's iterate, ALG_IN), pushed
through q -> q^D + c with interval arithmetic (Moore's; the approach of Knoll, Hijazi,
Kensler, Schott, Hansen and Hagen, "Fast ray tracing of arbitrary implicit surfaces with
interval and affine arithmetic", 2009), every bound moved one ulp outward after each
operation, so float64 rounding cannot make a proof false.  Where the proof fails the
segment is split; below ``floor`` it is tested at points and counted as unresolved.

Covered: the polynomial maps (sqr, cube) of all four algebras - quaternions, the
hypercomplex numbers (each complex component of the idempotent split on its own), CQuats
and the commutative rules (their multiplication tables).  The transcendental functions,
the other kinds and the rotation are not yet enclosed (``supports`` says which).
"""
from __future__ import annotations

import numpy as np

from pyjulia4d.reference.algebra import commutative, cquat
from pyjulia4d.reference.algebra.table import INDEX
from pyjulia4d.reference.formula import formula_of

_INF = np.inf


def supports(fractal) -> bool:
    """Whether this module can prove segments of ``fractal`` empty."""
    return (fractal.function in ("sqr", "cube") and fractal.kind == "julia" and fractal.theta == 0)


# ------------------------------------------------------------------ interval arithmetic
# An interval array is a pair (lo, hi) of float64 arrays; every result is widened outward.

def _out(lo, hi):
    return np.nextafter(lo, -_INF), np.nextafter(hi, _INF)


def iadd(a, b):
    return _out(a[0] + b[0], a[1] + b[1])


def isub(a, b):
    return _out(a[0] - b[1], a[1] - b[0])


def imul(a, b):
    p = np.stack([a[0] * b[0], a[0] * b[1], a[1] * b[0], a[1] * b[1]])
    with np.errstate(invalid="ignore"):   # 0 * inf: the box is unbounded anyway
        lo, hi = np.nanmin(p, axis=0), np.nanmax(p, axis=0)
    return _out(lo, hi)


def isqr(a):
    """x^2 over the interval: 0 where it spans 0 (tighter than imul(a, a))."""
    lo2, hi2 = a[0] * a[0], a[1] * a[1]
    span = (a[0] <= 0) & (a[1] >= 0)
    return _out(np.where(span, 0.0, np.minimum(lo2, hi2)), np.maximum(lo2, hi2))


def iscale(k: float, a):
    lo, hi = k * a[0], k * a[1]
    return _out(np.minimum(lo, hi), np.maximum(lo, hi))


def _sum(terms):
    out = terms[0]
    for t in terms[1:]:
        out = iadd(out, t)
    return out


def min_square(a):
    """The least x^2 over the interval."""
    return np.where((a[0] <= 0) & (a[1] >= 0), 0.0, np.minimum(a[0] * a[0], a[1] * a[1]))


# ------------------------------------------------------------------ the maps on boxes
# A box is a list of 4 intervals in the algebra's coordinates (ALG_IN).

def _quaternion_power(q, degree):
    x, y, z, w = q
    if degree == 2:   # (x^2 - y^2 - z^2 - w^2, 2xy, 2xz, 2xw)
        return [isub(isqr(x), _sum([isqr(y), isqr(z), isqr(w)])), iscale(2.0, imul(x, y)),
                iscale(2.0, imul(x, z)), iscale(2.0, imul(x, w))]
    v2 = _sum([isqr(y), isqr(z), isqr(w)])   # q^3 = (x^3 - 3 x |v|^2, (3 x^2 - |v|^2) v)
    x2 = isqr(x)
    s = isub(iscale(3.0, x2), v2)
    return [imul(x, isub(x2, iscale(3.0, v2))), imul(s, y), imul(s, z), imul(s, w)]


def _complex_power(r, i, degree):
    if degree == 2:
        return isub(isqr(r), isqr(i)), iscale(2.0, imul(r, i))
    r2, i2 = isqr(r), isqr(i)   # z^3 = (r (r^2 - 3 i^2), i (3 r^2 - i^2))
    return imul(r, isub(r2, iscale(3.0, i2))), imul(i, isub(iscale(3.0, r2), i2))


def _hypercomplex_power(q, degree):
    ar, ai = _complex_power(q[0], q[1], degree)
    br, bi = _complex_power(q[2], q[3], degree)
    return [ar, ai, br, bi]


def _table_product(sign, a, b, same: bool):
    """The bilinear product of the multiplication table on boxes; for a * a the terms of
    a_i a_j and a_j a_i are taken together and a_i a_i as a square (tighter)."""
    coef: dict[tuple[int, int, int], float] = {}
    for i in range(4):
        for j in range(4):
            key = (INDEX[i][j], min(i, j), max(i, j)) if same else (INDEX[i][j], i, j)
            coef[key] = coef.get(key, 0.0) + sign[i][j]
    out = [[] for _ in range(4)]
    for (k, i, j), s in coef.items():
        if s == 0:
            continue
        prod = isqr(a[i]) if same and i == j else imul(a[i], b[j])
        out[k].append(iscale(s, prod))
    return [_sum(t) for t in out]


def _table_power(sign, q, degree):
    qq = _table_product(sign, q, q, True)
    return qq if degree == 2 else _table_product(sign, qq, q, False)


_POWER = {"quaternion": _quaternion_power, "hypercomplex": _hypercomplex_power,
          "cquat": lambda q, d: _table_power(cquat.SIGN, q, d),
          "commutative": lambda q, d: _table_power(commutative.SIGN, q, d)}
_NORM_FACTOR = {"hypercomplex": 0.5}   # |h|^2 = (|a|^2 + |b|^2) / 2 (algebra/hypercomplex.py)


def segment_box(o, d, t0, t1, formula):
    """The box of the algebra's coordinates holding o + t d for every t in [t0, t1]: the
    coordinates are linear in t (ALG_IN is linear), so the ends bound them."""
    p0 = formula.ALG_IN(o + t0[:, None] * d)
    p1 = formula.ALG_IN(o + t1[:, None] * d)
    lo, hi = np.minimum(p0, p1), np.maximum(p0, p1)
    return [_out(lo[:, k], hi[:, k]) for k in range(4)]


def escapes(box, c, max_iter: int, bailout: float, algebra: str, degree: int) -> np.ndarray:
    """Per box: True where its orbit enclosure leaves the bailout ball at some n <= max_iter
    (a proof that no point of it is inside), False where that could not be shown."""
    power = _POWER[algebra]
    k = _NORM_FACTOR.get(algebra, 1.0)
    b2 = bailout * bailout
    n = len(box[0][0])
    proven = np.zeros(n, bool)
    q = box
    with np.errstate(over="ignore", invalid="ignore"):
        for it in range(max_iter + 1):
            least = k * sum(min_square(x) for x in q)
            proven |= least > b2
            if it == max_iter or proven.all():
                break
            q = power(q, degree)
            q = [iadd(x, (np.full(n, ck), np.full(n, ck))) for x, ck in zip(q, c)]
    return proven


def prove_empty(scene, o, d, t0, t1) -> np.ndarray:
    """Per ray: True where the segment [t0, t1] of o + t d is proven to hold no point of the
    scene's truncated set (``supports`` must hold)."""
    f = scene.fractal
    if not supports(f):
        raise ValueError(f"no enclosure for {f.algebra} {f.function} ({f.kind}, theta {f.theta})")
    F = formula_of(f)
    o, d = np.atleast_2d(np.asarray(o, np.float64)), np.atleast_2d(np.asarray(d, np.float64))
    t0, t1 = np.broadcast_to(np.asarray(t0, np.float64), len(o)), np.broadcast_to(np.asarray(t1, np.float64), len(o))
    box = segment_box(o, d, t0, t1, F)
    degree = 2 if f.function == "sqr" else 3
    return escapes(box, F.ALG_C(np.asarray(f.c, np.float64)), f.max_iter, f.bailout, f.algebra, degree)


def first_crossing(scene, o, d, near: float, far: float, floor: float = 1e-6, start: int = 64):
    """One ray's march that steps over nothing unproven: [near, far] cut into ``start``
    segments, each proven empty or split in two, in order, down to ``floor``; a segment at
    the floor is tested at its ends (``reference.julia_inside``).  Returns (t, unresolved):
    t the first floor segment found inside (+inf: none), unresolved the summed width of the
    floor segments before it that were neither proven empty nor found inside."""
    from pyjulia4d.reference.iterate import julia_inside

    f = scene.fractal
    F = formula_of(f)
    o, d = np.asarray(o, np.float64), np.asarray(d, np.float64)
    edges = np.linspace(near, far, start + 1)
    stack = [(float(a), float(b)) for a, b in zip(edges[-2::-1], edges[:0:-1])]   # nearest on top
    unresolved = 0.0
    while stack:
        a, b = stack.pop()
        if prove_empty(scene, o[None], d[None], a, b)[0]:
            continue
        if b - a > floor:
            m = 0.5 * (a + b)
            stack += [(m, b), (a, m)]
            continue
        pts = o[None] + np.array([a, b])[:, None] * d[None]
        ins = julia_inside(pts, f.c, f.max_iter, f.bailout, F)
        if ins.any():
            return (a if ins[0] else b), unresolved
        unresolved += b - a
    return np.inf, unresolved
