"""Twin of kernels/mesh/mesh.cl in float64 numpy: a MeshPlan's grid sampled, and the vertices
placed on the surface (the ball's sphere or a clip plane where it cuts the set, else the set's
crossing refined by refine_bracket)."""
from __future__ import annotations

import numpy as np

from pyjulia4d.reference.formula import formula_of
from pyjulia4d.reference.iterate import julia_inside
from pyjulia4d.reference.march import refine_bracket


def mesh_sample(plan, k0: int, nk: int) -> np.ndarray:
    """The inside mask of layers k0 .. k0 + nk - 1, uint8 (nk, n, n) [k, j, i]."""
    n = plan.n
    k, j, i = np.meshgrid(np.arange(k0, k0 + nk), np.arange(n), np.arange(n), indexing="ij")
    p = plan.to_world(np.stack([i, j, k], axis=-1).reshape(-1, 3))
    return _inside(plan, p, formula_of(plan.scene.fractal)).astype(np.uint8).reshape(nk, n, n)


def mesh_vertices(plan, ends_a: np.ndarray, ends_b: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(vertices (m, 4), bracket widths (m,), the brackets' inside ends (m, 4)) on the edges
    between world points ends_a and ends_b, one inside and one outside in either order; width
    -1 where both ends agree."""
    F = formula_of(plan.scene.fractal)
    pa, pb = np.asarray(ends_a, float), np.asarray(ends_b, float)
    ia, ib = _inside(plan, pa, F), _inside(plan, pb, F)
    po = np.where(ia[:, None], pb, pa)
    d = np.where(ia[:, None], pa, pb) - po
    length = np.linalg.norm(d, axis=1)
    d = d / length[:, None]
    outside = ~_kept(plan, po)   # the outside end cut away: the edge enters the region at a
    a = np.where(outside, _entry(plan, po, d, length), 0.0)
    pe = po + a[:, None] * d
    cut = outside.copy()
    cut[outside] = julia_inside(pe[outside], plan.c, plan.max_iter, plan.bailout, F)
    vertex, width, inner = pe.copy(), np.zeros(len(po)), pe.copy()
    k = ~cut & (ia != ib)
    if np.any(k):
        t, w = refine_bracket(po[k], d[k], a[k], length[k], plan.steps, plan.c, plan.max_iter, plan.bailout,
                              itp=plan.scene.march.refine == "itp", formula=F)
        vertex[k] = po[k] + (t + 0.5 * w)[:, None] * d[k]
        inner[k] = po[k] + (t + w)[:, None] * d[k]
        width[k] = w
    same = ia == ib
    vertex[same] = inner[same] = 0.5 * (pa[same] + pb[same])
    width[same] = -1.0
    return vertex, width, inner


def _kept(plan, p: np.ndarray) -> np.ndarray:
    """In the ball and in every clip half-space n . p <= offset (mesh.cl's mesh_kept)."""
    out = np.sum(p * p, axis=1) <= plan.radius ** 2
    for n, off in plan.clip.planes:
        out &= p @ np.asarray(n, float) <= off
    return out


def _entry(plan, po: np.ndarray, d: np.ndarray, length: np.ndarray) -> np.ndarray:
    """Where each ray po + a d enters the region of _kept (mesh.cl's mesh_entry): the largest
    entry of the sphere and of each plane it starts outside, within [0, length]."""
    b = np.sum(po * d, axis=1)
    e = np.sum(po * po, axis=1) - plan.radius ** 2
    a = np.where(e > 0, -b - np.sqrt(np.maximum(b * b - e, 0.0)), 0.0)
    for n, off in plan.clip.planes:
        so, sd = po @ np.asarray(n, float) - off, d @ np.asarray(n, float)
        hit = (so > 0) & (sd < 0)
        a = np.where(hit, np.maximum(a, so / np.where(hit, -sd, 1.0)), a)
    return np.clip(a, 0.0, length)


def _inside(plan, p: np.ndarray, F) -> np.ndarray:
    """In the ball, the half-spaces and the set, as mesh_sample tests a grid point."""
    out = _kept(plan, p)
    out[out] = julia_inside(p[out], plan.c, plan.max_iter, plan.bailout, F)
    return out
