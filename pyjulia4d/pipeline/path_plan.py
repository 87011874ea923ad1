"""The path tracer's part of a plan (shading.integrator = "path"): its record of numbers
(PathArgs, what kernels/path/path.cl takes beside the camera, march, light and shade
records), its program (path_config) and the focus distance camera.focus = "auto" resolves
to.  Pure Python and numpy, resolved once per render like the rest of the plan
(pipeline/plan.py); opencl/path.py and reference/path.py execute it.
"""
from __future__ import annotations

import math

from dataclasses import dataclass

import numpy as np

from pyjulia4d.pipeline import kernel_config
from pyjulia4d.geometry.camera import to_world
from pyjulia4d.pipeline.environment import Environment, load as load_environment
from pyjulia4d.pipeline.kernel_config import KernelConfig
from pyjulia4d.scene.model import Scene

# image.noise: the first adaptive check comes after this many samples of a pixel (the
# standard error of fewer is itself too noisy to stop on: at 16 samples its relative error
# is about 1 / sqrt(2 (16 - 1)) = 18 %)
MIN_SAMPLES = 16

# Samples a launch takes of each pixel: enough that a launch holds about LAUNCH_ITEMS paths
# (on Intel's CPU runtime a launch costs some 0.1 ms however small: an 80x60 picture's 26
# launches a sample spent a third of their time on it), a power of two up to BATCH_MAX.  It
# follows from the picture's size, never a tile's, so that the noise target - tested between
# launches - stops each pixel at the same sample on any tiling or cluster.
LAUNCH_ITEMS = 2 ** 16
BATCH_MAX = 16


def launch_batch(width: int, height: int, samples: int) -> int:
    """Samples a launch takes: 2^round(log2(LAUNCH_ITEMS / (width height))), 1 to
    BATCH_MAX, at most ``samples``."""
    k = 2 ** max(0, round(math.log2(LAUNCH_ITEMS / (width * height))))
    return max(1, min(k, BATCH_MAX, samples))


@dataclass(frozen=True)
class PathArgs:
    """kernels/path/path.cl's numbers: the path's length, the lens, the noise target, the
    material and the sky (and its image: kernels/path/environment.cl).  ``sky`` is the environment's radiance, shading.ambient times
    shading.sky; ``alpha2`` GGX's a^2 from shading.roughness; ``f0s`` the dielectric
    reflectance at normal incidence, 0.08 shading.specular (Burley 2012 §5.3)."""
    bounces: int
    samples: int
    first_sample: int      # the first sample's index: a later batch of the same picture (render's first_sample)
    batch: int             # samples a launch takes of each pixel (launch_batch)
    aperture: float
    focus: float
    noise: float
    min_samples: int
    metallic: float
    alpha2: float
    f0s: float
    sky: tuple[float, float, float, float]
    sky_weight: float      # what the sky gives a white matte surface, the share light choice gives it
    emission: float        # shading.emission: the surface's own light, times its colour and 1 - its colour value
    normals: str           # the bounces' normals: "jacobian" or "gradient" (bounce_normals)
    environment: Environment | None = None   # shading.environment's image and its distribution; None: uniform
    env_x: tuple[float, ...] = (1.0, 0.0, 0.0, 0.0)   # the scene's axes in 4D (the slice's rotation)
    env_y: tuple[float, ...] = (0.0, 1.0, 0.0, 0.0)
    env_z: tuple[float, ...] = (0.0, 0.0, 1.0, 0.0)

    @property
    def env_w(self) -> int:
        return self.environment.width if self.environment is not None else 0

    @property
    def env_h(self) -> int:
        return self.environment.height if self.environment is not None else 0


ALPHA_MIN = 0.002   # kernels/path/sample.cl ALPHA_MIN


def path_args(scene: Scene, focus: float, first_sample: int = 0) -> PathArgs:
    """The record of ``scene``, its lens focused at ``focus`` (resolve_focus), its samples
    numbered from ``first_sample``."""
    sh, im = scene.shading, scene.image
    a = max(sh.roughness ** 2, ALPHA_MIN)
    sky = tuple(sh.ambient * s for s in sh.sky) + (0.0,)
    env = None if sh.environment == "uniform" else load_environment(sh.environment)
    axes = [tuple(float(x) for x in to_world(scene, e, direction=True)) for e in np.eye(4)[:3]]
    return PathArgs(bounces=sh.bounces, samples=im.samples, first_sample=first_sample,
                    batch=launch_batch(im.width, im.height, im.samples), aperture=scene.camera.aperture, focus=focus,
                    noise=im.noise, min_samples=MIN_SAMPLES, metallic=sh.metallic, alpha2=a * a,
                    f0s=0.08 * min(sh.specular, 12.5), sky=sky,
                    sky_weight=sky_weight(sky, env), emission=sh.emission, normals=bounce_normals(scene),
                    environment=env,
                    env_x=axes[0], env_y=axes[1], env_z=axes[2])


def sky_weight(sky, env: Environment | None) -> float:
    """The sky's share in next-event estimation's choice of a light (kernels/path/path.cl
    light_weight gives the lights'): what it gives a white matte surface under a sky of its
    mean radiance, the luminance of ``sky`` times the image's mean luminance over the sphere
    (1 for the uniform sky).  Any positive share keeps the estimate unbiased; one near the
    truth spends the shadow rays where the light is."""
    return float(np.dot(np.float32(sky[:3]).astype(np.float64), [0.2126, 0.7152, 0.0722])
                 * (1.0 if env is None else env.mean))


def bounce_normals(scene: Scene) -> str:
    """The normals of the paths' hits: normals.method, or the Jacobian's for the Z-buffer's
    (a bounce has no image to difference; the Jacobian holds for every algebra)."""
    return "gradient" if scene.normals.method == "gradient" else "jacobian"


def path_config(scene: Scene) -> KernelConfig:
    """The path tracer's own program, one ray per work-item: the iteration and rays.cl
    (camera_uv), the bounces' normals where the march's program has none of them
    (bounce_normals: the gradient's, or the Jacobian's in place of the Z-buffer's), the cut
    faces' normals, the colour value (shade/light.cl) and path/sample.cl, path/path.cl.  Its
    rays are marched by path_march_config's program."""
    pieces = list(kernel_config.iteration_pieces(scene)) + ["rays"]
    defines = list(kernel_config.precision_defines(scene)) + list(kernel_config.fractal_defines(scene))
    normals = bounce_normals(scene)
    if normals != scene.normals.method or normals == "gradient":
        pieces.append(f"normals/{normals}")
    if scene.clip.planes:
        pieces.append("march/clip")
        defines.append("CLIP")
    sh = scene.shading
    if sh.coloring != "flat":
        pieces.append("shade/light")
        defines.append(f"COLOR_{sh.coloring.upper()}")
    if sh.lights:
        defines.append(f"EXTRA_LIGHTS={len(sh.lights)}")
    pieces.append("path/sample")
    if sh.environment != "uniform":
        pieces.append("path/environment")
        defines.append("ENV_MAP")
    return KernelConfig(tuple(pieces) + ("path/path",), tuple(defines) + ("PATH",))


def path_march_config(scene: Scene, lanes: int, pairs: bool) -> KernelConfig:
    """The march of the paths' rays: the render's own march reading given rays (-D
    RAYS_FROM_BUFFERS), in the camera march's packets (a packet's rays are a block of
    neighbouring pixels': coherent for the camera's and a light's rays), with the Jacobian
    normals where the scene takes them (kernel_config.march_config; shading.reflection's march
    is the same program)."""
    return kernel_config.march_config(scene, lanes, ray_buffers=True, pairs=pairs)


def resolve_focus(scene: Scene, frame, march) -> float:
    """camera.focus as a distance along the view axis: the number given, or for "auto" the
    depth of the surface at the picture's centre (focus_at)."""
    focus = scene.camera.focus
    if focus != "auto":
        return float(focus)
    w, h = scene.image.width, scene.image.height
    return focus_at(scene, frame, march, w // 2, h // 2)


def focus_at(scene: Scene, frame, march, px: int, py: int) -> float:
    """The distance along the view axis of the surface pixel (px, py) shows, found by the
    float64 march of its centre ray (the same march on any device, so the focus is too);
    where that ray meets nothing, the camera target's distance."""
    from pyjulia4d.geometry.camera import clip_planes
    from pyjulia4d.pipeline.codes import STATUS_HIT
    from pyjulia4d.reference.formula import formula_of
    from pyjulia4d.reference.march import march as march64
    from pyjulia4d.reference.rays import generate_rays
    w, h = scene.image.width, scene.image.height
    o, d = generate_rays(frame, w, h, px, py, 1, 1)
    with np.errstate(all="ignore"):
        depth, _, status, _ = march64(o, d, march, formula=formula_of(scene.fractal), clip=list(clip_planes(scene)))
    fwd = np.asarray(frame.forward, np.float64)
    if status[0] == STATUS_HIT and np.isfinite(depth[0]):
        return max(float(depth[0] * abs(float(np.dot(d[0], fwd)))), 1e-6)
    target = to_world(scene, scene.camera.target)
    return min(max(float(np.dot(target - np.asarray(frame.position, np.float64), fwd)), 1e-6), 1e7)
