"""The float64 executor: the whole pipeline of one scene in numpy, the second executor of
what the OpenCL one (opencl/executor.py) runs - slow, for small images."""
from __future__ import annotations

import time
import warnings

import numpy as np

from pyjulia4d.pipeline import colormap
from pyjulia4d.pipeline.antialias import THRESHOLD
from pyjulia4d.pipeline.framing import fit_camera
from pyjulia4d.pipeline.plan import Plan, make_plan
from pyjulia4d.pipeline.result import RenderResult, count_guards
from pyjulia4d.reference.antialias import flag_edges
from pyjulia4d.reference.cone import cone_of_pixels, cone_starts
from pyjulia4d.reference.enclose.disc import precision
from pyjulia4d.reference.formula import formula_of
from pyjulia4d.pipeline.film import Film
from pyjulia4d.reference.march import march
from pyjulia4d.reference.path import film as path_film
from pyjulia4d.reference.normals import clip_normals, normals_gradient, normals_jacobian, normals_zbuffer
from pyjulia4d.reference.rays import generate_rays
from pyjulia4d.reference.shade import extra_visibility, light_terms, reflect_color, reflect_rays, shade
from pyjulia4d.scene.checks import SceneError
from pyjulia4d.scene.model import Scene

def render(scene: Scene) -> RenderResult:
    """The whole pipeline in float64 numpy (slow: for small images), executing the same plan
    as the OpenCL executor (pipeline/plan.make_plan: the camera frame, the bounding ball and
    every kernel's argument record).  With image.samples = S > 1 the colour and alpha are
    the mean of S more passes through stratified samples of each pixel (rays.cl
    sample_offset); everything else comes from the pixel centres.  With image.adaptive, only
    the pixels flag_edges flags in the centre pass take that mean.  camera.fit frames the set
    as the OpenCL executor does (framing.py), from a float64 first pass: the camera may
    differ from the kernels' in its last bits (their pass is float32), so compare with
    ``reference.render(result.scene)`` for the kernels' own camera."""
    t0 = time.perf_counter()
    if not isinstance(scene, Scene):
        raise SceneError("scene", f"expected a pyjulia4d.Scene, got {type(scene).__name__}")
    if scene.camera.fit:
        scene, _ = fit_camera(scene, lambda s, outs: render(s))
    with warnings.catch_warnings():   # the work bound is the OpenCL executor's concern
        warnings.simplefilter("ignore")
        plan = make_plan(scene, "CPU", 1, force=True)
    return execute(plan, t0)


def execute(plan: Plan, t0: float | None = None) -> RenderResult:
    """Run ``plan`` (every pixel of its scene's image) in float64, its proofs with the rounding
    bounds of the plan's precision (reference/enclose/disc.py precision)."""
    with precision(plan.double):
        return _execute(plan, t0)


def _execute(plan: Plan, t0: float | None) -> RenderResult:
    t0 = time.perf_counter() if t0 is None else t0
    frame, ma, sa = plan.frame, plan.march, plan.shade
    w, h = plan.image.width, plan.image.height
    planes = list(plan.clip.planes)
    F = formula_of(plan.fractal)
    method = plan.normals_args.method

    def normals(point, depth, status, guard):
        if method == "jacobian":
            return normals_jacobian(point, status, frame, ma, guard, F)
        if method == "gradient":
            return normals_gradient(point, status, frame, ma, plan.normals_args, guard, F)
        return normals_zbuffer(point, depth, status, w, h, frame, guard)

    cone = None
    if ma.cone:   # march/cone.cl: each block's start, the same for every sample of its pixels
        cone = cone_of_pixels(cone_starts(frame, w, h, ma, F), (0, 0, w, h))

    def one_pass(sample: int, samples: int):
        origins, dirs = generate_rays(frame, w, h, sample=sample, samples=samples)
        guard = np.zeros(len(origins), np.int64)
        bracket = np.full(len(origins), np.inf)
        unresolved = np.zeros(len(origins))
        depth, point, status, smp = march(origins, dirs, ma, guard, bracket, F, planes, unresolved, cone)
        normal = clip_normals(guard, status, frame, planes, normals(point, depth, status, guard))
        refl = None
        if sa.reflection > 0:   # shade/reflect.cl: one mirror bounce, marched like a camera ray
            o2, d2 = reflect_rays(point, normal, status, frame, plan.light_args.bias, ma.radius)
            g2 = np.zeros(len(o2), np.int64)
            _, p2, s2, _ = march(o2, d2, ma, g2, None, F, planes)
            n2 = clip_normals(g2, s2, frame, planes, normals(p2, None, s2, g2))
            refl = reflect_color(s2, n2, p2, d2, frame, sa)
        la = plan.light_args
        terms = light_terms(point, normal, status, bracket, frame, ma, la, sa.light, F) if la.used else None
        vis_extra = extra_visibility(point, normal, status, frame, ma, la, sa, F) if la.extra_shadow != "none" else None
        lut = colormap.table_of(sa.colormap) if sa.colormap is not None else None
        rgba = shade(status, normal, point, frame, sa, terms, lut, vis_extra, refl)
        return rgba, depth, point, status, smp, normal, guard, bracket, unresolved

    rgba, depth, point, status, smp, normal, guard, bracket, unresolved = one_pass(0, 1)
    S = plan.image.samples
    if plan.passes > 1:
        mean = np.mean([one_pass(k, S)[0] for k in range(S)], axis=0)
        if plan.image.adaptive:   # antialias.py: the flagged pixels alone take the mean
            flags = flag_edges(rgba[:, :3].reshape(h, w, 3), rgba[:, 3].reshape(h, w), THRESHOLD).ravel()
            mean = np.where(flags[:, None], mean, rgba)
        rgba = mean
    res = RenderResult(color=rgba[:, :3].reshape(h, w, 3), alpha=rgba[:, 3].reshape(h, w),
                       depth=depth.reshape(h, w), normal=normal.reshape(h, w, 3),
                       position=point.reshape(h, w, 4), status=status.reshape(h, w),
                       samples=smp.reshape(h, w), bracket=bracket.reshape(h, w),
                       unresolved=unresolved.reshape(h, w),
                       device_name="numpy float64 reference", scene=plan.scene, march_method=ma.method,
                       guards=count_guards(status, depth, guard))
    if plan.path is not None:   # reference/path.py: the same paths, every pixel, in float64
        y, x = np.mgrid[0:h, 0:w]
        mean, cover, film = path_film(plan, x.ravel(), y.ravel())
        res.color, res.alpha = mean.reshape(h, w, 3).astype(np.float32), cover.reshape(h, w).astype(np.float32)
        res.film = Film(paths=film.paths.reshape(h, w), variance=film.variance.reshape(h, w, 3),
                        noise=film.noise.reshape(h, w), albedo=film.albedo.reshape(h, w, 3),
                        covered=film.covered.reshape(h, w), normal=film.normal.reshape(h, w, 3))
    res.seconds = res.kernel_seconds = time.perf_counter() - t0
    return res
