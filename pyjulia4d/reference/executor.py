"""The float64 executor: the whole pipeline of one scene in numpy, the second executor of
what the OpenCL one (opencl/executor.py) runs - slow, for small images."""
from __future__ import annotations

import time

import numpy as np

from pyjulia4d.fractal.registry import march_method
from pyjulia4d.geometry.camera import camera_frame, clip_planes, extra_lights, light_position, march_radius
from pyjulia4d.pipeline import colormap
from pyjulia4d.pipeline.antialias import THRESHOLD
from pyjulia4d.pipeline.framing import fit_camera
from pyjulia4d.pipeline.plan import fog_start, gradient_step, light_parameters
from pyjulia4d.pipeline.result import RenderResult, count_guards
from pyjulia4d.reference.antialias import flag_edges
from pyjulia4d.reference.formula import formula_of
from pyjulia4d.reference.march import march
from pyjulia4d.reference.normals import clip_normals, normals_gradient, normals_jacobian, normals_zbuffer
from pyjulia4d.reference.rays import generate_rays
from pyjulia4d.reference.shade import (extra_visibility_of_scene, light_terms_of_scene, reflect_color, reflect_rays,
                                       shade)
from pyjulia4d.scene.model import Scene

def render(scene: Scene) -> RenderResult:
    """The whole pipeline in float64 numpy (slow: for small images).  With image.samples = S
    > 1 the colour and alpha are the mean of S more passes through stratified samples of
    each pixel (rays.cl sample_offset); everything else comes from the pixel centres.  With
    image.adaptive, only the pixels flag_edges flags in the centre pass take that mean.
    camera.fit frames the set as executor.render does (framing.py), from a float64 first
    pass: the camera may differ from the kernels' in its last bits (their pass is float32),
    so compare with ``reference.render(result.scene)`` for the kernels' own camera."""
    t0 = time.perf_counter()
    if scene.camera.fit:
        scene, _ = fit_camera(scene, lambda s, outs: render(s))
    frame = camera_frame(scene)
    w, h = scene.image.width, scene.image.height
    sh = scene.shading

    def one_pass(sample: int, samples: int):
        f, m = scene.fractal, scene.march
        F = formula_of(f)
        origins, dirs = generate_rays(frame, w, h, sample=sample, samples=samples)
        near = -1.0 if m.near == "auto" else float(m.near)
        far = -1.0 if m.far == "auto" else float(m.far)
        guard = np.zeros(len(origins), np.int64)
        bracket = np.full(len(origins), np.inf)
        depth, point, status, smp = march(origins, dirs, f.c, f.max_iter, f.bailout, m.epsilon,
                                          march_radius(scene), near, far, m.z_resolution,
                                          m.post_steps, m.max_steps, march_method(scene), guard, m.refine,
                                          bracket, F, planes)
        if scene.normals.method == "jacobian":
            normal = normals_jacobian(point, status, f.c, f.max_iter, f.bailout, frame, guard, F)
        elif scene.normals.method == "gradient":
            step = gradient_step(scene)
            normal = normals_gradient(point, status, f.c, f.max_iter, f.bailout, step, frame, guard, F)
        else:
            normal = normals_zbuffer(point, depth, status, w, h, frame, guard)
        normal = clip_normals(guard, status, frame, planes, normal)
        refl = None
        if sh.reflection > 0:   # shade/reflect.cl: one mirror bounce, marched like a camera ray
            radius = march_radius(scene)
            o2, d2 = reflect_rays(point, normal, status, frame, light_parameters(scene, radius)["bias"], radius)
            g2 = np.zeros(len(o2), np.int64)
            _, p2, s2, _ = march(o2, d2, f.c, f.max_iter, f.bailout, m.epsilon, radius, near, far,
                                 m.z_resolution, m.post_steps, m.max_steps, march_method(scene), g2, m.refine,
                                 None, F, planes)
            if scene.normals.method == "jacobian":
                n2 = normals_jacobian(p2, s2, f.c, f.max_iter, f.bailout, frame, g2, F)
            else:
                n2 = normals_gradient(p2, s2, f.c, f.max_iter, f.bailout, gradient_step(scene), frame, g2, F)
            n2 = clip_normals(g2, s2, frame, planes, n2)
            refl = reflect_color(s2, n2, p2, d2, frame, light_position(scene), sh.color, sh.background,
                                 sh.light_color, sh.sky, sh.ambient, sh.diffuse)
        terms = light_terms_of_scene(scene, point, normal, status, bracket, F)
        lut = colormap.table(sh.colormap) if sh.coloring != "flat" else None
        geo, rgb = extra_lights(scene) if sh.lights else (None, None)
        rgba = shade(status, normal, point, frame, light_position(scene), sh.color, sh.background,
                     sh.light_color, sh.ambient, sh.diffuse, sh.specular, sh.shininess, terms, lut,
                     sh.fog, fog_start(frame.position, march_radius(scene)), sh.sky, geo, rgb,
                     extra_visibility_of_scene(scene, point, normal, status, F), refl, sh.reflection)
        return rgba, depth, point, status, smp, normal, guard, bracket

    planes = clip_planes(scene)
    rgba, depth, point, status, smp, normal, guard, bracket = one_pass(0, 1)
    S = scene.image.samples
    if S > 1:
        mean = np.mean([one_pass(k, S)[0] for k in range(S)], axis=0)
        if scene.image.adaptive:   # antialias.py: the flagged pixels alone take the mean
            flags = flag_edges(rgba[:, :3].reshape(h, w, 3), rgba[:, 3].reshape(h, w), THRESHOLD).ravel()
            mean = np.where(flags[:, None], mean, rgba)
        rgba = mean
    res = RenderResult(color=rgba[:, :3].reshape(h, w, 3), alpha=rgba[:, 3].reshape(h, w),
                       depth=depth.reshape(h, w), normal=normal.reshape(h, w, 3),
                       position=point.reshape(h, w, 4), status=status.reshape(h, w),
                       samples=smp.reshape(h, w), bracket=bracket.reshape(h, w),
                       device_name="numpy float64 reference", scene=scene,
                       guards=count_guards(status, depth, guard))
    res.seconds = res.kernel_seconds = time.perf_counter() - t0
    return res
