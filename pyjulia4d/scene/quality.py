"""Quality presets: one knob (``march.quality`` = draft | normal | final) that asks for an
accuracy instead of march settings.

Every preset is the proven march (kernels/march/proven.cl): it steps only over segments
of the ray proven to hold no point of the truncated set, down to a floor of (far - near) /
z_resolution, and each render states its own error, bracket plus the width it could not
prove empty (RenderResult.error_stats), which it proves.  So a preset's ``p99_bound`` is a
target: the closing line says whether a render's stated p99 met it.  The three floors and
their post-steps (ITP, which narrows the bracket by 2^post_steps to float32's spacing):

* draft: floor 1/5000 of the ray, 4 steps; targets 1e-2.
* normal: 1/20000, 8 steps; targets 1e-3.
* final: 1/200000, 12 steps; targets 1e-4.

How they were chosen (the default scene, real c = -1 and c = 0 at 80x60, kernels measured
side by side): the stated p99 falls with the floor until the floor reaches about 3e-5, the
distance from the surface inside which the enclosures, widened for float32's rounding, stop
proving segments; below that a finer floor only adds unproven segments in front of the
surface (at 1/200000 the default scene's stated p50 rose from 2.4e-7 to 1.4e-5 while its p99
fell from 1.9e-4 to 5.5e-5).  draft at 1/2000 stated 0.02-0.03, above its target, so its
floor is 1/5000 (3.6e-3 to 3.7e-3).  On all 24 algebra x function pairs at their defaults
(benchmarks/accuracy/pair_accuracy.py --set march.quality=normal, 80x60;
benchmarks/results/pair_accuracy.md) the real p99 error is within twice the stated one,
the silhouette wrong on at most 0.08 % of the pixels, and the share of pixels where the
truth lies in front of all the render states (a part of the set thinner than the floor,
inside a segment it reported unresolved) at most 0.1 % on 23 pairs, 0.10 % on the
hypercomplex sin (5 of 4800).  Sets with dust state more: the commutative cube p99 0.25,
the CQuat cube 0.089, against real p99 errors of 4.8e-3 and 3.2e-4.  Partial proofs
(march/proven.cl: the part of a segment in front that an enclosure keeps outside) later
brought normal's statement on the default scene to that float32 limit too (p99 1.4e-4 to
5.3e-5 at 640x480), so final states little less than normal there.  ``silhouette_bound``
is what the benchmarks (preset_check.py, error_vs_time.py) hold a preset's silhouette to.
"""
from __future__ import annotations

import functools
from typing import Any

from pyjulia4d.fractal.registry import ALGEBRAS_TABLE, FUNCTIONS_TABLE, has_distance_estimate

QUALITIES = ("auto", "custom", "draft", "normal", "final")

# "custom"'s march keys where none is given: the estimate where the set has one, else the
# fixed scan (march.method "auto", fractal/registry.march_method), at z_resolution 250
CUSTOM = {"method": "auto", "z_resolution": 250, "post_steps": 4, "epsilon": 1e-3, "refine": "itp"}

# Proven marches (kernels/march/proven.cl) at three floors; the bound is what each targets
# for the error a render states, bracket plus unresolved (RenderResult.error_stats), which
# the render proves.  Measured in benchmarks/results/pair_accuracy.md (the derivation above).
PRESETS: dict[str, dict] = {
    "draft": {"method": "proven", "z_resolution": 5000, "post_steps": 4, "epsilon": 1e-3, "refine": "itp",
              "p99_bound": 1e-2, "silhouette_bound": 0.005},
    "normal": {"method": "proven", "z_resolution": 20000, "post_steps": 8, "epsilon": 1e-3, "refine": "itp",
               "p99_bound": 1e-3, "silhouette_bound": 0.005},
    "final": {"method": "proven", "z_resolution": 200000, "post_steps": 12, "epsilon": 1e-3, "refine": "itp",
              "p99_bound": 1e-4, "silhouette_bound": 0.005},
}

MARCH_KEYS = ("method", "z_resolution", "post_steps", "epsilon", "refine")


# iterations of the critical orbit that decide connectedness (estimate_bounds_distance): an
# orbit escaping later belongs to a c within about 1e-6 of the connectedness locus
CONNECTED_ITER = 1000


@functools.lru_cache(maxsize=256)   # every Scene built with "auto" asks (0.3 ms each)
def critical_orbit_bounded(algebra: str, degree: int, c: tuple) -> bool:
    """Whether the orbit of the critical point 0 of q -> q^degree + c stays bounded for
    CONNECTED_ITER iterations, in the complex planes the orbit lives in: a quaternion orbit
    of 0 stays in the plane of 1 and c's imaginary part (powers of a + b u are a' + b' u),
    where it is z -> z^D + c' with c' = c_x + i |c_yzw| (Hart, Sandin & Kauffman 1989 §2); a hypercomplex one
    splits into its two idempotent components (kernels/algebra/hypercomplex.cl: c_a = (c_x +
    c_w) + i (c_y - c_z), c_b = (c_x - c_w) + i (c_y + c_z)), bounded when both are.  Beyond
    2 + 2|c| every orbit of a polynomial of degree >= 2 escapes."""
    x, y, z, w = c
    if algebra == "quaternion":
        planes = [complex(x, (y * y + z * z + w * w) ** 0.5)]
    else:
        planes = [complex(x + w, y - z), complex(x - w, y + z)]
    for cc in planes:
        radius, q = 2.0 + 2.0 * abs(cc), 0j
        for _ in range(CONNECTED_ITER):
            q = q ** degree + cc
            if abs(q) > radius:
                return False
    return True


# The most iterations at which "auto" trusts the estimate.  It bounds the distance to the
# limit set, not to the truncated set the picture shows, and the truncated set grows thin
# parts the limit set lacks as max_iter rises: on the quaternion and hypercomplex squares'
# default views (48x36, against a float64 brute force, benchmarks/accuracy/pair_accuracy.py
# --set fractal.max_iter=M), the estimate's depth lay behind the first crossing by more than
# its bracket on 0 % of the pixels at 12, 0.06-0.29 % at 13, 0.8-1.0 % at 16 and 2.1-4.2 % at
# 20 (its measured p99 error 4e-4, 1.5e-3, 1.6e-2, 5.3e-2), where the normal preset's
# measured p99 stayed at or below 1.7e-6 and its depth lay behind the first crossing on at most
# 0.17 % of the pixels, each inside the space it states unproven.
ESTIMATE_MAX_ITER = 12


def estimate_bounds_distance(fractal: Any) -> bool:
    """Whether the distance estimate d = |q_n| ln|q_n| / (2 |q_n'|) (Hart, Sandin & Kauffman 1989 §3.1, eq. 8)
    may be trusted to step over nothing.  In the complex plane it is the lower bound of
    Hart, Sandin & Kauffman 1989 §3.2 (eq. 7) - Koebe's 1/4 theorem on the Boettcher coordinate - where the filled
    Julia set is connected, that is where the critical point's orbit is bounded (Douady and
    Hubbard), and on the Mandelbrot set, which is connected.  A hypercomplex set is the
    product of two complex ones, so this carries over; for quaternions there is no such
    theorem, and the same test was measured instead.  Where the set is dust the estimate is
    no bound: at 64x48 its silhouettes were 1.1-3.6 % wrong on three quaternion scenes of
    that kind, and 1.3 % on the hypercomplex cube's default (c = -0.2 + 0.8i per component,
    whose critical orbit escapes at the 8th iteration), against none on the connected ones
    (benchmarks/results/pair_error_vs_time.md).  Rotated maps (fractal.theta) are left to
    the proven march: no test of this kind is at hand for them; so are Julia sets past
    ESTIMATE_MAX_ITER iterations, whose thin parts the estimate steps over."""
    if not has_distance_estimate(fractal):
        return False
    if fractal.kind != "julia":
        return True
    if fractal.theta or fractal.algebra not in ("quaternion", "hypercomplex"):
        return False
    if fractal.max_iter > ESTIMATE_MAX_ITER:
        return False
    return critical_orbit_bounded(fractal.algebra, FUNCTIONS_TABLE[fractal.function].degree,
                                  tuple(float(x) for x in fractal.c))


def auto_quality(fractal: Any) -> str:
    """What "auto" (the default) is for a [fractal]: "custom" - the distance estimate - where
    it bounds the distance to the set (estimate_bounds_distance: a connected quaternion or
    hypercomplex square or cube at max_iter up to ESTIMATE_MAX_ITER, the Mandelbrot set); its
    error statement is the whole ray in front, which it does not prove.  Everywhere else "normal", the proven march: where the set
    has no estimate the fixed scan stepped over thin parts on up to 12 % of the pixels
    (benchmarks/results/pair_accuracy.md), and on dust the estimate does."""
    return "custom" if estimate_bounds_distance(fractal) else "normal"


def resolved_quality(scene: Any) -> str:
    """The scene's march.quality with "auto" resolved for its set."""
    q = scene.march.quality
    return auto_quality(scene.fractal) if q == "auto" else q


def auto_values(fractal: Any) -> dict:
    """The march keys "auto" takes for a [fractal]: the normal preset's or custom's defaults."""
    q = auto_quality(fractal)
    return dict(CUSTOM) if q == "custom" else preset_values(q)


def preset_values(quality: str) -> dict:
    """The march keys a preset sets ({} for "custom" and for "auto", which depends on the set:
    auto_values)."""
    if quality in ("custom", "auto"):
        return {}
    if quality not in PRESETS:
        raise ValueError(f"march.quality: expected one of {', '.join(map(repr, QUALITIES))}, got {quality!r}")
    return {k: PRESETS[quality][k] for k in MARCH_KEYS}


def stated_p99(quality: str) -> float | None:
    """The p99 depth error (scene units) ``quality`` targets (resolved: resolved_quality);
    None for "custom".  A render states (and proves) its own error; the closing line says
    whether it is within this."""
    preset_values(quality)
    if quality in ("custom", "auto"):
        return None
    return PRESETS[quality]["p99_bound"]


def preset_overrides(quality: str) -> list[str]:
    """The ``march.*=VALUE`` overrides of one preset."""
    return [f"march.{k}={v}" for k, v in preset_values(quality).items()]


def apply_quality(scene: Any, quality: str) -> Any:
    """``scene`` (a scene.model.Scene, which imports this module for the presets) with ``march.quality`` set to ``quality``: the preset's method,
    z_resolution, post_steps, epsilon and refine replace the scene's ("custom" changes nothing)."""
    if quality == "custom":
        return scene
    preset_values(quality)  # the error for an unknown name
    return scene.with_overrides([f"march.quality={quality}"])


def auto_precision(scene: Any) -> str:
    """What render.float "auto" (the default) is for a scene, where the device has fp64 and is a
    CPU (opencl/executor.py takes "single" elsewhere: a GPU's double rate is a fraction of its
    single): "double" for a proven march of a set whose algebra or function prefers it
    (registry ``prefers_double``: the CQuats, the commutative rules, the hypercomplex sin and
    cos), whose float32 rounding bounds stop proofs short of the surface; "single" otherwise.
    On their default views (64x48, benchmarks/accuracy/pair_accuracy.py --set
    render.float=double) the stated p99 fell from 9.0e-3 to 3.0e-4 (sin), 2.3e-3 to 2.8e-4
    (cos), 0.34 to 1.8e-4 (commutative square), 0.26 to 4.2e-3 (CQuat cube) and 0.90 to 0.032
    (commutative cube), for 0.9-1.6x the CPU-seconds on the AMD EPYC and 1.2-2.1x on the Intel
    Xeon (benchmarks/accuracy/precision_cost.py, 320x240)."""
    f = scene.fractal
    prefers = ALGEBRAS_TABLE[f.algebra].prefers_double or FUNCTIONS_TABLE[f.function].prefers_double
    return "double" if prefers and scene.march.method == "proven" else "single"   # "auto" is never proven
