"""The iteration a scene compiles, assembled for the float64 reference the way
kernel_config.iteration_pieces assembles kernels: one algebra module (reference/algebra/) and one
function module (reference/function/), by the scene's names."""
from __future__ import annotations

import functools
import importlib
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from pyjulia4d.fractal.registry import ALGEBRAS_TABLE, FUNCTIONS_TABLE, KINDS_TABLE
from pyjulia4d.scene.model import Fractal


# The [fractal] keys that choose the map and the set (scene/model.Fractal: their meaning and
# defaults, one source for both); c, max_iter and bailout are the march's record's
# (pipeline/plan.MarchArgs), as the kernels take them.
FORMULA_KEYS = ("algebra", "function", "exponent", "kind", "theta", "c_from", "c_to", "component", "locus_radius")
_DEFAULT = {f.name: f.default for f in fields(Fractal) if f.name in FORMULA_KEYS}


@dataclass(frozen=True)
class Formula:
    """q -> f(q) + c in an algebra, with the interface iterate.cl uses: ALG_IN, ALG_C,
    ALG_NORM2, ALG_DOT, julia_f, julia_f_jvp and, where a distance estimate exists,
    JULIA_DF2; the kind's twin (kind_twin) and enclosures.  Its fields are the [fractal]
    table's FORMULA_KEYS, with that table's defaults."""
    algebra: str = _DEFAULT["algebra"]
    function: str = _DEFAULT["function"]
    exponent: tuple[float, float] = _DEFAULT["exponent"]
    kind: str = _DEFAULT["kind"]
    theta: float = _DEFAULT["theta"]
    c_from: tuple[float, float] = _DEFAULT["c_from"]
    c_to: tuple[float, float] = _DEFAULT["c_to"]
    component: str = _DEFAULT["component"]
    locus_radius: float = _DEFAULT["locus_radius"]
    alg: Any = field(init=False, repr=False, compare=False)
    fn: Any = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        # the twins the registry names (fractal/registry.py), and the function's degree from it
        alg = importlib.import_module(ALGEBRAS_TABLE[self.algebra].twin)
        entry = FUNCTIONS_TABLE[self.function]
        mod = importlib.import_module(entry.twin)
        if self.function == "pwr":
            p = complex(*self.exponent)
            fn = _Bound(functools.partial(mod.cfun, p=p), functools.partial(mod.cfun_d, p=p), None,
                        functools.partial(mod.cfun_disc, p=p), functools.partial(mod.FUNC_M2, p=p),
                        functools.partial(mod.FUNC_ROUND_GAIN, p=p))
        else:
            fn = _Bound(mod.cfun, mod.cfun_d, entry.degree, mod.cfun_disc, getattr(mod, "FUNC_M2", None),
                        FUNC_D2_SIGN=getattr(mod, "FUNC_D2_SIGN", None))
        object.__setattr__(self, "alg", alg)
        object.__setattr__(self, "fn", fn)

    # the algebra's interface
    def ALG_IN(self, p):
        return self.alg.ALG_IN(p)

    def ALG_C(self, c):
        return self.alg.ALG_C(c)

    def ALG_NORM2(self, q):
        return self.alg.ALG_NORM2(q)

    def ALG_DOT(self, a, b):
        return self.alg.ALG_DOT(a, b)

    def julia_f(self, q, c):
        if self.theta != 0:
            from pyjulia4d.reference.kind.rotate import rot_f
            return rot_f(q, c, self.theta, lambda x, cc: self.alg.julia_f(x, cc, self.fn))
        return self.alg.julia_f(q, c, self.fn)

    def julia_f_jvp(self, q, h):
        if self.theta != 0:
            from pyjulia4d.reference.kind.rotate import rot_f_jvp
            return rot_f_jvp(q, h, self.theta, lambda x, hh: self.alg.julia_f_jvp(x, hh, self.fn))
        return self.alg.julia_f_jvp(q, h, self.fn)

    @property
    def has_de(self) -> bool:
        de = self.alg.ALG_HAS_DE
        return bool(self.fn.FUNC_POWER) if de == "polynomial" else bool(de)

    @property
    def enclose(self):
        """The algebra's orbit enclosures for the proven march (reference/enclose/, the twin
        of the registry's enclosure piece)."""
        return importlib.import_module("pyjulia4d.reference." + ALGEBRAS_TABLE[self.algebra].enclosure_piece.replace("/", "."))

    @property
    def kind_enclose(self):
        """The kind's orbit enclosures (reference/enclose/julia.py, mandelbrot.py: the twin of the
        registry's kind enclosure piece)."""
        return importlib.import_module("pyjulia4d.reference." + KINDS_TABLE[self.kind].enclosure_piece.replace("/", "."))

    @property
    def kind_twin(self):
        """The kind's twin module (reference/kind/<kind>.py: inside, level, normal, and where it
        has them distance_formula and orbit_start), None for the Julia set itself."""
        twin = KINDS_TABLE[self.kind].twin
        return importlib.import_module(twin) if twin else None

    @property
    def own_map(self) -> bool:
        """The kind iterates a complex map of its own, not the algebra's (registry Kind.own_map)."""
        return KINDS_TABLE[self.kind].own_map

    @property
    def split(self) -> bool:
        """A split algebra: the estimate is that of a product of two sets (iterate.cl)."""
        return bool(getattr(self.alg, "ALG_SPLIT", False))

    @property
    def growth(self) -> int:
        """JULIA_GROWTH: the degree of a polynomial map, else 2 (iterate.cl)."""
        return self.fn.FUNC_POWER or 2

    def JULIA_DF2(self, m2):
        return self.alg.JULIA_DF2(m2, self.fn.FUNC_POWER)


@dataclass(frozen=True)
class _Bound:
    cfun: Any
    cfun_d: Any
    FUNC_POWER: int | None
    cfun_disc: Any = None   # its disc enclosure (reference/enclose/disc.py)
    FUNC_M2: Any = None     # its bound on |f''| over a disc, where it has one (reference/enclose/split.py)
    FUNC_ROUND_GAIN: Any = None   # how many times more than a few ulps its value loses, where it does
    FUNC_D2_SIGN: int | None = None   # f'' = FUNC_D2_SIGN f, where that holds (reference/enclose/split.py)


QUATERNION_SQR = Formula()


def formula_of(fractal) -> Formula:
    """The Formula of a scene's [fractal] table: its FORMULA_KEYS, numbers as floats."""
    def plain(v):
        if isinstance(v, str):
            return v
        return tuple(float(x) for x in v) if isinstance(v, (tuple, list)) else float(v)
    return Formula(**{k: plain(getattr(fractal, k)) for k in FORMULA_KEYS})


def complex_value(fn_name: str, z, exponent=(2.0, 0.0)):
    """The function module's f(z) on complex numbers (the tests' handle)."""
    f = Formula("hypercomplex", fn_name, tuple(exponent)).fn
    return f.cfun(np.asarray(z, np.complex128)), f.cfun_d(np.asarray(z, np.complex128))
