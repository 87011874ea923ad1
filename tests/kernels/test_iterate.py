"""iterate.cl (with common/lanes.cl, algebra/quaternion.cl, function/sqr.cl, through probe.cl)
against reference.julia_inside / julia_distance / julia_distance_formula."""
import numpy as np
import pytest

from harness import Runner
from pyjulia4d.pipeline import kernel_config
from pyjulia4d import reference as ref
from pyjulia4d.scene.model import Scene

CS = [(-0.2, 0.8, 0, 0), (-0.125, -0.256, 0.847, 0.0895), (0.4, 0.5, 0, 0), (0, 0, 0, 0),
      (-0.083, 0.0, -0.83, -0.025)]


def ball_points(n, radius, seed):
    rng = np.random.default_rng(seed)
    p = rng.normal(size=(n, 4))
    r = radius * rng.uniform(0, 1, n) ** 0.25  # uniform in the 4-ball
    return p * (r / np.linalg.norm(p, axis=1))[:, None]


def run_probe(fl, p, c, max_iter, bailout):
    R = Runner(kernel_config.probe_config(Scene.default().with_overrides([f"render.float={fl}"])))
    p = p.astype(R.real).astype(np.float64)  # both sides see the same, representable inputs
    n = len(p)
    ins, d, f = R.out(n, np.int32), R.out(n), R.out(n)
    R.named("probe_iterate", (n,), points=R.buf4(p), c=c, max_iter=max_iter, bailout=bailout, inside=ins,
            distance=d, formula=f)
    return p, ins.get().astype(bool), d.get().astype(np.float64), f.get().astype(np.float64)


@pytest.mark.parametrize("fl,rtol_med,rtol_p99", [("single", 1e-6, 1e-3), ("double", 1e-14, 1e-10)])
@pytest.mark.parametrize("c", CS)
@pytest.mark.parametrize("max_iter", [1, 8, 20])
def test_iteration_matches_reference(fl, rtol_med, rtol_p99, c, max_iter):
    # float32 against float64: each squaring doubles a relative error, so after n steps
    # near the set it can reach 2^n * 6e-8; classification flips only for points within
    # that of the bailout sphere (none of 20000 random points, measured), and the
    # distance estimate's relative error stays ~1e-7 typically, below 1e-3 for 99%.
    p, ins, d, f = run_probe(fl, ball_points(20000, 2.5, 7), c, max_iter, 4.0)
    r_ins = ref.julia_inside(p, c, max_iter, 4.0)
    r_d = ref.julia_distance(p, c, max_iter, 4.0)
    r_f, esc = ref.julia_distance_formula(p, c, max_iter, 4.0)
    assert np.mean(ins != r_ins) <= 5e-4
    assert np.mean((d > 0) != (r_d > 0)) <= 5e-4
    assert np.all(d[~r_ins & ~ins] > 0) and np.all(d[ins] == 0)
    both = (d > 0) & (r_d > 0)
    rel = np.abs(d[both] - r_d[both]) / r_d[both]
    assert np.median(rel) < rtol_med and np.percentile(rel, 99) < rtol_p99
    # the unclamped formula on escaped points (inside, q_n may underflow to 0: no meaning)
    rel_f = np.abs(f[esc] - r_f[esc]) / np.abs(r_f[esc])
    assert np.percentile(rel_f, 99) < rtol_p99
    assert np.all(np.isfinite(f))


def test_reference_escape_radius_c0():
    # c = 0: |q_n| = |p|^(2^n), so p is inside iff |p| <= bailout^(2^-max_iter)
    p = ball_points(5000, 1.5, 3)
    r = np.linalg.norm(p, axis=1)
    inside = ref.julia_inside(p, (0, 0, 0, 0), 6, 4.0)
    assert np.array_equal(inside, r <= 4.0 ** (2.0 ** -6))


def test_reference_distance_c0():
    # c = 0: d = |q_n| ln|q_n| / (2 |q_n'|) = r ln r / 2 exactly, whatever n the escape took
    p = ball_points(2000, 3.0, 4)
    r = np.linalg.norm(p, axis=1)
    d = ref.julia_distance(p, (0, 0, 0, 0), 30, 4.0)
    out = r > 1.0001
    np.testing.assert_allclose(d[out], r[out] * np.log(r[out]) / 2, rtol=1e-12)


def test_quaternion_algebra():
    rng = np.random.default_rng(0)
    a, b, c = rng.normal(size=(3, 100, 4))
    np.testing.assert_allclose(ref.alg_mul(ref.alg_mul(a, b), c), ref.alg_mul(a, ref.alg_mul(b, c)), atol=1e-12)
    np.testing.assert_allclose(ref.alg_sqr(a), ref.alg_mul(a, a), atol=1e-12)
    i, j, k = np.eye(4)[1:]
    np.testing.assert_allclose(ref.alg_mul(i, j), k)   # Ödegaard & Wennergren eq. 3
    np.testing.assert_allclose(ref.alg_mul(j, i), -k)
    h = 1e-6
    jvp = ref.alg_sqr_jvp(a, b)
    fd = (ref.alg_sqr(a + h * b) - ref.alg_sqr(a - h * b)) / (2 * h)
    np.testing.assert_allclose(jvp, fd, atol=1e-6)
