"""The registry of algebras, functions and kinds of set: one entry each, naming its OpenCL
piece and its float64 twin and stating its facts.  Adding a function is one FUNCTIONS_TABLE
entry plus kernels/function/<name>.cl and pyjulia4d/reference/function/<name>.py; adding a
kind of set is one KINDS_TABLE entry plus kernels/kind/<name>.cl, its host hooks
pyjulia4d/fractal/kinds/<name>.py (kind_hooks) and its twin pyjulia4d/reference/kind/<name>.py.
The scene's choices and rules, the kernel configuration (pipeline/kernel_config.py), the
bounding ball (geometry/camera.py) and the reference all read it here.

The algebras and functions are POV-Ray's julia_fractal's (POV-Ray 3.6 documentation), in
its order, with Gintz's CQuats and the naive commutative rules (Ödegaard & Wennergren
eqs. 14, 15); the kinds are Hart, Sandin & Kauffman 1989's (§2, §5).
"""
from __future__ import annotations

import importlib
import math
from dataclasses import dataclass
from typing import Any

Vec4 = tuple[float, float, float, float]
_ZERO = (0.0, 0.0, 0.0, 0.0)


class _Entry:
    """An entry of a table of pieces: kernels/<folder>/<name>.cl and its twin,
    pyjulia4d/reference/<folder>/<name>.py."""
    folder = ""
    name: str

    @property
    def piece(self) -> str:
        return f"{self.folder}/{self.name}"

    @property
    def twin(self) -> str:
        return f"pyjulia4d.reference.{self.folder}.{self.name}"


@dataclass(frozen=True)
class Function(_Entry):
    """f in q -> f(q) + c.  ``degree``: the polynomial maps' degree - they escape to infinity
    like |q|^degree, which gives the bounding ball and the distance estimate (camera.
    bounding_radius, iterate.cl); None for the others.  ``critical``: f's one critical (or
    asymptotic) value v, in the point's own coordinates, where the Mandelbrot set's orbit
    starts (q_1 = v + c, kernels/kind/mandelbrot.cl); None where f has several singular
    values (tan, tanh) or none (ln, the inverse functions): no one Mandelbrot set.
    ``prefers_double``: its orbits stretch their points apart so fast that float32's rounding
    bounds stop the proven march's proofs short of the surface (render.float "auto" takes
    double for it: scene/quality.py auto_precision)."""

    folder = "function"
    name: str
    degree: int | None = None
    critical: Vec4 | None = None
    prefers_double: bool = False


@dataclass(frozen=True)
class Algebra(_Entry):
    """A 4D algebra.  ``functions``: the f it takes (quaternions sqr and cube only, as in
    POV-Ray).  ``norm_bounded``: |q^D| >= |q|^D, so the escape bound holds - quaternions (the
    norm is multiplicative) and the hypercomplex numbers (the power mean of their two complex
    components); CQuats and the commutative rules have zero divisors with |q^2| < |q|^2.
    ``estimate``: the polynomial maps have a distance estimate (Hart, Sandin & Kauffman 1989 §3.1 eq. 8 for
    quaternions; the product of two complex Julia sets for the hypercomplex numbers).
    ``table``: a multiplication-table algebra whose powers come from algebra/power.cl.
    ``prefers_double``: as Function's, for every function of the algebra."""

    folder = "algebra"
    name: str
    functions: tuple[str, ...]
    norm_bounded: bool = False
    estimate: bool = False
    table: bool = False
    enclosure: str = "ball"
    prefers_double: bool = False

    @property
    def enclosure_piece(self) -> str:
        """Its orbit enclosures for the proven march: kernels/enclose/<enclosure>.cl (4D balls,
        or a disc per complex component of a split algebra) and their twin."""
        return f"enclose/{self.enclosure}"


@dataclass(frozen=True)
class Kind:
    """A kind of set a [fractal] table describes, plugged in as a function is: an entry here,
    its pieces and its twin.  ``piece``: its set test after iterate.cl (kernels/kind/<name>.cl,
    with kind/level.cl), None for the Julia set itself.  ``estimate``: whether a proven
    distance estimate exists for it (the stack's "de" is an empirical one).  ``enclosure``: its
    orbits' enclosures (enclose/<enclosure>.cl), which every kind has, so the proven march and
    the quality presets exist for every set.  ``own_map``: it iterates a complex map of its
    own, not the algebra's, so its enclosure piece is the whole enclosure (no algebra piece).
    ``packet_pairs``: its estimate runs two packets side by side (kernel_config.march_packets).
    ``host``: the module of its host-side hooks - its -D switches, the radius of a ball that
    holds it, its rules (fractal/kinds/<name>.py: kind_hooks).  ``twin``: its float64 twin's
    module (reference/kind/<name>.py: inside, level, normal and, where it has them,
    distance_formula and orbit_start), None where iterate.cl's own Julia set test is the set's."""

    name: str
    enclosure: str
    piece: str | None = None
    estimate: bool = True
    own_map: bool = False
    packet_pairs: bool = False
    empirical_estimate: bool = False   # march.method "de" takes an empirical estimate where no proven one exists

    @property
    def host(self) -> str:
        return f"pyjulia4d.fractal.kinds.{self.name}"

    @property
    def twin(self) -> str | None:
        return f"pyjulia4d.reference.kind.{self.name}" if self.piece else None

    @property
    def enclosure_piece(self) -> str:
        """Its orbits' enclosures for the proven march, after the algebra's: kernels/enclose/
        <enclosure>.cl and its twin."""
        return f"enclose/{self.enclosure}"


FUNCTIONS_TABLE: dict[str, Function] = {f.name: f for f in (
    Function("sqr", degree=2, critical=_ZERO),
    Function("cube", degree=3, critical=_ZERO),
    Function("exp", critical=_ZERO),          # asymptotic value 0
    Function("reciprocal", critical=_ZERO),   # asymptotic value 0: the orbit of c
    Function("sin", critical=(1.0, 0.0, 0.0, 0.0), prefers_double=True),    # sin(pi/2)
    Function("asin"),
    Function("sinh", critical=(0.0, 1.0, 0.0, 0.0)),   # sinh(i pi/2) = i, per hypercomplex component
    Function("asinh"),
    Function("cos", critical=(1.0, 0.0, 0.0, 0.0), prefers_double=True),    # cos(0)
    Function("acos"),
    Function("cosh", critical=(1.0, 0.0, 0.0, 0.0)),   # cosh(0)
    Function("acosh"),
    Function("tan"),
    Function("atan"),
    Function("tanh"),
    Function("atanh"),
    Function("ln"),
    Function("pwr", critical=_ZERO),          # critical point 0 for Re(exponent) > 1 (scene rules)
)}

FUNCTIONS = tuple(FUNCTIONS_TABLE)

ALGEBRAS_TABLE: dict[str, Algebra] = {a.name: a for a in (
    Algebra("quaternion", ("sqr", "cube"), norm_bounded=True, estimate=True),
    Algebra("hypercomplex", FUNCTIONS, norm_bounded=True, estimate=True, enclosure="split"),
    Algebra("cquat", ("sqr", "cube"), table=True, prefers_double=True),
    Algebra("commutative", ("sqr", "cube"), table=True, prefers_double=True),
)}

ALGEBRAS = tuple(ALGEBRAS_TABLE)

KINDS_TABLE: dict[str, Kind] = {k.name: k for k in (
    Kind("julia", enclosure="julia", packet_pairs=True),
    Kind("mandelbrot", piece="kind/mandelbrot", enclosure="mandelbrot", packet_pairs=True),
    Kind("julia_stack", piece="kind/julia_stack", estimate=False, enclosure="julia_stack", own_map=True,
         empirical_estimate=True),
    Kind("cubic_locus", piece="kind/cubic_locus", estimate=False, enclosure="cubic_locus", own_map=True),
)}

KINDS = tuple(KINDS_TABLE)

# Derived views, in the registry's order.
FUNCTIONS_OF = {a.name: a.functions for a in ALGEBRAS_TABLE.values()}
POLYNOMIAL_DEGREE = {f.name: f.degree for f in FUNCTIONS_TABLE.values() if f.degree is not None}
MANDELBROT_START = {f.name: f.critical for f in FUNCTIONS_TABLE.values() if f.critical is not None}
NORM_BOUNDED = tuple(a.name for a in ALGEBRAS_TABLE.values() if a.norm_bounded)


def escape_degree(f: Any) -> int | None:
    """D where |f(q)| >= |q|^D - |c| (bounds.bounding_radius), else None; ``f`` a [fractal]."""
    return POLYNOMIAL_DEGREE.get(f.function) if ALGEBRAS_TABLE[f.algebra].norm_bounded else None


def has_distance_estimate(f: Any) -> bool:
    """Whether the march may step by a distance estimate: a kind with a proven one, an
    algebra with estimates, a polynomial function.  The other pairs are marched by the fixed
    scan (march.method = "auto")."""
    return (KINDS_TABLE[f.kind].estimate and ALGEBRAS_TABLE[f.algebra].estimate
            and FUNCTIONS_TABLE[f.function].degree is not None)


def kind_hooks(name: str) -> Any:
    """The host-side hooks of kind ``name`` (its entry's ``host`` module): ``defines(scene)``,
    its -D switches; ``set_radius(scene)``, the radius of a ball about the origin that holds
    the set; ``check(scene)``, its rules (a SceneError naming the key to change)."""
    return importlib.import_module(KINDS_TABLE[name].host)


def march_method(scene: Any) -> str:
    """march.method with "auto" resolved: "de" where the pair has a distance estimate,
    else "fixed"."""
    m = scene.march.method
    if m != "auto":
        return m
    return "de" if has_distance_estimate(scene.fractal) else "fixed"


def locus_escape_radius(radius: float) -> float:
    """The escape radius of every f_{a,b}(z) = z^3 - 3 a^2 z + b with |a|, |b| <= radius: the
    root R of R^3 - (3 radius^2 + 1) R - radius = 0, beyond which |f(z)| >= |z|^3 - 3 |a|^2 |z|
    - |b| > |z| and the orbit grows without bound (kernels/kind/cubic_locus.cl)."""
    k = 3.0 * radius * radius + 1.0
    lo, hi = math.sqrt(k), math.sqrt(k) + radius + 1.0   # g(lo) = -radius < 0 < g(hi)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid * mid * mid - k * mid - radius > 0:
            hi = mid
        else:
            lo = mid
    return hi
