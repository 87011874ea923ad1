"""Twin of kernels/mesh/mesh.cl in float64 numpy: a MeshPlan's grid sampled, and the vertices
placed on the surface (the ball's sphere where it cuts the set, else the set's crossing refined
by refine_bracket)."""
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
    a = np.zeros(len(po))
    out_ball = np.sum(po * po, axis=1) > plan.radius ** 2
    b = np.sum(po * d, axis=1)
    e = np.sum(po * po, axis=1) - plan.radius ** 2
    a[out_ball] = np.clip(-b - np.sqrt(np.maximum(b * b - e, 0.0)), 0.0, length)[out_ball]
    pe = po + a[:, None] * d
    cut = out_ball.copy()
    cut[out_ball] = julia_inside(pe[out_ball], plan.c, plan.max_iter, plan.bailout, F)
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


def _inside(plan, p: np.ndarray, F) -> np.ndarray:
    """In the ball and the set, as mesh_sample tests a grid point."""
    out = np.sum(p * p, axis=1) <= plan.radius ** 2
    out[out] = julia_inside(p[out], plan.c, plan.max_iter, plan.bailout, F)
    return out
