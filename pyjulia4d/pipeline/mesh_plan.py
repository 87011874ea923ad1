"""The plan of a mesh: the grid the scene's 3D slice of the set is sampled on, in plain
records the mesh kernels (kernels/mesh/mesh.cl) and their float64 twin (reference/mesh.py)
both take.  No OpenCL here.

The grid covers the ball's section by the slice: the bounding ball |p| <= R about the world
origin (geometry/camera.py set_radius) meets the slice's hyperplane, at distance d from the
origin, in a 3D ball of radius r = sqrt(R^2 - d^2) about the slice's own origin.  The grid
spans [-r - h, r + h] on each axis, N points a side, spacing h = 2 r / (N - 3): its outermost
layer lies outside the ball, so the mesh is closed where the ball cuts the set.  The clip
planes cut it as they cut the render (kernels/mesh/mesh.cl, CLIP): a flat face where one
crosses the set, a base to print on."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pyjulia4d.geometry.camera import clip_planes, set_radius, slice_map
from pyjulia4d.pipeline.kernel_config import KernelConfig, mesh_config
from pyjulia4d.pipeline.records import ClipArgs
from pyjulia4d.scene.checks import SceneError, show
from pyjulia4d.scene.model import Scene

MIN_RESOLUTION, MAX_RESOLUTION = 8, 2048   # grid points a side (--resolution)
BLOCK_POINTS = 1 << 24                     # grid points sampled per kernel launch
# set tests refining each vertex: its bracket is then at most h / 2^REFINE_STEPS wide, below
# float32's resolution of the coordinates for any grid up to MAX_RESOLUTION
REFINE_STEPS = 24


@dataclass(frozen=True)
class MeshPlan:
    """The grid and the fractal's constants, as the kernels take them."""
    scene: Scene
    n: int                 # grid points a side
    origin: tuple          # (x, y, z) of grid point (0, 0, 0), slice coordinates
    spacing: float         # h
    axes: np.ndarray       # (3, 4): the world directions of the slice's x, y, z (rx, ry, rz)
    offset: np.ndarray     # (4,): the world point of the slice's origin
    radius: float          # the bounding ball's, in the world
    c: tuple
    max_iter: int
    bailout: float
    steps: int
    config: KernelConfig
    block: int             # z-layers a launch samples
    clip: ClipArgs = ClipArgs(())   # the clip planes in the world, as the render's (records.ClipArgs)

    @property
    def double(self) -> bool:
        return self.scene.precision == "double"

    # the kernels' names for what they take (pipeline/signatures.py MESH_SAMPLE, MESH_VERTICES)
    origin4 = property(lambda self: tuple(self.origin) + (0.0,))
    rx = property(lambda self: self.axes[0])
    ry = property(lambda self: self.axes[1])
    rz = property(lambda self: self.axes[2])
    radius2 = property(lambda self: self.radius ** 2)

    def to_world(self, ijk: np.ndarray) -> np.ndarray:
        """World points (..., 4) of grid coordinates (..., 3) (i, j, k; fractional allowed)."""
        xyz = np.asarray(self.origin) + self.spacing * np.asarray(ijk, float)
        return xyz @ self.axes + self.offset

    def to_slice(self, ijk: np.ndarray) -> np.ndarray:
        """Slice coordinates (x, y, z) of grid coordinates: the mesh's own units."""
        return np.asarray(self.origin) + self.spacing * np.asarray(ijk, float)


def check_resolution(value) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not MIN_RESOLUTION <= value <= MAX_RESOLUTION:
        raise SceneError("--resolution", f"expected a whole number of grid points a side in "
                                         f"[{MIN_RESOLUTION}, {MAX_RESOLUTION}], got {show(value, 80)}")
    return value


def make_mesh_plan(scene: Scene, resolution: int) -> MeshPlan:
    """The grid of ``resolution`` points a side over the ball's section by the slice."""
    if not isinstance(scene, Scene):
        raise SceneError("scene", f"expected a pyjulia4d.Scene, got {type(scene).__name__}")
    n = check_resolution(resolution)
    if scene.render.float == "auto":   # "auto" is for the proven march's proofs; the mesh samples the set test
        scene = scene.replace(**{"render.float": "single"})
    f = scene.fractal
    radius = set_radius(scene)   # the set's ball (the estimate march's shell is no part of the set)
    d = float(scene.slice.distance)
    if abs(d) >= radius:
        raise SceneError("slice.distance", f"{d!r} is outside the set's bounding ball (radius {radius:.4g}): "
                                           f"the slice holds nothing to mesh")
    r = math.sqrt(radius * radius - d * d)
    h = 2.0 * r / (n - 3)
    rot, offset = slice_map(scene)
    return MeshPlan(scene=scene, n=n, origin=(-r - h,) * 3, spacing=h, axes=rot[:, :3].T.copy(),
                    offset=offset, radius=radius, c=tuple(f.c), max_iter=f.max_iter,
                    bailout=f.bailout, steps=REFINE_STEPS, config=mesh_config(scene),
                    block=max(1, min(n, BLOCK_POINTS // (n * n))), clip=ClipArgs(tuple(clip_planes(scene))))
