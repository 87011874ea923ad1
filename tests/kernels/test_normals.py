"""normals/jacobian.cl, normals/gradient.cl and normals/zbuffer.cl against the reference,
on identical hit points."""
import numpy as np
import pytest

from harness import Runner, packet_widths
from pyjulia4d.pipeline import kernel_config
from pyjulia4d.pipeline.codes import GUARD_ULP_STEP
from pyjulia4d import reference as ref
from pyjulia4d.geometry.camera import camera_frame
from pyjulia4d.opencl.records import Packed, Precision
from pyjulia4d.pipeline import signatures
from pyjulia4d.pipeline.plan import make_plan, march_args
from pyjulia4d.scene.model import Scene

W, H = 64, 48


def hits(s: Scene, real):
    """Reference hit points of a small image, rounded to the kernel's precision."""
    m = s.march
    o, d = ref.generate_rays(camera_frame(s), W, H)
    depth, point, status, _ = ref.march(o, d, march_args(s, method=m.method))
    return depth.astype(real).astype(float), point.astype(real).astype(float), status


def angles(a, b):
    return np.degrees(np.arccos(np.clip(np.sum(a * b, -1), -1, 1)))


# (method, lanes): the Jacobian normals also run in packets of rays (kernel_config.march_config)
METHODS = [("jacobian", 1), ("gradient", 1), ("gradient pixel", 1), ("zbuffer", 1)] + \
    [("jacobian", w) for w in packet_widths((16,))]


@pytest.mark.parametrize("method,lanes", METHODS)
# the second c in double precision is marked slow (setup.cfg): the suite's five minutes
@pytest.mark.parametrize("c,fl", [((-0.2, 0.8, 0, 0), "single"), ((-0.2, 0.8, 0, 0), "double"),
                                  ((-0.125, -0.256, 0.847, 0.0895), "single"),
                                  pytest.param((-0.125, -0.256, 0.847, 0.0895), "double", marks=pytest.mark.slow)])
def test_normals_match_reference(method, lanes, fl, c):
    if lanes > 1 and fl == "double":   # double packets are at most 8 wide (opencl/lanes.py)
        lanes = max(packet_widths((4, 8), double=True), default=1)
        if lanes == 1:
            pytest.skip("this device runs no double-precision packets")
    method, _, step = method.partition(" ")   # "gradient pixel": normals.step = "pixel"
    s = Scene.default().with_overrides([f"normals.method={method}", f"render.float={fl}",
                                        "fractal.c=" + ",".join(map(str, c))] + ([f"normals.step={step}"] if step else []))
    R = Runner(kernel_config.march_config(s, lanes, ray_buffers=True) if lanes > 1
               else kernel_config.scene_config(s, ray_buffers=True))
    plan = make_plan(s, "CPU", 1)   # the kernel and its twin take the plan's records
    fr = plan.frame
    depth, point, status = hits(s, R.real)
    n = len(point)
    out = R.out4(n)
    # the march's flags buffer, holding a flag of its own the normals must keep
    flags0 = np.where(np.arange(n) % 7 == 0, GUARD_ULP_STEP, 0).astype(np.int32)
    flags = R.buf(flags0, np.int32)
    guard = flags0.astype(np.int64)   # the twin's guard: ORed into the same way
    packed = Packed(signatures.NORMALS[method], plan.records(), Precision(fl == "double"))
    given = dict(point=R.buf4(point), status=R.buf(status, np.int32), normal=out, flags=flags)
    if method == "jacobian":
        R("normals_jacobian", (n,), *packed(**given), lanes=lanes)
        want = ref.normals_jacobian(point, status, fr, plan.march, guard)
    elif method == "gradient":
        R("normals_gradient", (n,), *packed(**given))
        want = ref.normals_gradient(point, status, fr, plan.march, plan.normals_args, guard)
    else:
        R("normals_zbuffer", (W * H,), *packed(**given, depth=R.buf(depth), width=W, height=H))
        with np.errstate(invalid="ignore"):
            want = ref.normals_zbuffer(point, depth, status, W, H, fr, guard)
    got = R.get4(out)
    assert np.all(got[:, 3] == 0)   # the guard flags go to the flags buffer, not the normal's w
    # float32 and float64 may disagree on a degenerate normal at a rare pixel (none here)
    assert np.array_equal(flags.get(), guard.astype(np.int32))
    got = got[:, :3]
    hit = status == 1
    assert hit.sum() > 300
    np.testing.assert_allclose(np.linalg.norm(got[hit], axis=1), 1, atol=1e-5)
    assert np.all(got[~hit] == 0)
    a = angles(got[hit], want[hit])
    # float32: the gradient direction at max_iter 12 turns by ~1e3 rad per unit of position,
    # so float32 rounding of the iterates (~1e-7 relative) gives ~0.01 deg typically; the
    # 6-point difference divides d's rounding by 2h, a few pixels reach degrees (measured
    # max 5 deg on 80x60) at the step "auto" (1e-3).  At a pixel's footprint (about 0.03 here,
    # 30x that) the difference's rounding is 30x smaller: within 0.2 degrees at every pixel.
    # double: rounding only.
    if step == "pixel" and fl == "single":
        assert a.max() < 0.2
    elif fl == "double":
        assert a.max() < 1e-5
    else:
        assert np.median(a) < 0.05 and np.percentile(a, 99) < (2.0 if method == "gradient" else 0.5)
