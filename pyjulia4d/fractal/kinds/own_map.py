"""The rules the kinds with a complex map of their own share (the registry's Kind.own_map: Julia
set stacks, the cubic locus): the quaternion square stands for the map in the scene's
algebra and function, and what follows the quaternion map - its rotation, the colourings
that follow its orbit - does not apply."""
from __future__ import annotations

from typing import Any

from pyjulia4d.scene.checks import SceneError


def check_own_map(scene: Any, map_text: str, the_set: str, its_orbit: str) -> None:
    """``map_text``: the map the kind iterates ("the complex square z^2 + c"); ``the_set`` and
    ``its_orbit``: how the messages name the set ("a Julia set stack", "a stack's")."""
    f = scene.fractal
    if f.algebra != "quaternion" or f.function != "sqr":
        raise SceneError("fractal.kind", f"{f.kind} iterates {map_text}: leave "
                         "fractal.algebra=quaternion and fractal.function=sqr")
    if f.theta != 0:
        raise SceneError("fractal.theta", f"the rotation is of the quaternion map, not of {the_set}: set 0")
    if scene.shading.coloring in ("iteration", "trap"):
        raise SceneError("shading.coloring", f"{scene.shading.coloring} follows the quaternion orbit of "
                         f"fractal.c, not {its_orbit}; use flat or w")
