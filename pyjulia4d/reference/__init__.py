"""Float64 numpy twin of the OpenCL kernels, function for function, and the second executor
of a scene's plan (executor.render).

Each name here is the name of a kernel function or kernel in kernels/*.cl, with the same
formula, the same loop bounds and the same guards, vectorised over a batch of points or
rays instead of one per work-item.  It is slow and exact to float64: the tests hold the
kernels to it, and it can render a small scene.  The modules mirror kernels/ name for
name: iterate.py (iterate.cl), march.py (march/), rays.py (rays.cl), normals.py (normals/),
shade.py (shade/), algebra/ and function/ file for file, assembled by formula.py, kind/
(kind/); every function taking ``formula`` defaults to the quaternion square.  Needs no
OpenCL: ``import pyjulia4d.reference`` works without pyopencl.
"""
from pyjulia4d.reference.algebra.quaternion import alg_mul, alg_sqr, alg_sqr_jvp
from pyjulia4d.reference.antialias import flag_edges
from pyjulia4d.reference.executor import execute, render
from pyjulia4d.reference.formula import QUATERNION_SQR, Formula, formula_of
from pyjulia4d.reference.iterate import REAL_MIN, dot4, julia_distance, julia_distance_formula, julia_inside, julia_level
from pyjulia4d.reference.march import march, march_de, march_fixed, refine_bracket
from pyjulia4d.reference.normals import (clip_normals, de_field, normal_gradient, normal_jacobian, normals_gradient,
                                         normals_jacobian, normals_zbuffer, to_camera, to_camera_unit,
                                         unit_or_zero)
from pyjulia4d.reference.rays import generate_rays, sample_hash, sample_offset
from pyjulia4d.reference.shade import light_terms, reflect_color, reflect_rays, shade

__all__ = ["alg_mul", "alg_sqr", "alg_sqr_jvp", "flag_edges", "execute", "render", "QUATERNION_SQR", "Formula", "formula_of",
           "REAL_MIN", "dot4", "julia_distance", "julia_distance_formula", "julia_inside", "julia_level", "march",
           "march_de", "march_fixed", "refine_bracket", "clip_normals", "de_field", "normal_gradient",
           "normal_jacobian", "normals_gradient", "normals_jacobian", "normals_zbuffer", "to_camera",
           "to_camera_unit", "unit_or_zero", "generate_rays", "sample_hash", "sample_offset", "light_terms", "reflect_color",
           "reflect_rays", "shade"]
