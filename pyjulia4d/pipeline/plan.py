"""A render's plan: the scene resolved once into everything its kernels need.

scene -> plan -> tiles -> image.  ``make_plan`` checks the arguments once (check_arguments),
the work and the memory (workload.py), and resolves the image, the 4D camera frame, the
bounding radius, the light, one record of numbers per stage (MarchArgs, ClipArgs,
NormalsArgs, LightArgs, ShadeArgs: what each kernel takes, pipeline/signatures.py), the kernel
configurations (kernel_config.py) and the tile list, and fixes which outputs are kept.  A
plan holds plain values (numbers, numpy vectors, records; the scene only as the result's
metadata), so it can be pickled and a tile of it executed anywhere the same kernels build;
opencl/passes.py executes it, and reference/executor.py in float64, each reading the plan
alone.
"""
from __future__ import annotations

import dataclasses
import numbers
from dataclasses import dataclass

import numpy as np

from pyjulia4d.pipeline import colormap, kernel_config, workload
from pyjulia4d.pipeline.records import ClipArgs, LightArgs, MarchArgs, NormalsArgs, ShadeArgs, march_args
from pyjulia4d.pipeline.path_plan import PathArgs, path_args, path_config, path_march_config, resolve_focus
from pyjulia4d.pipeline.workload import resolve_outputs
from pyjulia4d.geometry.camera import Frame, camera_frame, clip_planes, extra_lights, light_position, march_radius
from pyjulia4d.scene.checks import SceneError, show
from pyjulia4d.scene.model import Fractal, Image, Scene
from pyjulia4d.fractal.registry import has_distance_estimate, march_method

# Tiles of at most TILE x TILE pixels (plus a one-pixel halo for the Z-buffer normals,
# which difference neighbours): device memory stays under ~20 MB single / ~36 MB double
# per tile in flight (two are) at any image size, no launch runs for minutes, and the
# progress bar moves per tile; 262,144 work-items per launch still fill a large GPU.
TILE = 512


@dataclass(frozen=True)
class Tile:
    """Pixels [x0, x0 + w) x [y0, y0 + h) of the image, computed over the box
    (ax0, ay0, aw, ah): the tile with its halo, clipped to the image."""
    x0: int
    y0: int
    w: int
    h: int
    ax0: int
    ay0: int
    aw: int
    ah: int

    @property
    def n(self) -> int:
        """Items the kernels run over (the box's pixels)."""
        return self.aw * self.ah

    def own(self) -> tuple[slice, slice]:
        """The tile's own pixels within its box (rows, columns)."""
        return (slice(self.y0 - self.ay0, self.y0 - self.ay0 + self.h),
                slice(self.x0 - self.ax0, self.x0 - self.ax0 + self.w))

    def dst(self) -> tuple[slice, slice]:
        """The tile's pixels in the image (rows, columns)."""
        return slice(self.y0, self.y0 + self.h), slice(self.x0, self.x0 + self.w)

    def cone_blocks(self) -> tuple[int, int, int, int]:
        """(bx0, by0, bw, bh): the image's CONE_BLOCK-pixel blocks the box meets, first and count."""
        return cone_blocks(self.ax0, self.ay0, self.aw, self.ah)


CONE_BLOCK = 4   # pixels on a side of a cone's block (kernels/march/cone.cl CONE_BLOCK)


def cone_blocks(x0: int, y0: int, w: int, h: int) -> tuple[int, int, int, int]:
    """(bx0, by0, bw, bh) of the CONE_BLOCK x CONE_BLOCK blocks of the image (block (bx, by) holds
    pixels [CONE_BLOCK bx, CONE_BLOCK (bx + 1)) x ...) that pixels [x0, x0 + w) x [y0, y0 + h) meet:
    blocks are the image's, whatever the tile, so a pixel starts where it would in any tiling."""
    b = CONE_BLOCK
    bx0, by0 = x0 // b, y0 // b
    return bx0, by0, (x0 + w - 1) // b - bx0 + 1, (y0 + h - 1) // b - by0 + 1


def make_tiles(width: int, height: int, tile: int = TILE, halo: int = 0,
               region: tuple[int, int, int, int] | None = None) -> tuple[Tile, ...]:
    """The tiles of the image (or of its ``region`` = (x0, y0, w, h)), row by row, each with
    its halo box clipped to the image: a pixel's box holds the same neighbours however the
    image is cut, so a region renders exactly as the same pixels of the whole image."""
    rx, ry, rw, rh = region if region is not None else (0, 0, width, height)
    out = []
    for y0 in range(ry, ry + rh, tile):
        for x0 in range(rx, rx + rw, tile):
            w, h = min(tile, rx + rw - x0), min(tile, ry + rh - y0)
            ax0, ay0 = max(0, x0 - halo), max(0, y0 - halo)
            ax1, ay1 = min(width, x0 + w + halo), min(height, y0 + h + halo)
            out.append(Tile(x0, y0, w, h, ax0, ay0, ax1 - ax0, ay1 - ay0))
    return tuple(out)


def kernel_arguments(scene: Scene, frame: Frame, radius: float) -> dict:
    """The argument records of every kernel of ``scene`` (Plan's march, clip, normals,
    light_args, shade)."""
    sh = scene.shading
    lp = light_position(scene, frame)
    light = light_parameters(scene, radius)
    geo, rgb = extra_lights(scene, frame)
    point_light = not isinstance(sh.light, str)
    return dict(
        march=march_args(scene, radius),
        clip=ClipArgs(tuple(clip_planes(scene))),
        normals=NormalsArgs(scene.normals.method, *gradient_step(scene, frame)),
        # light.cl traces the positioned light's shadows (the light at the eye lights all it sees)
        light_args=LightArgs(**light, shadow=sh.shadow if point_light else "none",
                             extra_shadow=sh.shadow if sh.lights else "none", coloring=sh.coloring),
        shade=ShadeArgs(light=lp if lp is not None else frame.position, point_light=lp, color=tuple(sh.color),
                        background=tuple(sh.background), light_color=tuple(sh.light_color), sky=tuple(sh.sky),
                        ambient=sh.ambient, diffuse=sh.diffuse, specular=sh.specular, shininess=sh.shininess,
                        fog=sh.fog, fog_start=fog_start(frame.position, radius), reflection=sh.reflection,
                        colormap=colormap.spec_of(sh) if sh.coloring != "flat" else None, lights_geo=geo, lights_rgb=rgb,
                        n_lights=len(sh.lights), light_radius=sh.light_radius,
                        lights_size=np.array([lt.radius for lt in sh.lights] or [0.0])))


@dataclass(frozen=True)
class Plan:
    """A scene resolved into what its kernels need (see the module docstring).  The executors
    read the records alone; ``scene`` rides along as the result's metadata."""
    scene: Scene
    image: Image                  # the image's size and samples (scene.image)
    fractal: Fractal              # the set (scene.fractal): the float64 twin's formula
    frame: Frame
    march: MarchArgs
    clip: ClipArgs
    normals_args: NormalsArgs
    light_args: LightArgs
    shade: ShadeArgs
    double: bool
    lanes: int                    # rays per work-item of the march (lanes.lanes_for)
    outputs: frozenset[str]
    config: kernel_config.KernelConfig         # normals but the Jacobian, shading (kernel_config.shade_config)
    march_config: kernel_config.KernelConfig   # the march, the Jacobian normals, the light terms
    tiles: tuple[Tile, ...]
    estimate: workload.Estimate
    reflect_config: kernel_config.KernelConfig | None   # the reflected rays' march: given rays (shade/reflect.cl)
    halo: int                     # pixels around each tile computed for its Z-buffer normals (halo_for)
    region: tuple[int, int, int, int] = (0, 0, 0, 0)   # (x0, y0, w, h) rendered: the image or a part
    pairs: bool = False           # two packets per work-item of the march, where they apply (kernel_config.march_packets)
    path: PathArgs | None = None  # shading.integrator = "path": the path tracer's record (path_plan.py)
    path_config: kernel_config.KernelConfig | None = None   # its program (path_plan.path_config)
    path_march_config: kernel_config.KernelConfig | None = None   # its rays' march (path_plan.path_march_config)

    def records(self) -> dict:
        """The records kernels take their constants from, by the names pipeline/signatures.py
        gives them ("march.c")."""
        return {"camera": self.frame, "image": self.image, "march": self.march, "clip": self.clip,
                "normals": self.normals_args, "light": self.light_args, "shade": self.shade, "path": self.path}

    @property
    def passes(self) -> int:
        """Passes over every pixel: the centre, and image.samples colour passes (workload.passes);
        a path-traced render's samples are its path pass's (opencl/path.py), not these."""
        return 1 if self.path is not None else workload.passes(self.image.samples, self.outputs)

    @property
    def rays_per_pixel(self) -> int:
        """Rays marched per pixel at most: the passes, or the centre pass and per path sample a
        march of each bounce's rays and of its shadow rays (workload.rays_per_pixel)."""
        if self.path is None:
            return self.passes
        return 1 + self.path.samples * 2 * self.path.bounces

    @property
    def radius(self) -> float:
        """The march's bounding 4-ball (camera.march_radius), as the march takes it."""
        return self.march.radius

    @property
    def normals(self) -> bool:
        """Whether the normals kernel runs: for the normal output or for shading."""
        return bool({"normal", "color"} & self.outputs)

    def retile(self, side: int) -> "Plan":
        """The same plan in tiles of at most side x side pixels (calibrate.tile_side)."""
        return dataclasses.replace(self, tiles=make_tiles(self.image.width, self.image.height, side, self.halo,
                                                          self.region))

    @property
    def shades(self) -> bool:
        return "color" in self.outputs

    @property
    def light_terms(self) -> bool:
        """Whether shade/light.cl runs (shadows, ambient occlusion, a colour map): only for shading."""
        return self.shades and "shade/light" in self.march_config.pieces

    @property
    def reflects(self) -> bool:
        """Whether the mirror bounce runs (shading.reflection > 0; shade/reflect.cl): only for shading."""
        return self.shades and "shade/reflect" in self.config.pieces

    @property
    def march_packets(self) -> int:
        """Packets of rays a work-item of the march takes (kernel_config.march_packets)."""
        return kernel_config.config_packets(self.march_config)

    @property
    def light_packets(self) -> int:
        """Packets of rays a work-item of the light terms takes (kernel_config.light_packets)."""
        return kernel_config.config_light_packets(self.march_config)

    @property
    def normals_in_march_config(self) -> bool:
        """The Jacobian normals are built with the march, in its packets (kernel_config.march_config)."""
        return self.normals_args.method == "jacobian"


def halo_for(normals_method: str, outputs) -> int:
    """Pixels around each tile computed for its Z-buffer normals, which difference neighbours:
    one where the normals run (for the normal output or for shading), else none."""
    return 1 if normals_method == "zbuffer" and {"normal", "color"} & set(outputs) else 0


def check_region(scene: Scene, region) -> tuple[int, int, int, int] | None:
    """``region`` = (x0, y0, w, h) as ints, checked to lie in the image (None: the whole)."""
    if region is None:
        return None
    try:
        vals = list(region)
    except Exception:   # not iterable, or an object whose own iteration fails: not a region either way
        vals = []
    if len(vals) != 4 or not all(isinstance(v, numbers.Integral) and not isinstance(v, bool) for v in vals):
        raise SceneError("region", f"expected (x0, y0, width, height), whole numbers, got {show(region, 120)}")
    x0, y0, w, h = (int(v) for v in vals)
    W, H = scene.image.width, scene.image.height
    if not (0 <= x0 and 0 <= y0 and w >= 1 and h >= 1 and x0 + w <= W and y0 + h <= H):
        raise SceneError("region", f"{(x0, y0, w, h)} is not inside the {W}x{H} image")
    return x0, y0, w, h


LANE_COUNTS = (1, 4, 8, 16)   # rays per work-item of the march (opencl/lanes.py WIDTHS and one)
MAX_TILE = 8192               # a tile's side: device buffers grow with its square


def check_lanes(lanes) -> int:
    """``lanes``: one of LANE_COUNTS (an int, not a bool)."""
    if isinstance(lanes, bool) or not isinstance(lanes, int) or lanes not in LANE_COUNTS:
        raise SceneError("lanes", f"expected one of {', '.join(map(str, LANE_COUNTS))} rays per work-item, "
                                  f"got {show(lanes, 120)}")
    return lanes


def check_tile(tile) -> int:
    """``tile``: a whole number of pixels in [1, MAX_TILE]."""
    if isinstance(tile, bool) or not isinstance(tile, int) or not 1 <= tile <= MAX_TILE:
        raise SceneError("tile", f"expected a tile side in [1, {MAX_TILE}] pixels, got {show(tile, 120)}")
    return tile


def check_flag(name: str, value) -> bool:
    """A yes/no argument of render(): True or False only (a string "no" would be true)."""
    if not isinstance(value, bool):
        raise SceneError(name, f"expected True or False, got {show(value, 120)}")
    return value


@dataclass(frozen=True)
class RenderArgs:
    """A render's own arguments, checked once (check_arguments): the outputs kept, whether to
    force hopeless work, the tile side and the region (x0, y0, w, h; None: the image)."""
    outputs: frozenset[str]
    force: bool = False
    tile: int = TILE
    region: tuple[int, int, int, int] | None = None
    first_sample: int = 0


MAX_FIRST_SAMPLE = 2 ** 31 - 2 ** 17   # first_sample + image.samples stays an int (the kernels' sample index)


def check_arguments(scene: Scene, outputs=None, force: bool = False, tile: int = TILE, region=None,
                    first_sample: int = 0) -> RenderArgs:
    """``scene``, ``outputs``, ``force``, ``tile``, ``region`` and ``first_sample`` (the path
    tracer's first sample index, a whole number in [0, MAX_FIRST_SAMPLE]) checked, each with
    the one-line SceneError naming it."""
    if not isinstance(scene, Scene):
        raise SceneError("scene", f"expected a pyjulia4d.Scene, got {type(scene).__name__}")
    check_tile(tile)
    check_flag("force", force)
    if isinstance(first_sample, bool) or not isinstance(first_sample, int) or not 0 <= first_sample <= MAX_FIRST_SAMPLE:
        raise SceneError("first_sample", f"expected a whole number in [0, {MAX_FIRST_SAMPLE}], got {show(first_sample, 120)}")
    return RenderArgs(resolve_outputs(outputs), force, tile, check_region(scene, region), first_sample)


def make_plan(scene: Scene, device, lanes: int, outputs=None, force: bool = False,
              tile: int = TILE, region=None, pairs: bool = False) -> Plan:
    """Check and resolve ``scene`` for ``device`` (a pyopencl Device, "CPU" or "GPU") with
    ``lanes`` rays per work-item of the march (``pairs``: two packets of them where they apply,
    kernel_config.march_packets), keeping ``outputs`` (None: all), over the image or its
    ``region`` (x0, y0, w, h) alone; each argument is checked, with the one-line SceneError
    naming it."""
    args = check_arguments(scene, outputs, force, tile, region)
    check_lanes(lanes)
    check_flag("pairs", pairs)
    return plan_from(scene, device, lanes, args, pairs)


def plan_from(scene: Scene, device, lanes: int, args: RenderArgs, pairs: bool = False,
              estimate: workload.Estimate | None = None) -> Plan:
    """The plan of ``scene`` under arguments already checked: the work judged (workload.check,
    or ``estimate`` where the caller judged it already) and every record resolved."""
    est = estimate or workload.check(scene, device, force=args.force, outputs=args.outputs)
    frame = camera_frame(scene)
    radius = march_radius(scene)
    halo = halo_for(scene.normals.method, args.outputs)
    records = kernel_arguments(scene, frame, radius)
    region = args.region
    path = scene.shading.integrator == "path" and bool({"color", "alpha"} & args.outputs)
    return Plan(
        scene=scene, image=scene.image, fractal=scene.fractal, frame=frame, march=records["march"],
        clip=records["clip"], normals_args=records["normals"], light_args=records["light_args"],
        shade=records["shade"], double=scene.precision == "double", lanes=lanes, outputs=args.outputs,
        config=kernel_config.shade_config(scene),
        march_config=kernel_config.march_config(scene, lanes, pairs=pairs),
        reflect_config=(kernel_config.march_config(scene, lanes, ray_buffers=True, pairs=pairs)
                        if scene.shading.reflection > 0 else None),
        halo=halo, tiles=make_tiles(scene.image.width, scene.image.height, args.tile, halo, region),
        region=region or (0, 0, scene.image.width, scene.image.height), pairs=pairs,
        estimate=est, path=path_args(scene, resolve_focus(scene, frame, records["march"]), args.first_sample) if path else None,
        path_config=path_config(scene) if path else None,
        path_march_config=path_march_config(scene, lanes, pairs) if path else None)


# ---------------------------------------------------------------- numbers the kernels take
# (resolved here, once, for both executors: opencl/executor.py, the OpenCL one, and the float64 reference)

GRADIENT_STEP_FLOOR = {"single": 1e-5, "double": 1e-8}


def gradient_step(scene: Scene, frame: Frame) -> tuple[float, float]:
    """The gradient normals' difference step, max(h, k d) at a hit a distance d from the eye, as
    (h, k): normals.step as given (k = 0); for "auto" march.epsilon floored at
    GRADIENT_STEP_FLOOR[render.float]; for "pixel" the footprint of a pixel at the hit, k = 2
    tan(fov / 2) / height (a pixel's height on the image plane at the view axis), no finer than
    that floor (h).  The last is Hart, Sandin & Kauffman's "clarity" (1989, §4.2: an epsilon
    growing linearly with the distance from the eye gives close and far parts the same detail):
    the difference spans what one pixel shows, so the normal follows the surface's shape at the
    pixel's scale, where the exact normal (jacobian) follows wrinkles far below it - on a
    quaternion cube at max_iter 50 about one pixel in a hundred then stands out, brighter or
    darker than all its neighbours (tests/render/test_render.py)."""
    if scene.normals.step == "pixel":
        return GRADIENT_STEP_FLOOR[scene.precision], 2.0 * frame.tan_half_fov / scene.image.height
    if scene.normals.step != "auto":
        return float(scene.normals.step), 0.0
    return max(scene.march.epsilon, GRADIENT_STEP_FLOOR[scene.precision]), 0.0


def fog_start(eye, radius: float) -> float:
    """Where depth cueing starts: the eye's distance to the bounding ball (0 inside it)."""
    return max(float(np.linalg.norm(eye)) - radius, 0.0)


SHADOW_SAMPLES = 1000   # the shadow scan of a proven march without a distance estimate


def light_parameters(sc: Scene, radius: float) -> dict:
    """shade/light.cl's numbers: the shadow rays' step (the march's epsilon, or the fixed
    scan's spacing across the bounding ball; a proven march's shadows step like the estimate
    where there is one, else like a 1000-sample scan) and cap, the offset of their start off the
    surface along the normal (two steps, at least 1e-3 of the ball's radius: the hit is
    the outside end of its bracket, so this starts clear of the surface), the penumbra,
    occlusion and trap settings."""
    m, sh = sc.march, sc.shading
    method = march_method(sc)
    if method == "de" or (method == "proven" and has_distance_estimate(sc.fractal)):
        step, cap = m.epsilon, m.max_steps
    elif method == "proven":
        # shadows and occlusion are a look, not a proof: the proven march's floor would make
        # its shadow rays take z_resolution (20000 for "normal") samples; a 1000-sample scan
        # is the fixed scan's look at z_resolution 1000
        step, cap = 2.0 * radius / SHADOW_SAMPLES, SHADOW_SAMPLES + 1
    else:
        step, cap = 2.0 * radius / m.z_resolution, m.z_resolution + 1
    return dict(step=step, max_steps=cap, bias=max(2.0 * step, 1e-3 * radius),
                softness=sh.shadow_softness, ao_distance=sh.ao_distance, ao_strength=sh.ao,
                trap=tuple(sh.trap) + (0.0,) * (4 - len(sh.trap)))
