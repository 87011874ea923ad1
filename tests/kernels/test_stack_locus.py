"""Julia set stacks (fractal.kind = "julia_stack", kernels/kind/julia_stack.cl,
Hart, Sandin & Kauffman 1989 §5.1) and the cubic connectedness locus (fractal.kind =
"cubic_locus", kernels/kind/cubic_locus.cl, §5.2): each kernel against its float64 twin
(pyjulia4d/reference/kind/), and the twin and kernels against the mathematics - every
u = const section of a stack is the complex Julia set of c(u), the locus is the bounded orbit
of its critical point and, at a = 0, the degree-3 Mandelbrot set, each computed here in plain
2D numpy."""
import numpy as np
import pytest

from harness import Runner, packet_widths
from pyjulia4d.pipeline import kernel_config
from pyjulia4d import reference as ref
from pyjulia4d.geometry.camera import march_radius
from pyjulia4d.opencl.executor import render
from pyjulia4d.pipeline.codes import STATUS_HIT
from pyjulia4d.scene.model import Scene
from pyjulia4d.scene.checks import SceneError
from pyjulia4d.fractal.registry import march_method

C0, C1 = -1.0 + 0.0j, -0.1 + 0.75j      # the defaults of fractal.c_from, fractal.c_to


def stack(*over):
    return Scene.default().with_overrides(["fractal.kind=julia_stack", *over])


def complex_julia(z, c, n_iter, bailout):
    """|z_n| <= bailout for n = 0..n_iter under z^2 + c: plain complex numpy, float64."""
    z = np.array(z, np.complex128)
    ok = np.abs(z) <= bailout
    for _ in range(n_iter):
        z = np.where(ok, z * z + c, z)
        ok &= np.abs(z) <= bailout
    return ok


def c_of(u):
    """c(u) = c_from + s (c_to - c_from), s = (u + 1) / 2."""
    return C0 + (u + 1) / 2 * (C1 - C0)


def probe(s, p):
    R = Runner(kernel_config.probe_config(s))
    n = len(p)
    ins, d, f = R.out(n, np.int32), R.out(n), R.out(n)
    R.named("probe_iterate", (n,), points=R.buf4(p), c=(9, 9, 9, 9), max_iter=s.fractal.max_iter,
            bailout=s.fractal.bailout, inside=ins, distance=d, formula=f)
    return ins.get().astype(bool), d.get().astype(np.float64), f.get().astype(np.float64)


def grid(u, n=96, w=7.0):
    """An n x n grid of the plane u = const, x, y in [-1.6, 1.6], w (ignored by the set) = w."""
    x, y = np.meshgrid(np.linspace(-1.6, 1.6, n), np.linspace(-1.6, 1.6, n))
    return np.stack([x.ravel(), y.ravel(), np.full(n * n, u), np.full(n * n, w)], axis=1)


# ------------------------------------------------------------ the sections are Julia sets

@pytest.mark.parametrize("u", [-1.0, -0.35, 0.4, 1.0])
def test_stack_sections_are_complex_julia_sets(u):
    # the twin exactly, the float32 kernel up to its rounding of orbits near the boundary;
    # the 4th coordinate (7 here) is ignored; just past the slab nothing is inside
    s = stack("fractal.max_iter=16")
    F = ref.formula_of(s.fractal)
    p = grid(u)
    p32 = p.astype(np.float32).astype(np.float64)
    want = complex_julia(p32[:, 0] + 1j * p32[:, 1], c_of(p32[0, 2]), 16, 4.0)
    assert min(want.sum(), (~want).sum()) > 500
    assert np.array_equal(ref.julia_inside(p32, None, 16, 4.0, F), want)
    got, d, _ = probe(s, p32)
    assert np.mean(got != want) < 5e-3
    assert np.all(np.isnan(d))            # no estimate compiled for the default fixed scan
    past = p32.copy()
    past[:, 2] = np.float32(np.sign(u) * 1.0001 if u else 1.0001)
    assert not probe(s, past)[0].any() and not ref.julia_inside(past, None, 16, 4.0, F).any()


def test_stack_cap_seen_head_on_is_the_julia_set_of_the_end_point():
    # a camera on the u axis in front of the c_from cap: a ray hits the cap (u = -1) exactly when
    # its point there lies in the filled Julia set of c_from (float64 2D), else it goes on
    s = stack("camera.position=0,0,-4,0", "camera.target=0,0,0,0", "fractal.max_iter=12", "image.width=48",
              "image.height=40", "camera.fov=50", "march.z_resolution=400")
    k = render(s)
    fr = __import__("pyjulia4d.geometry.camera", fromlist=["camera_frame"]).camera_frame(s)
    o, d = ref.generate_rays(fr, 48, 40)
    t_cap = (-1.0 - o[:, 2]) / d[:, 2]
    at = o + t_cap[:, None] * d
    in_cap = complex_julia(at[:, 0] + 1j * at[:, 1], C0, 12, 4.0).reshape(40, 48)
    hit = k.status == STATUS_HIT
    on_cap = hit & (np.abs(k.position[..., 2] + 1) < 1e-3)
    assert in_cap.mean() > 0.1 and np.mean(on_cap != in_cap) < 0.01
    # the cap's normal faces the eye (0, 0, 1 in camera coordinates)
    assert np.median(k.normal[on_cap & in_cap][:, 2]) > 0.999


# ------------------------------------------------------------ kernels against the twin

def test_stack_level_and_normal_twin_are_the_mathematics():
    # the level's sign is the set test; the normal is the gradient of |z_N|^2 (central
    # differences of the plain 2D iteration) and the cap's own where z stays bounded past it
    s = stack("fractal.max_iter=6")
    F = ref.formula_of(s.fractal)
    rng = np.random.default_rng(3)
    p = np.column_stack([rng.uniform(-1.6, 1.6, (3000, 2)), rng.uniform(-1.2, 1.2, 3000), rng.normal(size=3000)])
    lv, ins = ref.julia_level(p, None, 6, 4.0, F)
    assert np.array_equal(ins, ref.julia_inside(p, None, 6, 4.0, F)) and np.array_equal(lv <= 0, ins)
    sel = ref.julia_inside(p * [1, 1, 0.8, 1], None, 6, 4.0, F)
    q = (p * [1, 1, 0.8, 1])[sel][:200]

    def m2(x):
        z = x[:, 0] + 1j * x[:, 1]
        c = c_of(x[:, 2])
        for _ in range(6):
            z = z * z + c
        return np.abs(z) ** 2

    h = 1e-6
    fd = np.stack([(m2(q + h * e) - m2(q - h * e)) / (2 * h) for e in np.eye(4)], axis=-1)
    g = ref.normal_jacobian(q, None, 6, 4.0, formula=F)
    cos = np.sum(g * fd, 1) / (np.linalg.norm(g, axis=1) * np.linalg.norm(fd, axis=1) + 1e-300)
    assert len(q) == 200 and np.median(cos) > 1 - 1e-8
    cap = np.array([[0.0, 0.0, 1.01, 0.0], [0.0, 0.0, -1.01, 3.0]])
    np.testing.assert_array_equal(ref.normal_jacobian(cap, None, 6, 4.0, formula=F), [[0, 0, 1, 0], [0, 0, -1, 0]])


@pytest.mark.parametrize("over", [
    ("camera.position=2.0,2.4,-3.2,0",),
    ("camera.position=-1.5,1.0,3.0,0", "fractal.c_from=-1.3,0", "fractal.c_to=0.25,0", "march.refine=bisect"),
    ("camera.position=2.0,2.4,-3.2,0", "march.method=de", "march.epsilon=1e-3"),
])
def test_stack_render_matches_reference(over):
    # the whole pipeline (40 x 30): hit masks, certified depth and Jacobian normals against the twin
    s = stack(*over, "image.width=40", "image.height=30", "fractal.max_iter=8", "march.z_resolution=200",
              "march.post_steps=6")
    k, r = render(s), ref.render(s)
    hk, hr = k.status == STATUS_HIT, r.status == STATUS_HIT
    assert 0.1 < hr.mean() < 0.9 and np.mean(hk != hr) <= 0.02
    both = hk & hr
    assert np.median(np.abs(k.depth[both] - r.depth[both])) < 1e-4
    assert np.median(np.sum(k.normal[both] * r.normal[both], axis=-1)) > np.cos(np.radians(1.0))
    assert np.all(np.isfinite(k.color)) and not any(k.guards[g] for g in ("normal_fallback", "jacobian_tiny"))


def test_stack_empirical_estimate_kernel_matches_twin():
    s = stack("march.method=de", "fractal.max_iter=10")
    F = ref.formula_of(s.fractal)
    rng = np.random.default_rng(4)
    p = np.column_stack([rng.uniform(-2, 2, (6000, 2)), rng.uniform(-1.5, 1.5, 6000), np.zeros(6000)])
    p = p.astype(np.float32).astype(np.float64)
    ins, d, f = probe(s, p)
    rd = ref.julia_distance(p, None, 10, 4.0, F)
    assert np.mean(ins != ref.julia_inside(p, None, 10, 4.0, F)) < 5e-3
    both = (d > 0) & (rd > 0)
    assert both.mean() > 0.3 and np.all(np.isfinite(f))
    assert np.median(np.abs(d[both] - rd[both]) / rd[both]) < 1e-5


@pytest.mark.parametrize("lanes", packet_widths((8,)))
def test_stack_packets_give_the_same_pixels(lanes):
    s = stack("image.width=37", "image.height=29", "fractal.max_iter=10", "camera.position=2.0,2.4,-3.2,0")
    one, pk = render(s, lanes=1), render(s, lanes=lanes)
    assert np.mean(one.status == pk.status) >= 0.995
    hit = (one.status == STATUS_HIT) & (pk.status == STATUS_HIT)
    assert np.median(np.abs(one.depth[hit] - pk.depth[hit])) < 1e-5
    assert np.median(np.sum(one.normal[hit] * pk.normal[hit], axis=-1)) > 0.9999


# ------------------------------------------------------------ bounds and keys

@pytest.mark.parametrize("over", [(), ("fractal.c_from=-2,0", "fractal.c_to=0.3,0.5", "fractal.max_iter=3"),
                                  ("slice.distance=0.7",)])
def test_stack_radius_holds_the_stack(over):
    # no point just outside the ball (in the view's hyperplane w = w0) is inside
    s = stack(*over)
    # no estimate: by default the proven march (march.quality "auto")
    assert march_method(s) == "proven" and "STACK_DE" not in kernel_config.fractal_defines(s)
    r = march_radius(s)
    w0 = s.slice.distance
    u = np.random.default_rng(6).normal(size=(20000, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    rr = np.sqrt(r * r - w0 * w0) * (1 + 1e-9)
    p = np.column_stack([u * rr, np.full(len(u), w0)])
    assert not ref.julia_inside(p, None, s.fractal.max_iter, 4.0, ref.formula_of(s.fractal)).any()


@pytest.mark.parametrize("over,key", [
    (["fractal.algebra=hypercomplex"], "fractal.kind"),
    (["fractal.function=cube"], "fractal.kind"),
    (["fractal.theta=30"], "fractal.theta"),
    (["shading.coloring=trap"], "shading.coloring"),
    (["normals.method=gradient"], "normals.method"),
    (["slice.normal=0,0,1,1"], "slice.normal"),
    (["camera.limbo=0,1,0,1", "camera.up=1,0,0,0"], "camera.limbo"),
    (["camera.position=1,2,-3,0.5"], "camera.target"),
    (["fractal.c_to=4.5,0"], "fractal.c_to"),
    (["fractal.c_from=1,2,3"], "fractal.c_from"),
])
def test_stack_keys_refused_with_the_key(over, key):
    with pytest.raises(SceneError) as e:
        stack(*over)
    assert str(e.value).startswith(f"{key}: ") and "\n" not in str(e.value)


# ============================================================ the cubic connectedness locus
# fractal.kind = "cubic_locus" (kernels/kind/cubic_locus.cl, Hart, Sandin & Kauffman 1989 §5.2): p = (a, b) in C^2

def locus(*over):
    return Scene.default().with_overrides(["fractal.kind=cubic_locus", *over])


def cubic_orbit_bounded(z, a, b, n_iter, bailout):
    """|z_n| <= bailout for n = 0..n_iter under z^3 - 3 a^2 z + b: plain complex numpy."""
    z = np.array(z, np.complex128)
    ok = np.abs(z) <= bailout
    for _ in range(n_iter):
        z = np.where(ok, z ** 3 - 3 * a ** 2 * z + b, z)
        ok &= np.abs(z) <= bailout
    return ok


def locus_points(n, seed, r=1.9):
    """Points of the ball |p| <= r, float32-representable."""
    x = np.random.default_rng(seed).uniform(-1, 1, (4 * n, 4))
    x = x[np.linalg.norm(x, axis=1) <= 1][:n] * r
    return x.astype(np.float32).astype(np.float64)


@pytest.mark.parametrize("component", ["plus", "minus"])
def test_locus_is_the_bounded_orbit_of_its_critical_point(component):
    # the twin and the kernel against the plain 2D iteration of +a (C+) or -a (C-); and C- is
    # C+ mirrored in a (f_{-a,b} = f_{a,b}: the orbit of -a is that of +(-a))
    s = locus(f"fractal.component={component}", "fractal.max_iter=12")
    F = ref.formula_of(s.fractal)
    p = locus_points(8000, 11, 1.2)
    a, b = p[:, 0] + 1j * p[:, 1], p[:, 2] + 1j * p[:, 3]
    want = cubic_orbit_bounded(a if component == "plus" else -a, a, b, 12, 4.0)
    assert min(want.sum(), (~want).sum()) > 500
    tw = ref.julia_inside(p, None, 12, 4.0, F)
    assert np.mean(tw != want) < 1e-3            # float64 rounding order only
    got, d, _ = probe(s, p)
    assert np.mean(got != want) < 5e-3 and np.all(np.isnan(d))
    mirrored = p * [-1, -1, 1, 1]
    other = ref.formula_of(locus("fractal.component=" + ("minus" if component == "plus" else "plus")).fractal)
    assert np.mean(ref.julia_inside(mirrored, None, 12, 4.0, other) != tw) < 1e-3


def test_locus_section_a_zero_is_the_cubic_mandelbrot_set():
    # a = 0: the critical points +-a coincide at 0 and f = z^3 + b: both components are the
    # set of b whose orbit of 0 stays bounded (the degree-3 Mandelbrot set), in float64 exactly
    x, y = np.meshgrid(np.linspace(-1.5, 1.5, 101), np.linspace(-1.5, 1.5, 101))
    p = np.stack([0 * x.ravel(), 0 * x.ravel(), x.ravel(), y.ravel()], axis=1).astype(np.float32).astype(float)
    b = p[:, 2] + 1j * p[:, 3]
    z = np.zeros_like(b)
    want = np.ones(len(b), bool)
    for _ in range(15):
        z = np.where(want, z ** 3 + b, z)
        want &= np.abs(z) <= 4.0
    assert min(want.sum(), (~want).sum()) > 1000
    for comp in ("plus", "minus"):
        s = locus(f"fractal.component={comp}", "fractal.max_iter=15")
        assert np.array_equal(ref.julia_inside(p, None, 15, 4.0, ref.formula_of(s.fractal)), want)
        assert np.mean(probe(s, p)[0] != want) < 5e-3


def test_locus_level_and_normal_twin_are_the_mathematics():
    s = locus("fractal.max_iter=5", "fractal.component=minus")
    F = ref.formula_of(s.fractal)
    p = locus_points(4000, 12, 2.3)
    lv, ins = ref.julia_level(p, None, 5, 4.0, F)
    assert np.array_equal(ins, ref.julia_inside(p, None, 5, 4.0, F)) and np.array_equal(lv <= 0, ins)
    assert not ins[np.linalg.norm(p, axis=1) > 2.0].any()
    near = locus_points(4000, 14, 1.0)
    q = near[ref.julia_inside(near, None, 5, 4.0, F)][:200]

    def m2(x):
        a, b = x[:, 0] + 1j * x[:, 1], x[:, 2] + 1j * x[:, 3]
        z = -a
        for _ in range(5):
            z = z ** 3 - 3 * a * a * z + b
        return np.abs(z) ** 2

    h = 1e-6
    fd = np.stack([(m2(q + h * e) - m2(q - h * e)) / (2 * h) for e in np.eye(4)], axis=-1)
    g = ref.normal_jacobian(q, None, 5, 4.0, formula=F)
    cos = np.sum(g * fd, 1) / (np.linalg.norm(g, axis=1) * np.linalg.norm(fd, axis=1) + 1e-300)
    assert len(q) == 200 and np.median(cos) > 1 - 1e-8 and np.mean(cos > 0.9999) > 0.95
    # past the sphere, an orbit that stays bounded: the sphere's normal.  b = -a - 2 a^3 makes
    # -a a fixed point of f_{a,b}; a = 0.9 puts (a, b) at |p| = 2.52, outside the ball of 2
    a = 0.9
    cut = np.array([[a, 0.0, -a - 2 * a ** 3, 0.0]])
    assert np.linalg.norm(cut) > 2 and cubic_orbit_bounded(-a, a, cut[0, 2], 5, 4.0)[()]
    n = ref.normal_jacobian(cut, None, 5, 4.0, formula=F)
    np.testing.assert_allclose(n, cut)


@pytest.mark.parametrize("over", [
    ("camera.position=2.4,2.2,-3.0,0",),
    ("fractal.component=minus", "slice.normal=0,1,0,0", "camera.position=-2.0,2.5,-2.6,0"),
    ("camera.position=1.0,2.0,-3.2,0.6", "march.refine=bisect", "fractal.locus_radius=1.4"),
])
def test_locus_render_matches_reference(over):
    s = locus(*over, "image.width=40", "image.height=30", "fractal.max_iter=6", "march.z_resolution=200",
              "march.post_steps=6")
    k, r = render(s), ref.render(s)
    hk, hr = k.status == STATUS_HIT, r.status == STATUS_HIT
    assert 0.05 < hr.mean() < 0.9 and np.mean(hk != hr) <= 0.02
    both = hk & hr
    assert np.median(np.abs(k.depth[both] - r.depth[both])) < 1e-4
    assert np.median(np.sum(k.normal[both] * r.normal[both], axis=-1)) > np.cos(np.radians(1.0))
    assert np.all(np.isfinite(k.color)) and not any(k.guards[g] for g in ("normal_fallback", "jacobian_tiny"))


@pytest.mark.parametrize("lanes", packet_widths((8,)))
def test_locus_packets_give_the_same_pixels(lanes):
    s = locus("image.width=37", "image.height=29", "fractal.max_iter=8", "camera.position=2.4,2.2,-3.0,0")
    one, pk = render(s, lanes=1), render(s, lanes=lanes)
    assert np.mean(one.status == pk.status) >= 0.995
    hit = (one.status == STATUS_HIT) & (pk.status == STATUS_HIT)
    assert np.median(np.abs(one.depth[hit] - pk.depth[hit])) < 1e-5
    assert np.median(np.sum(one.normal[hit] * pk.normal[hit], axis=-1)) > 0.9999


@pytest.mark.parametrize("radius", [0.5, 2.0, 6.0])
def test_locus_escape_radius_is_one(radius):
    # beyond R every map of the ball grows |z| (the worst case |a| = |b| = radius, z, a^2 and b
    # lined up against z); below it one such map does not
    from pyjulia4d.fractal.registry import locus_escape_radius
    R = locus_escape_radius(radius)
    g = lambda r: r ** 3 - 3 * radius ** 2 * r - radius
    assert g(R * (1 + 1e-12)) > R * (1 + 1e-12) and g(R * 0.999) < R * 0.999
    rng = np.random.default_rng(13)
    a = radius * np.sqrt(rng.uniform(0, 1, 5000)) * np.exp(2j * np.pi * rng.uniform(size=5000))
    b = radius * np.sqrt(rng.uniform(0, 1, 5000)) * np.exp(2j * np.pi * rng.uniform(size=5000))
    z = R * 1.001 * np.exp(2j * np.pi * rng.uniform(size=5000))
    assert np.all(np.abs(z ** 3 - 3 * a * a * z + b) > np.abs(z))
    assert march_radius(locus(f"fractal.locus_radius={min(radius, 2.0)}")) >= min(radius, 2.0)


@pytest.mark.parametrize("over,key", [
    (["fractal.algebra=hypercomplex"], "fractal.kind"),
    (["fractal.function=cube"], "fractal.kind"),
    (["fractal.theta=30"], "fractal.theta"),
    (["shading.coloring=iteration"], "shading.coloring"),
    (["normals.method=gradient"], "normals.method"),
    (["march.method=de"], "march.method"),
    (["fractal.locus_radius=3"], "fractal.bailout"),
    (["fractal.bailout=3"], "fractal.bailout"),
    (["fractal.component=both"], "fractal.component"),
    (["fractal.locus_radius=0"], "fractal.locus_radius"),
])
def test_locus_keys_refused_with_the_key(over, key):
    with pytest.raises(SceneError) as e:
        locus(*over)
    assert str(e.value).startswith(f"{key}: ") and "\n" not in str(e.value)


def test_locus_radius_with_bailout_raised_is_accepted():
    s = locus("fractal.locus_radius=3", "fractal.bailout=6")
    assert march_method(s) == "proven" and "LOCUS_SIGN=1" in kernel_config.fractal_defines(s)
