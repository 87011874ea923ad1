"""float64 twin of kernels/kind/rotate.cl: the rotated Julia set of
Hart, Sandin & Kauffman 1989 §2.3, f_theta(q) = u f(u^-1 q) + u c with u = e^(i theta), the
map conjugated by the rotation g(z) = u z of the complex plane (the seed's eqs. 5-6,
reconstructed)."""
from __future__ import annotations

import math

import numpy as np


def rot_left(q, co, si):
    """u q for u = co + si i (Hamilton product): the (1, i) and (j, k) pairs turned by theta."""
    x, y, z, w = np.moveaxis(np.asarray(q, np.float64), -1, 0)
    return np.stack([co * x - si * y, co * y + si * x, co * z - si * w, co * w + si * z], axis=-1)


def cos_sin(theta_degrees):
    t = math.radians(theta_degrees)
    return math.cos(t), math.sin(t)


def rot_f(q, c, theta, julia_f):
    """u (f(u^-1 q) + c); ``julia_f`` the unrotated map."""
    co, si = cos_sin(theta)
    return rot_left(julia_f(rot_left(q, co, -si), c), co, si)


def rot_f_jvp(q, h, theta, julia_f_jvp):
    """u f'(u^-1 q)[u^-1 h]."""
    co, si = cos_sin(theta)
    return rot_left(julia_f_jvp(rot_left(q, co, -si), rot_left(h, co, -si)), co, si)
