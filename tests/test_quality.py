"""Each quality preset meets its stated error on the exact oracles: c = 0 (the ball)
and real c (the 2D oracle); the presets differ where they say they do."""
import numpy as np
import pytest

from pyjulia4d.measure import truth
from pyjulia4d.scene.quality import (BOUND_MAX_ITER, MARCH_KEYS, PRESETS, QUALITIES, apply_quality, preset_overrides,
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
    assert stated_p99(quality, scene.fractal.max_iter) == p["p99_bound"]
    res = render(s)
    hit = res.status == 1
    both = hit & tr.hit
    assert both.sum() > 0.2 * W * H
    err = np.abs(res.depth[both].astype(np.float64) - tr.depth[both])
    assert np.mean(hit != tr.hit) <= p["silhouette_bound"]
    assert np.percentile(err, 99) <= p["p99_bound"]
    # the certified bracket holds the truth (float32 slack: 8 spacings at the depth)
    br = res.bracket[both].astype(np.float64)
    signed = res.depth[both].astype(np.float64) - tr.depth[both]
    slack = 8 * truth._ulp32(res.depth[both])
    assert np.mean((signed <= slack) & (-signed <= br + slack)) >= 0.99


def test_presets_differ_where_they_say(truths):
    """draft -> normal -> final: each a narrower certified bracket and a smaller p99 depth
    error on the real-c oracle, and a smaller (or equal) epsilon - fewer thin parts stepped
    over (benchmarks/results/error_vs_time.md)."""
    scene, tr = truths["real"]
    got = {}
    for q in ("draft", "normal", "final"):
        res = render(apply_quality(scene, q))
        both = (res.status == 1) & tr.hit
        err = np.abs(res.depth[both].astype(np.float64) - tr.depth[both])
        got[q] = (res.bracket_stats()["p99"], np.percentile(err, 99))
    assert got["draft"][0] > 10 * got["normal"][0] and got["normal"][0] > 2 * got["final"][0]
    assert got["draft"][1] > 10 * got["normal"][1] and got["normal"][1] > 2 * got["final"][1]
    eps = [PRESETS[q]["epsilon"] for q in ("draft", "normal", "final")]
    posts = [PRESETS[q]["post_steps"] for q in ("draft", "normal", "final")]
    assert eps == sorted(eps, reverse=True) and posts == sorted(posts)


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
    s2 = Scene.from_dict({"march": {"quality": "final", "epsilon": 1e-3}})
    assert s2.march.epsilon == 1e-3 and s2.march.post_steps == p["post_steps"]
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
    assert "refine" in MARCH_KEYS and set(QUALITIES) == {"custom"} | set(PRESETS)
    assert preset_values("custom") == {} and set(preset_values("normal")) == set(MARCH_KEYS)
    # no bound is stated beyond BOUND_MAX_ITER (float32 cannot resolve those sets: quality.py)
    assert stated_p99("final", BOUND_MAX_ITER) == PRESETS["final"]["p99_bound"]
    assert stated_p99("final", BOUND_MAX_ITER + 1) is None and stated_p99("custom", 12) is None
    for q in PRESETS:
        Scene.default().with_overrides(preset_overrides(q))
    with pytest.raises(ValueError):
        apply_quality(Scene.default(), "ultra")
