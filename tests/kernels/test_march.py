"""march.cl with march/fixed.cl / march/de.cl / march/refine.cl against reference.march, on
identical rays, one ray per work-item and in packets of rays (kernels/common/lanes.cl, "Lanes")."""
import numpy as np
import pytest

from harness import Runner, packet_widths
from pyjulia4d.pipeline import kernel_config
from pyjulia4d.opencl.records import Packed, Precision
from pyjulia4d.pipeline import signatures
from pyjulia4d.pipeline.plan import march_args
from pyjulia4d import reference as ref
from pyjulia4d.geometry.camera import camera_frame, march_radius
from pyjulia4d.opencl.runner import march_items
from pyjulia4d.scene.model import Scene

W, H = 48, 36


def march_kernel(s: Scene, config, lanes: int, w: int = W, h: int = H):
    """The march kernel of ``config`` on the (float32-representable) rays of a small image:
    its outputs, the rays and the march's record (pipeline/plan.MarchArgs), which the kernel
    takes packed by its signature and the twin as it is."""
    R = Runner(config)
    o, d = ref.generate_rays(camera_frame(s), w, h)
    o, d = o.astype(R.real).astype(float), d.astype(R.real).astype(float)
    n = len(o)
    outputs = dict(depth=R.out(n), point=R.out4(n), status=R.out(n, np.int32), samples=R.out(n, np.int32),
                   flags=R.out(n, np.int32), bracket=R.out(n), unresolved=R.out(n))
    record = march_args(s)
    packed = Packed(signatures.MARCH, {"march": record}, Precision(R.double), config.defines)
    R("march", (n,), *packed(tile_w=w, origins=R.buf4(o), dirs=R.buf4(d), **outputs),
      items=march_items(n, w, lanes, kernel_config.config_packets(config)))
    out = {k: (R.get4(v) if k == "point" else v.get()) for k, v in outputs.items()}
    return out, o, d, record


def run_march(s: Scene, lanes: int = 1):
    """Kernel and reference on the same (float32-representable) rays of a small image."""
    config = (kernel_config.march_config(s, lanes, ray_buffers=True, pairs=True) if lanes > 1
              else kernel_config.scene_config(s, ray_buffers=True))
    out, o, d, args = march_kernel(s, config, lanes)
    k = (out["depth"].astype(float), out["point"], out["status"], out["samples"], out["bracket"].astype(float))
    n = len(o)
    rflags = np.zeros(n, np.int32)
    rbracket = np.zeros(n)
    r = ref.march(o, d, args, rflags, rbracket) + (rbracket,)
    # the guard flags (kernels/common/codes.cl) agree wherever the statuses do
    same = k[2] == r[2]
    assert np.array_equal(out["flags"][same], rflags[same])
    return k, r


BISECT = "march.refine=bisect"
CASES = [
    ["march.method=fixed", "march.z_resolution=120", "march.post_steps=0"],
    ["march.method=fixed", "march.z_resolution=60", "march.post_steps=10", BISECT],
    ["march.method=fixed", "march.z_resolution=60", "march.post_steps=10"],
    ["march.method=de", "march.post_steps=0"],
    ["march.method=de", "march.post_steps=6", "fractal.c=0.4,0.5,0,0", "fractal.max_iter=8", BISECT],
    ["march.method=de", "march.post_steps=12", "fractal.c=0.4,0.5,0,0", "fractal.max_iter=20",
     "march.epsilon=1e-5"],
    ["march.method=fixed", "march.z_resolution=80", "march.post_steps=4", "render.float=double", BISECT],
    ["march.method=fixed", "march.z_resolution=80", "march.post_steps=8", "render.float=double"],
    ["march.method=de", "march.post_steps=4", "render.float=double", "camera.position=-2,1,5,8", BISECT],
    ["march.method=de", "march.post_steps=10", "render.float=double", "camera.position=-2,1,5,8"],
]


def _variants(case):
    # packets of 16 and 8 rays (48x36 = 1728: whole packets; a 7-ray tail at 13 lanes is
    # not a width we build); double precision packets are at most 8 wide (opencl/lanes.py)
    if "render.float=double" in case:
        return [1] + packet_widths((8,), double=True)
    return [1] + packet_widths((8, 16))


# packets of 8 single-precision rays on the first case, the rest marked slow (setup.cfg):
# the suite's five minutes; 16 (the width a CPU runs) and one ray on every case
@pytest.mark.parametrize("over,lanes", [
    pytest.param(c, n, marks=[pytest.mark.slow] if n == 8 and "render.float=double" not in c and i >= 1 else [])
    for i, c in enumerate(CASES) for n in _variants(c)])
def test_march_matches_reference(over, lanes):
    s = Scene.default().with_overrides(over)
    (kd, kp, ks, kn, kb), (rd, rp, rs, rn, rb) = run_march(s, lanes)
    double = s.render.float == "double"
    # float32 can flip the classification of a sample that grazes the surface, which moves
    # that ray's first hit to a neighbouring sample: allowed on at most 1% of rays (none
    # in double).
    assert np.mean(ks != rs) <= (0 if double else 0.01)
    both = (ks == 1) & (rs == 1)
    assert both.sum() > 0.02 * W * H
    # every hit's bracket is certified in both: [depth, depth + width], both ends classified
    # by the set test, so two renders of one ray must give overlapping brackets.  Float32
    # places t to ~2e-7 t and can classify a point within that of the surface either way.
    tol = 1e-12 if double else 1e-6
    slack = tol * (1 + np.maximum(kd[both], rd[both]))
    lo, hi = np.maximum(kd[both], rd[both]), np.minimum(kd[both] + kb[both], rd[both] + rb[both])
    assert np.mean(lo > hi + slack) <= (0 if double else 0.01)
    dz = np.abs(kd[both] - rd[both])
    if s.march.refine == "bisect":
        # bisection takes the same decisions in both: equal to rounding of t = near + i h
        assert np.mean(dz > 10 * tol) <= (0 if double else 0.01)
        np.testing.assert_allclose(kb[both][dz <= 10 * tol], rb[both][dz <= 10 * tol],
                                   atol=20 * tol)
    else:
        # ITP's interpolation differs with rounding: equal within the wider bracket
        assert np.mean(dz > np.maximum(kb[both], rb[both]) + slack) <= (0 if double else 0.01)
    assert np.median(dz) < 10 * tol + np.median(np.maximum(kb[both], rb[both]))
    np.testing.assert_allclose(kp[both][dz <= tol], rp[both][dz <= tol], atol=4 * tol)
    assert np.all(np.isinf(kd[ks != 1])) and np.all(np.isnan(kp[ks != 1]))
    assert np.all(np.isinf(kb[ks != 1])) and np.all(kb[ks == 1] >= 0)
    assert np.mean(kn != rn) <= (0 if double else 0.01)


def test_rays_missing_the_bounding_sphere_do_no_work():
    s = Scene.default().with_overrides(["camera.fov=120"])
    (kd, kp, ks, kn, kb), _ = run_march(s)
    o, d = ref.generate_rays(camera_frame(s), W, H)
    b = np.sum(o * d, 1)
    miss = b * b - (np.sum(o * o, 1) - march_radius(s) ** 2) < -1e-6
    assert miss.any() and np.all(kn[miss] == 0) and np.all(ks[miss] == 0)


def test_step_cap_is_reported_not_hung():
    s = Scene.default().with_overrides(["march.method=de", "march.max_steps=3", "march.epsilon=1e-6"])
    (kd, kp, ks, kn, kb), (rd, rp, rs, rn, rb) = run_march(s)
    assert np.any(ks == 2) and np.all(kn <= 3)
    assert np.array_equal(ks == 2, rs == 2)


def test_post_steps_halve_the_bracket():
    # Ödegaard & Wennergren eq. 12: n post-steps shrink the bracket from h to h / 2^n; ITP reaches the
    # same bound (or better) with no more set tests
    s = Scene.default().with_overrides(["fractal.c=0,0,0,0", "fractal.max_iter=3"])
    f = s.fractal
    o = np.array([[0.0, 0, 0, 0], [0.1, 0.2, 0, 0]]) - 3 * np.array([1.0, 0, 0, 0])
    d = np.tile([1.0, 0, 0, 0], (2, 1))
    for itp in (False, True):
        for n in range(0, 16):
            a, w = ref.refine_bracket(o, d, np.array([1.0, 1.0]), np.array([2.6, 2.6]), n,
                                      f.c, f.max_iter, f.bailout, itp)
            assert np.all(w <= 1.6 / 2 ** n + 1e-15)
            # certified: a outside, a + w inside
            assert not ref.julia_inside(o + a[:, None] * d, f.c, f.max_iter, f.bailout).any()
            assert ref.julia_inside(o + (a + w)[:, None] * d, f.c, f.max_iter, f.bailout).all()


def test_itp_needs_fewer_set_tests_than_bisection():
    # the level function is smooth along the ray: ITP reaches bisection's 20-step bracket
    # in far fewer tests (counted by the early exit: remaining steps unused)
    s = Scene.default().with_overrides(["fractal.c=-0.2,0.8,0,0"])
    f = s.fractal
    o, d = ref.generate_rays(camera_frame(s), 24, 18)
    t, _, st, _ = ref.march(o, d, march_args(s, epsilon=1e-3, z_resolution=250, post_steps=0, max_steps=4096,
                                             method="fixed"))
    hit = st == 1
    o, d, t = o[hit], d[hit], t[hit]
    h = 0.02
    a0, b0 = t - h, t
    out = ~ref.julia_inside(o + a0[:, None] * d, f.c, f.max_iter, f.bailout)
    o, d, a0, b0 = o[out], d[out], a0[out], b0[out]
    for steps in (10, 20):
        n_bis, n_itp = np.zeros(len(o), int), np.zeros(len(o), int)
        _, w_bis = ref.refine_bracket(o, d, a0, b0, steps, f.c, f.max_iter, f.bailout, False, n_bis)
        _, w_itp = ref.refine_bracket(o, d, a0, b0, steps, f.c, f.max_iter, f.bailout, True, n_itp)
        assert np.all(w_itp <= h / 2 ** steps * (1 + 1e-9)) and np.all(w_bis <= h / 2 ** steps * (1 + 1e-9))
        assert np.all(n_itp <= steps + 1) and np.all(n_bis == steps)
        # measured: median 4 tests for 10 steps, 5 for 20 (c = -0.2+0.8i, max_iter 12)
        assert np.median(n_itp) <= steps / 2


@pytest.mark.parametrize("over,size", [
    ([], (48, 36)),
    # 37 blocks to a row: the last work-item's second packet lies past the tile's edge
    (["fractal.c=0.4,0.5,0,0"], (146, 9)),
    # |q'|^2 rescaled (iterate.cl DE_RESCALE) in both packets' orbits; shell steps, refinement
    (["fractal.max_iter=60", "fractal.bailout=50", "march.epsilon=1e-4"], (40, 20)),
    (["fractal.function=cube", "fractal.c=0.3,0.5,0.1,0", "fractal.theta=30"], (44, 28)),
    # a split algebra's estimate (iterate.cl, ALG_SPLIT), its four derivatives rescaled
    (["fractal.algebra=hypercomplex", "fractal.c=-0.123,0.745,0,0", "fractal.max_iter=40",
      "fractal.bailout=20"], (40, 24)),
    # the Mandelbrot sets' own estimate and level (kind/mandelbrot.cl), quaternion and split
    (["fractal.kind=mandelbrot", "fractal.max_iter=30", "camera.position=0.4,2.2,-3.2,0",
      "camera.target=-0.5,0,0,0"], (36, 20)),
    (["fractal.kind=mandelbrot", "fractal.algebra=hypercomplex", "fractal.max_iter=30",
      "camera.position=0.4,2.2,-3.2,0", "camera.target=-0.5,0,0,0"], (36, 20)),
])
def test_packet_pairs_give_the_single_packets_pixels(over, size):
    """Two packets per work-item (-D PACKET_PAIRS: march/de.cl march_ray_pair, their estimates side
    by side) take the same steps lane for lane as one packet per work-item: every output equal,
    bit for bit, whatever the tile's shape."""
    lanes = max(packet_widths((8, 16)), default=None)
    if lanes is None:
        pytest.skip("no packet width on this device")
    s = Scene.default().with_overrides(["march.method=de", *over])
    pairs = kernel_config.march_config(s, lanes, ray_buffers=True, pairs=True)
    assert kernel_config.config_packets(pairs) == 2
    single = kernel_config.KernelConfig(pairs.pieces, tuple(x for x in pairs.defines if x != "PACKET_PAIRS"))
    a, _, _, _ = march_kernel(s, pairs, lanes, *size)
    b, _, _, _ = march_kernel(s, single, lanes, *size)
    assert (a["status"] == 1).any() and (a["status"] != 1).any()
    for key in a:
        assert np.array_equal(a[key], b[key], equal_nan=True), key


def test_packet_pairs_only_where_the_estimate_is_the_iterations():
    """march_packets: pairs for the estimate's march of a Julia or Mandelbrot set in packets; one
    packet for one ray per work-item, the other marches and the other kinds' estimates."""
    d = Scene.default()
    assert kernel_config.march_packets(d, 16) == 2
    assert kernel_config.march_packets(d.with_overrides(["fractal.algebra=hypercomplex"]), 8) == 2
    assert kernel_config.march_packets(d.with_overrides(["fractal.kind=mandelbrot"]), 16) == 2
    assert kernel_config.march_packets(d, 1) == 1 and kernel_config.march_packets(d, 16, pairs=False) == 1
    for over in (["march.method=fixed"], ["march.method=proven"], ["fractal.kind=julia_stack"],
                 ["fractal.algebra=hypercomplex", "fractal.function=sin"]):
        assert kernel_config.march_packets(d.with_overrides(over), 16) == 1, over
    assert march_items(48 * 36, 48, 16, 2) == 6 * 9 and march_items(146 * 9, 146, 16, 2) == 19 * 3
    # the proven march takes one packet; its light terms, stepping by the estimate, take two
    proven = d.with_overrides(["march.quality=normal"])
    assert kernel_config.light_packets(proven, 16) == 2 and kernel_config.light_packets(proven, 16, pairs=False) == 1
    cfg = kernel_config.march_config(proven, 16, pairs=True)
    assert kernel_config.config_packets(cfg) == 1 and kernel_config.config_light_packets(cfg) == 2
    sin = proven.with_overrides(["fractal.algebra=hypercomplex", "fractal.function=sin"])
    assert kernel_config.light_packets(sin, 16) == 1   # no estimate: its shadows scan


def test_pairs_where_a_packet_fills_one_vector_register():
    """lanes.packet_pairs: two packets per work-item where one fills no more than the device's
    native vector (AVX-512: 16 floats, 8 doubles), not where it spans two (AVX2's 8 floats)."""
    from types import SimpleNamespace

    from pyjulia4d.opencl.lanes import packet_pairs

    avx512 = SimpleNamespace(native_vector_width_float=16, native_vector_width_double=8)
    avx2 = SimpleNamespace(native_vector_width_float=8, native_vector_width_double=4)
    assert packet_pairs(avx512, 16, False) and packet_pairs(avx512, 8, True)
    assert not packet_pairs(avx2, 16, False) and not packet_pairs(avx2, 8, True)
    assert not packet_pairs(avx512, 1, False) and not packet_pairs(SimpleNamespace(), 16, False)
