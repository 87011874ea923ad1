"""The sets other than today's Julia set (kernels/kind/, pyjulia4d/reference/kind/): the
Mandelbrot sets of the algebras' sqr and cube (fractal.kind = "mandelbrot") and the rotated
Julia sets (fractal.theta), each against its float64 twin and the twin against the
mathematics it claims (the complex plane, symmetries, finite differences, lower bounds)."""
import numpy as np
import pytest

from harness import Runner, packet_widths
from pyjulia4d.pipeline import kernel_config
from pyjulia4d import reference as ref
from pyjulia4d.geometry.bounds import mandelbrot_radius
from pyjulia4d.reference.formula import Formula, formula_of
from pyjulia4d.reference.kind import rotate
from pyjulia4d.opencl.executor import render
from pyjulia4d.pipeline.codes import STATUS_HIT
from pyjulia4d.scene.model import Scene
from pyjulia4d.scene.checks import SceneError

E = np.eye(4)


def rand4(n, seed, scale=1.0):
    return np.random.default_rng(seed).normal(size=(n, 4)) * scale


def mandel(algebra="quaternion", function="sqr", *over):
    return Scene.default().with_overrides([f"fractal.algebra={algebra}", f"fractal.function={function}",
                                           "fractal.kind=mandelbrot", *over])


def complex_mandelbrot(c, n_iter, bailout, power=2):
    """|z_n| <= bailout for n = 1..n_iter, z_1 = c: plain complex numpy."""
    z = c.copy()
    ok = np.abs(z) <= bailout
    for _ in range(n_iter - 1):
        z = np.where(ok, z ** power + c, z)
        ok &= np.abs(z) <= bailout
    return ok


def probe(s, p, c=(0, 0, 0, 0)):
    """probe.cl's probe_iterate on points p: (inside, distance, formula) from the kernels."""
    R = Runner(kernel_config.probe_config(s))
    n = len(p)
    ins, d, f = R.out(n, np.int32), R.out(n), R.out(n)
    R.named("probe_iterate", (n,), points=R.buf4(p), c=c, max_iter=s.fractal.max_iter, bailout=s.fractal.bailout,
            inside=ins, distance=d, formula=f)
    return ins.get().astype(bool), d.get().astype(np.float64), f.get().astype(np.float64)


# ------------------------------------------------------------ the default compiles as today

def test_default_compiles_todays_kernels():
    # fractal.kind = "julia" and theta = 0 add no piece and no switch: the program of the
    # default scene is built from the same files and -D switches as before these keys existed
    d = Scene.default()
    explicit = d.with_overrides(["fractal.kind=julia", "fractal.theta=0"])
    assert kernel_config.scene_config(explicit) == kernel_config.scene_config(d)
    assert kernel_config.iteration_pieces(d) == ("common/codes", "common/lanes", "algebra/complex", "function/sqr", "algebra/quaternion",
                                         "iterate")
    assert kernel_config.fractal_defines(d) == ()
    src = kernel_config.source(kernel_config.scene_config(d))
    assert '#line 1 "kind/' not in src and "KIND_MANDELBROT" not in kernel_config.scene_config(d).defines
    # and the new switches do appear where asked
    m = kernel_config.scene_config(mandel())
    assert "kind/mandelbrot" in m.pieces and "KIND_MANDELBROT" in m.defines
    r = kernel_config.scene_config(d.with_overrides(["fractal.theta=30"]))
    assert "kind/rotate" in r.pieces and any(x.startswith("ROTATE_COS=") for x in r.defines)


# ------------------------------------------------------------ Mandelbrot: the twin's mathematics

@pytest.mark.parametrize("function,power", [("sqr", 2), ("cube", 3)])
def test_mandelbrot_twin_on_the_complex_plane(function, power):
    # on the plane of 1 and i the quaternion Mandelbrot set is the complex one
    rng = np.random.default_rng(1)
    c = rng.uniform(-2.2, 1.2, 20000) + 1j * rng.uniform(-1.5, 1.5, 20000)
    p = np.stack([c.real, c.imag, 0 * c.real, 0 * c.real], axis=1)
    got = ref.julia_inside(p, None, 20, 4.0, Formula("quaternion", function, kind="mandelbrot"))
    want = complex_mandelbrot(c, 20, 4.0, power)
    assert min(want.sum(), (~want).sum()) > 1000
    assert np.array_equal(got, want)


def test_quaternion_mandelbrot_is_a_solid_of_revolution():
    # q^2 + c with c = (x, v): every iterate lies in the complex plane of 1 and v, so the set
    # depends on x and |v| only (Quilez 2002's 3D Mandelbrot)
    p = rand4(20000, 2, 0.7) + [-0.3, 0, 0, 0]
    F = Formula("quaternion", "sqr", kind="mandelbrot")
    turned = np.stack([p[:, 0], np.linalg.norm(p[:, 1:], axis=1), 0 * p[:, 0], 0 * p[:, 0]], axis=1)
    a, b = ref.julia_inside(p, None, 15, 4.0, F), ref.julia_inside(turned, None, 15, 4.0, F)
    assert min(a.sum(), (~a).sum()) > 2000
    assert np.mean(a != b) < 1e-3   # rounding at the boundary only


@pytest.mark.parametrize("algebra,function", [("quaternion", "sqr"), ("quaternion", "cube"),
                                              ("hypercomplex", "sqr"), ("cquat", "sqr")])
def test_mandelbrot_jacobian_is_the_gradient(algebra, function):
    # grad_c |q_N|^2 (reference normal_jacobian, J_{n+1} = f' J_n + I) against central
    # differences of the plain iteration from q_0 = 0
    F = Formula(algebra, function, kind="mandelbrot")
    N = 5
    p = rand4(4000, 3, 0.7)
    p = p[ref.julia_inside(p, None, N, 4.0, F)][:200]
    assert len(p) >= 50

    def level(x):
        c = F.ALG_IN(x)
        q = np.zeros_like(c)
        for _ in range(N):
            q = F.julia_f(q, np.zeros(4)) + c
        return F.ALG_NORM2(q)

    h = 1e-6
    fd = np.stack([(level(p + h * e) - level(p - h * e)) / (2 * h) for e in E], axis=-1)
    g = ref.normal_jacobian(p, None, N, 4.0, formula=F)
    cos = np.sum(g * fd, axis=1) / (np.linalg.norm(g, axis=1) * np.linalg.norm(fd, axis=1))
    assert np.median(cos) > 1 - 1e-8 and np.mean(cos > 0.9999) > 0.95


@pytest.mark.parametrize("n_iter", [1, 2, 5, 12, 40])
@pytest.mark.parametrize("function,power", [("sqr", 2), ("cube", 3)])
def test_mandelbrot_radius_holds_the_set(function, power, n_iter):
    # no point just outside the ball is inside the truncated set, and the ball is not loose:
    # the square attains it on the negative real axis (|c^2 + c| = r^2 - r there); the cube's
    # bound |q^3 + c| >= |q|^3 - |c| is attained only at the first step (measured: inside
    # points out to 0.95 r at every max_iter)
    r = mandelbrot_radius(4.0, n_iter, power)
    F = Formula("quaternion", function, kind="mandelbrot")
    u = rand4(20000, 4)
    u /= np.linalg.norm(u, axis=1)[:, None]
    assert not ref.julia_inside(u * r * (1 + 1e-7), None, n_iter, 4.0, F).any()
    if power == 2:
        assert ref.julia_inside(np.array([[-r * (1 - 1e-6), 0, 0, 0]]), None, n_iter, 4.0, F).all()
    else:
        x = u * r * np.random.default_rng(5).uniform(0.9, 1, 20000)[:, None]
        assert ref.julia_inside(x, None, n_iter, 4.0, F).any()


@pytest.mark.parametrize("algebra,function", [("quaternion", "sqr"), ("quaternion", "cube"),
                                              ("hypercomplex", "sqr")])
def test_mandelbrot_distance_is_a_lower_bound(algebra, function):
    # no point of the ball of radius d around an outside point is inside the truncated set
    # (200 random points in each of 200 balls)
    F = Formula(algebra, function, kind="mandelbrot")
    p = np.random.default_rng(5).uniform(-2, 2, (6000, 4))
    d = ref.julia_distance(p, None, 12, 4.0, F)
    rng = np.random.default_rng(6)
    checked = 0
    for i in np.nonzero(d > 1e-4)[0][:200]:
        u = rng.normal(size=(200, 4))
        u /= np.linalg.norm(u, axis=1)[:, None]
        x = p[i] + u * (d[i] * rng.uniform(0, 1, 200) ** 0.25)[:, None]
        assert not ref.julia_inside(x, None, 12, 4.0, F).any()
        checked += 1
    assert checked == 200


# ------------------------------------------------------------ Mandelbrot: kernels vs twin

@pytest.mark.parametrize("fl", ["single", "double"])
@pytest.mark.parametrize("algebra,function", [("quaternion", "sqr"), ("quaternion", "cube"),
                                              ("hypercomplex", "sqr"), ("hypercomplex", "cube"),
                                              ("cquat", "sqr"), ("commutative", "cube")])
def test_mandelbrot_probe_matches_reference(algebra, function, fl):
    # the set test and the estimate of kind/mandelbrot.cl against the twin: float32 orbits
    # part from float64 ones near the boundary (a few in a thousand classified differently)
    s = mandel(algebra, function, "fractal.max_iter=10", f"render.float={fl}")
    F = ref.formula_of(s.fractal)
    p = (rand4(8000, 7, 0.7) + [-0.3, 0, 0, 0]).astype(np.float32).astype(np.float64)
    ins, d, _ = probe(s, p, c=(5, 5, 5, 5))            # c is unused by a Mandelbrot set
    r = ref.julia_inside(p, None, 10, 4.0, F)
    assert min(r.sum(), (~r).sum()) > 400
    assert np.mean(ins != r) <= (5e-3 if fl == "single" else 1e-4)
    if not F.has_de:
        assert np.all(np.isnan(d))
        return
    rd = ref.julia_distance(p, None, 10, 4.0, F)
    both = (d > 0) & (rd > 0)
    assert both.mean() > 0.3
    rel = np.abs(d[both] - rd[both]) / rd[both]
    assert np.median(rel) < (1e-5 if fl == "single" else 1e-12) and np.percentile(rel, 99) < 1e-2


@pytest.mark.parametrize("over", [
    ("quaternion", "sqr", "camera.position=-0.5,1.4,-2.6,0", "camera.target=-0.5,0,0,0"),
    pytest.param(("quaternion", "cube", "camera.position=0.3,1.6,-2.4,0.5", "march.method=fixed"),
                 marks=pytest.mark.slow),   # the suite's five minutes; the fixed scan's kinds: test_stack_locus
    ("hypercomplex", "sqr", "camera.position=-0.4,2.2,-3.2,0", "camera.target=-0.4,0,0,0",
     "normals.method=gradient"),
])
def test_mandelbrot_render_matches_reference(over):
    # the whole pipeline (40 x 30): hit masks, certified depth and normals against the twin
    s = mandel(*over, "image.width=40", "image.height=30", "fractal.max_iter=8",
               "march.z_resolution=150", "march.post_steps=6", "march.epsilon=1e-3")
    k, r = render(s), ref.render(s)
    hk, hr = k.status == STATUS_HIT, r.status == STATUS_HIT
    assert 0.1 < hr.mean() < 0.9 and np.mean(hk != hr) <= 0.02
    both = hk & hr
    assert np.median(np.abs(k.depth[both] - r.depth[both])) < 1e-4
    cos = np.sum(k.normal[both] * r.normal[both], axis=-1)
    assert np.median(cos) > np.cos(np.radians(1.0))
    assert np.all(np.isfinite(k.color)) and not any(k.guards[g] for g in ("normal_fallback", "jacobian_tiny"))


@pytest.mark.parametrize("lanes", packet_widths((8,)))
@pytest.mark.parametrize("over", [
    ["fractal.kind=mandelbrot", "camera.position=-0.5,1.4,-2.6,0", "camera.target=-0.5,0,0,0"],
    pytest.param(["fractal.kind=mandelbrot", "fractal.algebra=hypercomplex", "camera.position=-0.5,2,-3,0"],
                 marks=pytest.mark.slow),
    ["fractal.theta=60", "fractal.function=cube", "fractal.c=0.3,0.4,0,0"],
])
def test_new_kinds_packets_give_the_same_pixels(over, lanes):
    # kind/*.cl on the lane types (common/lanes.cl): a packet of rays gives the one-ray pixels
    s = Scene.default().with_overrides(over + ["image.width=37", "image.height=29", "fractal.max_iter=10"])
    one, pk = render(s, lanes=1), render(s, lanes=lanes)
    assert np.mean(one.status == pk.status) >= 0.995
    hit = (one.status == STATUS_HIT) & (pk.status == STATUS_HIT)
    assert np.median(np.abs(one.depth[hit] - pk.depth[hit])) < 1e-5
    assert np.median(np.sum(one.normal[hit] * pk.normal[hit], axis=-1)) > 0.9999


# ------------------------------------------------------------ rotated Julia sets

def test_rotation_conjugates_the_map():
    # f_theta(q) = u f(u^-1 q) + u c: on the complex plane e^(-i theta) z^2 + e^(i theta) c, and its
    # 4D set is u times the unrotated one (u = e^(i theta) on the left)
    th = 35.0
    u = np.exp(1j * np.radians(th))
    z = np.random.default_rng(8).normal(size=50) + 1j * np.random.default_rng(9).normal(size=50)
    c = -0.2 + 0.8j
    F = Formula("quaternion", "sqr", theta=th)
    q = np.stack([z.real, z.imag, 0 * z.real, 0 * z.real], axis=1)
    got = F.julia_f(q, np.array([c.real, c.imag, 0, 0]))
    want = z * z / u + u * c
    np.testing.assert_allclose(got[:, 0] + 1j * got[:, 1], want, atol=1e-12)
    p = rand4(20000, 10, 0.6)
    co, si = rotate.cos_sin(th)
    a = ref.julia_inside(p, (-0.2, 0.8, 0, 0), 10, 4.0, F)
    b = ref.julia_inside(rotate.rot_left(p, co, -si), (-0.2, 0.8, 0, 0), 10, 4.0, Formula("quaternion", "sqr"))
    assert min(a.sum(), (~a).sum()) > 1000 and np.mean(a != b) < 1e-3
    # a different 3D section: the w = 0 slices of the two sets differ
    s3 = p.copy()
    s3[:, 3] = 0
    a3 = ref.julia_inside(s3, (-0.2, 0.8, 0, 0), 10, 4.0, F)
    b3 = ref.julia_inside(s3, (-0.2, 0.8, 0, 0), 10, 4.0, Formula("quaternion", "sqr"))
    assert np.mean(a3 != b3) > 0.02


@pytest.mark.parametrize("function", ["sqr", "cube"])
def test_rotated_jvp_is_the_derivative(function):
    F = Formula("quaternion", function, theta=-70.0)
    q, h = rand4(100, 11), rand4(100, 12)
    eps = 1e-6
    fd = (F.julia_f(q + eps * h, np.zeros(4)) - F.julia_f(q - eps * h, np.zeros(4))) / (2 * eps)
    np.testing.assert_allclose(F.julia_f_jvp(q, h), fd, rtol=1e-6, atol=1e-6)


@pytest.mark.parametrize("fl,tol", [("single", 2e-5), ("double", 1e-11)])
@pytest.mark.parametrize("function", ["sqr", "cube"])
def test_rotated_step_and_set_match_reference(function, fl, tol):
    s = Scene.default().with_overrides([f"fractal.function={function}", "fractal.theta=50",
                                        "fractal.max_iter=8", f"render.float={fl}"])
    R = Runner(kernel_config.probe_config(s))
    F = ref.formula_of(s.fractal)
    p = rand4(4000, 13, 0.7).astype(R.real).astype(np.float64)
    h = rand4(4000, 14).astype(R.real).astype(np.float64)
    c = np.array(s.fractal.c)
    n = len(p)
    val, jvp = R.out4(n), R.out4(n)
    R.named("probe_step", (n,), points=R.buf4(p), dirs=R.buf4(h), c=c, value=val, jvp=jvp)
    for k, r in ((R.get4(val), F.julia_f(p, c)), (R.get4(jvp), F.julia_f_jvp(p, h))):
        assert np.max(np.abs(k - r) / (1 + np.abs(r))) < tol
    ins, d, _ = probe(s, p, c)
    r = ref.julia_inside(p, c, 8, 4.0, F)
    assert min(r.sum(), (~r).sum()) > 200 and np.mean(ins != r) <= 5e-3
    rd = ref.julia_distance(p, c, 8, 4.0, F)
    both = (d > 0) & (rd > 0)
    assert np.median(np.abs(d[both] - rd[both]) / rd[both]) < 1e-4


def test_rotated_render_matches_reference_and_differs_from_unrotated():
    over = ["image.width=40", "image.height=30", "fractal.max_iter=8", "fractal.c=-0.2,0.8,0,0"]
    s = Scene.default().with_overrides(over + ["fractal.theta=90"])
    k, r = render(s), ref.render(s)
    hk, hr = k.status == STATUS_HIT, r.status == STATUS_HIT
    assert np.mean(hk != hr) <= 0.02
    both = hk & hr
    assert np.median(np.abs(k.depth[both] - r.depth[both])) < 1e-4
    assert np.median(np.sum(k.normal[both] * r.normal[both], axis=-1)) > np.cos(np.radians(1.0))
    plain = render(Scene.default().with_overrides(over))
    assert np.mean((plain.status == STATUS_HIT) != hk) > 0.05


# ------------------------------------------------------------ validation

def test_truth_uses_the_quaternion_oracles_for_plain_julia_sets_only():
    # the sphere (c = 0) and 2D (real c) oracles of pyjulia4d.truth hold for the unrotated
    # Julia set only: a Mandelbrot set at c = 0 or a rotated map must take the converged scan
    from pyjulia4d.measure import truth
    assert truth.is_real_c(Scene.default().with_overrides(["fractal.c=0,0,0,0"]))
    assert not truth.is_real_c(mandel("quaternion", "sqr", "fractal.c=0,0,0,0"))
    assert not truth.is_real_c(Scene.default().with_overrides(["fractal.c=0,0,0,0", "fractal.theta=30"]))


@pytest.mark.parametrize("over,key", [
    (["fractal.kind=mandelbrot", "fractal.algebra=hypercomplex", "fractal.function=tan"], "fractal.kind"),
    (["fractal.kind=mandelbrot", "fractal.algebra=hypercomplex", "fractal.function=ln"], "fractal.kind"),
    (["fractal.kind=mandelbrot", "fractal.algebra=hypercomplex", "fractal.function=pwr", "fractal.exponent=1,0.5"],
     "fractal.exponent"),
    (["fractal.kind=mandelbrot", "fractal.theta=10"], "fractal.theta"),
    (["fractal.kind=mandelbrot", "fractal.algebra=cquat", "march.method=de"], "march.method"),
    (["fractal.theta=10", "fractal.algebra=hypercomplex"], "fractal.theta"),
    (["fractal.theta=361"], "fractal.theta"),
    (["fractal.theta=nan"], "fractal.theta"),
    (["fractal.kind=bulb"], "fractal.kind"),
])
def test_new_keys_refused_with_the_key(over, key):
    with pytest.raises(SceneError) as e:
        Scene.default().with_overrides(over)
    assert str(e.value).startswith(f"{key}: ") and "\n" not in str(e.value)


@pytest.mark.slow   # builds every kind's configuration (~25 s from cold); the benchmark is the sweep
def test_kinds_gallery_runs(tmp_path):
    # benchmarks/galleries/kinds_gallery.py end to end on tiny images: every picture, the sheet, and an
    # error row per scene and setting, each with a finite time and a silhouette error in [0, 1]
    import csv
    import importlib.util
    from pathlib import Path
    root = Path(__file__).resolve().parents[2]
    spec = importlib.util.spec_from_file_location("kinds_gallery", root / "benchmarks" / "galleries" / "kinds_gallery.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert mod.main(["--size", "16x12", "--picture", "32x24", "--repeats", "1", "--out", str(tmp_path)]) == 0
    for name in list(mod.GALLERY) + ["sheet"]:
        assert (tmp_path / f"{name}.png").stat().st_size > 0
    rows = list(csv.DictReader(open(tmp_path / "kinds_error.csv")))
    assert len(rows) == sum(len(mod.settings(Scene.default().with_overrides(o))) for o, _ in mod.ERROR.values())
    assert all(float(r["kernel_s"]) > 0 and 0 <= float(r["silhouette_err"]) <= 1 for r in rows)


@pytest.mark.parametrize("function,start", [("cos", 1), ("sin", 1), ("sinh", 1j), ("exp", 0), ("reciprocal", 0)])
def test_transcendental_mandelbrot_on_the_complex_plane(function, start):
    """On the plane (x, y, 0, 0) both hypercomplex components are x + iy, so the twin's set is
    the complex one: c whose orbit of f's critical (or asymptotic) value, z_1 = v + c, stays
    within the bailout (scene.MANDELBROT_START), against plain complex numpy."""
    s = Scene.default().with_overrides(["fractal.kind=mandelbrot", "fractal.algebra=hypercomplex",
                                        f"fractal.function={function}", "fractal.max_iter=8"])
    F = formula_of(s.fractal)
    x, y = np.meshgrid(np.linspace(-4, 4, 121), np.linspace(-3, 3, 91))
    pts = np.stack([x.ravel(), y.ravel(), 0 * x.ravel(), 0 * x.ravel()], -1)
    inside = ref.julia_inside(pts, (0, 0, 0, 0), 8, 4.0, F)
    c = x.ravel() + 1j * y.ravel()
    fn = {"cos": np.cos, "sin": np.sin, "sinh": np.sinh, "exp": np.exp, "reciprocal": lambda z: 1 / z}[function]
    z = start + c
    ok = np.abs(z) <= 4
    with np.errstate(all="ignore"):
        for _ in range(7):
            z = np.where(ok, fn(z) + c, z)
            ok &= np.abs(z) <= 4
    assert 0.05 < ok.mean() < 0.95
    np.testing.assert_array_equal(inside, ok)


@pytest.mark.parametrize("function", ["cos", pytest.param("sinh", marks=pytest.mark.slow)])
def test_transcendental_mandelbrot_kernel_matches_twin(function):
    # the whole pipeline (fixed scan: no estimate for these) against the float64 render, the
    # twin framing the camera from its own float64 pass as render() does
    s = Scene.from_dict({}, ["fractal.kind=mandelbrot", "fractal.algebra=hypercomplex",
                             f"fractal.function={function}", "fractal.max_iter=8", "image.width=40",
                             "image.height=30"])
    k, r = render(s), ref.render(s)
    assert k.hit_fraction > 0.1
    assert np.mean(k.status == r.status) > 0.99
    both = (k.status == 1) & (r.status == 1)
    assert np.median(np.abs(k.depth[both] - r.depth[both])) < 1e-4
    assert np.all(np.isfinite(k.color))


@pytest.mark.parametrize("kind", ["julia", "mandelbrot", "julia_stack", "cubic_locus"])
def test_every_kind_takes_the_quality_presets(kind):
    """Every kind has orbit enclosures (kernels/enclose/), so every preset is its proven march."""
    for q in ("draft", "normal", "final"):
        s = Scene.default().with_overrides([f"fractal.kind={kind}", f"march.quality={q}"])
        assert s.march.method == "proven" and s.march.quality == q
