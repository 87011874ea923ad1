"""``pyjulia4d mesh``: the scene's 3D slice of the set as a triangle mesh, for 3D printing
and Blender (STL, PLY, OBJ, glTF binary).

1. The grid of the mesh plan (pipeline/mesh_plan.py) is sampled by the kernel mesh_sample
   (kernels/mesh/mesh.cl) a block of z-layers at a time, with the set's own inside test.
2. Marching cubes (PyMCubes; Lorensen & Cline 1987) runs on each block with the layer before
   it, so only two blocks are held at once; vertices shared across blocks are merged.
3. Every vertex lies on a grid edge whose ends differ; mesh_vertices moves it onto the
   surface: the set's crossing refined by ITP on the level function (march/refine.cl), or the
   bounding ball's sphere where the ball cuts the set - so the mesh is not staircased, and
   it is closed.
4. trimesh orients it outwards, computes vertex normals, optionally smooths it (Taubin's
   lambda|mu filter, which keeps the volume), optionally decimates it (quadric error metrics,
   through fast-simplification), colours its vertices as the render colours its
   hits (shading.coloring: flat, iteration, trap, w) and writes it, atomically; STL carries
   no colour, PLY, OBJ and glTF do.

The mesh is in the slice's own 3D coordinates (the scene units the camera sees)."""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from pyjulia4d.pipeline.mesh_plan import MeshPlan, make_mesh_plan
from pyjulia4d.scene.checks import SceneError, show
from pyjulia4d.scene.model import Scene

FORMATS = {".stl": "stl", ".ply": "ply", ".obj": "obj", ".glb": "glb"}
MAX_SMOOTH = 1000
# iterations a second the sampling is assumed to reach for the work estimate: below what
# benchmarks/speed/mesh_scale.py measured on this project's 2-core CPU, so the estimate errs long
ESTIMATE_RATE = 3e8
WARN_SECONDS, REFUSE_SECONDS = 120.0, 6 * 3600.0
# thinnest_wall: grid points within this many spacings of the outside are measured exactly in a
# slab of layers with this margin, so walls up to 2 WALL_MARGIN - 1 spacings thick are found
WALL_MARGIN = 16
MAX_WALL_RESOLUTION = 1024    # the whole inside mask is kept: n^3 bytes


@dataclass
class MeshResult:
    """The mesh and what making it cost and found."""
    mesh: Any                    # trimesh.Trimesh, slice coordinates
    plan: MeshPlan
    inside_points: int           # grid points inside (the voxel count of the set on the grid)
    widest_bracket: float        # the widest vertex bracket (slice units)
    seconds: dict = field(default_factory=dict)   # "sample", "cubes", "vertices", "finish", "total"
    # thinnest_wall's (thickness, where (x, y, z)), or (bound, None): no wall thinner than bound;
    # None where not asked for
    wall: tuple | None = None
    moved: float = 0.0           # the farthest smoothing moved a vertex off its bracket (slice units)
    decimated: bool = False      # vertices placed by decimation: no longer on the brackets

    @property
    def voxel_volume(self) -> float:
        """The set's volume by counting grid points: inside points times h^3."""
        return self.inside_points * self.plan.spacing ** 3

    def summary(self) -> str:
        m = self.mesh
        vol = f"volume {m.volume:.6g} (grid count {self.voxel_volume:.6g})" if m.is_watertight else "not watertight"
        wall = ""
        if self.wall is not None:
            thick, where = self.wall
            h = self.plan.spacing
            wall = (f"; no wall thinner than {thick:.3g}" if where is None else
                    f"; thinnest wall about {thick:.3g} (to within 3 grid spacings, {3 * h:.2g}) at "
                    f"({where[0]:.4g}, {where[1]:.4g}, {where[2]:.4g})")
        if self.decimated:
            where = "vertices placed by decimation (their distance from the surface is not bounded)"
        elif self.moved > 0:
            where = (f"vertices within {self.widest_bracket + self.moved:.2g} of the surface (bracketed to "
                     f"{self.widest_bracket:.2g}, then moved up to {self.moved:.2g} by smoothing)")
        else:
            where = f"vertices within {self.widest_bracket:.2g} of the surface"
        return (f"{len(m.faces)} triangles, {len(m.vertices)} vertices, {vol}, {where}, grid {self.plan.n}^3 "
                f"at spacing {self.plan.spacing:.4g}{wall}")


def estimate_seconds(plan: MeshPlan) -> float:
    """A long-side estimate of the sampling's time: every grid point iterated max_iter times."""
    return plan.n ** 3 * plan.max_iter / ESTIMATE_RATE


def check_mesh_path(path: str | Path) -> Path:
    """An output path for a mesh: its format (.stl, .ply, .obj, .glb) and the checks of an
    image path (a temp file really made beside it: app/output.check_output_path)."""
    from pyjulia4d.app.output import check_output_path

    return check_output_path(path, tuple(FORMATS), "mesh")


def check_walls(walls: bool, resolution: int) -> None:
    """--walls keeps the whole grid: refused past MAX_WALL_RESOLUTION points a side."""
    if walls and resolution > MAX_WALL_RESOLUTION:
        raise SceneError("--walls", f"measured on grids up to {MAX_WALL_RESOLUTION}^3 (the whole grid is kept); "
                                    f"got {resolution}^3")


def check_smooth(value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= MAX_SMOOTH:
        raise SceneError("--smooth", f"expected a whole number of smoothing passes in [0, {MAX_SMOOTH}], "
                                     f"got {show(value, 80)}")
    return value


MAX_SIZE_MM = 1e5   # a 100 m print is no print


def check_size(value: Any) -> float | None:
    """--size: the printed length of the mesh's longest side in millimetres, (0, MAX_SIZE_MM];
    None keeps scene units."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 < value <= MAX_SIZE_MM:
        raise SceneError("--size", f"expected the longest side in millimetres, in (0, {MAX_SIZE_MM:g}], "
                                   f"got {show(value, 80)}")
    return float(value)


def check_decimate(value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 < value <= 1.0:
        raise SceneError("--decimate", f"expected the share of triangles to keep, in (0, 1], got {show(value, 80)}")
    return float(value)


def thinnest_wall(mask: np.ndarray, plan: MeshPlan) -> tuple[float, np.ndarray | None]:
    """The thinnest wall of the set on the grid, for printing: the local thickness of Hildebrand
    and Ruegsegger (the diameter of the largest ball inside the set about each point of its
    medial ridge), from the Euclidean distance transform of the inside ``mask`` [k, j, i].

    Each inside point's distance e to the nearest outside point, in grid spacings; on the
    ridge (points where e is a local maximum) a wall is about 2 e - 1 spacings thick: exact for
    a slab an odd number of points thick, one less for an even one; the surface between two
    grid points and a ridge point off the true medial axis (by up to half a cell's diagonal)
    put it within 3 spacings of the true thickness.  The distance is taken a
    slab of layers at a time with WALL_MARGIN layers on each side, exact up to WALL_MARGIN.
    Returns (thickness, (x, y, z)) in scene units, or (bound, None) where no wall is thinner
    than the bound, (2 WALL_MARGIN - 1) h.  Parts thinner than the spacing are not on the grid."""
    from scipy import ndimage

    n, h = mask.shape[0], plan.spacing
    slab = max(1, (1 << 22) // (n * n))
    best, where = math.inf, None
    for k0 in range(0, n, slab):
        lo, hi = max(0, k0 - WALL_MARGIN), min(n, k0 + slab + WALL_MARGIN)
        edt = ndimage.distance_transform_edt(mask[lo:hi])
        ridge = (edt == ndimage.maximum_filter(edt, size=3)) & (edt > 0) & (edt <= WALL_MARGIN)
        core = slice(k0 - lo, k0 - lo + min(slab, n - k0))
        e = np.where(ridge[core], edt[core], np.inf)
        k = int(np.argmin(e))
        if e.flat[k] < best:
            best = float(e.flat[k])
            kk, j, i = np.unravel_index(k, e.shape)
            where = plan.to_slice(np.array([i, j, kk + k0], float))
    if where is None:
        return (2 * WALL_MARGIN - 1) * h, None
    return (2 * best - 1) * h, where


def build_mesh(scene: Scene, resolution: int = 128, device: Any = None, smooth: int = 0, force: bool = False,
               progress: bool = False, executor: str = "opencl", warn: Callable[[str], None] | None = None,
               decimate: float = 1.0, walls: bool = False) -> MeshResult:
    """The mesh of ``scene`` on a grid of ``resolution`` points a side (see the module's
    docstring).  ``executor`` "reference" runs the float64 twins (small grids only).  Work
    estimated past REFUSE_SECONDS is refused unless ``force``; past WARN_SECONDS ``warn`` is
    told.  ``decimate`` below 1 keeps that share of the triangles (quadric decimation,
    fast-simplification through trimesh; it may open the mesh: summary() says whether it is
    watertight).  ``walls``: also the thinnest wall (thinnest_wall; grids up to
    MAX_WALL_RESOLUTION, whose whole mask is kept)."""
    import mcubes
    import trimesh

    from pyjulia4d.pipeline.plan import check_flag
    from pyjulia4d.pipeline.progress import Progress

    t0 = time.perf_counter()
    for name, value in (("force", force), ("progress", progress), ("walls", walls)):
        check_flag(name, value)
    if warn is not None and not callable(warn):
        raise SceneError("warn", f"expected None or a callable, got {type(warn).__name__}")
    smooth = check_smooth(smooth)
    decimate = check_decimate(decimate)
    plan = make_mesh_plan(scene, resolution)
    check_walls(walls, plan.n)
    est = estimate_seconds(plan)
    if est > REFUSE_SECONDS and not force:
        raise SceneError("--resolution", f"{plan.n}^3 grid points at max_iter {plan.max_iter}: about "
                                         f"{est / 3600:.0f} h of sampling; lower it, or --force")
    if est > WARN_SECONDS and warn is not None:
        warn(f"about {est / 60:.0f} min of sampling ({plan.n}^3 grid points at max_iter {plan.max_iter})")
    sample, vertices = _executor(plan, device, executor)
    seconds = {"sample": 0.0, "cubes": 0.0}
    parts_v, parts_f, count, prev = [], [], 0, None
    mask = np.empty((plan.n,) * 3, np.uint8) if walls else None
    with Progress(plan.n, "mesh", "layer", enabled=progress) as bar:
        for k0 in range(0, plan.n, plan.block):
            nk = min(plan.block, plan.n - k0)
            t = time.perf_counter()
            block = sample(k0, nk)
            seconds["sample"] += time.perf_counter() - t
            if mask is not None:
                mask[k0:k0 + nk] = block
            count += int(np.count_nonzero(block))
            t = time.perf_counter()
            vol = block if prev is None else np.concatenate([prev[None], block])
            start = k0 if prev is None else k0 - 1
            if vol.shape[0] >= 2:
                v, f = mcubes.marching_cubes(vol, 0.5)
                if len(f):
                    v[:, 0] += start
                    parts_f.append(f.astype(np.int64) + sum(len(p) for p in parts_v))
                    parts_v.append(v)
            prev = block[-1]
            seconds["cubes"] += time.perf_counter() - t
            bar.update(nk)
    t = time.perf_counter()
    if not parts_v:
        cut = ", or clip.planes that keep more of it" if scene.clip.planes else ""
        raise SceneError("scene", f"the slice of the set holds no grid point of a {plan.n}^3 grid: nothing to "
                                  f"mesh (a finer --resolution, or another slice{cut})")
    # (k, j, i) -> (i, j, k); vertices on shared layers merge (exact halves: no tolerance needed)
    grid = trimesh.Trimesh(np.concatenate(parts_v)[:, ::-1], np.concatenate(parts_f), process=True)
    gv = np.asarray(grid.vertices)
    axis = np.argmax(np.abs(gv - np.round(gv)) > 0.25, axis=1)    # the coordinate at a half
    lo = gv.copy()
    lo[np.arange(len(gv)), axis] = np.floor(gv[np.arange(len(gv)), axis])
    hi = lo.copy()
    hi[np.arange(len(gv)), axis] += 1.0
    world, width, inner = vertices(plan.to_world(lo), plan.to_world(hi))
    seconds["vertices"] = time.perf_counter() - t
    t = time.perf_counter()
    # world points -> the slice's coordinates: x = axes (p - offset), axes orthonormal
    xyz = (world - plan.offset) @ plan.axes.T
    mesh = trimesh.Trimesh(xyz, np.asarray(grid.faces), process=False)
    if mesh.is_watertight and mesh.volume < 0:
        mesh.invert()
    moved = 0.0
    if smooth:
        before = np.array(mesh.vertices)
        trimesh.smoothing.filter_taubin(mesh, iterations=smooth)
        moved = float(np.max(np.linalg.norm(np.asarray(mesh.vertices) - before, axis=1))) if len(before) else 0.0
    if decimate < 1.0:   # new vertices: coloured at themselves (within h of the surface)
        keep = round(len(mesh.faces) * decimate)
        if keep < 4:   # a tetrahedron's: fewer closes nothing (1e-300 wrote an empty file)
            raise SceneError("--decimate", f"{decimate:g} of the mesh's {len(mesh.faces)} triangles keeps {keep}, "
                                           f"fewer than the 4 of the least closed surface; keep a larger share")
        mesh = mesh.simplify_quadric_decimation(percent=1.0 - decimate)
        world = inner = np.asarray(mesh.vertices) @ plan.axes + plan.offset
    mesh.visual.vertex_colors = vertex_colours(scene, world, inner)
    seconds["finish"] = time.perf_counter() - t
    widest = float(np.max(width)) if len(width) else 0.0
    wall = None
    if mask is not None:
        t = time.perf_counter()
        wall = thinnest_wall(mask, plan)
        seconds["walls"] = time.perf_counter() - t
    seconds["total"] = time.perf_counter() - t0
    return MeshResult(mesh, plan, count, widest, seconds, wall, moved, decimate < 1.0)


def _executor(plan: MeshPlan, device: Any, executor: str):
    """(sample(k0, nk), vertices(a, b)) of the OpenCL kernels or of their float64 twins."""
    if not isinstance(executor, str) or executor not in ("opencl", "reference"):
        raise SceneError("executor", f"expected 'opencl' or 'reference', got {show(executor, 80)}")
    if executor == "reference":
        from pyjulia4d.reference import mesh as twin

        return (lambda k0, nk: twin.mesh_sample(plan, k0, nk)), (lambda a, b: twin.mesh_vertices(plan, a, b))
    from pyjulia4d.opencl.devices import device_of
    from pyjulia4d.opencl.mesh import MeshRunner

    runner = MeshRunner(plan, device_of(device))
    return runner.sample, runner.vertices


def colouring_values(scene: Scene, world: np.ndarray, inner: np.ndarray) -> np.ndarray | None:
    """The colour map's value at each vertex, as the render takes it at a hit
    (kernels/shade/light.cl): the smooth time in the unit ball or the orbit trap of the bracket's
    inside end ``inner``, or w over [-R/2, R/2] at the vertex ``world``; computed by the float64
    twins (reference/shade.py).  None for the "flat" colouring."""
    from pyjulia4d.geometry.camera import march_radius, to_world
    from pyjulia4d.reference.formula import formula_of
    from pyjulia4d.reference.shade import orbit_iteration, orbit_trap

    sh, f = scene.shading, scene.fractal
    F = formula_of(f)
    if sh.coloring == "iteration":
        return orbit_iteration(inner, f.c, f.max_iter, f.bailout, F)
    if sh.coloring == "trap":
        return orbit_trap(inner, f.c, f.max_iter, f.bailout, to_world(scene, sh.trap), F)
    if sh.coloring == "w":
        return np.clip(0.5 + world[:, 3] / march_radius(scene), 0.0, 1.0)
    return None


def vertex_colours(scene: Scene, world: np.ndarray, inner: np.ndarray) -> np.ndarray:
    """(m, 4) uint8 sRGB colours of the vertices, as the render colours a hit (shade/shade.cl):
    shading.color for "flat", else the colour map at colouring_values."""
    from pyjulia4d.pipeline.colormap import linear_to_srgb, lookup, spec_of, table_of

    val = colouring_values(scene, world, inner)
    if val is None:
        base = np.broadcast_to(np.asarray(scene.shading.color, np.float64), (len(world), 3))
    else:
        base = lookup(table_of(spec_of(scene.shading)).astype(np.float64), val)
    rgb = np.rint(linear_to_srgb(np.clip(base, 0.0, 1.0)) * 255)
    return np.concatenate([rgb, np.full((len(world), 1), 255.0)], axis=1).astype(np.uint8)


# the length a file's unit stands for: STL, PLY and OBJ have none and slicers read millimetres;
# glTF's is the metre
UNIT_MM = {"stl": 1.0, "ply": 1.0, "obj": 1.0, "glb": 1000.0}


def write_mesh(path: str | Path, result: MeshResult, size_mm: float | None = None) -> str:
    """The mesh in the format of ``path``'s suffix, atomically (files.atomic_write); the path
    checked first (check_mesh_path).  ``size_mm``: scaled so that its longest side prints at
    that many millimetres (in the file's unit: millimetres, metres for .glb).  Returns what
    the scale is, for the closing line ("" in scene units)."""
    from pyjulia4d.app.output import OutputError, write_file

    path = check_mesh_path(path)
    if not isinstance(result, MeshResult):
        raise OutputError(f"{path}: expected a MeshResult to write, got {type(result).__name__}")
    size_mm = check_size(size_mm)
    kind = FORMATS[path.suffix.lower()]
    mesh, said = result.mesh, ""
    if size_mm is not None:
        longest = float(np.max(mesh.extents)) if len(mesh.vertices) else 0.0
        if not longest > 0:
            raise SceneError("--size", "the mesh has no extent to scale")
        mm_per_unit = size_mm / longest
        mesh = mesh.copy()
        mesh.apply_scale(mm_per_unit / UNIT_MM[kind])
        said = (f"; scaled to {size_mm:g} mm along its longest side (1 scene unit = {mm_per_unit:.4g} mm"
                f"{', in metres: glTF' if kind == 'glb' else ''})")
        if result.wall is not None and result.wall[1] is not None:
            said += f", thinnest wall about {result.wall[0] * mm_per_unit:.3g} mm"
    # vertex normals where the format has them (trimesh writes them only when asked)
    extra = {"ply": {"vertex_normal": True}, "obj": {"include_normals": True},
             "glb": {"include_normals": True}}.get(kind, {})
    write_file(path, mesh.export(file_type=kind, **extra))
    return said
