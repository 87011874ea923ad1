"""Every kernel family on a GPU-shaped device: Oclgrind, with its memory, API and data-race checks.

Oclgrind (tests/devices/simulated.py) runs one ray per work-item in work-groups of 64, as a
GPU does, and reports every read or write outside a buffer, every API call the OpenCL
specification refuses and every data race between work-items.  Each scene below renders
there at 12x9 and on the CPU runtime (one ray per work-item too, so only the compilers
differ), and the test fails on:

- any report of Oclgrind's that is the project's own (pyopencl's two are told apart in
  simulated.PYOPENCL_OWN, and test_pyopencl_owns_the_api_errors_left shows they are its);
- a hit or miss that differs from the CPU's on more than MISS_PIXELS of the 108 pixels: the
  two compilers contract and order floating-point operations differently, which can move a
  ray that grazes the set across the hit threshold;
- a depth on a pixel both hit that lies outside the two stated brackets, widened by
  DEPTH_SLACK of the depth (the rounding of two float32 marches that take different steps);
- a picture whose mean colour differs by more than MEAN_SLACK (relative).

A mesh (``mesh*``: the mesh kernels on a grid of 24 points a side) must find the same grid points inside
and the same faces, its vertices within the widest stated bracket of each other.

A sample of four runs by default; ``-m slow`` runs all of them: every algebra, each hypercomplex
function, every kind, every march, every normals method, the shading terms, reflection,
antialiasing, the path tracer with a lens, the mesh, and double precision.
"""
from __future__ import annotations

import numpy as np
import pytest

import simulated
from pyjulia4d.opencl.devices import indexed_devices, is_simulator

pytestmark = pytest.mark.skipif(not any(is_simulator(d) for _, _, d in indexed_devices()),
                                reason="Oclgrind is not installed (pip install '.[test]')")

SMALL = ["image.width=12", "image.height=9"]
MISS_PIXELS = 2
DEPTH_SLACK = 1e-4
MEAN_SLACK = 2e-3

SCENES = {
    # the sample: the default (estimate, cone starts, Jacobian normals, soft shadows, occlusion)
    "default": [],
    "hypercomplex_sin_proven": ["fractal.algebra=hypercomplex", "fractal.function=sin", "march.quality=normal"],
    "path_lens": ["shading.integrator=path", "image.samples=2", "camera.aperture=0.05"],
    "mesh_default": [],
}
SAMPLE = tuple(SCENES)
SCENES.update({
    "double": ["render.float=double"],
    "mandelbrot_zbuffer_aa": ["fractal.kind=mandelbrot", "fractal.c=[0,0,0,0]", "normals.method=zbuffer",
                              "image.samples=2"],
    "quaternion_cube": ["fractal.function=cube", "fractal.c=[-0.5,0.3,0,0]"],
    "cquat_sqr": ["fractal.algebra=cquat"],
    "cquat_cube": ["fractal.algebra=cquat", "fractal.function=cube", "fractal.c=[-0.5,0.3,0,0]"],
    "commutative_sqr": ["fractal.algebra=commutative"],
    "commutative_cube": ["fractal.algebra=commutative", "fractal.function=cube", "fractal.c=[-0.5,0.3,0,0]"],
    "julia_stack": ["fractal.kind=julia_stack"],
    "cubic_locus": ["fractal.kind=cubic_locus"],
    "fixed_scan": ["march.quality=custom", "march.method=fixed", "march.z_resolution=60"],
    "final_double": ["march.quality=final", "render.float=double"],
    "gradient_iteration_reflect": ["normals.method=gradient", "shading.coloring=iteration", "shading.reflection=0.3"],
    "clip_fog_lights": ["clip.planes=[[0,0,1,0.1]]", "shading.fog=0.5",
                        "shading.lights=[{position=[2,2,-2,0],color=[0.5,0.5,1]}]", "shading.specular=0.8"],
    "path_double": ["shading.integrator=path", "image.samples=2", "render.float=double", "shading.metallic=0.5"],
    "mesh_cquat_double": ["fractal.algebra=cquat", "render.float=double"],
    "mesh_clipped": ["clip.planes=[[0,-1,0,0.3],[1,0.2,0.5,0.4]]"],
})
SCENES.update({f"hypercomplex_{f}": ["fractal.algebra=hypercomplex", f"fractal.function={f}", "fractal.max_iter=8"]
               for f in ("sqr", "cube", "exp", "reciprocal", "asin", "sinh", "asinh", "cos", "acos", "cosh",
                         "acosh", "tan", "atan", "tanh", "atanh", "ln", "pwr")})


def check(name: str, rec: dict) -> None:
    assert not rec.get("reports"), f"{name}: Oclgrind reports:\n\n" + "\n\n".join(rec["reports"][:5])
    if rec.get("mesh"):   # the same grid points inside, the same faces, vertices within the widest bracket
        sim, cpu = rec["sim"], rec["cpu"]
        assert (sim["inside"], sim["faces"]) == (cpu["inside"], cpu["faces"]), name
        gap = np.max(np.abs(np.array(sim["vertices"]) - np.array(cpu["vertices"])))
        assert gap <= max(sim["bracket"], cpu["bracket"]) + 1e-6, f"{name}: vertices {gap:.3g} apart"
        return
    sim, cpu = rec["sim"], rec["cpu"]
    s, c = np.array(sim["status"]), np.array(cpu["status"])
    assert np.count_nonzero(s != c) <= MISS_PIXELS, f"{name}: {np.count_nonzero(s != c)} pixels hit on one device only"
    both = (s == 1) & (c == 1)
    ds, dc = np.array(sim["depth"])[both], np.array(cpu["depth"])[both]
    room = np.array(sim["bracket"])[both] + np.array(cpu["bracket"])[both] + DEPTH_SLACK * (1 + dc)
    assert np.all(np.abs(ds - dc) <= room), f"{name}: depths differ by up to {np.max(np.abs(ds - dc) - room):.3g} beyond the brackets"
    assert abs(sim["mean"] - cpu["mean"]) <= MEAN_SLACK * max(cpu["mean"], 1e-3), \
        f"{name}: mean colour {sim['mean']:.6f} on the simulator, {cpu['mean']:.6f} on the CPU"


def test_kernels_on_a_gpu_shaped_device():
    # the sample, in one child (one test: under pytest-xdist a fixture shared by several tests
    # would run again in each worker that takes one of them)
    got = simulated.run([(n, SMALL + SCENES[n]) for n in SAMPLE], timeout=600)
    assert sorted(got) == sorted(SAMPLE)
    for name in SAMPLE:
        check(name, got[name])


@pytest.mark.slow
def test_every_family_on_a_gpu_shaped_device():
    got = simulated.run([(n, SMALL + v) for n, v in SCENES.items() if n not in SAMPLE], timeout=1800)
    for name, rec in got.items():
        check(name, rec)


CHILD = r"""
import os, sys
import numpy as np
import pyopencl as cl
from pyjulia4d.opencl.devices import select_device
dev = select_device("oclgrind")
ctx = cl.Context([dev]); q = cl.CommandQueue(ctx)
what = sys.argv[1]
def mark(s): os.write(2, ("@@ " + s + "\n").encode())
if what == "broken":
    src = '''__kernel void past(__global float *a, int n) { a[get_global_id(0) + n] = 1.0f; }
             __kernel void race(__global float *a) { a[0] = (float)get_global_id(0); }'''
    prg = cl.Program(ctx, src).build()
    a = cl.Buffer(ctx, cl.mem_flags.READ_WRITE, 64 * 4)
    mark("past"); prg.past(q, (64,), (64,), a, np.int32(1)); q.finish()
    mark("race"); prg.race(q, (64,), (64,), a); q.finish()
elif what == "own":
    from pyjulia4d.opencl.capabilities import capabilities
    from pyjulia4d.opencl.devices import device_key, has_fp64
    from pyjulia4d.opencl.listing import describe_devices
    from pyjulia4d.opencl.lanes import packet_pairs
    mark("own"); describe_devices(); capabilities(dev); device_key(dev); has_fp64(dev); packet_pairs(dev, 1, False)
    dev.max_compute_units; dev.native_vector_width_float
else:
    from pyopencl.characterize import nv_compute_capability
    mark("nv"); nv_compute_capability(dev)
    prg = cl.Program(ctx, "__kernel void k(__global float *a) { a[0] = 1.0f; }").build()
    again = cl.Program(ctx, [dev], prg.get_info(cl.program_info.BINARIES)).build()   # as build.py loads its cache
    mark("kernel"); cl.Kernel(again, "k")
"""


def _child(what: str) -> dict[str, str]:
    import os
    import subprocess
    import sys

    env = dict(os.environ, **simulated.CHECKS, PYTHONPATH=str(simulated.ROOT))
    p = subprocess.run([sys.executable, "-c", CHILD, what], capture_output=True, text=True, env=env, timeout=300)
    assert p.returncode == 0, p.stderr[-2000:]
    return {part.partition("\n")[0]: part.partition("\n")[2] for part in p.stderr.split("@@ ")[1:]}


def test_the_checks_catch_a_bad_kernel():
    # the harness can fail: a write past the buffer and a race are reported, and not excused
    got = _child("broken")
    past, race = (simulated.reports(got[k]) for k in ("past", "race"))
    assert past and "Invalid write" in past[0], got["past"][:500]
    assert race and "data race" in race[0].lower(), got["race"][:500]


def test_the_projects_own_device_queries_are_clean():
    # every device query of pyjulia4d's own (the listing, capabilities, keys, widths): no API error at all
    got = _child("own")["own"]
    assert "Oclgrind - OpenCL runtime error" not in got, got[:1000]


def test_pyopencl_owns_the_api_errors_left():
    # the two API errors simulated.PYOPENCL_OWN excuses come from pyopencl's own calls, made alone
    got = _child("pyopencl")
    for part, words in zip(("nv", "kernel"), simulated.PYOPENCL_OWN):
        blocks = [b for b in got[part].split("\n\n") if "runtime error" in b]
        assert any(all(w in b for w in words) for b in blocks), got[part][:800]
        assert not simulated.reports(got[part]), got[part][:800]
