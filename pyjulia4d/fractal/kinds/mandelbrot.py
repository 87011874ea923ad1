"""The Mandelbrot set of the map (fractal.kind = "mandelbrot"): the c whose orbit of f's one
critical or asymptotic value v stays bounded, q_1 = v + c (kernels/kind/mandelbrot.cl;
Quilez 2002 traces it with the Julia sets' primitive)."""
from __future__ import annotations

from typing import Any

import numpy as np

from pyjulia4d.fractal.registry import MANDELBROT_START, escape_degree
from pyjulia4d.geometry.bounds import mandelbrot_radius
from pyjulia4d.scene.checks import SceneError


def defines(scene: Any) -> tuple[str, ...]:
    """KIND_MANDELBROT (normals/jacobian.cl, shade/light.cl), and v where it is not 0."""
    f = scene.fractal
    out = ("KIND_MANDELBROT",)
    if any(MANDELBROT_START[f.function]):   # q_1 = v + c (kind/mandelbrot.cl)
        out += tuple(f"MANDEL_V_{a}={v!r}" for a, v in zip("XYZW", MANDELBROT_START[f.function]))
    return out


def set_radius(scene: Any) -> float:
    """The escape bound of the critical orbit (geometry/bounds.mandelbrot_radius)."""
    f = scene.fractal
    return mandelbrot_radius(f.bailout, f.max_iter, escape_degree(f), float(np.linalg.norm(MANDELBROT_START[f.function])))


def check(scene: Any) -> None:
    """A function with one critical or asymptotic value; pwr with a critical point at 0; no
    rotation (it leaves the set unchanged)."""
    f = scene.fractal
    if f.function not in MANDELBROT_START:
        raise SceneError("fractal.kind", f"mandelbrot follows the orbit of f's one critical or asymptotic "
                         f"value; {f.function} has several or none: use one of "
                         f"{', '.join(MANDELBROT_START)}")
    if f.function == "pwr" and f.exponent[0] <= 1:
        raise SceneError("fractal.exponent", f"mandelbrot with pwr needs a critical point at 0, "
                         f"real part above 1, got {f.exponent[0]!r}")
    if f.theta != 0:
        raise SceneError("fractal.theta", "the rotation leaves a Mandelbrot set unchanged (its orbits are "
                         "the unrotated ones times e^(i theta)): set 0")
