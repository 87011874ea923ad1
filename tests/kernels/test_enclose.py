"""Proofs of empty space (kernels/enclose/, kernels/march/proven.cl, and their twins in
reference/enclose/ and reference/march.py), held to the mathematics:

- every function's disc enclosure (cfun_disc) holds the float64 images of points sampled in
  its disc, near poles and across branch cuts included;
- every pair's orbit enclosure (enc_segment, enc_step) holds the float64 orbits of points
  sampled along its segment, step after step;
- no segment proven empty holds an inside point (the set test at 201 samples);
- the kernel's proofs match the twin's, and the proven march's kernel matches its twin;
- a render's stated error holds the float64 brute force's first crossing: it lies in the
  bracket or in the unproven segments in front, so within [depth - unresolved, depth + bracket]
  unless it hides in a segment farther out (a thin part: at most 1 % of the pixels here).

Tolerances: the enclosures are checked exactly (float64 samples against float64 radii, with
a relative 1e-12 for the samples' own rounding); kernel against twin with the float32
classification slack of tests/kernels/test_march.py."""
from __future__ import annotations

import importlib

import numpy as np
import pytest

from harness import Runner
from pyjulia4d import Scene, reference as ref
from pyjulia4d.fractal.registry import FUNCTIONS, FUNCTIONS_OF, MANDELBROT_START
from pyjulia4d.geometry.camera import camera_frame, march_radius
from pyjulia4d.measure.brute_force import brute_force_depth
from pyjulia4d.pipeline import kernel_config
from pyjulia4d.pipeline.plan import march_args
from pyjulia4d.reference.formula import Formula, formula_of
from pyjulia4d.reference.enclose.disc import precision
from pyjulia4d.reference.march import enc_prove

PAIRS = [(a, f) for a, fs in FUNCTIONS_OF.items() for f in fs]
# every pair, the rotated quaternion maps (fractal.theta, kernels/kind/rotate.cl) and the
# Mandelbrot sets (kernels/enclose/mandelbrot.cl): of the powers, and of functions whose orbit
# starts at their critical or asymptotic value (sin, cosh: V = 1; sinh: V = i; exp: 0)
CASES = [(a, f, 0.0) for a, f in PAIRS] + [("quaternion", "sqr", 30.0), ("quaternion", "cube", -75.0)] + [
    (a, f, "mandelbrot") for a, f in (("quaternion", "sqr"), ("quaternion", "cube"), ("hypercomplex", "sin"),
                                      ("hypercomplex", "sinh"), ("hypercomplex", "cosh"), ("hypercomplex", "exp"),
                                      ("cquat", "sqr"), ("commutative", "cube"))] + [
    ("quaternion", "sqr", "julia_stack"), ("quaternion", "sqr", "cubic_locus")]


def _case(algebra, function, how):
    """A case's scene: a rotation angle, or a kind's name."""
    if isinstance(how, str):
        return _scene(algebra, function, kind=how)
    return _scene(algebra, function, theta=how)
# centres where each function is hard: poles of tan / tanh / 1/z, the cuts of ln, sqrt and
# the inverse functions, large imaginary parts for sin and cos
HARD = {"tan": [np.pi / 2, -np.pi / 2 + 0.01j], "tanh": [1j * np.pi / 2, 0.01 - 1.5707j],
        "reciprocal": [0.0, 1e-3j], "ln": [-1.0, -0.5 + 1e-3j, 0.0], "pwr": [-1.0 + 1e-4j, -2.0, 0.0],
        "asin": [1.5, -1.2 + 1e-3j], "acos": [-1.5, 1.01], "acosh": [0.5, -2.0 - 1e-4j],
        "atanh": [1.0, -1.3], "atan": [1j, -1.5j], "asinh": [2j, -1.1j], "sin": [3 + 4j], "cos": [-2 - 5j]}


def _sample_disc(m, r, rng, k=64):
    """Points of the disc {|z - m| <= r}: its boundary and interior."""
    ang = rng.uniform(0, 2 * np.pi, (len(m), k))
    rad = np.concatenate([np.ones((len(m), k // 2)), np.sqrt(rng.uniform(0, 1, (len(m), k - k // 2)))], axis=1)
    return m[:, None] + r[:, None] * rad * np.exp(1j * ang)


@pytest.mark.parametrize("name", FUNCTIONS)
@pytest.mark.parametrize("exponent", [(2.0, 0.0), (2.5, 0.7)], ids=["p2", "p2.5+0.7i"])
def test_disc_enclosures_hold_the_images(name, exponent):
    if name != "pwr" and exponent != (2.0, 0.0):
        pytest.skip("the exponent is pwr's")
    fn = Formula("hypercomplex", name, exponent).fn
    rng = np.random.default_rng(abs(hash((name, exponent))) % 2**32)
    m = np.concatenate([rng.uniform(-3, 3, 300) + 1j * rng.uniform(-3, 3, 300), np.repeat(HARD.get(name, [0.3]), 40)])
    r = np.exp(rng.uniform(np.log(1e-6), np.log(1.0), len(m)))
    fm, fr = fn.cfun_disc((m.astype(np.complex128), r))
    z = _sample_disc(m, r, rng)
    with np.errstate(all="ignore"):
        w = fn.cfun(z)
    ok = np.isfinite(w) & (fr[:, None] < np.inf)   # an infinite radius: no bound given, none claimed
    dist = np.abs(w - fm[:, None])
    bound = fr[:, None] * (1 + 1e-12) + 1e-300
    assert not (ok & ~(dist <= bound)).any(), (name, np.argwhere(ok & ~(dist <= bound))[:3])
    assert np.isfinite(fr).mean() > 0.5   # the enclosures are not all given up


def _scene(algebra, function, **fractal):
    return Scene.from_dict({"fractal": {"algebra": algebra, "function": function, "max_iter": 8, **fractal},
                            "image": {"width": 16, "height": 12}})


def _segments(s, n, rng, lengths=(0.5, 0.05, 0.005, 5e-4)):
    R = march_radius(s)
    o = rng.uniform(-R, R, (n, 4)) * 0.8
    d = rng.normal(size=(n, 4))
    d /= np.linalg.norm(d, axis=1)[:, None]
    return o, d, np.zeros(n), rng.choice(lengths, n)


@pytest.mark.parametrize("algebra,function,how", [c for c in CASES if c[2] not in ("julia_stack", "cubic_locus")])
def test_orbit_enclosures_hold_the_orbits(algebra, function, how):
    _check_orbits_held(algebra, function, how)


# double precision's rounding bounds are 2^-28 of single's (kernels/enclose/disc.cl): the
# enclosures must still hold float64's own orbits with them
@pytest.mark.parametrize("algebra,function,how", [("quaternion", "sqr", 0.0), ("quaternion", "cube", -75.0),
                                                  ("hypercomplex", "sin", 0.0), ("hypercomplex", "pwr", 0.0), ("hypercomplex", "cube", 0.0),
                                                  ("hypercomplex", "cube", 0.0), ("cquat", "cube", 0.0),
                                                  ("commutative", "sqr", 0.0), ("hypercomplex", "exp", "mandelbrot")])
def test_double_enclosures_hold_the_orbits(algebra, function, how):
    with precision(True):
        _check_orbits_held(algebra, function, how)


def _check_orbits_held(algebra, function, how):
    s = _case(algebra, function, how)
    F = formula_of(s.fractal)
    K = F.kind_enclose
    rng = np.random.default_rng(len(algebra) * 31 + len(function))
    n, k = 120, 33
    o, d, t0, t1 = _segments(s, n, rng)
    e, param = K.enc_start(o, d, t0, t1, s.fractal.c, F)
    sk = np.linspace(-1, 1, k)
    tm, hw = 0.5 * (t0 + t1), 0.5 * (t1 - t0)
    q = F.ALG_IN(o[:, None] + (tm[:, None] + sk[None] * hw[:, None])[..., None] * d[:, None])
    if s.fractal.kind == "mandelbrot":   # the points are the parameters; q_1 = V + c (kind/mandelbrot.cl)
        c = q.reshape(-1, 4)
        q = q + F.ALG_C(np.asarray(MANDELBROT_START[function], np.float64))
    else:
        c = F.ALG_C(np.asarray(s.fractal.c, np.float64))
    alive = np.ones((n, k), bool)
    checked = 0
    for step in range(K.enc_steps(s.fractal.max_iter) + 1):
        with np.errstate(all="ignore"):
            for comp, (m, v, r) in (_components(e, algebra)):
                pts = q[..., comp]
                if len(comp) == 2:
                    pts = pts[..., 0] + 1j * pts[..., 1]
                    dist = np.abs(pts - (m[:, None] + sk[None] * v[:, None]))
                else:
                    dist = np.linalg.norm(pts - (m[:, None] + sk[None, :, None] * v[:, None]), axis=-1)
                live = alive & np.isfinite(dist) & (r[:, None] < np.inf)
                bad = live & ~(dist <= r[:, None] * (1 + 1e-9) + 1e-12 * (1 + np.abs(dist)))
                assert not bad.any(), (step, np.argwhere(bad)[:3], dist[bad][:3], np.broadcast_to(r[:, None], bad.shape)[bad][:3])
                checked += live.sum()
            qn = F.julia_f(q.reshape(-1, 4), c).reshape(n, k, 4)
            alive &= np.all(np.isfinite(qn), axis=-1) & (F.ALG_NORM2(q) < 1e6)
            q = qn
            e = K.enc_next(e, param, F)
    assert checked > n * k   # the enclosures were finite and checked beyond the first step


@pytest.mark.parametrize("kind", ["julia_stack", "cubic_locus"])
@pytest.mark.parametrize("seed", [0, 1])
def test_own_map_enclosures_hold_the_orbits(kind, seed):
    """The kinds that iterate a complex map of their own (enclose/julia_stack.cl,
    cubic_locus.cl): the form of z_n holds the float64 z_n of points sampled along the
    segment, step after step (the twins' own orbits, reference/kind/)."""
    from pyjulia4d.reference.kind import cubic_locus as locus, julia_stack as stack
    s = _case("quaternion", "sqr", kind)
    F = formula_of(s.fractal)
    K = F.kind_enclose
    rng = np.random.default_rng(seed)
    n, k = 150, 33
    o, d, t0, t1 = _segments(s, n, rng)
    e, param = K.enc_start(o, d, t0, t1, s.fractal.c, F)
    sk = np.linspace(-1, 1, k)
    tm, hw = 0.5 * (t0 + t1), 0.5 * (t1 - t0)
    p = o[:, None] + (tm[:, None] + sk[None] * hw[:, None])[..., None] * d[:, None]
    if kind == "julia_stack":
        z, c, _ = stack._start(p, F)
        step = lambda z: z * z + c   # noqa: E731
    else:
        a, b, sign, _ = locus._start(p, F)
        z = sign * a
        step = lambda z: locus.locus_f(z, a, b)   # noqa: E731
    alive, checked = np.ones((n, k), bool), 0
    for _ in range(K.enc_steps(s.fractal.max_iter) + 1):
        m, v, r = e[0]
        with np.errstate(all="ignore"):
            dist = np.abs(z - (m[:, None] + sk[None] * v[:, None]))
            live = alive & np.isfinite(dist) & (r[:, None] < np.inf)
            bad = live & ~(dist <= r[:, None] * (1 + 1e-9) + 1e-12 * (1 + np.abs(dist)))
            assert not bad.any(), (np.argwhere(bad)[:3], dist[bad][:3])
            checked += live.sum()
            z = step(z)
            alive &= np.isfinite(z) & (np.abs(z) < 1e6)
        e = K.enc_next(e, param, F)
    assert checked > n * k


def _components(e, algebra):
    """(coordinates, (centre, tangent, radius)) of each part of an enclosure."""
    if algebra == "hypercomplex":
        return [([0, 1], e[0]), ([2, 3], e[1])]
    return [([0, 1, 2, 3], e)]


@pytest.mark.parametrize("algebra,function,how", CASES)
def test_proven_segments_hold_no_inside_point(algebra, function, how):
    s = _case(algebra, function, how)
    f, F = s.fractal, formula_of(s.fractal)
    rng = np.random.default_rng(len(algebra) * 7 + len(function))
    n = 400
    o, d, t0, t1 = _segments(s, n, rng)
    proven, _, _ = enc_prove(o, d, t0, t1, f.c, f.max_iter, f.bailout, F)
    ts = np.linspace(0.0, 1.0, 201)
    p = o[:, None, :] + (ts[None, :] * t1[:, None])[..., None] * d[:, None, :]
    inside = ref.julia_inside(p.reshape(-1, 4), f.c, f.max_iter, f.bailout, F).reshape(n, -1).any(axis=1)
    assert not (proven & inside).any()


# each builds its own programs (seconds from cold): a sample by default, the rest marked slow
_SLOW = pytest.mark.slow
KERNEL_PAIRS = [("quaternion", "sqr", 0.0), pytest.param("quaternion", "cube", 0.0, marks=_SLOW),
                ("hypercomplex", "sin", 0.0), ("hypercomplex", "pwr", 0.0), ("hypercomplex", "cube", 0.0),
                pytest.param("hypercomplex", "tan", 0.0, marks=_SLOW), pytest.param("hypercomplex", "ln", 0.0, marks=_SLOW),
                pytest.param("hypercomplex", "asinh", 0.0, marks=_SLOW), ("cquat", "cube", 0.0),
                pytest.param("commutative", "sqr", 0.0, marks=_SLOW), ("quaternion", "sqr", 30.0),
                ("quaternion", "sqr", "mandelbrot"), pytest.param("hypercomplex", "sinh", "mandelbrot", marks=_SLOW),
                pytest.param("cquat", "cube", "mandelbrot", marks=_SLOW), ("quaternion", "sqr", "julia_stack"),
                ("quaternion", "sqr", "cubic_locus")]


@pytest.mark.parametrize("algebra,function,how", KERNEL_PAIRS + [
    pytest.param("commutative", "sqr", "double", id="commutative-sqr-double"),
    pytest.param("hypercomplex", "sin", "double", id="hypercomplex-sin-double")])
def test_kernel_proofs_match_the_twin(algebra, function, how):
    double = how == "double"   # the double kernel against the twin with double's rounding bounds
    s = _case(algebra, function, 0.0 if double else how).with_overrides(
        ["march.method=proven"] + (["render.float=double"] if double else []))
    with precision(double):
        _check_kernel_proofs(s)


def _check_kernel_proofs(s):
    f, F = s.fractal, formula_of(s.fractal)
    R = Runner(kernel_config.scene_config(s, ray_buffers=True))
    rng = np.random.default_rng(5)
    n = 600
    o, d, t0, t1 = _segments(s, n, rng)
    o, d = o.astype(np.float32).astype(float), d.astype(np.float32).astype(float)
    t1 = t1.astype(np.float32).astype(float)
    proven, margin, prefix = R.out(n, np.int32), R.out(n), R.out(n)
    R.named("prove_segments", (n,), origins=R.buf4(o), dirs=R.buf4(d), t0s=R.buf(t0), t1s=R.buf(t1), c=f.c,
            max_iter=f.max_iter, bailout=f.bailout, proven=proven, margins=margin, prefixes=prefix)
    kp = proven.get().astype(bool)
    rp, rm, rpre = enc_prove(o, d, t0, t1, f.c, f.max_iter, f.bailout, F)
    # float32 against float64: a proof decided by a hair may go either way, on few segments
    assert np.mean(kp != rp) <= 0.02
    assert kp.sum() > 0.2 * n
    # the partial proofs (enc_prefix, where the enclosure piece has one): 1 exactly where
    # proven, the same part elsewhere within float32's reach (a root of a quadratic in the
    # form's centre and tangent: 1e-3 of the segment; an iteration's part decided by a hair
    # may appear in one only, on few segments)
    kpre = prefix.get()
    assert (kpre[kp] == 1).all() and (kpre >= -1).all() and (kpre <= 1).all()
    both = ~kp & ~rp
    if getattr(F.kind_enclose if F.own_map else F.enclose, "enc_prefix", None) is None:
        assert (kpre[both] == -1).all()
    else:
        assert np.mean(np.abs(kpre[both] - rpre[both]) > 1e-3) <= 0.03
        if both.sum() >= 20:   # partial proofs do occur on these segments (1.5 % of the unproven for
            assert np.mean(rpre[both] > -1) > 0.01   # tan, ln and asinh, 14-49 % for the others)


MARCH_PAIRS = [("quaternion", "sqr"), ("hypercomplex", "sin")] + [
    pytest.param(*p, marks=_SLOW) for p in (("quaternion", "cube"), ("hypercomplex", "pwr"), ("hypercomplex", "tan"),
                                            ("hypercomplex", "ln"), ("hypercomplex", "asinh"), ("cquat", "cube"),
                                            ("commutative", "sqr"))]


@pytest.mark.parametrize("algebra,function", MARCH_PAIRS)
def test_proven_march_matches_its_twin(algebra, function):
    s = Scene.from_dict({"fractal": {"algebra": algebra, "function": function},
                         "march": {"method": "proven", "z_resolution": 2000}, "image": {"width": 32, "height": 24}})
    k = ref_render = None
    from pyjulia4d import render
    k = render(s)
    ref_render = ref.render(k.scene)
    both = (k.status == 1) & (ref_render.status == 1)
    assert np.mean(k.status != ref_render.status) <= 0.01
    assert both.sum() > 20
    # the two stated intervals overlap where both hit (each holds the crossing it proved)
    lo_k, hi_k = k.depth - k.unresolved, k.depth + k.bracket
    lo_r, hi_r = ref_render.depth - ref_render.unresolved, ref_render.depth + ref_render.bracket
    slack = 1e-5 * (1 + k.depth)
    assert np.mean((lo_k <= hi_r + slack) & (lo_r <= hi_k + slack)) >= 0.99


def march_on_rays(s, o, d):
    """The scene's march kernel on the given rays (kernels/march/march.cl, RAYS_FROM_BUFFERS):
    depth, status, bracket, unresolved."""
    R = Runner(kernel_config.scene_config(s, ray_buffers=True))
    f, m = s.fractal, s.march
    n = len(o)
    depth, point, status, samples = R.out(n), R.out4(n), R.out(n, np.int32), R.out(n, np.int32)
    flags, bracket, unresolved = R.out(n, np.int32), R.out(n), R.out(n)
    R.named("march", (n,), tile_w=n, origins=R.buf4(o), dirs=R.buf4(d), c=f.c, max_iter=f.max_iter,
            bailout=f.bailout, epsilon=m.epsilon, radius=march_radius(s), near_set=-1.0, far_set=-1.0,
            z_resolution=m.z_resolution, post_steps=m.post_steps, max_steps=m.max_steps, depth=depth,
            point=point, status=status, samples=samples, flags=flags, bracket=bracket,
            unresolved=unresolved)
    return (depth.get().astype(float), status.get(), bracket.get().astype(float), unresolved.get().astype(float))


@pytest.mark.parametrize("algebra,function,kind", [pytest.param("quaternion", "cube", "julia", marks=_SLOW),
                                                   ("hypercomplex", "sin", "julia"),
                                                   pytest.param("hypercomplex", "cosh", "julia", marks=_SLOW),
                                                   pytest.param("cquat", "sqr", "julia", marks=_SLOW),
                                                   pytest.param("commutative", "cube", "julia", marks=_SLOW),
                                                   ("quaternion", "sqr", "mandelbrot"),
                                                   pytest.param("hypercomplex", "cosh", "mandelbrot", marks=_SLOW),
                                                   pytest.param("quaternion", "sqr", "julia_stack", marks=_SLOW),
                                                   pytest.param("quaternion", "sqr", "cubic_locus", marks=_SLOW),
                                                   ("commutative", "sqr", "double"),
                                                   pytest.param("hypercomplex", "sin", "double", marks=_SLOW)])
def test_stated_interval_holds_the_brute_force(algebra, function, kind):
    # the cubic locus hits few pixels of a small view, and its spikes can be thinner than the
    # floor's point spacing: one pixel of 43 is 2.3 %, so it takes a larger view; "double": the
    # Julia set in double precision, whose proofs reach far closer (kernels/enclose/disc.cl)
    w, h = (40, 30) if kind == "cubic_locus" else (20, 15)
    double = kind == "double"
    s = Scene.from_dict({"fractal": {"algebra": algebra, "function": function, "kind": "julia" if double else kind},
                         "march": {"method": "proven", "z_resolution": 5000}, "image": {"width": w, "height": h},
                         "render": {"float": "double" if double else "single"}})
    from pyjulia4d import render
    s = render(s.with_overrides(["image.width=4", "image.height=3"])).scene   # camera.fit's camera
    o, d = ref.generate_rays(camera_frame(s), w, h)
    # the kernel and the brute force on the same rays: float32's, exactly (a grazing ray moved by
    # its rounding crosses the surface elsewhere)
    o, d = o.astype(np.float32).astype(float), d.astype(np.float32).astype(float)
    depth, status, bracket, unresolved = march_on_rays(s, o, d)
    truth = brute_force_depth(s, o, d)
    hit = (status == 1) & np.isfinite(truth)
    assert hit.sum() > 10
    slack = 16 * np.spacing(np.float32(np.maximum(depth, 1))) + 1e-6
    lo = depth - unresolved - slack
    # nothing in front of what the render admits to, but on the odd pixel where float32's
    # set test and float64's differ or a part hides in an unproven segment farther out
    assert np.mean(truth[hit] < lo[hit]) <= 0.01
    # a miss with nothing unresolved is a miss of the truth
    sure_miss = (status != 1) & (unresolved == 0)
    assert np.mean(np.isfinite(truth[sure_miss])) <= 0.01


def test_caff_kernel_matches_the_twin_and_holds_the_products():
    """kernels/enclose/caff.cl against reference/enclose/caff.py on random forms (its
    caff_ops kernel): products, sums and scalings agree in centre and tangent to float32's
    rounding of the terms (1e-5 of their sizes); the kernel's radius is at least the twin's
    less that rounding, and at most twice it plus it (both bound the same terms); and the
    kernel's product form holds the float64 products of points sampled from the two forms
    (its radius raised by float32's own slack).  Whether a form is outside the bailout disc
    agrees but for the odd form decided by a hair."""
    from pyjulia4d.reference.enclose import caff as T
    s = _case("quaternion", "sqr", "julia_stack").with_overrides(["march.method=proven"])
    R = Runner(kernel_config.scene_config(s, ray_buffers=True))
    rng = np.random.default_rng(11)
    n = 500
    scale = rng.choice([1e-3, 0.1, 1.0, 3.0], (n, 1))
    a_mv, b_mv = rng.normal(size=(n, 4)) * scale, rng.normal(size=(n, 4)) * scale
    a_mv, b_mv = a_mv.astype(np.float32).astype(float), b_mv.astype(np.float32).astype(float)
    a_r = (np.abs(rng.normal(size=n)) * 0.1 * scale[:, 0]).astype(np.float32).astype(float)
    b_r = (np.abs(rng.normal(size=n)) * 0.1 * scale[:, 0]).astype(np.float32).astype(float)
    k, bailout = (0.7, -1.3), 2.0
    outs = [R.out4(n), R.out(n), R.out4(n), R.out(n), R.out4(n), R.out(n), R.out(n, np.int32)]
    R.named("caff_ops", (n,), a_mv=R.buf4(a_mv), a_r=R.buf(a_r), b_mv=R.buf4(b_mv), b_r=R.buf(b_r), k=(*k, 0, 0),
            bailout=bailout, mul_mv=outs[0], mul_r=outs[1], add_mv=outs[2], add_r=outs[3],
            scale_mv=outs[4], scale_r=outs[5], outside=outs[6])
    form = lambda mv, r: (mv[:, 0] + 1j * mv[:, 1], mv[:, 2] + 1j * mv[:, 3], r)   # noqa: E731
    a, b = form(a_mv, a_r), form(b_mv, b_r)
    twins = [T.caff_mul(a, b), T.caff_add(a, b), T.caff_scale(complex(*k), a)]
    for j, (tm, tv, tr) in enumerate(twins):
        mv, r = R.get4(outs[2 * j]), outs[2 * j + 1].get().astype(float)
        km, kv = mv[:, 0] + 1j * mv[:, 1], mv[:, 2] + 1j * mv[:, 3]
        size = (np.abs(a[0]) + np.abs(a[1]) + a[2]) * (np.abs(b[0]) + np.abs(b[1]) + b[2] + 2) + 1e-30
        assert np.all(np.abs(km - tm) <= 1e-5 * size) and np.all(np.abs(kv - tv) <= 1e-5 * size), j
        assert np.all(r >= tr - 1e-5 * size) and np.all(r <= 2 * tr + 1e-5 * size), j
    # the kernel's product holds the products of sampled points
    sk = rng.uniform(-1, 1, (n, 64))
    ea = a[2][:, None] * np.sqrt(rng.uniform(0, 1, (n, 64))) * np.exp(2j * np.pi * rng.uniform(0, 1, (n, 64)))
    eb = b[2][:, None] * np.sqrt(rng.uniform(0, 1, (n, 64))) * np.exp(2j * np.pi * rng.uniform(0, 1, (n, 64)))
    za, zb = a[0][:, None] + sk * a[1][:, None] + ea, b[0][:, None] + sk * b[1][:, None] + eb
    mv, r = R.get4(outs[0]), outs[1].get().astype(float)
    centre = (mv[:, 0] + 1j * mv[:, 1])[:, None] + sk * (mv[:, 2] + 1j * mv[:, 3])[:, None]
    slack = 1e-6 * (np.abs(za) * np.abs(zb) + np.abs(centre))
    assert np.all(np.abs(za * zb - centre) <= r[:, None] + slack)
    ko = outs[6].get().astype(bool)
    assert np.mean(ko != T.caff_outside(a, bailout * bailout)) <= 0.02 and 0 < ko.sum() < n


def test_grazing_rays_widen_the_floor_and_finish():
    """Rays grazing a hypercomplex acos's surface (max_iter 6) run unproven for a third of
    their length: at the final preset's floor of 1/200000 they were capped past 65536
    segments.  The floor doubles after FLOOR_RUN unproven floor segments in a row
    (march/proven.cl), so they finish, kernel and twin alike, with the same status and
    overlapping stated intervals, the grazing stretch in their unresolved reach."""
    s = Scene.from_dict({"fractal": {"algebra": "hypercomplex", "function": "acos", "c": [0.0567, 0.124, -0.0511, 0.6521],
                                     "max_iter": 6},
                         "camera": {"position": [10.189, 3.66988, 6.38096, 0.465], "target": [0, 0, 0, 0.465]},
                         "slice": {"normal": [0, 0, -0.081, 1]}, "march": {"quality": "final"},
                         "image": {"width": 64, "height": 48}})
    o, d = ref.generate_rays(camera_frame(s), 64, 48)
    pick = np.ravel_multi_index(([2, 7, 9, 19, 28, 38, 40, 45, 24, 10], [27, 17, 15, 10, 53, 48, 46, 36, 32, 5]),
                                (48, 64))
    o, d = o[pick].astype(np.float32).astype(float), d[pick].astype(np.float32).astype(float)
    depth, status, bracket, unresolved = march_on_rays(s, o, d)
    f, m = s.fractal, s.march
    rb, ru = np.zeros(len(o)), np.zeros(len(o))
    rd, _, rs, rn = ref.march(o, d, march_args(s, method="proven"), bracket=rb, formula=formula_of(f),
                              unresolved=ru)
    assert np.all(status != 2) and np.all(rs != 2)          # none capped
    assert np.mean(status != rs) <= 0.1
    assert np.all(rn < m.max_steps / 8)
    both = (status == 1) & (rs == 1)
    assert both.sum() >= 6
    slack = 1e-5 * (1 + depth)
    lo_k, hi_k, lo_r, hi_r = depth - unresolved, depth + bracket, rd - ru, rd + rb
    assert np.all(((lo_k <= hi_r + slack) & (lo_r <= hi_k + slack))[both])


def test_a_lone_near_miss_is_looked_at_again(monkeypatch):
    """A floor segment left open right after a proof is gone over at a floor 16 times finer
    (march/proven.cl FINE_DIV): on rays of the hypercomplex sin's framed default view that pass
    the set closer than the floor long before they hit it, kernel and twin state the same
    narrow reach (the look proved the near miss empty), where without the look the twin
    states at least 10 times more - the distance from the near miss to the surface."""
    s = Scene.from_dict({"fractal": {"algebra": "hypercomplex", "function": "sin"}, "march": {"quality": "normal"},
                         "camera": {"position": [5.3162, 4.46233, -5.95002, 0], "target": [0.80689, 0.45405, -0.43864, 0]},
                         "image": {"width": 48, "height": 36}})
    o, d = ref.generate_rays(camera_frame(s), 48, 36)
    pick = np.array([298, 354, 495, 544, 554, 557, 595, 609])
    o, d = o[pick].astype(np.float32).astype(float), d[pick].astype(np.float32).astype(float)
    depth, status, bracket, unresolved = march_on_rays(s, o, d)
    M = importlib.import_module("pyjulia4d.reference.march")

    def twin():
        rb, ru = np.zeros(len(o)), np.zeros(len(o))
        rd, _, rs, _ = ref.march(o, d, march_args(s, method="proven"), bracket=rb, formula=formula_of(s.fractal),
                                 unresolved=ru)
        return rd, rs, ru

    rd, rs, ru = twin()
    assert np.all(status == 1) and np.all(rs == 1)
    assert np.all(np.abs(depth - rd) <= 1e-4 * (1 + rd))
    assert np.all(np.abs(unresolved - ru) <= 1e-4 + 0.1 * ru)
    monkeypatch.setattr(M, "FINE_LEAST", 1.0)   # no floor is that coarse: no look
    _, _, wide = twin()
    assert np.median(wide / np.maximum(ru, 1e-6)) >= 10

