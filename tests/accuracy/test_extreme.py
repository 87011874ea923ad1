"""The extreme-case catalogue (pyjulia4d/measure/catalogue.py), both march methods.

Every case must terminate within its step caps, leak no NaN or infinity into the
outputs, count every guard that fired, and agree with the float64 render of the same
scene within the case's stated tolerance - or be a documented precision limit, whose
measured error benchmarks/accuracy/extreme_cases.py reports.  The float64 renders are the
double kernels, held here to the numpy reference on the cases cheap enough for it.
Plus: the distance estimate and the normals stay finite at max_iter 10000 and
bailout 1e6 in float32; overflowing bailouts and hopeless workloads are refused
before any kernel runs.
"""
import time
import warnings
from functools import lru_cache

import numpy as np
import pytest

from harness import Runner
from pyjulia4d.pipeline import kernel_config, workload
from pyjulia4d.measure import catalogue as cat
from pyjulia4d import reference as ref
from pyjulia4d.geometry.camera import camera_frame
from pyjulia4d.opencl.executor import render
from pyjulia4d.pipeline.codes import STATUS_CAPPED, STATUS_HIT, STATUS_MISS
from pyjulia4d.scene.model import Scene
from pyjulia4d.scene.checks import SceneError
from pyjulia4d.fractal.registry import march_method

CASES = cat.catalogue()
IDS = [c.name for c in CASES]
PAIRS = [pytest.param(c, m, id=f"{c.name}-{m}") for c in CASES for m in c.methods]


@lru_cache(maxsize=None)
def rendered(name, method, precision):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)   # epsilon_below_ulp warns by design
        return render(cat.scene(name, method, precision))


def check_outputs(res, s):
    """Terminated within the caps; no NaN/inf; guards consistent with the outputs."""
    st = res.status
    assert set(np.unique(st)) <= {STATUS_MISS, STATUS_HIT, STATUS_CAPPED}
    hit = st == STATUS_HIT
    m = s.march
    cap = m.z_resolution + 1 if march_method(s) == "fixed" else m.max_steps
    assert np.all((res.samples >= 0) & (res.samples <= cap))
    assert not np.any(np.isnan(res.depth))
    assert np.all(np.isfinite(res.depth[hit])) and np.all(res.depth[hit] >= 0)
    assert np.all(np.isposinf(res.depth[~hit]))
    assert np.all(np.isfinite(res.normal))
    np.testing.assert_allclose(np.linalg.norm(res.normal[hit], axis=-1), 1, atol=1e-5)
    assert np.all(res.normal[~hit] == 0)
    assert np.all(np.isfinite(res.color)) and np.all(np.isfinite(res.alpha))
    assert np.all(np.isfinite(res.position[hit])) and np.all(np.isnan(res.position[~hit]))
    g = res.guards
    assert set(g) == {"ulp_step", "normal_fallback", "jacobian_tiny", "eye_hit", "shell_miss"}
    # every hit's depth is certified: a bracket of finite width >= 0 behind it, +inf elsewhere
    assert np.all(np.isfinite(res.bracket[hit])) and np.all(res.bracket[hit] >= 0)
    assert np.all(np.isposinf(res.bracket[~hit]))
    assert g["shell_miss"] == 0 or march_method(s) == "de"
    assert g["eye_hit"] == int(np.sum(hit & (res.depth == 0)))
    assert all(0 <= v <= st.size for v in g.values())


def _termination_cases():
    """Every case and method in single precision; in double every other case (the rest
    marked slow: `pytest -m slow`), which keeps the suite within its five minutes."""
    out = []
    for i, c in enumerate(CASES):
        for m in c.methods:
            out.append(pytest.param(c, m, "single", id=f"{c.name}-{m}-single"))
            out.append(pytest.param(c, m, "double", id=f"{c.name}-{m}-double",
                                    marks=[] if i % 2 == 0 else [pytest.mark.slow]))
    return out


@pytest.mark.parametrize("case,method,precision", _termination_cases())
def test_terminates_and_stays_finite(case, method, precision):
    # returning at all, with every sample count within its cap, is the termination guarantee
    check_outputs(rendered(case.name, method, precision), cat.scene(case, method, precision))


def errors(case, method):
    a, b = rendered(case.name, method, "single"), rendered(case.name, method, "double")
    both = (a.status == STATUS_HIT) & (b.status == STATUS_HIT)
    err = np.abs(a.depth[both].astype(float) - b.depth[both].astype(float))
    return float(np.mean(a.status != b.status)), err, int(both.sum())


@pytest.mark.parametrize("case,method", PAIRS)
def test_single_agrees_with_double(case, method):
    mism, err, nboth = errors(case, method)
    if case.limit:
        # a documented precision limit: measured and reported (benchmarks/accuracy/extreme_cases.py),
        # not held to a tolerance; it must still be finite and terminated (test above)
        assert np.all(np.isfinite(err))
        return
    assert nboth >= case.both_hit_min
    assert mism <= case.status_tol_for(method)
    if err.size:
        tol = case.depth_tol_for(method)
        assert np.median(err) <= tol
        assert np.mean(err > tol) <= case.status_tol_for(method)


# the float64 truth itself: double kernels against the numpy reference, where it is cheap
# (c_zero's fixed scan is left out: its first sample lies exactly on the surface, so the
# last bit of float64 rounding decides it, differently in numpy and OpenCL)
REF_CASES = [(n, m) for n in ["c_zero", "camera_far", "camera_inside", "critical_point_eye",
                              "max_iter_1", "bailout_1e3", "post_steps_60", "deep_zoom"]
             for m in cat.METHODS if (n, m) != ("c_zero", "fixed")]


@pytest.mark.parametrize("name,method", REF_CASES)
def test_double_kernel_matches_reference(name, method):
    s = cat.scene(name, method, "double")
    k = rendered(name, method, "double")
    r = ref.render(s)
    check_outputs(r, s)
    assert np.mean(k.status != r.status) <= 0.005
    both = (k.status == STATUS_HIT) & (r.status == STATUS_HIT)
    # depth is returned as float32 by render(): one float32 ulp of t
    np.testing.assert_allclose(k.depth[both], r.depth[both], rtol=2e-7, atol=1e-9)
    assert k.guards == r.guards


def test_far_camera_near_far_no_cancellation():
    """The bounding-sphere entry of a camera 1e4 away: b^2 - |o|^2 cancelled in float32
    and threw near/far off by ~1 (20% of pixels lost); radius^2 - |o - b d|^2 does not."""
    a = rendered("camera_far", "de", "single")
    b = rendered("camera_far", "de", "double")
    assert np.mean(a.status != b.status) <= 0.01
    both = (a.status == 1) & (b.status == 1)
    assert np.median(np.abs(a.depth[both] - b.depth[both])) < 2e-3   # ~ ulp(1e4) = 1e-3


def test_epsilon_below_ulp_steps_by_ulp_and_counts_it():
    """t + step == t in float32: the march steps one ulp instead of stalling (or spinning to
    max_steps), reaches the surface and counts the pixels (guards["ulp_step"])."""
    a = rendered("epsilon_below_ulp", "de", "single")
    b = rendered("epsilon_below_ulp", "de", "double")
    assert a.guards["ulp_step"] > 0 and a.capped == 0
    assert b.guards["ulp_step"] == 0          # 1e-8 is far above float64's spacing
    assert np.mean(a.status != b.status) <= 0.01
    both = (a.status == STATUS_HIT) & (b.status == STATUS_HIT)
    # effective epsilon = ulp(t) ~ 2.4e-7 at t ~ 2.5: the depth within a few ulp of float64
    assert np.median(np.abs(a.depth[both] - b.depth[both])) < 1e-6
    assert np.median(a.samples[both]) < 200   # a few ulp steps past the geometric approach
    with pytest.warns(RuntimeWarning, match="march.epsilon"):
        workload.check(cat.scene("epsilon_below_ulp", "de", "single"))


def test_critical_point_guards_counted():
    for method in cat.METHODS:
        res = rendered("critical_point_eye", method, "single")
        n = res.status.size
        assert res.guards["eye_hit"] == n and res.guards["normal_fallback"] == n


# ------------------------------------------------------------ overflow-safe estimate

def probe_points(n=4000, seed=1):
    rng = np.random.default_rng(seed)
    p = rng.uniform(-1.6, 1.6, (n, 4))
    p[: n // 2, 3] = 0   # half on the w = 0 slice the renders see
    return p


@pytest.mark.parametrize("max_iter,bailout", [(10000, 4.0), (100, 1e6), (10000, 1e6), (10000, 9e8)])
def test_distance_estimate_finite_float32(max_iter, bailout):
    s = Scene.default().with_overrides([f"fractal.max_iter={max_iter}", f"fractal.bailout={bailout}"])
    R = Runner(kernel_config.probe_config(s))
    p = probe_points()
    n = len(p)
    inside, dist, formula = R.out(n, np.int32), R.out(n), R.out(n)
    R.named("probe_iterate", (n,), points=R.buf4(p), c=s.fractal.c, max_iter=max_iter, bailout=bailout,
            inside=inside, distance=dist, formula=formula)
    d, fm = dist.get(), formula.get()
    assert np.all(np.isfinite(d)) and np.all(d >= 0)
    assert np.all(np.isfinite(fm))
    assert np.any(inside.get() == 1) and np.any(d > 0)


@pytest.mark.parametrize("fl", ["single", "double"])
def test_derivative_beyond_range_is_rescaled(fl):
    """c = -2: points of the segment [-2, 2] never escape and their orbits are chaotic with
    |f'| ~ 2 on average, so |q_n'|^2 ~ 4^n passes 3e38 (float32) after ~64 and 1.8e308
    (float64) after ~512 iterations.  Carried as mantissa * 2^e it stays finite: the
    estimate formula (what the gradient normal differences) and the Jacobian normal."""
    s = Scene.default().with_overrides(["fractal.c=-2,0,0,0", "fractal.max_iter=10000",
                                        f"render.float={fl}"])
    x = np.linspace(-1.9, 1.9, 64)
    p = np.zeros((64, 4))
    p[:, 0] = x
    p[1::2, 1] = 1e-9      # and just off it (escaping late, or not at all in float32)
    R = Runner(kernel_config.probe_config(s))
    n = len(p)
    inside, dist, formula = R.out(n, np.int32), R.out(n), R.out(n)
    R.named("probe_iterate", (n,), points=R.buf4(p), c=s.fractal.c, max_iter=10000, bailout=4.0, inside=inside,
            distance=dist, formula=formula)
    assert np.all(np.isfinite(formula.get())) and np.all(np.isfinite(dist.get()))
    assert np.mean(inside.get()) > 0.4
    d64, esc = ref.julia_distance_formula(p, s.fractal.c, 10000, 4.0)
    assert np.all(np.isfinite(d64))
    R = Runner(kernel_config.march_config(s.with_overrides(["normals.method=jacobian"]), 1))
    fr = camera_frame(s)
    out = R.out4(n)
    R.named("normals_jacobian", (n,), point=R.buf4(p), status=R.buf(np.ones(n), np.int32), c=s.fractal.c,
            max_iter=10000, bailout=4.0, right=fr.right, up=fr.up, forward=fr.forward, normal=out,
            flags=R.buf(np.zeros(n), np.int32))
    nrm = R.get4(out)
    assert np.all(np.isfinite(nrm))
    np.testing.assert_allclose(np.linalg.norm(nrm[:, :3], axis=1), 1, atol=1e-5)


@pytest.mark.parametrize("nm", ["jacobian", "gradient", "zbuffer"])
@pytest.mark.parametrize("method", cat.METHODS)
def test_normals_finite_float32_max_iter_10000_bailout_1e6(nm, method):
    s = Scene.default().with_overrides([f"march.method={method}", f"normals.method={nm}",
                                        "fractal.max_iter=10000", "fractal.bailout=1e6",
                                        "image.width=4", "image.height=3"])
    res = render(s)
    check_outputs(res, s)
    assert res.hit_fraction > 0.3


def test_overflowing_bailout_refused():
    s = Scene.default().with_overrides(["fractal.bailout=1e10", "image.width=2", "image.height=2"])
    with pytest.raises(SceneError, match=r"^fractal\.bailout: .*overflows single"):
        render(s)
    assert workload.max_bailout("single") > 9e8
    render(s.with_overrides(["render.float=double"]))          # fine in float64
    with pytest.raises(SceneError, match=r"^fractal\.bailout:"):
        workload.check(s.with_overrides(["render.float=double", "fractal.bailout=1e80"]))


# ----------------------------------------------------------------- hopeless settings

def test_hopeless_refused_instantly():
    s = Scene.default().with_overrides(["march.method=fixed", "march.z_resolution=1000000000",
                                        "image.width=3840", "image.height=2160"])
    t0 = time.perf_counter()
    with pytest.raises(SceneError) as e:
        render(s)
    assert time.perf_counter() - t0 < 1.0
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith("march.z_resolution: 1000000000 ")
    assert "iterations" in msg and " h " in msg
    est = workload.estimate(s)
    assert est.iterations == pytest.approx(3840 * 2160 * (1e9 + 1 + 4 + 3) * 12 + 3840 * 2160 * 12 * 4)
    assert est.dominant == "march.z_resolution"
    assert workload.check(s, force=True).hours > 1   # force skips the refusal (nothing rendered)


def test_workload_warns_and_names_the_key():
    s = Scene.default().with_overrides(["fractal.max_iter=100000", "image.width=640", "image.height=480",
                                        "march.method=de"])
    with pytest.raises(SceneError, match=r"^fractal\.max_iter: "):
        workload.check(s)
    # the bound alone never warns: the 4K default's is ~5 min, its render a few seconds
    # (the probe render judges it: tests/render/test_calibrate.py)
    s = Scene.default().with_overrides(["image.width=3840", "image.height=2160", "fractal.max_iter=12"])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert workload.check(s).hours > 0.05   # the bound: ~5 min
        workload.check(Scene.default())   # the default scene: silent


def test_int_loop_counters_refused():
    s = Scene.default().with_overrides(["march.method=fixed", f"march.z_resolution={2**31 - 1}",
                                        "image.width=1", "image.height=1", "fractal.max_iter=1"])
    with pytest.raises(SceneError, match=r"^march\.z_resolution: must be below"):
        workload.check(s, force=True)
