"""Ground truth for any algebra x function pair and kind, by brute force: the first crossing of
each ray into the scene's truncated set, from a chord scan, a fine scan back over the chord
and bisection, all in float64 with the set's own inside test (reference.julia_inside) - no
distance estimate, no kernel; and a refinement that finds what a coarse chord stepped over."""
from __future__ import annotations

import numpy as np

from pyjulia4d import reference as ref
from pyjulia4d.measure.ray_scan import bisect, first_inside, ray_interval
from pyjulia4d.scene.model import Scene


def brute_force_depth(scene: Scene, origins, dirs, chord: float = 2e-4, fine: float = 2e-6,
                      radius: float | None = None) -> np.ndarray:
    """The first crossing of each unit ray o + t d into the scene's truncated set (inside
    when |q_n| <= bailout for n = 0..max_iter, its float64 twin ``reference.julia_inside``
    with the scene's algebra, function and kind), +inf where none: a chord scan at spacing
    at most ``chord`` through the bounding ball (bounds.bounding_radius, ``radius``), then a
    scan at ``fine`` back over the chord before the first inside sample, then bisection to
    float64 resolution.  It steps over parts of the set thinner than ``chord`` along a ray
    that the fine scan does not reach: a truth for the thickness it resolves, whatever
    march a render used; no distance estimate, no kernel."""
    from pyjulia4d.geometry.camera import march_radius

    f = scene.fractal
    F = ref.formula_of(f)
    o, d = np.asarray(origins, np.float64), np.asarray(dirs, np.float64)

    def inside(p):
        return ref.julia_inside(p, f.c, f.max_iter, f.bailout, F)

    R = march_radius(scene) if radius is None else radius
    near, far, live = ray_interval(o, d, R)
    out = np.full(len(o), np.inf)
    idx = np.nonzero(live)[0]
    if idx.size == 0:
        return out
    n_scan = max(1, int(np.ceil(float(np.max(far[idx] - near[idx])) / chord)))
    first = first_inside(inside, o[idx], d[idx], near[idx], far[idx], n_scan)
    hit = first >= 0
    k = idx[hit]
    if k.size == 0:
        return out
    h = (far[k] - near[k]) / n_scan
    t_in = near[k] + first[hit] * h
    out[k] = _crossing_before(inside, o[k], d[k], np.maximum(t_in - h, near[k]), t_in, fine)
    return out


def _crossing_before(inside, o, d, t_lo, t_in, fine):
    """The first crossing in [t_lo, t_in], t_in inside: a scan at ``fine``, then bisection;
    t_lo itself where it is inside already (the ray's entry, or the eye)."""
    n_fine = max(1, int(np.ceil(float(np.max(t_in - t_lo)) / fine)))
    j = first_inside(inside, o, d, t_lo, t_in, n_fine)   # never -1: t_in is inside
    j = np.where(j < 0, n_fine, j)
    hf = (t_in - t_lo) / n_fine
    t_hit = t_lo + j * hf
    at_start = j == 0
    t_out = np.where(at_start, t_hit, t_hit - hf)
    polished = bisect(inside, o, d, t_out, t_hit)
    return np.where(at_start, t_hit, polished)


def refine_depth(scene: Scene, origins, dirs, truth, t_inside, chord: float = 2e-4, fine: float = 2e-6,
                 radius: float | None = None) -> tuple[np.ndarray, int]:
    """brute_force_depth's ``truth`` with more samples: per ray, a point ``t_inside`` (from
    anywhere: a render's inside end) that lies in front of the truth and that the float64
    set test finds inside proves the chord scan stepped over a part there; the crossing is
    then found by the fine scan over the chord before it and bisection, as brute_force_depth
    does after its own inside sample.  Returns (the earlier of the two per ray, how many rays
    moved)."""
    from pyjulia4d.geometry.camera import march_radius

    f = scene.fractal
    F = ref.formula_of(f)
    o, d = np.asarray(origins, np.float64), np.asarray(dirs, np.float64)
    t = np.asarray(t_inside, np.float64)
    out = np.array(truth, np.float64)
    near, far, live = ray_interval(o, d, march_radius(scene) if radius is None else radius)
    with np.errstate(invalid="ignore"):
        k = np.nonzero(live & np.isfinite(t) & (t < out) & (t >= near) & (t <= far))[0]
    if k.size:
        k = k[ref.julia_inside(o[k] + t[k, None] * d[k], f.c, f.max_iter, f.bailout, F)]
    if k.size == 0:
        return out, 0
    inside = lambda p: ref.julia_inside(p, f.c, f.max_iter, f.bailout, F)  # noqa: E731
    out[k] = np.minimum(out[k], _crossing_before(inside, o[k], d[k], np.maximum(t[k] - chord, near[k]), t[k], fine))
    return out, int(k.size)
