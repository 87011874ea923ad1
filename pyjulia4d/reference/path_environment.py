"""Twin of kernels/path/environment.cl in float64 numpy: shading.environment's image looked
up nearest and sampled by its light (pipeline/environment.py has the layout and the
distribution), over arrays of 4D directions."""
from __future__ import annotations

import numpy as np

from pyjulia4d.pipeline.environment import Environment

PI = np.pi


class EnvTwin:
    """The environment of a plan's PathArgs (its image and the scene's axes in 4D)."""

    def __init__(self, env: Environment, ex, ey, ez):
        self.e = env
        self.ax = np.array([ex, ey, ez], np.float64)   # (3, 4)

    def texel(self, d):
        """(row, col, sin(theta)) of 4D directions d (n, 4) (env_texel)."""
        s = d @ self.ax.T
        length = np.linalg.norm(s, axis=1)
        k = np.where(length > 0, 1 / np.where(length > 0, length, 1), 0.0)
        y = np.clip(s[:, 1] * k, -1, 1)
        u = (np.arctan2(s[:, 0] * k, -s[:, 2] * k) + PI) * (0.5 / PI)
        v = np.arccos(y) / PI
        col = np.clip((u * self.e.width).astype(int), 0, self.e.width - 1)
        row = np.clip((v * self.e.height).astype(int), 0, self.e.height - 1)
        return row, col, np.sqrt(np.maximum(1 - y * y, 0))

    def pdf(self, d):
        row, col, st = self.texel(d)
        e = self.e
        p = (e.marginal[row + 1] - e.marginal[row]) * (e.conditional[row, col + 1] - e.conditional[row, col])
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(st > 0, p * (e.width * e.height) / (2 * PI * PI * st), 0.0)

    def radiance(self, d):
        row, col, _ = self.texel(d)
        return self.e.image[row, col, :3].astype(np.float64)

    def sample(self, u1, u2):
        """4D directions drawn by (u1, u2) (env_sample)."""
        e = self.e
        row = np.clip(np.searchsorted(e.marginal, u1, side="right") - 1, 0, e.height - 1)
        fr = (u1 - e.marginal[row]) / np.maximum(e.marginal[row + 1] - e.marginal[row], np.finfo(float).tiny)
        c = e.conditional[row]
        col = np.clip((c <= u2[:, None]).sum(axis=1) - 1, 0, e.width - 1)
        lo, hi = c[np.arange(len(row)), col], c[np.arange(len(row)), col + 1]
        fc = (u2 - lo) / np.maximum(hi - lo, np.finfo(float).tiny)
        theta = PI * (row + np.clip(fr, 0, 1)) / e.height
        phi = 2 * PI * (col + np.clip(fc, 0, 1)) / e.width - PI
        st = np.sin(theta)
        return (st * np.sin(phi))[:, None] * self.ax[0] + np.cos(theta)[:, None] * self.ax[1] \
            - (st * np.cos(phi))[:, None] * self.ax[2]
