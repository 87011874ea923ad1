"""The kernels' argument records: what each kernel takes besides its buffers, resolved from
the scene once, in float64 (pipeline/plan.py makes them; pipeline/signatures.py names which
field each kernel parameter takes).  The OpenCL executor casts them to the device's
precision in the order the kernel declares them; the float64 reference executes the same
records.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from pyjulia4d.pipeline import kernel_config
from pyjulia4d.geometry.camera import march_radius
from pyjulia4d.scene.model import Scene
from pyjulia4d.fractal.registry import march_method




@dataclass(frozen=True)
class MarchArgs:
    """march/march.cl's constants (and the reflected rays' march, shade/reflect.cl)."""
    c: tuple[float, float, float, float]
    max_iter: int
    bailout: float
    epsilon: float
    radius: float          # the bounding 4-ball (camera.march_radius)
    near: float            # march.near, or -1 for "the ball's entry"
    far: float             # march.far, or -1 for "the ball's exit"
    z_resolution: int
    post_steps: int
    max_steps: int
    method: str            # "fixed", "de" or "proven": march.method resolved (fractal/registry.march_method)
    refine: str
    cone: bool = False     # camera rays start where their block's cone reached (kernel_config.cone_start)


@dataclass(frozen=True)
class ClipArgs:
    """[clip]'s half-spaces in world space, as march.cl and march/clip.cl take them: up to
    four (normal, offset) pairs, the unused ones zero."""
    planes: tuple[tuple[np.ndarray, float], ...]

    @property
    def n_clip(self) -> int:
        return len(self.planes)

    def normal(self, k: int):
        return self.planes[k][0] if k < len(self.planes) else (0.0, 0.0, 0.0, 0.0)

    clip_n0 = property(lambda self: self.normal(0))
    clip_n1 = property(lambda self: self.normal(1))
    clip_n2 = property(lambda self: self.normal(2))
    clip_n3 = property(lambda self: self.normal(3))

    @property
    def clip_off(self) -> tuple[float, ...]:
        return tuple(self.planes[k][1] if k < len(self.planes) else 0.0 for k in range(4))


@dataclass(frozen=True)
class NormalsArgs:
    method: str            # "jacobian", "gradient" or "zbuffer"
    step: float            # the gradient's difference step (gradient_step), at least
    step_per_distance: float = 0.0   # times the hit's distance from the eye (normals.step = "pixel")


@dataclass(frozen=True)
class LightArgs:
    """shade/light.cl's numbers (light_parameters): shadow rays, occlusion, the orbit trap."""
    step: float
    max_steps: int
    bias: float
    softness: float
    ao_distance: float
    ao_strength: float
    trap: tuple[float, float, float, float]
    shadow: str            # the positioned light's shadows: "none", "hard" or "soft" (none for the light at the eye)
    extra_shadow: str      # shading.lights' shadows: "none" without them
    coloring: str          # shading.coloring: the colour value light.cl computes

    @property
    def used(self) -> bool:
        """Whether shade/light.cl has anything to compute (kernel_config.light_defines)."""
        return self.shadow != "none" or self.extra_shadow != "none" or self.ao_strength > 0 or self.coloring != "flat"


@dataclass(frozen=True)
class ShadeArgs:
    """shade/shade.cl's constants and shade/reflect.cl's colour."""
    light: np.ndarray      # the positioned light in world space, or the eye (what the kernels take)
    point_light: np.ndarray | None   # the positioned light, None for the light at the eye (-D LIGHT_POINT)
    color: tuple[float, ...]
    background: tuple[float, ...]
    light_color: tuple[float, ...]
    sky: tuple[float, ...]
    ambient: float
    diffuse: float
    specular: float
    shininess: float
    fog: float
    fog_start: float       # the eye's distance to the bounding ball (fog_start)
    reflection: float
    colormap: Any          # the colour table's spec (colormap.ColorSpec) where a colouring uses one, else None
    lights_geo: np.ndarray     # shading.lights (camera.extra_lights; one inert row where there are none)
    lights_rgb: np.ndarray
    n_lights: int = 0          # how many shading.lights there are
    light_radius: float = 0.0  # the path tracer's: shading.light_radius
    lights_size: np.ndarray | None = None   # and each of shading.lights' radius (one inert 0 where there are none)


def march_args(scene: Scene, radius: float | None = None, **changes) -> MarchArgs:
    """The march's record of ``scene`` (its bounding ball's ``radius``: camera.march_radius
    where None), with ``changes`` to its fields (the tests' and benchmarks' own settings)."""
    f, m = scene.fractal, scene.march
    args = MarchArgs(c=tuple(f.c), max_iter=f.max_iter, bailout=f.bailout, epsilon=m.epsilon,
                     radius=march_radius(scene) if radius is None else radius,
                     near=-1.0 if m.near == "auto" else float(m.near), far=-1.0 if m.far == "auto" else float(m.far),
                     z_resolution=m.z_resolution, post_steps=m.post_steps, max_steps=m.max_steps,
                     method=march_method(scene), refine=m.refine, cone=kernel_config.cone_start(scene))
    return dataclasses.replace(args, **changes) if changes else args
