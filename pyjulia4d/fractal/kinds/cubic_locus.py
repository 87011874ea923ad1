"""The cubic connectedness locus (fractal.kind = "cubic_locus", Hart, Sandin & Kauffman 1989
§5.2): the (a, b) whose cubic z^3 - 3 a^2 z + b keeps the orbit of a critical point +a or -a
bounded (kernels/kind/cubic_locus.cl)."""
from __future__ import annotations

from typing import Any

from pyjulia4d.fractal.registry import locus_escape_radius
from pyjulia4d.fractal.kinds.own_map import check_own_map
from pyjulia4d.scene.checks import SceneError


def defines(scene: Any) -> tuple[str, ...]:
    """KIND_CUBIC_LOCUS; the critical point followed (+a or -a) and the ball drawn."""
    f = scene.fractal
    return ("KIND_CUBIC_LOCUS", f"LOCUS_SIGN={1 if f.component == 'plus' else -1}", f"LOCUS_R2={f.locus_radius ** 2!r}")


def set_radius(scene: Any) -> float:
    """The ball |p| <= locus_radius the piece draws within, widened by 2^-20 so that a scan
    starts outside."""
    return scene.fractal.locus_radius * (1.0 + 2.0 ** -20)


def check(scene: Any) -> None:
    """fractal.kind = "cubic_locus": the complex cubic only, no rotation, no orbit colouring,
    no estimate (fixed scan, Jacobian or zbuffer normals), and a bailout that is an escape
    radius for every map in the ball, so that the truncated set tends to the locus."""
    f, m = scene.fractal, scene.march
    check_own_map(scene, "the complex cubic z^3 - 3 a^2 z + b", "the cubic locus", "the cubic locus's")
    if m.method == "de" and m.quality == "custom":   # a preset's de: refused by name below
        raise SceneError("march.method", "no distance estimate is known for the cubic connectedness locus "
                         "(Hart, Sandin & Kauffman 1989 section 5.2); use fixed or auto")
    if scene.normals.method == "gradient":
        raise SceneError("normals.method", "gradient differences a distance estimate, which the cubic locus "
                         "has none of; use jacobian or zbuffer")
    need = locus_escape_radius(f.locus_radius)
    if f.bailout < need:
        raise SceneError("fractal.bailout", f"{f.bailout!r} is below the escape radius {need:.4g} of the cubic "
                         f"maps within fractal.locus_radius={f.locus_radius!r}: set at least that")
