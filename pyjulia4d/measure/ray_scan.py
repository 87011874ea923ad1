"""Scans along rays in float64, for the ground-truth oracles (truth.py, brute_force.py): the
interval of each ray through a ball, the first inside sample of a scan, and bisection of a
crossing to float64 resolution."""
from __future__ import annotations

import numpy as np


def ray_interval(o, d, radius):
    b = np.sum(o * d, -1)
    disc = b * b - (np.sum(o * o, -1) - radius ** 2)
    s = np.sqrt(np.maximum(disc, 0.0))
    near = np.maximum(-b - s, 0.0)
    far = -b + s
    live = (disc >= 0) & (far >= near)
    return near, far, live


def first_inside(inside_fn, o, d, near, far, n_scan, chunk=512):
    """Index of the first sample t_i = near + i (far - near)/n_scan, i = 0..n_scan,
    for which inside_fn is true; -1 if none.  Vectorised over rays, in chunks of
    samples, so rays that hit stop early."""
    n = len(o)
    first = np.full(n, -1, np.int64)
    h = (far - near) / n_scan
    active = np.arange(n)
    for i0 in range(0, n_scan + 1, chunk):
        if active.size == 0:
            break
        i = np.arange(i0, min(i0 + chunk, n_scan + 1))
        t = near[active, None] + i[None, :] * h[active, None]
        p = o[active, None, :] + t[..., None] * d[active, None, :]
        ins = inside_fn(p)
        got = ins.any(1)
        first[active[got]] = i0 + np.argmax(ins[got], 1)
        active = active[~got]
    return first


def bisect(inside_fn, o, d, t_out, t_in, steps=60):
    """Shrink brackets [t_out (outside), t_in (inside)] to float64 resolution."""
    t_out, t_in = t_out.copy(), t_in.copy()
    for _ in range(steps):
        mid = 0.5 * (t_out + t_in)
        ins = inside_fn(o + mid[:, None] * d)
        t_in = np.where(ins, mid, t_in)
        t_out = np.where(ins, t_out, mid)
    return t_in
