"""A named catalogue of extreme cases: the places where 4D Julia rendering is known
to break (the quaternion square's, and the singular points of the hypercomplex
functions: zero divisors, overflow, poles), each with what it stresses, what pyjulia4d must do,
and how close the float32 render must come to the float64 one.

Every case is a list of scene overrides on top of the default scene, runnable with
its march methods (``scene(case, "fixed" | "de", "single" | "double")``; the
hypercomplex cases have no distance estimate, so the fixed scan only).  Images
are tiny (the costly cases a handful of pixels) so that tests/accuracy/test_extreme.py runs
the whole catalogue, both methods and both precisions, in well under a minute;
benchmarks/accuracy/extreme_cases.py runs the same scenes and writes the error table.

Tolerances are against the float64 render of the same scene (the double-precision
kernels, themselves held to the numpy reference by tests/kernels/test_march.py and
tests/accuracy/test_extreme.py): ``status_tol`` bounds the fraction of pixels whose status
(miss / hit / capped) differs, and ``depth_tol`` the depth error on pixels both
renders hit (the median must be below it, and at most ``status_tol`` of those
pixels above it).  A case whose float32 error is inherently larger is marked with
``limit``: a documented precision limit, whose measured error is reported by the
benchmark instead of asserted.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache
from importlib import resources

try:
    import tomllib
except ModuleNotFoundError:   # Python 3.10
    import tomli as tomllib

import numpy as np

from pyjulia4d.scene.model import Scene

METHODS = ("fixed", "de")

# Pinned here so that a change of the default camera does not move the targets below.
EYE = (1.8, 1.6, -2.2, 0.0)


@dataclass(frozen=True)
class Case:
    name: str
    overrides: tuple[str, ...]
    stresses: str
    expected: str
    status_tol: float = 0.02       # fraction of pixels whose status may differ from float64
    depth_tol: float = 1e-4        # depth error on common hits (median below; <= status_tol above)
    limit: str = ""                # non-empty: a documented float32 precision limit (measured, not asserted)
    size: tuple[int, int] = (24, 18)
    per_method: dict = field(default_factory=dict)  # method -> extra overrides
    both_hit_min: int = 1          # pixels both renders must hit (0: a case that may see nothing)
    fixed_depth_tol: float = 0.0   # depth_tol for the fixed scan where it differs (0: the same)
    methods: tuple[str, ...] = METHODS  # the march methods the case runs with (no de without an estimate)
    de_status_tol: float = 0.0     # status_tol for the estimate where it differs (0: the same)

    def status_tol_for(self, method: str) -> float:
        return self.de_status_tol if method == "de" and self.de_status_tol else self.status_tol

    def depth_tol_for(self, method: str) -> float:
        return self.fixed_depth_tol if method == "fixed" and self.fixed_depth_tol else self.depth_tol

    def overrides_for(self, method: str) -> list[str]:
        w, h = self.size
        return ([f"march.method={method}", f"image.width={w}", f"image.height={h}"]
                + list(self.overrides) + list(self.per_method.get(method, ())))


@lru_cache(maxsize=None)
def surface_point() -> tuple[float, float, float, float]:
    """A point on the surface of the default set: where the centre ray from EYE
    meets it, by a float64 reference scan (z_resolution 4000, 40 post-steps: the
    bracket is below 1e-15)."""
    from pyjulia4d import reference as ref
    from pyjulia4d.geometry.camera import camera_frame
    from pyjulia4d.pipeline.plan import march_args
    s = Scene.default().with_overrides([f"camera.position={_v(EYE)}", "camera.target=0,0,0,0",
                                        "march.method=fixed"])
    fr = camera_frame(s)
    depth, point, status, _ = ref.march(fr.position[None], fr.forward[None],
                                        march_args(s, epsilon=1e-3, z_resolution=4000, post_steps=40, max_steps=1,
                                                   method="fixed"))
    assert status[0] == 1, "the centre ray of the default scene must hit the set"
    return tuple(float(x) for x in point[0])


def _v(v) -> str:
    return ",".join(repr(float(x)) for x in v)


def _far_camera() -> list[str]:
    """Eye at distance 1e4 along EYE's direction, field of view just holding the bounding
    ball (radius ~1.6) so the set fills the frame."""
    u = np.asarray(EYE) / np.linalg.norm(EYE)
    fov = math.degrees(2 * math.atan(1.2 / 1e4))
    return [f"camera.position={_v(1e4 * u)}", "camera.target=0,0,0,0", f"camera.fov={fov!r}"]


def _deep_zoom() -> list[str]:
    return [f"camera.position={_v(EYE)}", f"camera.target={_v(surface_point())}",
            "camera.fov=1e-5"]


# Cameras computed from the default set, which a case names instead of writing them out
CAMERAS = {"far": _far_camera, "deep_zoom": _deep_zoom}


def _build() -> list[Case]:
    """The cases of catalogue.toml (beside this module), each a Case: its keys are Case's
    fields, with a computed camera (CAMERAS) put before its overrides."""
    table = tomllib.loads(resources.files("pyjulia4d.measure").joinpath("catalogue.toml").read_text(encoding="utf-8"))
    cases = []
    for entry in table["case"]:
        entry = dict(entry)
        camera = CAMERAS[entry.pop("camera")]() if "camera" in entry else []
        entry["overrides"] = tuple(camera) + tuple(entry.get("overrides", ()))
        for key in ("size", "methods"):
            if key in entry:
                entry[key] = tuple(entry[key])
        if "per_method" in entry:
            entry["per_method"] = {m: tuple(v) for m, v in entry["per_method"].items()}
        cases.append(Case(**entry))
    return cases


@lru_cache(maxsize=None)
def catalogue() -> tuple[Case, ...]:
    return tuple(_build())


def names() -> list[str]:
    return [c.name for c in catalogue()]


def get(name: str) -> Case:
    for c in catalogue():
        if c.name == name:
            return c
    raise KeyError(name)


def scene(case: Case | str, method: str, precision: str = "single") -> Scene:
    """The scene of one case with one march method in one precision."""
    if isinstance(case, str):
        case = get(case)
    return Scene.default().with_overrides(case.overrides_for(method) + [f"render.float={precision}"])
