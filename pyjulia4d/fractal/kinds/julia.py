"""The Julia set itself (fractal.kind = "julia"): the orbit of each point p under
q -> f(q) + c (Hart, Sandin & Kauffman 1989 §2), iterate.cl's own set test."""
from __future__ import annotations

from typing import Any

from pyjulia4d.fractal.registry import escape_degree
from pyjulia4d.geometry.bounds import bounding_radius


def defines(scene: Any) -> tuple[str, ...]:
    return ()


def set_radius(scene: Any) -> float:
    """The escape bound of q^D + c (geometry/bounds.bounding_radius), or the bailout sphere
    where f is no polynomial."""
    f = scene.fractal
    return bounding_radius(f.c, f.bailout, f.max_iter, escape_degree(f))


def check(scene: Any) -> None:
    """No rules of its own: the pair's are scene/rules.check_fractal's."""
