"""The escape ladder of the proven march's enclosures (kernels/march/proven.cl enc_ladder_of,
kernels/enclose/julia.cl, kernels/enclose/split.cl enc_outside_parts; twin
reference/enclose/julia.py ladder), held to the mathematics in float64: a point beyond the
ladder's radius for j iterations left is beyond the bailout within j iterations of the map,
on the worst first step and on random ones; a weakened ladder fails these."""
from __future__ import annotations

import importlib

import numpy as np
import pytest

from pyjulia4d.reference.formula import Formula


@pytest.mark.parametrize("function,c,bailout", [("sqr", (-0.2, 0.8, 0.0, 0.0), 4.0), ("cube", (0.3, -0.5, 0.4, 0.1), 4.0),
                                                ("sqr", (-1.1, 0.1, 0.2, -0.3), 16.0), ("sqr", (0.0, 1.9, 0.0, 0.0), 1.5)])
def test_the_ladder_passes_the_bailout_in_time(function, c, bailout):
    """The escape ladder (kernels/march/proven.cl enc_ladder_of, twin reference/enclose/julia.py
    ladder): a point beyond t_j is beyond the bailout within j iterations.  Checked on the worst
    first step, q^D opposite c (|q^D + c| = |q|^D - |c|, which makes the bound tight there:
    a point 0.1 % inside t_1 need not pass), and on random directions, in float64; t_j never
    exceeds the bailout, and with a bailout under the fixed point it is the bailout itself."""
    F = Formula(algebra="quaternion", function=function)
    D, c = F.fn.FUNC_POWER, np.asarray(c, float)
    t, t2, parts = importlib.import_module("pyjulia4d.reference.enclose.julia").ladder(c, 30, bailout, F)
    assert parts is None
    assert t[0] == bailout and all(x <= bailout for x in t) and np.allclose(np.square(t), t2, rtol=1e-12)
    u = -c / np.linalg.norm(c)   # q^D = -|q|^D c / |c|: the principal D-th root of that quaternion
    root = lambda s: (lambda a, v: np.concatenate([[s ** (1 / D) * np.cos(a)], s ** (1 / D) * np.sin(a) * v]))(
        np.arccos(np.clip(u[0], -1, 1)) / D, u[1:] / max(np.linalg.norm(u[1:]), 1e-300))
    rng = np.random.default_rng(7)
    for j in range(1, len(t)):
        q = np.vstack([root(t[j] ** D * (1 + 1e-9)), rng.normal(size=(500, 4))])
        q[1:] *= t[j] * (1 + 1e-9) / np.linalg.norm(q[1:], axis=1, keepdims=True)
        assert np.allclose(F.julia_f(q[:1], c * 0)[0], t[j] ** D * (1 + 1e-9) * u, rtol=1e-9)
        passed = np.linalg.norm(q, axis=1) > bailout   # some |q_i| > bailout, i = 0 .. j: outside
        for _ in range(j):
            q = np.where(passed[:, None], 0.0, F.julia_f(q, c))   # the passed stop (no overflow)
            passed |= np.linalg.norm(q, axis=1) > bailout
        assert passed.all(), j
    if t[1] < bailout:   # tight on the first step: just inside t_1 the worst point stays in
        q = root(t[1] ** D * (1 - 1e-3))[None]
        assert np.linalg.norm(F.julia_f(q, c)) <= bailout


@pytest.mark.parametrize("function", ["sqr", "cube"])
def test_the_part_ladder_passes_the_bailout_in_time(function):
    """A split algebra's ladder per component (twin reference/enclose/julia.py ladder,
    kernels/enclose/split.cl enc_outside_parts): a component a beyond pa_j has |a| > sqrt(2)
    bailout within j iterations of a^D + c_a, so |h| >= |a| / sqrt(2) is past the bailout; on the
    worst first step (a^D opposite c_a) and random ones, in float64."""
    F = Formula(algebra="hypercomplex", function=function)
    D, c, bailout = F.fn.FUNC_POWER, np.array([0.3, -0.5, 0.4, 0.1]), 4.0
    _, _, parts = importlib.import_module("pyjulia4d.reference.enclose.julia").ladder(c, 30, bailout, F)
    cp = F.ALG_C(c)
    rng = np.random.default_rng(3)
    for (pa, _), ck in zip((parts[0:2], parts[2:4]), (complex(cp[0], cp[1]), complex(cp[2], cp[3]))):
        assert pa[0] >= np.sqrt(2) * bailout and max(pa) == pa[0]
        for j in range(1, len(pa)):
            r = pa[j] * (1 + 1e-9)
            a = np.concatenate([[r * np.exp(1j * (np.angle(-ck) + 2 * np.pi * k) / D) for k in range(D)],
                                r * np.exp(2j * np.pi * rng.random(200))])
            passed = np.abs(a) > np.sqrt(2) * bailout
            for _ in range(j):
                a = np.where(passed, 0, a ** D + ck)
                passed |= np.abs(a) > np.sqrt(2) * bailout
            assert passed.all(), j
