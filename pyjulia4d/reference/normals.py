"""Twin of kernels/normals/ (jacobian.cl, gradient.cl, zbuffer.cl) and march/clip.cl's
cut-face normals."""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from pyjulia4d.geometry.camera import Frame
from pyjulia4d.pipeline.codes import FLAG_CUT_FACE, GUARD_JACOBIAN_TINY, GUARD_NORMAL_FALLBACK, STATUS_HIT
from pyjulia4d.reference.formula import QUATERNION_SQR, Formula

if TYPE_CHECKING:
    from pyjulia4d.pipeline.records import MarchArgs, NormalsArgs
from pyjulia4d.reference.iterate import REAL_MIN, dot4, julia_distance_formula
from pyjulia4d.reference.kind.level import rescale_columns

def to_camera(g, frame: Frame):
    return np.stack([g @ frame.right, g @ frame.up, -(g @ frame.forward)], axis=-1)


def unit_or_zero(n):
    """Normalise, 0 where degenerate (used by truth.py; the normals kernels use
    to_camera_unit, which never returns 0 on a hit)."""
    l = np.linalg.norm(n, axis=-1, keepdims=True)
    ok = (l > 0) & np.isfinite(l)
    return np.where(ok, n / np.where(ok, l, 1), 0.0)


def to_camera_unit(n, guard=None):
    """Normalise (the caller projects with to_camera); a zero or non-finite vector becomes
    the view axis (0, 0, 1), flagged GUARD_NORMAL_FALLBACK in ``guard``
    (normals/jacobian.cl / normals/gradient.cl)."""
    l = np.linalg.norm(n, axis=-1, keepdims=True)
    ok = (l > 0) & np.isfinite(l)
    if guard is not None:
        guard |= np.where(ok[..., 0], 0, GUARD_NORMAL_FALLBACK)
    return np.where(ok, n / np.where(ok, l, 1), np.array([0.0, 0.0, 1.0]))


def normal_jacobian(p, c, max_iter, bailout, guard=None, formula: Formula = QUATERNION_SQR):
    """grad |q_n|^2 = 2 J^T q_n with J carried by the chain rule (Quilez (n.d.) method 3).
    J is rescaled both ways (no underflow on orbits drawn to an attracting cycle), and the
    iteration stops while q is a normal number, |q|^2 >= sqrt(REAL_MIN): inside points of
    c ~ 0 go to exactly 0 otherwise, and the normal with them (GUARD_JACOBIAN_TINY)."""
    F = formula
    kind = F.kind_twin
    if kind is not None:   # normals/jacobian.cl under the kind's switch (KIND_MANDELBROT, KIND_NORMAL)
        return kind.normal(p, max_iter, bailout, F, guard, GUARD_JACOBIAN_TINY)
    q = F.ALG_IN(np.array(p, np.float64)).copy()
    c = F.ALG_C(np.asarray(c, np.float64))
    # J[..., k, :] = column k, in the algebra's coordinates: ALG_IN of the unit vectors
    J = np.broadcast_to(F.ALG_IN(np.eye(4)), q.shape[:-1] + (4, 4)).copy()
    live = np.ones(q.shape[:-1], bool)
    tiny = np.zeros(q.shape[:-1], bool)
    for _ in range(max_iter):
        m2 = F.ALG_NORM2(q)
        live &= m2 <= bailout * bailout
        stop = live & (m2 < np.sqrt(REAL_MIN))
        tiny |= stop
        live &= ~stop
        if not live.any():
            break
        ql = q[live]
        with np.errstate(all="ignore"):
            Jl = J[live]
            Jl = F.julia_f_jvp(np.broadcast_to(ql[:, None, :], Jl.shape), Jl)
            q[live] = F.julia_f(ql, c)
        rescale_columns(Jl)
        J[live] = Jl
    if guard is not None:
        guard |= np.where(tiny, GUARD_JACOBIAN_TINY, 0)
    with np.errstate(all="ignore"):
        return F.ALG_DOT(J, q[..., None, :])


def normals_jacobian(point, status, frame: Frame, march: MarchArgs, guard=None, formula: Formula = QUATERNION_SQR):
    """normals/jacobian.cl with the march's record (``march``: its c, max_iter, bailout): unit
    normals of the hits in camera coordinates, 0 elsewhere; ``guard`` (int array, optional)
    gets the flags."""
    c, max_iter, bailout = march.c, march.max_iter, march.bailout
    out = np.zeros(point.shape[:-1] + (3,))
    hit = status == STATUS_HIT
    if hit.any():
        g = np.zeros(int(hit.sum()), np.int64)
        out[hit] = to_camera_unit(to_camera(normal_jacobian(point[hit], c, max_iter, bailout, g, formula), frame), g)
        if guard is not None:
            guard[hit] |= g
    return out


def de_field(p, c, max_iter, bailout, formula: Formula = QUATERNION_SQR):
    return julia_distance_formula(p, c, max_iter, bailout, formula)[0]


def normal_gradient(p, c, max_iter, bailout, h, frame: Frame, formula: Formula = QUATERNION_SQR):
    """6-point central difference of the estimate (Hart, Sandin & Kauffman 1989 §4.1.2 eq. 15) along the camera axes."""
    f = lambda x: de_field(x, c, max_iter, bailout, formula)
    r, u, w = frame.right, frame.up, frame.forward
    return np.stack([f(p + h * r) - f(p - h * r), f(p + h * u) - f(p - h * u),
                     f(p - h * w) - f(p + h * w)], axis=-1)


def normals_gradient(point, status, frame: Frame, march: MarchArgs, normals: NormalsArgs, guard=None,
                     formula: Formula = QUATERNION_SQR):
    """normals/gradient.cl with the same records (the march's c, max_iter, bailout; the
    normals' difference step, max(h, k |p - eye|)): unit normals of the hits, 0 elsewhere."""
    c, max_iter, bailout = march.c, march.max_iter, march.bailout
    out = np.zeros(point.shape[:-1] + (3,))
    hit = status == STATUS_HIT
    if hit.any():
        g = np.zeros(int(hit.sum()), np.int64)
        p = point[hit]
        h = np.maximum(normals.step, normals.step_per_distance * np.linalg.norm(p - frame.position, axis=-1))[:, None]
        with np.errstate(invalid="ignore"):
            out[hit] = to_camera_unit(normal_gradient(p, c, max_iter, bailout, h, frame, formula), g)
        if guard is not None:
            guard[hit] |= g
    return out


def normals_zbuffer(point, depth, status, width, height, frame: Frame, guard=None):
    """Plane through the hit and its neighbours' hits (Ödegaard & Wennergren §5.1, Hart, Sandin & Kauffman 1989 §4.1.1);
    per axis the central difference where both neighbours' depth jumps are within a
    factor 2, else the one-sided difference with the smaller jump, else the image axis."""
    P = to_camera(np.nan_to_num(point.reshape(height, width, 4)) - frame.position, frame)
    Z = depth.reshape(height, width)
    H = (status == STATUS_HIT).reshape(height, width)

    def shifted(a, dy, dx, fill):
        out = np.full_like(a, fill)
        ys = slice(max(dy, 0), height + min(dy, 0))
        yd = slice(max(-dy, 0), height + min(-dy, 0))
        xs = slice(max(dx, 0), width + min(dx, 0))
        xd = slice(max(-dx, 0), width + min(-dx, 0))
        out[yd, xd] = a[ys, xs]
        return out

    def tangent(da, db, axis):
        # neighbour a at offset da (the "-1" side), b at db (the "+1" side)
        ok_a, ok_b = shifted(H, *da, False), shifted(H, *db, False)
        za, zb = shifted(Z, *da, np.inf), shifted(Z, *db, np.inf)
        both = ok_a & ok_b
        with np.errstate(invalid="ignore"):  # inf - inf where neither hit: masked below
            ja, jb = np.abs(za - Z), np.abs(zb - Z)
        central = both & (np.maximum(ja, jb) <= 2 * np.minimum(ja, jb))
        a_wins = both & (ja < jb)
        ok_a_final = ok_a & (~both | a_wins)
        ok_b_final = ok_b & (~both | ~a_wins)
        pa, pb = shifted(P, *da, 0.0), shifted(P, *db, 0.0)
        t = np.broadcast_to(np.asarray(axis, float), P.shape).copy()
        t = np.where(ok_a_final[..., None], P - pa, t)
        t = np.where(ok_b_final[..., None], pb - P, t)
        return np.where(central[..., None], 0.5 * (pb - pa), t)

    tx = tangent((0, -1), (0, 1), (1, 0, 0))   # left, right
    ty = tangent((1, 0), (-1, 0), (0, 1, 0))   # row below, row above (image y grows down)
    n = np.cross(tx, ty)
    view = -P
    n = np.where((dot4(n, view) < 0)[..., None], -n, n)
    l = np.linalg.norm(n, axis=-1, keepdims=True)
    bad = ~((l > 0) & np.isfinite(l))
    n = np.where(bad, view, n)
    # the hit is the eye itself (camera inside the set): the view axis (normals/zbuffer.cl)
    lv = np.linalg.norm(n, axis=-1, keepdims=True)
    n = np.where(bad & ~((lv > 0) & np.isfinite(lv)), np.array([0.0, 0.0, 1.0]), n)
    n = n / np.linalg.norm(n, axis=-1, keepdims=True)
    if guard is not None:
        guard |= np.where((bad[..., 0] & H).ravel(), GUARD_NORMAL_FALLBACK, 0)
    return np.where(H[..., None], n, 0.0).reshape(-1, 3)


def clip_normals(flags, status, frame: Frame, planes, normal):
    """march/clip.cl: hits on a cut face take their plane's normal (camera coordinates)."""
    face = (status == STATUS_HIT) & ((np.asarray(flags) & FLAG_CUT_FACE) != 0)
    if not face.any():
        return normal
    out = normal.copy()
    k = (np.asarray(flags)[face] >> 5) & 3
    m = np.array([planes[i][0] for i in k])
    out[face] = unit_or_zero(to_camera(m, frame))
    return out
