"""Every algebra x function pair (kernels/algebra/, kernels/function/) against its float64
twin (pyjulia4d/reference/algebra/, reference/function/): the multiplication tables by
their identities, each function's derivative, one step of the map and its derivative in
the kernels, the inside test, the Jacobian normal, and whole renders."""
import numpy as np
import pytest

from harness import Runner
from pyjulia4d.pipeline import kernel_config
from pyjulia4d import reference as ref
from pyjulia4d.reference.algebra import commutative as cm, cquat as cq, hypercomplex as hc, quaternion as qa
from pyjulia4d.reference.algebra.power import product_matrix
from pyjulia4d.reference.formula import Formula, complex_value
from pyjulia4d.opencl.executor import render
from pyjulia4d.pipeline.codes import STATUS_HIT
from pyjulia4d.fractal.registry import FUNCTIONS, FUNCTIONS_OF
from pyjulia4d.scene.model import Scene
from pyjulia4d.scene.checks import SceneError

PAIRS = [(a, f) for a in FUNCTIONS_OF for f in FUNCTIONS_OF[a]]
E = np.eye(4)
ONE, I, J, K = E


def rand4(n, seed, scale=1.0):
    return np.random.default_rng(seed).normal(size=(n, 4)) * scale


# ------------------------------------------------------------ multiplication tables

def test_quaternion_table():
    # i^2 = j^2 = k^2 = ijk = -1, ij = -ji = k: associative, not commutative (Ödegaard & Wennergren eq. 3)
    m = qa.alg_mul
    for u in (I, J, K):
        np.testing.assert_array_equal(m(u, u), -ONE)
    np.testing.assert_array_equal(m(m(I, J), K), -ONE)
    np.testing.assert_array_equal(m(I, J), K)
    np.testing.assert_array_equal(m(J, I), -K)
    a, b, c = rand4(100, 1), rand4(100, 2), rand4(100, 3)
    np.testing.assert_allclose(m(m(a, b), c), m(a, m(b, c)), atol=1e-12)
    assert np.max(np.abs(m(a, b) - m(b, a))) > 0.1
    # the norm is multiplicative, and the closed forms are the products
    np.testing.assert_allclose(np.linalg.norm(m(a, b), axis=1),
                               np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1), rtol=1e-12)
    np.testing.assert_allclose(qa.alg_sqr(a), m(a, a), atol=1e-12)
    np.testing.assert_allclose(qa.alg_cube(a), m(m(a, a), a), atol=1e-12)


def test_hypercomplex_table():
    # ij = ji = k, jk = kj = -i, ki = ik = -j, i^2 = j^2 = -1, k^2 = +1 (POV-Ray 3.6 documentation's table:
    # its "kk = -1" contradicts ij = k with ijk = 1); commutative and associative, with
    # zero divisors (1 + k)(1 - k) = 0
    m = hc.alg_mul
    np.testing.assert_array_equal(m(I, I), -ONE)
    np.testing.assert_array_equal(m(J, J), -ONE)
    np.testing.assert_array_equal(m(K, K), ONE)
    np.testing.assert_array_equal(m(I, J), K)
    np.testing.assert_array_equal(m(J, K), -I)
    np.testing.assert_array_equal(m(K, I), -J)
    np.testing.assert_array_equal(m(m(I, J), K), ONE)
    np.testing.assert_array_equal(m(ONE + K, ONE - K), 0 * ONE)
    a, b, c = rand4(100, 1), rand4(100, 2), rand4(100, 3)
    np.testing.assert_allclose(m(a, b), m(b, a), atol=1e-12)
    np.testing.assert_allclose(m(m(a, b), c), m(a, m(b, c)), atol=1e-12)


def test_cquat_table():
    # Ödegaard & Wennergren eq. 14: i^2 = -1, j^2 = k^2 = 1, ij = ji = -k, ki = ik = -j, jk = kj = i;
    # commutative, NOT associative, zero divisors (1 + j)(1 - j) = 0
    m = cq.alg_mul
    np.testing.assert_array_equal(m(I, I), -ONE)
    np.testing.assert_array_equal(m(J, J), ONE)
    np.testing.assert_array_equal(m(K, K), ONE)
    np.testing.assert_array_equal(m(I, J), -K)
    np.testing.assert_array_equal(m(K, I), -J)
    np.testing.assert_array_equal(m(J, K), I)
    np.testing.assert_array_equal(m(m(I, I), J), -J)
    np.testing.assert_array_equal(m(I, m(I, J)), J)          # (ii)j != i(ij)
    np.testing.assert_array_equal(m(ONE + J, ONE - J), 0 * ONE)
    a, b = rand4(100, 1), rand4(100, 2)
    np.testing.assert_allclose(m(a, b), m(b, a), atol=1e-12)


def test_commutative_table():
    # Ödegaard & Wennergren eq. 15: i^2 = j^2 = k^2 = -1, ij = ji = k, ki = ik = j, jk = kj = i;
    # commutative, NOT associative
    m = cm.alg_mul
    for u in (I, J, K):
        np.testing.assert_array_equal(m(u, u), -ONE)
    np.testing.assert_array_equal(m(J, I), K)
    np.testing.assert_array_equal(m(I, K), J)
    np.testing.assert_array_equal(m(K, J), I)
    np.testing.assert_array_equal(m(m(I, I), J), -J)
    np.testing.assert_array_equal(m(I, m(I, J)), J)          # (ii)j != i(ij)
    a, b, c = rand4(100, 1), rand4(100, 2), rand4(100, 3)
    np.testing.assert_allclose(m(a, b), m(b, a), atol=1e-12)
    assert np.max(np.abs(m(m(a, b), c) - m(a, m(b, c)))) > 0.1


@pytest.mark.parametrize("algebra", ["cquat", "commutative"])
@pytest.mark.parametrize("power", ["sqr", "cube"])
def test_power_jvp_is_the_derivative(algebra, power):
    F = Formula(algebra, power)
    q, h = rand4(100, 8), rand4(100, 9)
    eps = 1e-6
    fd = (F.julia_f(q + eps * h, 0) - F.julia_f(q - eps * h, 0)) / (2 * eps)
    np.testing.assert_allclose(F.julia_f_jvp(q, h), fd, rtol=1e-6, atol=1e-6)


def test_hypercomplex_split_is_the_product():
    # the split (algebra/hypercomplex.cl) turns the table's product into two complex
    # products, and |h|^2 into (|a|^2 + |b|^2) / 2
    a, b = rand4(200, 4), rand4(200, 5)
    sa, sb = hc.ALG_IN(a), hc.ALG_IN(b)
    za, wa = sa[:, 0] + 1j * sa[:, 1], sa[:, 2] + 1j * sa[:, 3]
    zb, wb = sb[:, 0] + 1j * sb[:, 1], sb[:, 2] + 1j * sb[:, 3]
    prod = hc.ALG_IN(hc.alg_mul(a, b))
    np.testing.assert_allclose(prod[:, 0] + 1j * prod[:, 1], za * zb, atol=1e-12)
    np.testing.assert_allclose(prod[:, 2] + 1j * prod[:, 3], wa * wb, atol=1e-12)
    np.testing.assert_allclose(hc.ALG_NORM2(sa), np.sum(a * a, axis=1), rtol=1e-12)
    np.testing.assert_allclose(hc.ALG_OUT(sa), a, atol=1e-12)
    # the lifted sqr and cube are the table's h h and h h h
    F2, F3 = Formula("hypercomplex", "sqr"), Formula("hypercomplex", "cube")
    zero = np.zeros(4)
    np.testing.assert_allclose(hc.ALG_OUT(F2.julia_f(sa, zero)), m2 := hc.alg_mul(a, a), atol=1e-12)
    np.testing.assert_allclose(hc.ALG_OUT(F3.julia_f(sa, zero)), hc.alg_mul(m2, a), atol=1e-12)


@pytest.mark.parametrize("name", FUNCTIONS)
def test_function_derivative(name):
    # f'(z) of each function/<name>.py against a central difference of f, at points off the
    # branch cuts (a cut never lies within 1e-3 of these)
    rng = np.random.default_rng(11)
    z = rng.uniform(-1.5, 1.5, 400) + 1j * rng.uniform(-1.5, 1.5, 400)
    z = z[(np.abs(z.imag) > 1e-2) & (np.abs(z.real) > 1e-2) & (np.abs(np.abs(z) - 1) > 1e-2)]
    h = 1e-6
    f, df = complex_value(name, z, (2.5, 0.7))
    fp, _ = complex_value(name, z + h, (2.5, 0.7))
    fm, _ = complex_value(name, z - h, (2.5, 0.7))
    fd = (fp - fm) / (2 * h)
    np.testing.assert_allclose(df, fd, rtol=1e-5, atol=1e-5)


# Each function piece against its twin, on the complex plane itself (one file each)
FUNCTION_FILES = {name: f"kernels/function/{name}.cl vs pyjulia4d/reference/function/{name}.py"
                  for name in ("sqr", "cube", "exp", "reciprocal", "sin", "asin", "sinh", "asinh", "cos",
                               "acos", "cosh", "acosh", "tan", "atan", "tanh", "atanh", "ln", "pwr")}


@pytest.mark.parametrize("fl,tol", [("single", 2e-5), ("double", 1e-11)])
@pytest.mark.parametrize("name", list(FUNCTION_FILES))
def test_function_piece_matches_its_twin(name, fl, tol):
    # cfun and cfun_d of function/<name>.cl (through probe.cl's probe_cfun) against numpy's
    # complex function and its derivative: float32 keeps ~1e-7 relative per operation, a few
    # dozen of them here; points within rounding of a branch cut may land on its other side
    assert set(FUNCTION_FILES) == set(FUNCTIONS)
    s = scene_of("hypercomplex", name, f"render.float={fl}")
    R = Runner(kernel_config.probe_config(s))
    rng = np.random.default_rng(21)
    z = rng.uniform(-2, 2, 5000) + 1j * rng.uniform(-2, 2, 5000)
    z = (z.real.astype(R.real) + 1j * z.imag.astype(R.real)).astype(np.complex128)
    n = len(z)
    outs = [R.out(n) for _ in range(4)]
    R.named("probe_cfun", (n,), re=R.buf(z.real), im=R.buf(z.imag), f_re=outs[0], f_im=outs[1], d_re=outs[2],
            d_im=outs[3])
    kf = outs[0].get() + 1j * outs[1].get()
    kd = outs[2].get() + 1j * outs[3].get()
    rf, rd = complex_value(name, z, (2.5, 0.7))
    for k, r in ((kf, rf), (kd, rd)):
        ok = np.isfinite(r)
        err = np.abs(k[ok] - r[ok]) / (1 + np.abs(r[ok]))
        assert np.mean(err < tol) >= 0.995, (FUNCTION_FILES[name], np.percentile(err, [50, 99, 100]))


def test_pwr_is_the_power():
    z = rand4(50, 6)[:, 0] + 1j * rand4(50, 7)[:, 0]
    f, _ = complex_value("pwr", z, (3.0, 0.0))
    np.testing.assert_allclose(f, z ** 3, rtol=1e-12)


@pytest.mark.parametrize("power", ["sqr", "cube"])
def test_quaternion_jvp_is_the_derivative(power):
    F = Formula("quaternion", power)
    q, h = rand4(100, 8), rand4(100, 9)
    eps = 1e-6
    fd = (F.julia_f(q + eps * h, 0) - F.julia_f(q - eps * h, 0)) / (2 * eps)
    np.testing.assert_allclose(F.julia_f_jvp(q, h), fd, rtol=1e-6, atol=1e-6)


# ------------------------------------------------------------ kernels vs reference

def scene_of(algebra, function, *over):
    return Scene.default().with_overrides([f"fractal.algebra={algebra}", f"fractal.function={function}",
                                           "fractal.exponent=2.5,0.7", *over])


@pytest.mark.parametrize("fl,tol", [("single", 2e-5), ("double", 1e-11)])
@pytest.mark.parametrize("algebra,function", PAIRS)
def test_step_matches_reference(algebra, function, fl, tol):
    # one step of f(q) + c and its derivative, in the algebra's coordinates: float32 keeps
    # ~1e-7 relative per operation; the transcendental functions take a few dozen, and
    # cosh, exp amplify an argument's error by at most its size (|q| <= 2 here)
    s = scene_of(algebra, function, f"render.float={fl}")
    R = Runner(kernel_config.probe_config(s))
    p = rand4(4000, 12, 0.7).astype(R.real).astype(np.float64)
    h = rand4(4000, 13).astype(R.real).astype(np.float64)
    c = np.array(s.fractal.c)
    n = len(p)
    val, jvp = R.out4(n), R.out4(n)
    R.named("probe_step", (n,), points=R.buf4(p), dirs=R.buf4(h), c=c, value=val, jvp=jvp)
    F = ref.formula_of(s.fractal)
    q = F.ALG_IN(p)
    rv, rj = F.julia_f(q, F.ALG_C(c)), F.julia_f_jvp(q, F.ALG_IN(h))
    for k, r in ((R.get4(val), rv), (R.get4(jvp), rj)):
        ok = np.all(np.isfinite(r), axis=1)
        err = np.max(np.abs(k[ok] - r[ok]) / (1 + np.abs(r[ok])), axis=1)
        # points within rounding of a branch cut may land on its other side: 0.5% allowed
        assert np.mean(err < tol) >= 0.995, (np.percentile(err, [50, 99, 100]))


def _product_norm(alg_mul, q):
    """The norm of h -> q h, exactly: the largest singular value of its matrix."""
    return np.linalg.norm(product_matrix(alg_mul, q), ord=2, axis=(-2, -1))


@pytest.mark.parametrize("algebra,twin", [("quaternion", qa), ("cquat", cq), ("commutative", cm)])
def test_product_bound_holds_and_is_tight(algebra, twin):
    # the enclosures' bound L(q) on |q h| / |h| (kernels/algebra/power.cl, enclose/ball.cl), in
    # the float32 kernel and the float64 twin, against the exact norm: never below it by more
    # than rounding (2^-21 relative in float32, well under the 2^-18 that enclose/disc.cl's
    # ENC_UP raises each radius by; the float64 SVD's own 1e-12), and for the tables within
    # 20 % of it on every point (|q|_1 is up to 66 % above), 6 % on average; the quaternions'
    # is the norm itself
    s = scene_of(algebra, "sqr")
    R = Runner(kernel_config.probe_config(s))
    q = np.concatenate([rand4(3000, 21), rand4(500, 22, 1e-3), rand4(500, 23, 300.0),
                        E * 0.7, (E[0] + E[2]) * np.array([[1.0], [-2.5]])])
    q = q.astype(np.float32).astype(np.float64)
    out = R.out(len(q))
    R.named("probe_lbound", (len(q),), points=R.buf4(q), lbound=out)
    exact = _product_norm(twin.alg_mul, q)
    for bound, rounding in ((out.get().astype(np.float64), 2.0 ** -21), (twin.ALG_LBOUND(q), 1e-12)):
        assert np.all(bound >= exact * (1 - rounding)), np.min(bound / exact)
        assert np.all(bound <= exact * (1 + 1e-6 if algebra == "quaternion" else 1.2)), np.max(bound / exact)
    if algebra != "quaternion":
        assert np.mean(twin.ALG_LBOUND(q) / exact) < 1.06
        sq = twin.alg_mul(q, q)
        np.testing.assert_allclose(twin.ALG_LBOUND_SQR(q), twin.ALG_LBOUND(sq), rtol=1e-15)


@pytest.mark.parametrize("algebra,function", PAIRS)
def test_inside_matches_reference(algebra, function):
    # the set test over 20000 points of the ball: chaotic maps separate float32 and float64
    # orbits near the boundary, so a few in a thousand may be classified differently
    s = scene_of(algebra, function, "fractal.max_iter=6")
    R = Runner(kernel_config.probe_config(s))
    p = rand4(20000, 14, 1.6).astype(np.float32).astype(np.float64)
    n = len(p)
    ins, d, f = R.out(n, np.int32), R.out(n), R.out(n)
    c = s.fractal.c
    R.named("probe_iterate", (n,), points=R.buf4(p), c=c, max_iter=6, bailout=4.0, inside=ins, distance=d,
            formula=f)
    r = ref.julia_inside(p, c, 6, 4.0, ref.formula_of(s.fractal))
    assert min(r.sum(), (~r).sum()) >= 50   # both classes present: the test means something
    assert np.mean(ins.get().astype(bool) != r) <= 5e-3


def fd_normal(F, p, c, n_iter, bailout, h=1e-6):
    """4D gradient of |q_N|^2 by central differences of the reference iteration."""
    def level(x):
        q = F.ALG_IN(x)
        cc = F.ALG_C(np.asarray(c, float))
        for _ in range(n_iter):
            q = F.julia_f(q, cc)
        return F.ALG_NORM2(q)
    return np.stack([(level(p + h * e) - level(p - h * e)) / (2 * h) for e in E], axis=-1)


@pytest.mark.parametrize("algebra,function", PAIRS)
def test_jacobian_normal_is_the_gradient(algebra, function):
    # normal_jacobian (reference) against a finite difference of the same iteration, on
    # points whose orbit stays within the bailout for max_iter steps
    s = scene_of(algebra, function, "fractal.max_iter=4")
    F = ref.formula_of(s.fractal)
    p = rand4(3000, 15, 0.8)
    inside = ref.julia_inside(p, s.fractal.c, 4, 4.0, F)
    p = p[inside][:200]
    assert len(p) >= 20
    g = ref.normal_jacobian(p, s.fractal.c, 4, 4.0, formula=F)
    fd = fd_normal(F, p, s.fractal.c, 4, 4.0)
    cos = np.sum(g * fd, axis=1) / (np.linalg.norm(g, axis=1) * np.linalg.norm(fd, axis=1))
    assert np.median(cos) > 1 - 1e-8 and np.mean(cos > 0.9999) > 0.95


# whole renders of every pair take ~2 s each to build from cold: a sample runs by default
# (each algebra, the polynomial, exponential, trigonometric, logarithmic, reciprocal and
# power families), the rest is marked slow (setup.cfg); every function's piece, step,
# inside test and Jacobian are checked above for all pairs
RENDER_SAMPLE = {("quaternion", "sqr"), ("hypercomplex", "sqr"), ("hypercomplex", "cube"),
                 ("hypercomplex", "exp"), ("hypercomplex", "sin"), ("hypercomplex", "atanh"),
                 ("hypercomplex", "ln"), ("hypercomplex", "reciprocal"), ("hypercomplex", "pwr"),
                 ("cquat", "sqr")}


@pytest.mark.parametrize("algebra,function", [
    pytest.param(a, f, marks=[] if (a, f) in RENDER_SAMPLE else [pytest.mark.slow]) for a, f in PAIRS])
def test_render_matches_reference(algebra, function):
    # the whole pipeline on a 40 x 30 image: hit masks, certified depth and Jacobian normals
    # of the kernels against the float64 reference render
    s = scene_of(algebra, function, "image.width=40", "image.height=30", "fractal.max_iter=6",
                 "march.z_resolution=120", "march.post_steps=6", "camera.position=2.4,2.1,-3.2,0")
    k, r = render(s), ref.render(s)
    hk, hr = k.status == STATUS_HIT, r.status == STATUS_HIT
    assert np.mean(hk != hr) <= 0.02
    both = hk & hr
    if both.sum() < 10:
        return
    dd = np.abs(k.depth[both] - r.depth[both])
    assert np.median(dd) < 1e-4
    cos = np.sum(k.normal[both] * r.normal[both], axis=-1)
    assert np.median(cos) > np.cos(np.radians(1.0))
    for res in (k,):
        assert np.all(np.isfinite(res.color)) and np.all(np.isfinite(res.normal))


# ------------------------------------------------------------ assembly and validation

def test_a_scene_compiles_only_its_algebra_and_function():
    src = kernel_config.source(kernel_config.scene_config(scene_of("hypercomplex", "sin")))
    assert '"algebra/quaternion.cl"' not in src and "alg_sqr" not in src   # no quaternion code
    assert '"function/sin.cl"' in src and '"function/cos.cl"' not in src
    src = kernel_config.source(kernel_config.scene_config(Scene.default()))
    assert '"algebra/hypercomplex.cl"' not in src and '"function/sqr.cl"' in src


@pytest.mark.parametrize("over,key", [
    (["fractal.function=sin"], "fractal.function"),
    (["fractal.algebra=hypercomplex", "fractal.function=exp", "march.method=de"], "march.method"),
    (["fractal.algebra=hypercomplex", "fractal.function=exp", "normals.method=gradient"], "normals.method"),
])
def test_pairs_refused_with_the_key(over, key):
    with pytest.raises(SceneError) as e:
        Scene.default().with_overrides(over)
    assert str(e.value).startswith(f"{key}: ") and "\n" not in str(e.value)


@pytest.mark.parametrize("function,c", [("sqr", (-0.123, 0, -0.745, 0)), ("cube", (0.4, 0, -0.6, 0))])
def test_hypercomplex_distance_estimate(function, c):
    # iterate.cl's split estimate d = sqrt(d_a^2 + d_b^2) / sqrt(2): (1) the kernel against the
    # float64 twin; (2) a lower bound: no point of the ball of radius d around an outside
    # point is inside the truncated set (200 random points in each of 300 balls)
    s = scene_of("hypercomplex", function, f"fractal.c={','.join(map(str, c))}", "fractal.max_iter=12")
    F = ref.formula_of(s.fractal)
    R = Runner(kernel_config.probe_config(s))
    p = np.random.default_rng(16).uniform(-1.5, 1.5, (8000, 4)).astype(np.float32).astype(np.float64)
    n = len(p)
    ins, d, f = R.out(n, np.int32), R.out(n), R.out(n)
    R.named("probe_iterate", (n,), points=R.buf4(p), c=c, max_iter=12, bailout=4.0, inside=ins, distance=d,
            formula=f)
    kd = d.get().astype(np.float64)
    rd = ref.julia_distance(p, c, 12, 4.0, F)
    both = (kd > 0) & (rd > 0)
    assert both.mean() > 0.3 and np.mean((kd > 0) != (rd > 0)) < 2e-3
    rel = np.abs(kd[both] - rd[both]) / rd[both]
    assert np.median(rel) < 1e-5 and np.percentile(rel, 99) < 1e-2
    rng = np.random.default_rng(17)
    for i in np.nonzero(rd > 1e-4)[0][:300]:
        u = rng.normal(size=(200, 4))
        u /= np.linalg.norm(u, axis=1)[:, None]
        x = p[i] + u * (rd[i] * rng.uniform(0, 1, 200) ** 0.25)[:, None]
        assert not ref.julia_inside(x, c, 12, 4.0, F).any()
