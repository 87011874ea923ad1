"""4-vectors: unit vectors scaled safely, the 4D cross product, and the Gram-Schmidt frame
every 4D camera is built from (Ödegaard & Wennergren §4) - written once, for the
camera (geometry/camera.py), the scene's check of it (scene/rules.py) and keyframed
cameras (scene/keyframes.py)."""
from __future__ import annotations

import math

import numpy as np


class Degenerate(ValueError):
    """A frame vector with nothing left after Gram-Schmidt; ``which`` is "forward",
    "limbo" or "up"."""

    def __init__(self, which: str) -> None:
        super().__init__(which)
        self.which = which


def norm(v) -> float:
    return float(np.linalg.norm(np.asarray(v, float)))


def unit(v) -> np.ndarray:
    """v / |v| for a finite, non-zero v, divided by its largest component first: |v|
    neither overflows (1e300 components) nor underflows (1e-300 ones) on the way."""
    v = np.asarray(v, float)
    v = v / np.max(np.abs(v))
    return v / np.linalg.norm(v)


def unit_or_none(v, least: float = 1e-9) -> np.ndarray | None:
    """unit(v), or None where v is zero, not finite, or its norm after scaling by its
    largest component is at most ``least`` (a direction interpolated through zero)."""
    v = np.asarray(v, float)
    m = float(np.max(np.abs(v)))
    if not m > 0 or not math.isfinite(m):
        return None
    v = v / m
    n = float(np.linalg.norm(v))
    return v / n if n > least else None


def cross4(a, b, c) -> np.ndarray:
    """The 4D cross product of Ödegaard & Wennergren §4: a vector
    perpendicular to a, b and c (the signed cofactors of the 3x4 matrix [a; b; c])."""
    a1, a2, a3, a4 = a
    b1, b2, b3, b4 = b
    c1, c2, c3, c4 = c
    return np.array([
        a2 * (b4 * c3 - b3 * c4) + b2 * (a3 * c4 - a4 * c3) + c2 * (a4 * b3 - a3 * b4),
        a1 * (b3 * c4 - b4 * c3) + b1 * (a4 * c3 - a3 * c4) + c1 * (a3 * b4 - a4 * b3),
        a1 * (b4 * c2 - b2 * c4) + b1 * (a2 * c4 - a4 * c2) + c1 * (a4 * b2 - a2 * b4),
        a1 * (b2 * c3 - b3 * c2) + b1 * (a3 * c2 - a2 * c3) + c1 * (a2 * b3 - a3 * b2),
    ])


def _checked_unit(v: np.ndarray, which: str, tiny: float) -> np.ndarray:
    n = float(np.linalg.norm(v))
    if not n > tiny or not math.isfinite(n):
        raise Degenerate(which)
    return unit(v)


def orthonormalise(forward, limbo, up, tiny: float = 1e-9) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gram-Schmidt in the camera's order: forward; limbo made orthogonal to it; up made
    orthogonal to both.  Raises Degenerate naming the first vector whose remainder has a
    norm of at most ``tiny`` (or is not finite).  ``limbo`` and ``up`` are taken as given
    (unit vectors, for a threshold that means an angle)."""
    f = _checked_unit(np.asarray(forward, float), "forward", tiny)
    lv = np.asarray(limbo, float)
    lv = _checked_unit(lv - (lv @ f) * f, "limbo", tiny)
    uv = np.asarray(up, float)
    uv = _checked_unit(uv - (uv @ f) * f - (uv @ lv) * lv, "up", tiny)
    return f, lv, uv
