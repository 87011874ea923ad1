"""Refuse hopeless settings before any kernel runs, and refuse settings whose
arithmetic the chosen precision, or whose image the memory, cannot hold.

``estimate(scene)`` bounds the work from above, in iterations of the set test
(one q -> q^2 + c step with its bailout check):

    fixed:  pixels x (z_resolution + 1 + refine) x max_iter
    de:     pixels x (max_steps + refine) x max_iter
    refine: post_steps (bisect) or post_steps + 3 (itp: one extra test, two end levels)
    normals: + pixels x max_iter x (4 jacobian columns | 6 gradient estimates | 0 zbuffer)

and turns it into hours with a measured throughput.  ``check(scene)`` raises a
:class:`WorkloadError` (a SceneError: one line, starting with the key that dominates)
when even the bound's share of a probe render is too much to run (PROBE_LIMIT_ITERATIONS)
and the bound is above ``REFUSE_ITERATIONS``: hopeless per ray, refused instantly.
Everything else is judged by a probe render of the scene itself (calibrate.py), which
render() runs right after the plan: the bound is 50-100x the truth for the distance
estimate march.  ``render(scene, force=True)`` skips the refusals.
"""
from __future__ import annotations

import math
import os
import warnings
from dataclasses import dataclass

from pyjulia4d.geometry.camera import march_radius, to_world
from pyjulia4d.scene.model import Scene
from pyjulia4d.scene.checks import SceneError
from pyjulia4d.fractal.registry import march_method

# Set-test throughput, iterations of f per second, measured by benchmarks/speed/throughput.py
# (benchmarks/results/throughput.md, commit 19393ea) inside the march of the default scene on
# the 2-core AMD EPYC development machine with Debian's PoCL: float32 in packets of 16 rays
# 1.29e9, float64 (one ray per work-item) 1.6e8.  Other CPUs and PyPI's PoCL can be several
# times slower; the estimate is an upper bound of the work, so the hours are too.
# "GPU" is NOT measured here (no GPU OpenCL device on the development machine): an
# assumed 2e10 it/s, a conservative figure for a current discrete GPU (~30 flops per
# iteration, a few TFLOP/s sustained); fp64 on consumer GPUs can be 32x slower.
ITERATIONS_PER_SECOND = {
    ("CPU", "single"): 1.29e9,
    ("CPU", "double"): 1.6e8,
    ("GPU", "single"): 2e10,
    ("GPU", "double"): 2e10 / 32,
}
REFUSE_ITERATIONS = 1e13   # ~2 h at the bound on the development CPU
# calibrate.py's probe renders PROBE_RAYS pixels; where their share of the bound is above
# PROBE_LIMIT_ITERATIONS (~4 s here) the probe is not run and the bound decides alone
PROBE_RAYS = 2048
PROBE_LIMIT_ITERATIONS = 5e9

NORMAL_COST = {"jacobian": 4, "gradient": 6, "zbuffer": 0}

# Defaults the dominant key is judged against (the default scene's values).
_TYPICAL = {"image": 640 * 480, "march.z_resolution": 250, "march.max_steps": 4096,
            "march.post_steps": 4, "fractal.max_iter": 12}


class WorkloadError(SceneError):
    """A legal scene that would take hours (or that the precision cannot hold)."""


@dataclass(frozen=True)
class Estimate:
    iterations: float          # upper bound of set-test iterations, march + normals
    seconds: float             # predicted at ITERATIONS_PER_SECOND[kind, precision]
    kind: str                  # "CPU" or "GPU": the throughput used
    dominant: str              # the dotted key furthest above its typical value
    value: object = None       # that key's value in the scene

    @property
    def hours(self) -> float:
        return self.seconds / 3600.0


def _kind(device) -> str:
    if device is None:
        return "CPU"
    if isinstance(device, str):
        return "GPU" if device.upper() == "GPU" else "CPU"
    from pyjulia4d.opencl.devices import device_type
    return "GPU" if device_type(device) == "GPU" else "CPU"


def estimate(scene: Scene, device=None, outputs=None) -> Estimate:
    """Upper bound of the work of ``scene`` keeping ``outputs`` (None: all) and its predicted
    time on ``device`` (a pyopencl Device, "CPU", "GPU", or None for the measured CPU figure)."""
    f, m = scene.fractal, scene.march
    pixels = scene.image.width * scene.image.height * rays_per_pixel(scene, outputs)
    # ITP refinement: up to post_steps + 1 set tests and the two ends' levels (march/refine.cl)
    refine = m.post_steps + 3 if m.refine == "itp" else m.post_steps
    if march_method(scene) == "fixed":
        per_ray = m.z_resolution + 1 + refine
        march_key = "march.z_resolution"
    else:
        per_ray = m.max_steps + refine
        march_key = "march.max_steps"
    its = float(pixels) * per_ray * f.max_iter
    its += float(pixels) * f.max_iter * NORMAL_COST.get(scene.normals.method, 6)
    kind = _kind(device)
    ips = ITERATIONS_PER_SECOND[kind, scene.precision]
    factors = {"image": pixels, march_key: getattr(m, march_key.split(".")[1]),
               "march.post_steps": max(m.post_steps, 1), "fractal.max_iter": f.max_iter}
    dominant = max(factors, key=lambda k: factors[k] / _TYPICAL[k])
    if dominant == "image":
        dominant = "image.width" if scene.image.width >= scene.image.height else "image.height"
    return Estimate(its, its / ips, kind, dominant, _value(scene, dominant))


def _value(scene: Scene, dotted: str):
    section, _, key = dotted.partition(".")
    return getattr(getattr(scene, section), key)


# The largest bailout whose square survives one more squaring: the iterate that first
# exceeds the bailout has |q|^2 <= (bailout^2 + |c|)^2, which must stay below REAL_MAX / 4
# (the margin covers the dot product and the derivative's 4 |q|^2 factor).  float32:
# bailout <= ~9.6e8 (measured: 1e10 turns 34% of a de image's hits into misses, 1e20
# squares to inf and zeroes the normals).
REAL_MAX = {"single": 3.4028234663852886e38, "double": 1.7976931348623157e308}


def max_bailout(precision: str, cabs: float = 0.0) -> float:
    return math.sqrt(math.sqrt(REAL_MAX[precision] / 4.0) - cabs)


def check_numerics(scene: Scene) -> None:
    """Refuse settings the kernels' arithmetic cannot hold (always; not skipped by force)."""
    f, m = scene.fractal, scene.march
    cabs = math.sqrt(sum(x * x for x in f.c))
    lim = max_bailout(scene.precision, cabs)
    if f.bailout > lim:
        alt = ' or render.float="double"' if scene.precision == "single" else ""
        raise WorkloadError("fractal.bailout",
                            f"{f.bailout:g} overflows {scene.precision} precision (|q|^2 "
                            f"reaches ~1e{4 * math.log10(f.bailout):.0f} one squaring past the "
                            f"bailout, above {REAL_MAX[scene.precision]:.1e}); use at most "
                            f"{lim:.2g}{alt}")
    if march_method(scene) == "de" and scene.precision == "single":
        t_far = float(sum(x * x for x in to_world(scene, scene.camera.position))) ** 0.5 + march_radius(scene)
        ulp = t_far * 2.0 ** -23
        if m.epsilon < ulp / 2:
            warnings.warn(f"march.epsilon: {m.epsilon:g} is below half the float32 spacing of the "
                          f"ray parameter ({ulp:.1e} at t = {t_far:.3g}): the de march will step by "
                          f"that spacing instead where the estimate is smaller (effective "
                          f'epsilon ~{ulp:.1e}, pixels counted as guards["ulp_step"]); raise it '
                          f'or use render.float="double"',
                          RuntimeWarning, stacklevel=5)
    # the fixed scan counts i = 0 .. z_resolution and post-stepping n = 1 .. post_steps in
    # an OpenCL int: at 2^31 - 1 the loop counter would overflow instead of ending
    for key, v in (("march.z_resolution", m.z_resolution), ("march.post_steps", m.post_steps)):
        if v >= 2**31 - 2:
            raise WorkloadError(key, f"must be below {2**31 - 2} (the kernel's int loop counter), got {v}")


@dataclass(frozen=True)
class Output:
    """One array a render can keep (RenderResult's field of the same name): its channels per
    pixel, its host type, and the tile's device buffers it is read from (opencl/runner.py)."""
    channels: int
    dtype: str
    buffers: tuple[str, ...]

    @property
    def bytes(self) -> int:
        return 4 * self.channels

    def shape(self, height: int, width: int) -> tuple[int, ...]:
        return (height, width) if self.channels == 1 else (height, width, self.channels)


# What a render can keep on the host, the one table of them.  "bracket" and "unresolved" are
# always kept: they are the depth's certificate and every render reports their statistics.
# The device holds two tiles at a time (plan.TILE), whatever the size.  Alpha is read from
# shading's colour where it runs, else from the status (a hit).
OUTPUTS_TABLE = {
    "color": Output(3, "float32", ("rgba",)), "alpha": Output(1, "float32", ("status",)),
    "depth": Output(1, "float32", ("depth",)), "bracket": Output(1, "float32", ("bracket",)),
    "unresolved": Output(1, "float32", ("unresolved",)), "normal": Output(3, "float32", ("normal",)),
    "position": Output(4, "float32", ("point",)), "status": Output(1, "int32", ("status",)),
    "samples": Output(1, "int32", ("samples",)),
}
OUTPUTS = tuple(OUTPUTS_TABLE)
OUTPUT_BYTES = {k: o.bytes for k, o in OUTPUTS_TABLE.items()}


def passes(samples: int, outputs) -> int:
    """Passes over every pixel: the centre, and ``samples`` colour passes where there are more
    than one and colour or alpha is kept (opencl/passes.py, the float64 executor)."""
    return 1 + samples if samples > 1 and {"color", "alpha"} & set(outputs) else 1
HOST_MEMORY_SHARE = 0.5     # of the physical memory


def resolve_outputs(outputs) -> frozenset[str]:
    """The outputs kept: all (None) or the named ones, plus "bracket" and "unresolved" (always)."""
    if outputs is None:
        return frozenset(OUTPUTS)
    if isinstance(outputs, str):   # one name, not its letters
        outputs = [outputs]
    try:
        names = set(outputs)
    except Exception:   # not iterable, unhashable items, or an object whose own iteration fails
        raise SceneError("outputs", f"expected a list of output names ({', '.join(OUTPUTS)}), got "
                                    f"{type(outputs).__name__}") from None
    if not all(isinstance(n, str) for n in names):
        raise SceneError("outputs", f"expected output names ({', '.join(OUTPUTS)}), got "
                                    f"{sorted(repr(n) for n in names if not isinstance(n, str))[0]}")
    unknown = sorted(names - set(OUTPUTS))
    if unknown:
        raise SceneError("outputs", f"unknown output {unknown[0]!r}; one of {', '.join(OUTPUTS)}")
    return frozenset(names | {"bracket", "unresolved"})


def output_bytes_per_pixel(outputs=None) -> int:
    """Bytes a pixel of the host images a render keeping ``outputs`` holds."""
    return sum(OUTPUT_BYTES[k] for k in resolve_outputs(outputs))


def host_bytes_per_pixel(outputs=None) -> int:
    """Host memory per pixel of a render keeping ``outputs``: the arrays themselves, and as
    much again for the copies the PNG/EXR writers make (contiguous channels, 8-bit RGBA)."""
    return 2 * output_bytes_per_pixel(outputs)


def physical_memory() -> int:
    """Bytes of physical memory (0 where the platform does not say)."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return 0


def check_memory(scene: Scene, outputs=None) -> None:
    """Refuse an image whose kept ``outputs`` (None: all) would not fit in memory (always; not
    skipped by force: it would fail, not merely take long).  Any size that fits renders, tile
    by tile, in the same device memory."""
    w, h = scene.image.width, scene.image.height
    per_pixel = host_bytes_per_pixel(outputs)
    need = float(w) * h * per_pixel
    total = physical_memory()
    if total and need > HOST_MEMORY_SHARE * total:
        key = "image.width" if w >= h else "image.height"
        most = int(HOST_MEMORY_SHARE * total / per_pixel)
        raise WorkloadError(key, f"{w}x{h} = {float(w) * h:.3g} pixels needs ~{need / 2**30:.3g} GiB "
                                 f"of memory for the image ({per_pixel} bytes per pixel), over "
                                 f"half of this machine's {total / 2**30:.3g} GiB; at most ~{most:.3g} pixels")


def rays_per_pixel(scene: Scene, outputs=None) -> int:
    """Rays marched per pixel, at most: a pass each (``passes``), or for a path-traced render
    the centre pass and per sample a march of each bounce's rays and of its shadow rays."""
    outs = resolve_outputs(outputs)
    if scene.shading.integrator == "path" and {"color", "alpha"} & outs:
        return 1 + scene.image.samples * 2 * scene.shading.bounces
    return passes(scene.image.samples, outs)


def probe_iterations(scene: Scene, est: Estimate, outputs=None) -> float:
    """The bound's share of calibrate.py's probe render (PROBE_RAYS pixels, one ray each)."""
    pixels = scene.image.width * scene.image.height
    return est.iterations / rays_per_pixel(scene, outputs) * min(1.0, PROBE_RAYS / pixels)


def check(scene: Scene, device=None, force: bool = False, outputs=None) -> Estimate:
    """Before any kernel runs: refuse what the precision or the memory cannot hold, and (unless
    ``force``) work that is hopeless per ray: above REFUSE_ITERATIONS with even the probe
    render beyond PROBE_LIMIT_ITERATIONS.  The rest is judged by calibrate.py.  Returns the
    estimate (the bound)."""
    check_numerics(scene)
    check_memory(scene, outputs)
    est = estimate(scene, device, outputs)
    if (est.iterations > REFUSE_ITERATIONS and probe_iterations(scene, est, outputs) > PROBE_LIMIT_ITERATIONS
            and not force):
        text = (f"~{est.iterations:.1e} set-test iterations (upper bound), "
                f"~{est.hours:.2g} h at {ITERATIONS_PER_SECOND[est.kind, scene.precision]:.1e} it/s "
                f"on a {est.kind}")
        raise WorkloadError(est.dominant,
                            f"{est.value} could take {text}, over the limit of "
                            f"{REFUSE_ITERATIONS:.0e}; lower {est.dominant}, or force it "
                            f"(--force; render(..., force=True))")
    return est
