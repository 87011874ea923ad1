"""float64 twin of kernels/kind/mandelbrot.cl: the Mandelbrot set of q -> f(q) + c, the
parameters c (the point, in the algebra's coordinates) whose orbit of the critical point 0
stays within the bailout for n = 1 .. max_iter (q_1 = c); Hart, Sandin & Kauffman 1989 §2.1,
§3.1 eq. 8 with the derivative taken with respect to c; Quilez 2002."""
from __future__ import annotations

import numpy as np

from pyjulia4d.reference.kind.level import kind_level, rescale_columns

REAL_MIN = np.finfo(np.float64).tiny


def mandel_start(F, c):
    """q_1 = v + c, v f's critical or asymptotic value (scene.MANDELBROT_START; kind/mandelbrot.cl
    MANDEL_START), in the algebra's coordinates."""
    from pyjulia4d.fractal.registry import MANDELBROT_START
    return c + F.ALG_IN(np.asarray(MANDELBROT_START[F.function], np.float64))


def mandel_f(F, q, c):
    """f(q) + c with c per point (the kernel's julia_f(q, 0) + c)."""
    return F.julia_f(q, np.zeros(4)) + c


def mandel_inside(p, max_iter, bailout, F):
    """|q_n| <= bailout for n = 1 .. max_iter, q_1 = c = ALG_IN(p)."""
    c = F.ALG_IN(np.array(p, dtype=np.float64))
    q = mandel_start(F, c)
    b2 = bailout * bailout
    out = np.ones(q.shape[:-1], bool)
    with np.errstate(all="ignore"):
        for _ in range(max_iter - 1):
            out &= F.ALG_NORM2(q) <= b2
            if not out.any():
                return out
            q[out] = mandel_f(F, q[out], c[out])
        return out & (F.ALG_NORM2(q) <= b2)


def mandel_level(p, max_iter, bailout, F):
    """F = |q_N|^2 / b^2 - 1, an escape at n < N extrapolated as in reference.julia_level.
    Returns (F, inside)."""
    c = F.ALG_IN(np.array(p, dtype=np.float64))
    q = mandel_start(F, c)
    b2 = bailout * bailout
    m2 = F.ALG_NORM2(q)
    n = np.ones(m2.shape, np.int64)
    live = np.ones(m2.shape, bool)
    with np.errstate(all="ignore"):
        for _ in range(max_iter - 1):
            live &= m2 <= b2
            if not live.any():
                break
            q[live] = mandel_f(F, q[live], c[live])
            m2[live] = F.ALG_NORM2(q[live])
            n[live] += 1
    inside = m2 <= b2
    return np.where(inside, m2 / b2 - 1.0, kind_level(m2, b2, max_iter - n, F.growth)), inside


def _de_value(m2, dr):
    """d = |q| ln|q| / (2 |q'|) = sqrt(m2) ln(m2) / (4 |q'|)."""
    mq = np.maximum(m2, REAL_MIN)
    return np.sqrt(mq) / np.maximum(dr, REAL_MIN) * np.log(mq) / 4.0


def mandel_distance_formula(p, max_iter, bailout, F):
    """d = |q_n| ln|q_n| / (2 |q_n'|), |q'_1| = 1, |q'_{n+1}| <= |f'(q_n)| |q'_n| + 1 carried as
    the bound (float64 needs no mantissa-exponent split below 1e300); the split algebra's is
    sqrt(d_a^2 + d_b^2) / sqrt(2).  Returns (d, escaped)."""
    c = F.ALG_IN(np.array(p, dtype=np.float64))
    q = mandel_start(F, c)
    b2 = bailout * bailout
    m2 = F.ALG_NORM2(q)
    live = np.ones(m2.shape, bool)
    D = F.fn.FUNC_POWER
    if F.split:
        da, db = np.ones_like(m2), np.ones_like(m2)
    else:
        dr = np.ones_like(m2)
    with np.errstate(over="ignore"):
        for _ in range(max_iter - 1):
            live &= m2 <= b2
            if not live.any():
                break
            if F.split:
                ql = q[live]
                da[live] = da[live] * np.sqrt(F.alg.JULIA_DF2(ql[:, 0] ** 2 + ql[:, 1] ** 2, D)) + 1.0
                db[live] = db[live] * np.sqrt(F.alg.JULIA_DF2(ql[:, 2] ** 2 + ql[:, 3] ** 2, D)) + 1.0
            else:
                dr[live] = dr[live] * np.sqrt(F.JULIA_DF2(m2[live])) + 1.0
            q[live] = mandel_f(F, q[live], c[live])
            m2[live] = F.ALG_NORM2(q[live])
    escaped = m2 > b2
    if not F.split:
        return _de_value(m2, dr), escaped
    ma, mb = q[..., 0] ** 2 + q[..., 1] ** 2, q[..., 2] ** 2 + q[..., 3] ** 2
    ra, rb = 1 + np.hypot(c[..., 0], c[..., 1]), 1 + np.hypot(c[..., 2], c[..., 3])
    d_a = np.where(ma > ra * ra, _de_value(ma, da), 0.0)
    d_b = np.where(mb > rb * rb, _de_value(mb, db), 0.0)
    return np.sqrt(d_a ** 2 + d_b ** 2) / np.sqrt(2.0), escaped


def mandel_normal_jacobian(p, max_iter, bailout, F, guard=None, tiny_flag=0):
    """grad_p |q_N|^2 = 2 J^T q_N with J_1 = ALG_IN, J_{n+1} = f'(q_n) J_n + ALG_IN
    (normals/jacobian.cl, -D KIND_MANDELBROT), rescaled both ways with the added identity
    kept at J's scale; the same underflow stop as the Julia normal."""
    c = F.ALG_IN(np.array(p, np.float64)).copy()
    q = mandel_start(F, c)
    E = F.ALG_IN(np.eye(4))
    J = np.broadcast_to(E, q.shape[:-1] + (4, 4)).copy()
    unit = np.ones(q.shape[:-1])
    live = np.ones(q.shape[:-1], bool)
    tiny = np.zeros(q.shape[:-1], bool)
    for _ in range(max_iter - 1):
        m2 = F.ALG_NORM2(q)
        live &= m2 <= bailout * bailout
        stop = live & (m2 < np.sqrt(REAL_MIN))
        tiny |= stop
        live &= ~stop
        if not live.any():
            break
        ql = q[live]
        with np.errstate(all="ignore"):
            Jl = F.julia_f_jvp(np.broadcast_to(ql[:, None, :], J[live].shape), J[live])
            Jl = Jl + unit[live][:, None, None] * E
            q[live] = mandel_f(F, ql, c[live])
        ul = unit[live]
        rescale_columns(Jl, ul)
        unit[live] = ul
        J[live] = Jl
    if guard is not None:
        guard |= np.where(tiny, tiny_flag, 0)
    with np.errstate(all="ignore"):
        return F.ALG_DOT(J, q[..., None, :])


# The twin interface the registry names (Kind.twin; reference/formula.Formula.kind_twin): what
# iterate.py, normals.py and shade.py ask of a kind.
inside, level, distance_formula, normal = mandel_inside, mandel_level, mandel_distance_formula, mandel_normal_jacobian


def orbit_start(F, p):
    """The orbit the colourings follow (shade/light.cl ORBIT_*): that of v with c = p, from
    q_1 = v + c: (q_1, step(q, live) -> f(q) + c on the live points, first index 1)."""
    cp = F.ALG_IN(np.asarray(p, np.float64))
    return mandel_start(F, cp), (lambda q, live: mandel_f(F, q[live], cp[live])), 1
