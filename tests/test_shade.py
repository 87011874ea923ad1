"""shade.cl against reference.shade on identical normals and points."""
import numpy as np
import pyopencl as cl
import pytest

from harness import Runner
from pyjulia4d import build, reference as ref
from pyjulia4d.camera import camera_frame, light_position
from pyjulia4d.scene import Scene


@pytest.mark.parametrize("over", [[], ["shading.light=2,3,-4"], ["shading.specular=0"],
                                  ["shading.light=-1,2,-3,0.5", "shading.shininess=5",
                                   "shading.light_color=1,0.5,0.2", "shading.background=0.1,0.2,0.3"]])
@pytest.mark.parametrize("fl", ["single", "double"])
def test_shade_matches_reference(over, fl):
    s = Scene.default().with_overrides(over + [f"render.float={fl}"])
    R = Runner(build.scene_config(s))
    fr = camera_frame(s)
    rng = np.random.default_rng(5)
    n = 4000
    status = rng.integers(0, 3, n).astype(np.int32)
    point = rng.normal(size=(n, 4)) * 0.5
    nrm = rng.normal(size=(n, 3))
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    nrm[:, 2] = np.abs(nrm[:, 2])  # facing the eye, like every visible surface
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    point, nrm = point.astype(R.real).astype(float), nrm.astype(R.real).astype(float)
    lp = light_position(s)
    sh = s.shading
    out = R.out(n, cl.cltypes.float4)
    c4 = lambda v: cl.cltypes.make_float4(*[float(x) for x in v], 0.0)
    R("shade", (n,), R.buf(status, np.int32), R.buf4(np.c_[nrm, np.zeros(n)]), R.buf4(point),
      R.vec(fr.position), R.vec(fr.right), R.vec(fr.up), R.vec(fr.forward),
      R.vec(lp if lp is not None else fr.position), c4(sh.color), c4(sh.background),
      c4(sh.light_color), np.float32(sh.ambient), np.float32(sh.diffuse), np.float32(sh.specular),
      np.float32(sh.shininess), out)
    got = out.get().view(np.float32).reshape(n, 4)
    want = ref.shade(status, nrm, point, fr, lp, sh.color, sh.background, sh.light_color,
                     sh.ambient, sh.diffuse, sh.specular, sh.shininess)
    # the shading itself is float32 in both variants (colour needs no more; shade.cl):
    # float32 arithmetic on values of order 1 (pow() amplifies by the shininess: 40 x 6e-8)
    np.testing.assert_allclose(got, want, atol=2e-5)
    assert np.all(got[status != 1, 3] == 0) and np.all(got[status == 1, 3] == 1)
