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


def _build() -> list[Case]:
    cheap = (24, 18)
    small = (12, 9)
    tiny = (4, 3)
    cases = [
        Case("c_zero", ("fractal.c=0,0,0,0",),
             "c = 0: the set is a ball; inside orbits go to 0 and underflow (the Jacobian "
             "normal would be 0); the bounding sphere IS the surface, so the fixed scan's "
             "first sample lies exactly on the boundary",
             "a ball of radius bailout^(2^-max_iter), radial normals (jacobian_tiny counted); "
             "fixed: rounding decides the boundary sample, in float64 too (depth within a step)",
             size=cheap, fixed_depth_tol=1e-2),
        Case("c_parabolic_0.25", ("fractal.c=0.25,0,0,0", "fractal.max_iter=100"),
             "c = 1/4 on the cardioid cusp: orbits creep to the parabolic fixed point 1/2 "
             "(|f'| = 1), escape-time classification is stiff",
             "terminates; float32 agrees with float64 up to the stiff boundary pixels",
             0.05, 1e-3, "", cheap),
        Case("c_parabolic_-0.75", ("fractal.c=-0.75,0,0,0", "fractal.max_iter=100"),
             "c = -3/4, the parabolic 2-cycle root: slow convergence, stiff classification",
             "terminates; float32 agrees with float64 up to the stiff boundary pixels",
             0.05, 1e-3, "", cheap),
        Case("c_dust_0.2501", ("fractal.c=0.2501,0,0,0", "fractal.max_iter=100"),
             "c just outside the Mandelbrot set: the Julia set is dust, orbits escape only "
             "after ~300 iterations (slow passage by 1/2)",
             "terminates; at max_iter 100 still a solid (truncated) set",
             0.05, 1e-3, "", cheap),
        Case("c_dust_0.26", ("fractal.c=0.26,0,0,0", "fractal.max_iter=100"),
             "c outside the Mandelbrot set: Cantor dust, no interior at all; the truncated set "
             "is a thin hull that marching may step over",
             "terminates; the fixed scan may miss the thin hull (as float64 does); both "
             "methods find the certified truncated surface, whose first crossing float32 and "
             "float64 decide differently where the hull is thinner than their steps (de: 10 %, "
             "its over-relaxed steps landing on other points; 7 % with plain steps)",
             0.08, 1e-3, "", cheap, de_status_tol=0.15),
        Case("c_dendrite_-2", ("fractal.c=-2,0,0,0", "fractal.max_iter=30"),
             "c = -2: the set is the segment [-2, 2] (zero volume); thin object",
             "the truncated set is a thin spindle both methods step over (de: rays that came "
             "within epsilon by the estimate are counted as shell_miss, never drawn as hits): "
             "both precisions see (almost) nothing",
             0.05, 1e-3, "", cheap, both_hit_min=0),
        Case("c_dendrite_i", ("fractal.c=0,1,0,0", "fractal.max_iter=30"),
             "c = i: a dendrite (no interior), thin branches",
             "fixed: thin hull, mostly stepped over; de: the certified march finds the hull "
             "where its epsilon steps meet it (rays passing within epsilon without entering it "
             "are shell_miss); float32 and float64 find different first crossings of the "
             "branches on ~5 % of the rays both hit (96x72; 12 % at 24x18 with the estimate's "
             "over-relaxed steps)",
             0.08, 1e-3, "", cheap, de_status_tol=0.15),
        Case("max_iter_1", ("fractal.max_iter=1",),
             "max_iter 1: the estimate and normals from a single iterate",
             "a smooth blob; exact agreement", 0.02, 1e-4, "", cheap),
        Case("max_iter_1000", ("fractal.max_iter=1000",),
             "max_iter 1000: |q'| ~ 2^1000 overflows float32 (and float64) without rescaling",
             "no NaN/inf: derivative carried as mantissa * 2^e, Jacobian rescaled; fixed: a "
             "sample grazing the rough boundary may flip, moving the hit by one step (1.2e-2)",
             0.05, 1e-3, "", small, fixed_depth_tol=1.2e-2),
        Case("max_iter_10000", ("fractal.max_iter=10000",),
             "max_iter 10000: |q'| ~ 2^10000, far beyond float64 too",
             "no NaN/inf: derivative carried as mantissa * 2^e, Jacobian rescaled; fixed: a "
             "sample grazing the rough boundary may flip, moving the hit by one step (1.2e-2)",
             0.1, 1e-3, "", tiny, fixed_depth_tol=1.2e-2),
        Case("bailout_2", ("fractal.bailout=2",),
             "bailout 2: the smallest radius that still bounds the set; crude estimate",
             "terminates; estimate low but safe", 0.02, 1e-4, "", cheap),
        Case("bailout_1e3", ("fractal.bailout=1e3",),
             "bailout 1e3: |q|^2 up to 1e6 before one more squaring",
             "no overflow; sharper estimate", 0.02, 1e-4, "", cheap),
        Case("bailout_1e6", ("fractal.bailout=1e6", "fractal.max_iter=100"),
             "bailout 1e6: |q|^2 up to 1e12 -> 1e24 after a squaring, derivative squared "
             "up to 1e40 before rescaling in float32",
             "no NaN/inf from the estimate or the normals; the certified de march finds the "
             "rough max_iter-100 surface, where float32 and float64 differ on ~6 % of rays",
             0.08, 1e-3, "", small, fixed_depth_tol=1.2e-2),
        Case("camera_far", tuple(_far_camera()),
             "camera at distance 1e4 with a 0.014 degree field of view: the march starts at "
             "the bounding sphere ~1e4 away, where float32 spacing of t is ~1e-3",
             "terminates; float32 depth quantised to ulp(1e4) ~ 1e-3",
             0.1, 2e-3, "float32 depth resolution at t = 1e4 is ~1e-3 (ulp), the size of "
             "the set's fine detail; render.float = \"double\" resolves it", cheap),
        Case("deep_zoom", tuple(_deep_zoom()),
             "field of view 1e-5 degrees onto a surface point: the frame is ~5e-7 wide, "
             "about two float32 ulps of the eye position and of t",
             "terminates; float32 rays and depths quantised to ~2e-7, the image is blocky",
             0.1, 1e-5, "float32 cannot resolve a 5e-7 frame at distance 3: pixels share "
             "rays and depths (ulp(3) = 2.4e-7); render.float = \"double\" resolves it", small),
        Case("camera_inside", ("camera.position=0.05,0.1,-0.1,0", "camera.target=0,0,1,0",
                               "camera.up=0,1,0,0"),
             "the eye inside the set: near = 0, the first sample is inside, the hit point "
             "is the eye itself (no eye-to-point direction for shading)",
             "every pixel a hit at depth 0 (guards eye_hit = all), finite colour; "
             "zbuffer normals fall back to the view axis (normal_fallback)", 0.0, 1e-6, "", small),
        Case("critical_point_eye", ("camera.position=0,0,0,0", "camera.target=0,0,1,0",
                                    "camera.up=0,1,0,0"),
             "the eye at the critical point 0 inside the set: f'(0) = 0, so the Jacobian "
             "and the derivative vanish exactly on the first step",
             "every pixel a hit at depth 0; the zero gradient is replaced by the view axis "
             "and counted (normal_fallback, jacobian_tiny), never a zero or NaN normal",
             0.0, 1e-6, "", small),
        Case("epsilon_below_ulp", ("march.epsilon=1e-8", "march.post_steps=0",
                                   "fractal.max_iter=100"),
             "epsilon 1e-8 below float32 spacing at the hit distance (ulp(2.5) = 2.4e-7): "
             "t + d == t, the DE march cannot advance",
             "terminates: where the step rounds away the march steps one ulp of t "
             "(effective epsilon = ulp(t), counted as ulp_step), never a stall or a hang; "
             "depth within 1e-5 of float64 (median one ulp); the hit is the max_iter-"
             "truncated surface itself, rough at max_iter 100 (normals speckled, as in a "
             "float64 fixed scan); the first crossing of that rough surface differs from "
             "float64's on ~4 % of rays (3.5-3.7 % of 3085 at 96x72; 6-8 % of the 49 both hit "
             "at the checked 12x9, where one ray is 2 %)",
             0.1, 1e-5, "", small, fixed_depth_tol=1e-3),
        Case("z_resolution_1", ("march.z_resolution=1",),
             "z_resolution 1: only the near and far samples",
             "fixed: almost nothing hit (first sample inside only); de unaffected",
             0.02, 1e-4, "", cheap, both_hit_min=0),
        Case("z_resolution_1e6", ("march.z_resolution=1000000",),
             "z_resolution 10^6: steps of ~3e-6, close to float32 spacing of t",
             "terminates; fixed depth within a few ulp of float64",
             0.1, 1e-5, "", tiny),
        Case("post_steps_0", ("march.post_steps=0",),
             "no post-stepping: depth error up to one step", "exact agreement",
             0.02, 1e-4, "", cheap),
        Case("post_steps_60", ("march.post_steps=60",),
             "60 post-steps: the bracket h / 2^60 is far below float32 (and float64) spacing",
             "terminates; depth converges to float precision and stays there",
             0.02, 1e-4, "", cheap),
        # The hypercomplex numbers have zero divisors: h = a e1 + b e2 with a = 0 or b = 0
        # (x = -w, y = z or x = w, y = -z; algebra/hypercomplex.cl), where 1/h and ln h are
        # infinite in one component.  An eye on x = 0, y = z looking at the origin sends the
        # centre ray (an odd image size has one: u = v = 0) along them.
        Case("hc_reciprocal_zero_divisors", ("fractal.algebra=hypercomplex", "fractal.function=reciprocal",
                                            "fractal.c=0.3,0.1,0,0", "camera.position=0,1.5,1.5,0",
                                            "camera.target=0,0,0,0", "fractal.max_iter=10"),
             "1/h on the zero divisors (a = 0 exactly along the view axis): inf in one component",
             "the orbit escapes there (inf and NaN fail the bailout test): a hole around the "
             "centre, no NaN in any output, terminates",
             0.05, 1e-3, "", (25, 19), methods=("fixed",)),
        Case("hc_ln_zero_divisors", ("fractal.algebra=hypercomplex", "fractal.function=ln",
                                    "fractal.c=0.5,0.2,0,0", "camera.position=0,1.5,1.5,0",
                                    "camera.target=0,0,0,0", "fractal.max_iter=10"),
             "ln h on the zero divisors: -inf in one component",
             "escapes there, no NaN in any output, terminates",
             0.05, 1e-3, "", (25, 19), methods=("fixed",)),
        Case("hc_exp_overflow", ("fractal.algebra=hypercomplex", "fractal.function=exp",
                                "fractal.bailout=1000", "fractal.c=-0.5,0.3,0,0", "fractal.max_iter=20",
                                "camera.position=2500,2000,-3000,0", "camera.fov=50"),
             "e^h with bailout 1e3: e^|a| overflows float32 (above 88.7) and float64 (above 709) "
             "before an orbit reaches the bailout",
             "inf components escape; no NaN in any output; terminates",
             0.05, 1e-3, "", cheap, methods=("fixed",), both_hit_min=0),
        Case("hc_cosh_overflow", ("fractal.algebra=hypercomplex", "fractal.function=cosh",
                                 "fractal.bailout=1000", "fractal.c=0.2,0.1,0,0", "fractal.max_iter=20",
                                 "camera.position=2500,2000,-3000,0", "camera.fov=50"),
             "cosh h with bailout 1e3: cosh and sinh overflow on every sample with a component "
             "beyond 89 (float32) or 710 (float64)",
             "inf components escape; no NaN in any output; terminates (the set is hairy and thin "
             "at this scale: a 250-step scan sees none of it)",
             0.05, 1e-3, "", cheap, methods=("fixed",), both_hit_min=0),
        Case("hc_tan_poles", ("fractal.algebra=hypercomplex", "fractal.function=tan",
                             "fractal.c=1.5707964,0,0,0", "fractal.max_iter=30",
                             "camera.position=4.4,3.9,-5.4,0"),
             "tan h with c on a pole (pi/2): orbits land next to poles, values near 1e7 and beyond",
             "escapes or stays, never NaN in an output; terminates; chaotic near poles, so "
             "float32 and float64 orbits part: measured, not asserted",
             0.05, 1e-3, "chaotic: float32 and float64 orbits separate near the poles", cheap,
             methods=("fixed",), both_hit_min=0),
        # Mandelbrot sets (fractal.kind, kernels/kind/mandelbrot.cl): the point is c.
        Case("mandelbrot_eye_at_zero", ("fractal.kind=mandelbrot", "camera.position=0,0,0,0",
                                        "camera.target=0,0,1,0", "camera.up=0,1,0,0"),
             "the eye at c = 0, inside the Mandelbrot set: every iterate is exactly 0 (q_1 = c = 0), "
             "the derivative with respect to c is 1 + 0 + ...",
             "every pixel a hit at depth 0 (eye_hit); the Jacobian stops before q underflows "
             "(jacobian_tiny) and the zero gradient falls back to the view axis, counted; no NaN",
             0.0, 1e-6, "", small),
        Case("mandelbrot_max_iter_1000", ("fractal.kind=mandelbrot", "fractal.max_iter=1000",
                                          "camera.position=-0.5,1.6,-2.9,0", "camera.target=-0.5,0,0,0"),
             "1000 iterations of the orbit of 0: |dq/dc| grows like 2^n |q_1 ... q_n| past float32's "
             "range (carried as mantissa * 2^e) and the boundary is chaotic",
             "finite estimate and normals; terminates; float32 and float64 orbits part near the "
             "boundary, so the first crossing differs on some rays",
             0.1, 1e-3, "chaotic: float32 and float64 orbits of 1000 iterations part near the boundary",
             small),
        Case("theta_90_cube", ("fractal.function=cube", "fractal.c=0.3,0.4,0,0", "fractal.theta=90",
                               "fractal.max_iter=20"),
             "the rotated map u (u^-1 q)^3 + u c (Hart, Sandin & Kauffman 1989 §2.3) with u = i: cos 90 degrees is "
             "6e-17 in float64 and -4e-8 in float32, not 0",
             "agrees with float64 as the unrotated cube does", 0.02, 1e-4, "", cheap),
        # Julia set stacks (fractal.kind = "julia_stack", kernels/kind/julia_stack.cl); "de" is the
        # empirical estimate (Hart, Sandin & Kauffman 1989 §5.1: none is proven)
        Case("stack_through_boundary", ("fractal.kind=julia_stack", "fractal.c_from=0,0", "fractal.c_to=0.5,0",
                                        "fractal.max_iter=40", "camera.position=1.6,1.9,-3.0,0"),
             "a c-line through the Mandelbrot set's cusp c = 1/4: the sections implode from the "
             "cauliflower (parabolic at 1/4, orbits creeping past the fixed point) to Cantor dust "
             "(c > 1/4), thinner than any scan step beyond; 40 iterations near a parabolic point",
             "no NaN in any output; terminates; the dust past 1/4 is what max_iter 40 leaves of it",
             0.03, 1e-4, "", cheap),
        Case("stack_zero_length", ("fractal.kind=julia_stack", "fractal.c_from=-0.12,0.75",
                                   "fractal.c_to=-0.12,0.75", "fractal.max_iter=20",
                                   "camera.position=2.0,2.4,-3.2,0"),
             "c_from = c_to: c_half = 0, the stack a prism over one Julia set (the rabbit); the "
             "derivative in u is exactly 0 on the sides",
             "the sides' normals perpendicular to u, the caps' along it; no NaN; agrees with float64",
             0.02, 1e-4, "", cheap),
        # the cubic connectedness locus (fractal.kind = "cubic_locus", kernels/kind/cubic_locus.cl):
        # the fixed scan only (no estimate is known)
        Case("locus_a_zero_plus", ("fractal.kind=cubic_locus", "camera.position=0,0,-3,0", "camera.target=0,0,0,0",
                                   "camera.up=0,1,0,0", "fractal.max_iter=30"),
             "a = 0 along the view axis (odd image: the centre ray has a = 0 exactly): the critical "
             "points +a and -a collide, z_0 = 0 exactly, f = z^3 + b (the degree-3 Mandelbrot set); "
             "the derivative in a starts at 1 with z_0 = 0",
             "no NaN, no normal fallback; terminates; agrees with float64", 0.03, 1e-4, "", (25, 19),
             methods=("fixed",)),
        Case("locus_a_zero_minus", ("fractal.kind=cubic_locus", "fractal.component=minus",
                                    "camera.position=0,0,-3,0", "camera.target=0,0,0,0", "camera.up=0,1,0,0",
                                    "fractal.max_iter=30"),
             "C- seen along a = 0: the same set as C+ there (both critical points are 0), mirrored "
             "(a -> -a) elsewhere",
             "as locus_a_zero_plus; tests/kernels/test_stack_locus.py checks the mirror and the a = 0 section",
             0.03, 1e-4, "", (25, 19), methods=("fixed",)),
    ]
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
