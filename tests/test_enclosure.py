"""Proofs of empty space (reference/enclosure.py), held to the float64 twin of the set:
a segment proven empty holds no inside point at any of 201 samples along it (soundness,
every polynomial pair); proofs succeed on most short segments that sampling finds empty
(usefulness); the proving march finds each ray's first crossing no later than a float64
brute force, within its floor."""
from __future__ import annotations

import numpy as np
import pytest

from pyjulia4d import Scene, reference as ref
from pyjulia4d.geometry.camera import camera_frame, march_radius
from pyjulia4d.measure.truth import brute_force_depth
from pyjulia4d.reference import enclosure
from pyjulia4d.reference.formula import formula_of

PAIRS = [(a, f) for a in ("quaternion", "hypercomplex", "cquat", "commutative") for f in ("sqr", "cube")]


def scene_of(algebra, function, **fractal):
    return Scene.from_dict({"fractal": {"algebra": algebra, "function": function, "max_iter": 8, **fractal},
                            "camera": {"position": [2.5, 2.0, -3.0]}, "image": {"width": 12, "height": 9}})


@pytest.mark.parametrize("algebra,function", PAIRS)
def test_proven_segments_hold_no_inside_point(algebra, function):
    s = scene_of(algebra, function)
    f, F, R = s.fractal, formula_of(s.fractal), march_radius(s)
    rng = np.random.default_rng(len(algebra) * 7 + len(function))
    n = 600
    o = rng.uniform(-R, R, (n, 4))
    d = rng.normal(size=(n, 4))
    d /= np.linalg.norm(d, axis=1)[:, None]
    length = rng.choice([0.5, 0.05, 0.005], n)
    proven = enclosure.prove_empty(s, o, d, np.zeros(n), length)
    ts = np.linspace(0.0, 1.0, 201)
    p = o[:, None, :] + (ts[None, :] * length[:, None])[..., None] * d[:, None, :]
    inside = ref.julia_inside(p.reshape(-1, 4), f.c, f.max_iter, f.bailout, F).reshape(n, -1).any(axis=1)
    assert not (proven & inside).any()   # soundness: never a proof over an inside sample
    empty = ~inside
    short = empty & (length == 0.005)
    assert proven[short].mean() > 0.9    # usefulness: short empty segments are proven
    assert proven.sum() > 0.5 * n


def test_unsupported_pairs_are_refused():
    s = Scene.from_dict({"fractal": {"algebra": "hypercomplex", "function": "sin"}})
    assert not enclosure.supports(s.fractal)
    with pytest.raises(ValueError, match="no enclosure for hypercomplex sin"):
        enclosure.prove_empty(s, np.zeros((1, 4)), np.ones((1, 4)) / 2, 0.0, 1.0)


@pytest.mark.parametrize("algebra,function", [("quaternion", "sqr"), ("hypercomplex", "cube")])
def test_proving_march_is_never_behind_the_brute_force(algebra, function):
    """Each hit of the proving march lies no later than the brute force's crossing plus the
    floor (all before it is proven empty or counted unresolved), and it hits where the
    brute force does."""
    s = scene_of(algebra, function, max_iter=6)
    o, d = ref.generate_rays(camera_frame(s), 12, 9)
    every = brute_force_depth(s, o, d)
    hits, misses = np.nonzero(np.isfinite(every))[0], np.nonzero(~np.isfinite(every))[0]
    rays = list(hits[:: max(1, len(hits) // 4)][:4]) + [misses[len(misses) // 2]]   # hits across the set, a miss
    assert len(rays) == 5
    tb = every[rays]
    R = march_radius(s)
    floor = 1e-5
    for k, i in enumerate(rays):
        b = o[i] @ d[i]
        disc = b * b - (o[i] @ o[i] - R * R)
        if disc < 0:
            assert not np.isfinite(tb[k])
            continue
        near, far = max(-b - np.sqrt(disc), 0.0), -b + np.sqrt(disc)
        t, unresolved = enclosure.first_crossing(s, o[i], d[i], near, far, floor=floor, start=16)
        assert np.isfinite(t) == np.isfinite(tb[k])
        if np.isfinite(t):
            assert t <= tb[k] + floor
            assert 0 <= unresolved < 0.01
