"""Each quality preset (a proven march, kernels/march/proven.cl) meets its target on the exact
oracles, c = 0 (the ball) and real c (the 2D oracle), and its stated interval holds the
truth; the presets differ where they say they do; every pair takes them."""
import numpy as np
import pytest

from pyjulia4d.measure import truth
from pyjulia4d.scene.quality import (MARCH_KEYS, PRESETS, QUALITIES, apply_quality, preset_overrides,
                               preset_values, stated_p99)
from pyjulia4d.opencl.executor import render
from pyjulia4d.scene.model import Scene

W, H = 40, 30
ORACLES = {
    "sphere": ["fractal.c=0,0,0,0"],
    "real": ["fractal.c=-1,0,0,0"],
}


@pytest.fixture(scope="module")
def truths():
    out = {}
    for name, over in ORACLES.items():
        s = Scene.default().with_overrides(over + [f"image.width={W}", f"image.height={H}"])
        out[name] = (s, truth.ground_truth(s, n_scan=4000))
    return out


@pytest.mark.parametrize("quality", list(PRESETS))
@pytest.mark.parametrize("oracle", list(ORACLES))
def test_preset_meets_its_stated_error(truths, quality, oracle):
    scene, tr = truths[oracle]
    s = apply_quality(scene, quality)
    p = PRESETS[quality]
    assert (s.march.method, s.march.z_resolution, s.march.post_steps, s.march.epsilon, s.march.refine) == \
        (p["method"], p["z_resolution"], p["post_steps"], p["epsilon"], p["refine"])
    assert stated_p99(quality) == p["p99_bound"]
    res = render(s)
    hit = res.status == 1
    both = hit & tr.hit
    assert both.sum() > 0.2 * W * H
    err = np.abs(res.depth[both].astype(np.float64) - tr.depth[both])
    assert np.mean(hit != tr.hit) <= p["silhouette_bound"]
    assert np.percentile(err, 99) <= p["p99_bound"]
    # the render's own statement is within the target, and holds the truth: the crossing in
    # the bracket or the unproven segments in front of it, all within [depth - unresolved,
    # depth + bracket] here (float32 slack: 8 spacings at the depth)
    assert res.error_stats()["p99"] <= p["p99_bound"]
    d = res.depth[both].astype(np.float64)
    signed = d - tr.depth[both]
    slack = 8 * truth.ulp32(res.depth[both])
    assert np.mean((signed <= res.unresolved[both] + slack) & (-signed <= res.bracket[both] + slack)) >= 0.99


def test_presets_differ_where_they_say(truths):
    """draft -> normal -> final: a finer floor, more post-steps and a stated p99 error that
    falls (draft's several times normal's) and stays within each preset's bound, on the
    real-c oracle.  With partial proofs normal already reaches about 3e-5, where the
    enclosures widened for float32's rounding stop proving (scene/quality.py), so final
    states little less there."""
    scene, tr = truths["real"]
    got = {}
    for q in ("draft", "normal", "final"):
        res = render(apply_quality(scene, q))
        got[q] = res.error_stats()["p99"]
        assert got[q] <= PRESETS[q]["p99_bound"]
    assert got["draft"] > 3 * got["normal"] and got["normal"] >= got["final"]
    zs = [PRESETS[q]["z_resolution"] for q in ("draft", "normal", "final")]
    posts = [PRESETS[q]["post_steps"] for q in ("draft", "normal", "final")]
    assert zs == sorted(zs) and posts == sorted(posts)


@pytest.mark.parametrize("algebra,function", [("hypercomplex", "sin"), pytest.param("hypercomplex", "ln", marks=pytest.mark.slow),
                                              ("cquat", "cube"), pytest.param("commutative", "sqr", marks=pytest.mark.slow),
                                              pytest.param("quaternion", "cube", marks=pytest.mark.slow)])
def test_every_pair_takes_the_presets(algebra, function):
    s = Scene.from_dict({"fractal": {"algebra": algebra, "function": function}, "march": {"quality": "draft"},
                         "image": {"width": 24, "height": 18}})
    assert s.march.method == "proven"
    res = render(s)
    assert res.proven and (res.status == 1).any()


def test_custom_leaves_the_scene_alone():
    s = Scene.default().with_overrides(["march.z_resolution=123"])
    assert s.march.quality == "custom"
    assert apply_quality(s, "custom") is s


def test_quality_key_sets_the_march_and_explicit_keys_win():
    s = Scene.from_dict({"march": {"quality": "final"}})
    p = PRESETS["final"]
    assert (s.march.quality, s.march.method, s.march.post_steps, s.march.epsilon) == \
        ("final", p["method"], p["post_steps"], p["epsilon"])
    # a key set in the same table as the quality wins, and the scene says it is custom now
    s2 = Scene.from_dict({"march": {"quality": "final", "z_resolution": 999}})
    assert s2.march.z_resolution == 999 and s2.march.post_steps == p["post_steps"]
    assert s2.march.quality == "custom"
    # an override after the file wins over the file; a later quality override wins over keys
    s3 = Scene.from_dict({"march": {"method": "fixed", "z_resolution": 99}}, ["march.quality=draft"])
    assert s3.march.method == PRESETS["draft"]["method"] and s3.march.quality == "draft"
    s4 = Scene.from_dict({"march": {"quality": "draft"}}, ["march.post_steps=7"])
    assert s4.march.post_steps == 7 and s4.march.quality == "custom"
    # the resolved scene round-trips through TOML unchanged
    assert Scene.from_dict(s.to_dict()) == s
    assert Scene.from_dict(s2.to_dict()) == s2


def test_presets_are_valid_overrides_and_ordered():
    bounds = [PRESETS[q]["p99_bound"] for q in ("draft", "normal", "final")]
    assert bounds == sorted(bounds, reverse=True) and len(set(bounds)) == 3
    assert "refine" in MARCH_KEYS and set(QUALITIES) == {"auto", "custom"} | set(PRESETS)
    assert preset_values("custom") == {} == preset_values("auto") and set(preset_values("normal")) == set(MARCH_KEYS)
    assert stated_p99("final") == PRESETS["final"]["p99_bound"] and stated_p99("custom") is None
    for q in PRESETS:
        Scene.default().with_overrides(preset_overrides(q))
    with pytest.raises(ValueError):
        apply_quality(Scene.default(), "ultra")


# auto: the distance estimate only where it bounds the distance (connected sets)
@pytest.mark.parametrize("over,expect", [
    ([], True),                                                              # quaternion c = -0.2 + 0.8i: connected
    (["fractal.c=-1,0,0,0"], True),                                          # the basilica
    (["fractal.c=0.5414,0.3870,-0.0241,-0.0321"], False),                    # dust: escapes at the 5th iteration
    (["fractal.function=cube", "fractal.c=0.1668,0.2887,0.0337,-0.1034"], True),
    (["fractal.algebra=hypercomplex"], True),
    (["fractal.algebra=hypercomplex", "fractal.function=cube"], False),      # c_a = c_b = -0.2 + 0.8i: dust for z^3
    (["fractal.algebra=hypercomplex", "fractal.c=0.3,0,0,0.6"], False),      # c_a = 0.9 (dust), c_b = -0.3 (connected)
    (["fractal.kind=mandelbrot"], True),
    (["fractal.theta=30"], False),
    (["fractal.algebra=hypercomplex", "fractal.function=sin"], False),       # no estimate at all
    (["fractal.max_iter=12"], True),                                         # the most the estimate is trusted at
    (["fractal.max_iter=13"], False),                                        # thin parts it steps over from here
    (["fractal.algebra=hypercomplex", "fractal.max_iter=30"], False),
    (["fractal.kind=mandelbrot", "fractal.max_iter=30"], True),              # measured on the Julia sets only
])
def test_auto_takes_the_estimate_only_on_connected_sets(over, expect):
    from pyjulia4d.fractal.registry import march_method
    from pyjulia4d.scene.quality import estimate_bounds_distance
    s = Scene.default().with_overrides(over)
    assert estimate_bounds_distance(s.fractal) is expect
    assert march_method(s) == ("de" if expect else "proven")


def test_critical_orbit_in_its_planes_is_the_4d_orbit():
    """The planes critical_orbit_bounded iterates in hold the 4D orbit of 0: the float64 twin's
    own map (reference.julia_inside of the point 0) agrees on c drawn near and far from the
    connectedness locus, for both algebras and degrees."""
    from pyjulia4d.reference import Formula, julia_inside
    from pyjulia4d.scene.quality import CONNECTED_ITER, critical_orbit_bounded
    rng = np.random.default_rng(7)
    agree, seen = 0, set()
    for algebra in ("quaternion", "hypercomplex"):
        for function, degree in (("sqr", 2), ("cube", 3)):
            F = Formula(algebra=algebra, function=function)
            for _ in range(20):
                c = tuple(rng.normal(size=4) * rng.uniform(0.1, 0.6))
                radius = 2.0 + 2.0 * 2 * float(np.linalg.norm(c))   # beyond both components' escape radii
                twin = bool(julia_inside(np.zeros((1, 4)), c, CONNECTED_ITER, radius, F)[0])
                agree += twin == critical_orbit_bounded(algebra, degree, c)
                seen.add(twin)
    assert agree == 4 * 20 and seen == {True, False}
