"""The ground-truth oracles of pyjulia4d/measure/truth.py checked on their own terms:
the real-c reduction against direct 4D iteration, the c = 0 depth against the
analytic ball, the 2D oracle against the analytic ball (c1 = 0), and the
converged double-precision scan against the 2D oracle."""
import numpy as np
import pytest

from pyjulia4d import reference as ref
from pyjulia4d.measure import brute_force, truth
from pyjulia4d.geometry.camera import camera_frame, march_radius
from pyjulia4d.opencl.executor import render
from pyjulia4d.scene.model import Scene

W, H = 32, 24


def rays(scene):
    return ref.generate_rays(camera_frame(scene), scene.image.width, scene.image.height)


@pytest.mark.parametrize("c1", [-1.0, -0.75, -0.12, 0.25, -1.4])
@pytest.mark.parametrize("max_iter", [3, 8, 12])
def test_real_c_reduction_matches_4d_iteration(c1, max_iter):
    rng = np.random.default_rng(int(1000 * abs(c1)) + max_iter)
    # random points in the bounding box plus points near the set's boundary (where
    # a wrong reduction would show): jitter points found inside by a coarse grid
    p = rng.uniform(-1.8, 1.8, (6000, 4))
    ins = ref.julia_inside(p, (c1, 0, 0, 0), max_iter, 4.0)
    near = p[ins][:300, None, :] + rng.normal(0, 0.05, (min(300, ins.sum()), 10, 4))
    p = np.concatenate([p, near.reshape(-1, 4)])
    got = truth.real_c_inside(p, c1, max_iter, 4.0)
    want = ref.julia_inside(p, (c1, 0, 0, 0), max_iter, 4.0)
    assert want.any() and not want.all()
    assert np.array_equal(got, want)


def test_sphere_depth_matches_fixed_scan_with_post_steps():
    s = Scene.default().with_overrides(["fractal.c=0,0,0,0", f"image.width={W}", f"image.height={H}",
                                        "march.method=fixed", "march.z_resolution=200", "march.post_steps=10"])
    o, d = rays(s)
    rho = truth.sphere_radius(s.fractal.max_iter, s.fractal.bailout)
    t = truth.sphere_depth(o, d, rho)
    res = render(s)
    hit = res.status.ravel() == 1
    assert np.mean(hit != np.isfinite(t)) < 0.01          # only grazing rays may differ
    both = hit & np.isfinite(t)
    R = march_radius(s)
    h = 2 * R / s.march.z_resolution                        # the longest chord's step
    err = np.abs(res.depth.ravel()[both] - t[both])
    assert err.max() < h / 2 ** 10 + 2e-5                 # Ödegaard & Wennergren eq. 12, plus float32


def test_real_c_depth_with_c1_zero_is_the_ball():
    s = Scene.default().with_overrides(["fractal.c=0,0,0,0", f"image.width={W}", f"image.height={H}"])
    o, d = rays(s)
    rho = truth.sphere_radius(12, 4.0)
    want = truth.sphere_depth(o, d, rho)
    got = truth.real_c_depth(o, d, 0.0, 12, 4.0, n_scan=2000)
    both = np.isfinite(want) & np.isfinite(got)
    assert np.mean(np.isfinite(want) != np.isfinite(got)) < 0.01
    assert np.abs(got[both] - want[both]).max() < 1e-9


def test_converged_depth_converges_and_matches_the_2d_oracle():
    s = Scene.default().with_overrides(["fractal.c=-1,0,0,0", "image.width=24", "image.height=18"])
    cd = truth.converged_depth(s, z_start=1000)
    assert cd.converged
    last = cd.record[-1]
    assert last["changed_fraction"] <= cd.frac
    assert [r["z_resolution"] for r in cd.record][:2] == [1000, 2000]
    o, d = rays(s)
    want = truth.real_c_depth(o, d, -1.0, 12, 4.0, n_scan=4000).reshape(18, 24)
    assert np.mean(np.isfinite(want) != cd.hit) <= 2 / want.size
    both = cd.hit & np.isfinite(want)
    assert np.median(np.abs(cd.depth[both] - want[both])) < 1e-9


def test_converged_depth_on_a_complex_c():
    s = Scene.default().with_overrides(["fractal.c=-0.803762,-0.40615,0,0", "fractal.max_iter=8",
                                        "image.width=24", "image.height=18"])
    cd = truth.converged_depth(s, z_start=1000)
    assert cd.converged and cd.hit.any()
    # the polished depth is on the set's boundary: just before it outside, just after inside
    o, d = rays(s)
    k = np.nonzero(cd.hit.ravel())[0]
    t = cd.depth.ravel()[k]
    f = s.fractal
    inside = ref.julia_inside(o[k] + (t + 1e-9)[:, None] * d[k], f.c, f.max_iter, f.bailout)
    outside = ~ref.julia_inside(o[k] + (t - 1e-9)[:, None] * d[k], f.c, f.max_iter, f.bailout)
    assert np.mean(inside & outside) > 0.95


def test_truth_normals():
    s = Scene.default().with_overrides(["fractal.c=0,0,0,0", f"image.width={W}", f"image.height={H}"])
    tr = truth.ground_truth(s)
    o, d = rays(s)
    t = np.where(tr.hit.ravel(), tr.depth.ravel(), 0.0)
    jac = truth.jacobian_normals(np.where(tr.hit.ravel()[:, None], o + t[:, None] * d, np.nan), s)
    a = np.sum(jac.reshape(H, W, 3)[tr.hit] * tr.normal[tr.hit], -1)
    assert np.all(a > 1 - 1e-9)                             # the analytic normal is radial at c = 0


def test_earliest_keeps_the_earlier_crossing_and_counts_each_source():
    inf = np.inf
    scan = np.array([1.0, 2.0, inf, 3.0, inf])
    de = np.array([1.0, 1.5, 2.5, inf, inf])
    t, rec = truth.earliest(None, None, scan, de)
    assert np.array_equal(t, [1.0, 1.5, 2.5, 3.0, inf])
    assert (rec["de_first"], rec["scan_first"], rec["de_only"], rec["scan_only"], rec["rays_hit"]) == (2, 1, 1, 1, 4)
    assert rec["de_lead_max"] == 0.5


def test_de_search_finds_hairs_the_scan_steps_over():
    # real c = -1 at max_iter 50: the truncated set has inside runs 1e-9..1e-6 long in front of
    # its thick surface; the 2D oracle's scan misses many, the double-precision de search finds
    # them; the truth is the earlier crossing and is verified in float64 (inside at the depth)
    s = Scene.default().with_overrides(["fractal.c=-1,0,0,0", "fractal.max_iter=50", "camera.position=-2,1,5,0.8",
                                        "image.width=24", "image.height=18"])
    o, d = rays(s)
    scan = truth.real_c_depth(o, d, -1.0, 50, 4.0, n_scan=2000)
    tr = truth.ground_truth(s, n_scan=2000)
    rec = tr.record["de_search"]
    assert rec["de_first"] > 0 and rec["verified"] >= 0.9 * rec["hit"]
    t = tr.depth.ravel()
    hit = tr.hit.ravel()
    assert np.all(t[hit] <= scan[hit] + 1e-12)           # never later than the scan
    assert np.array_equal(hit, np.isfinite(scan) | hit)
    # inside at the depth by the 4D iteration or by the 2D oracle (at 1e-9 scales the two
    # orders of float64 arithmetic can classify a point differently)
    p = o[hit] + t[hit, None] * d[hit]
    inside = ref.julia_inside(p, s.fractal.c, 50, 4.0) | truth.real_c_inside(p, -1.0, 50, 4.0)
    assert np.mean(inside) >= 0.99


def test_brute_force_depth_is_the_analytic_ball():
    """c = 0: the brute force's first crossing is the ray-ball entry to float64 rounding."""
    s = Scene.default().with_overrides([f"image.width={W}", f"image.height={H}", "fractal.c=0,0,0,0",
                                        "fractal.max_iter=3"])
    o, d = rays(s)
    t = brute_force.brute_force_depth(s, o, d)
    ts = truth.sphere_depth(o, d, truth.sphere_radius(3, 4.0))
    assert np.array_equal(np.isfinite(t), np.isfinite(ts)) and np.isfinite(t).sum() > 100
    m = np.isfinite(ts)
    assert np.max(np.abs(t[m] - ts[m])) < 1e-12


def test_refine_depth_finds_what_a_coarse_chord_stepped_over():
    """c = 0 with a chord as long as the ball is wide: the scan steps over the ball on many
    rays; a point inside it (the analytic chord's midpoint) as a sample brings back the
    analytic entry, and a point outside it (or behind the truth) changes nothing."""
    s = Scene.default().with_overrides([f"image.width={W}", f"image.height={H}", "fractal.c=0,0,0,0",
                                        "fractal.max_iter=3"])
    o, d = rays(s)
    R = truth.sphere_radius(3, 4.0)
    ts = truth.sphere_depth(o, d, R)
    coarse = brute_force.brute_force_depth(s, o, d, chord=2.2 * R)
    m = np.isfinite(ts)
    stepped = m & ~np.isfinite(coarse)
    assert stepped.sum() > 20                      # the coarse scan stepped over the ball there
    b = np.sum(o * d, -1)
    mid = np.where(m, -b, np.inf)                  # the chord's midpoint: inside the ball
    fixed, moved = brute_force.refine_depth(s, o, d, coarse, mid, chord=2.2 * R)
    assert moved >= stepped.sum()
    assert np.max(np.abs(fixed[m] - ts[m])) < 1e-12 and not np.isfinite(fixed[~m]).any()
    outside = np.where(m, ts - 1e-3, np.inf)       # just in front of the ball: outside
    same, moved = brute_force.refine_depth(s, o, d, coarse, outside, chord=2.2 * R)
    assert moved == 0 and np.array_equal(same, coarse)


@pytest.mark.parametrize("algebra,function", [("quaternion", "sqr"), ("hypercomplex", "sin"), ("cquat", "cube")])
def test_brute_force_depth_is_a_verified_crossing(algebra, function):
    """Any pair: each crossing is inside the set (its float64 twin) with an outside point
    1e-9 in front of it (bisection to float64 resolution)."""
    s = Scene.from_dict({"fractal": {"algebra": algebra, "function": function, "max_iter": 6},
                         "camera": {"position": [2.5, 2.0, -3.0]}, "image": {"width": 16, "height": 12}})
    o, d = rays(s)
    t = brute_force.brute_force_depth(s, o, d)
    hit = np.isfinite(t)
    assert hit.sum() > 5
    F, f = ref.formula_of(s.fractal), s.fractal
    inside = lambda p: ref.julia_inside(p, f.c, f.max_iter, f.bailout, F)  # noqa: E731
    k = np.nonzero(hit)[0]
    assert inside(o[k] + t[k, None] * d[k]).all()
    front = np.maximum(t[k] - 1e-9, 0)
    entered = t[k] - 1e-9 > 0
    assert not inside(o[k][entered] + front[entered, None] * d[k][entered]).any()
