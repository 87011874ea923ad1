"""Quality presets: one knob (``march.quality`` = draft | normal | final) that picks
march settings from the measured error-against-time trade-off (issue 3).

How they were derived: ``benchmarks/error_vs_time.py`` (results in
benchmarks/results/error_vs_time.csv and .md, section "Cheapest settings meeting an
error bound on every scene") rendered nine scenes - seed 000's Figs. 1, 5, 6, 8
(max_iter 8 and 12) and 9, POV-Ray's example, c = 0 and real c = -1 - with every
fixed (z_resolution x post_steps) and distance-estimate (epsilon x post_steps)
setting of its grid, against ground truth from pyjulia4d/truth.py.  Each preset is
the setting with the least total kernel time over the nine scenes whose depth error
at the 99th percentile of the pixels that hit is within the preset's ``p99_bound``
(scene units) on *every* scene, with the silhouette (pixels hit by one of render
and truth but not the other) wrong on at most ``silhouette_bound`` of the pixels.
Such a setting is on the Pareto front by construction.  The bounds are what was
measured on those scenes at the benchmark's image size; a scene with thinner parts
than any of them (high max_iter, seed 000 Fig. 4 and 9) can need a finer
z-resolution than the preset gives.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # scene.py imports this module for the presets
    from .scene import Scene

QUALITIES = ("custom", "draft", "normal", "final")

# From benchmarks/results/error_vs_time.md (96x72 px, PoCL on 2 CPU cores), section
# "Cheapest settings meeting an error bound on every scene".  Measured worst case over
# the nine scenes (run of commit 79133b1): draft p99 0.028, silhouette 0.04 %; normal
# p99 2.6e-5; final p99 1.2e-6 (float32's floor: the kernels place p = o + t d to
# ~1e-6).  Total kernel time over the nine scenes: 0.057 s, 0.081 s, 0.10 s - against
# 1.17 s for the cheapest fixed scan within 1e-4 (z_resolution 4000, 10 post-steps).
# The de settings' times differ by less than the timing noise at that image size, so
# the benchmark's pick among epsilons moves between runs; these are fixed from one run.
PRESETS: dict[str, dict] = {
    "draft": {"method": "de", "z_resolution": 250, "post_steps": 2, "epsilon": 1e-5, "refine": "itp",
              "p99_bound": 1e-2, "silhouette_bound": 0.005},
    "normal": {"method": "de", "z_resolution": 250, "post_steps": 10, "epsilon": 1e-6, "refine": "itp",
               "p99_bound": 1e-4, "silhouette_bound": 0.005},
    "final": {"method": "de", "z_resolution": 250, "post_steps": 20, "epsilon": 5e-7, "refine": "itp",
              "p99_bound": 1e-5, "silhouette_bound": 0.005},
}

# The bounds are stated for scenes with fractal.max_iter up to this; beyond it (measured at
# 30 and 50) no float32 setting has one: see the module docstring.
BOUND_MAX_ITER = 20

MARCH_KEYS = ("method", "z_resolution", "post_steps", "epsilon", "refine")


def preset_values(quality: str) -> dict:
    """The march keys a preset sets ({} for "custom")."""
    if quality == "custom":
        return {}
    if quality not in PRESETS:
        raise ValueError(f"march.quality: expected one of {', '.join(map(repr, QUALITIES))}, got {quality!r}")
    return {k: PRESETS[quality][k] for k in MARCH_KEYS}


def stated_p99(quality: str, max_iter: int) -> float | None:
    """The p99 depth error (scene units) ``quality`` states for a scene of ``max_iter``
    iterations: its ``p99_bound`` up to BOUND_MAX_ITER, None (no bound) beyond."""
    preset_values(quality)
    if quality == "custom":
        return None
    return PRESETS[quality]["p99_bound"] if int(max_iter) <= BOUND_MAX_ITER else None


def preset_overrides(quality: str) -> list[str]:
    """The ``march.*=VALUE`` overrides of one preset."""
    return [f"march.{k}={v}" for k, v in preset_values(quality).items()]


def apply_quality(scene: Scene, quality: str) -> Scene:
    """``scene`` with ``march.quality`` set to ``quality``: the preset's method,
    z_resolution, post_steps, epsilon and refine replace the scene's ("custom" changes nothing)."""
    if quality == "custom":
        return scene
    preset_values(quality)  # the error for an unknown name
    return scene.with_overrides([f"march.quality={quality}"])
