"""rays.cl (generate_rays) against reference.generate_rays, and the camera frame."""
import numpy as np
import pytest

from harness import Runner
from pyjulia4d.pipeline import kernel_config
from pyjulia4d import reference as ref
from pyjulia4d.geometry.camera import camera_frame, slice_rotation
from pyjulia4d.geometry.vec4 import cross4
from pyjulia4d.scene.model import Scene
from pyjulia4d.scene.checks import SceneError


@pytest.mark.parametrize("over", [[], ["camera.position=-2,1,5,8", "camera.fov=60"],
                                  ["camera.limbo=0,0.3,0,1", "camera.position=1,2,-3,0.5"],
                                  ["slice.normal=0.2,0,0.3,1", "slice.distance=0.3"]])
@pytest.mark.parametrize("fl,tol", [("single", 2e-6), ("double", 1e-14)])
def test_generate_rays_matches_reference(over, fl, tol):
    s = Scene.default().with_overrides(over + ["image.width=37", "image.height=23", f"render.float={fl}"])
    R = Runner(kernel_config.shade_config(s))
    f = camera_frame(s)
    w, h = 37, 23
    o, d = R.out4(w * h), R.out4(w * h)
    R.named("generate_rays", (w * h,), position=f.position, forward=f.forward, right=f.right, up=f.up,
            tan_half_fov=f.tan_half_fov, width=w, height=h, x0=0, y0=0, tile_w=w, origins=o,
            dirs=d)
    ro, rd = ref.generate_rays(f, w, h)
    # rounding of the frame to the kernel's precision and one normalise: a few ulp of a
    # unit vector (float32: 2e-6; float64: 1e-14)
    np.testing.assert_allclose(R.get4(d), rd, atol=tol)
    np.testing.assert_allclose(R.get4(o), ro, atol=tol * np.abs(ro).max())
    np.testing.assert_allclose(np.linalg.norm(R.get4(d), axis=1), 1, atol=tol / 2)


def test_frame_is_orthonormal_and_default_drops_w():
    s = Scene.default().with_overrides(["camera.position=0,0,-3.2"])
    f = camera_frame(s)
    m = np.stack([f.forward, f.right, f.up])
    np.testing.assert_allclose(m @ m.T, np.eye(3), atol=1e-12)
    assert np.allclose(m[:, 3], 0)   # limbo e_w, w = 0: the 3D view of Ödegaard & Wennergren §4
    np.testing.assert_allclose(f.right, [1, 0, 0, 0], atol=1e-12)  # looking +z with y up: x is right


def test_cross4_is_perpendicular():
    rng = np.random.default_rng(1)
    a, b, c = rng.normal(size=(3, 4))
    q = cross4(a, b, c)
    assert max(abs(q @ a), abs(q @ b), abs(q @ c)) < 1e-12


def test_slice_rotation_maps_w_to_normal():
    for n in ([0, 0, 0, 1], [0, 0, 0, -1], [1, 2, 3, 0], [0.2, 0, 0.3, 1], [0, 0, 1e-9, -1]):
        r = slice_rotation(n)
        np.testing.assert_allclose(r @ r.T, np.eye(4), atol=1e-12)
        np.testing.assert_allclose(r[:, 3], np.array(n) / np.linalg.norm(n), atol=1e-9)


def test_slice_camera_rays_stay_in_hyperplane():
    s = Scene.default().with_overrides(["slice.normal=0.3,-0.2,0.1,1", "slice.distance=0.25",
                                        "image.width=8", "image.height=6"])
    f = camera_frame(s)
    o, d = ref.generate_rays(f, 8, 6)
    n = np.array([0.3, -0.2, 0.1, 1.0]) / np.linalg.norm([0.3, -0.2, 0.1, 1.0])
    np.testing.assert_allclose(o @ n, 0.25, atol=1e-12)
    np.testing.assert_allclose(d @ n, 0, atol=1e-12)


@pytest.mark.parametrize("over,key", [(["camera.up=-1.8,-1.6,2.2,0"], "camera.up"),
                                      (["camera.limbo=1.8,1.6,-2.2,0"], "camera.limbo")])
def test_degenerate_camera_names_the_key(over, key):
    with pytest.raises(SceneError, match=f"^{key}"):
        camera_frame(Scene.default().with_overrides(over))


def test_tile_of_rays_matches_the_whole_image():
    # render.py renders in tiles: the tile at (x0, y0) is the same rays as that part of the image
    s = Scene.default().with_overrides(["image.width=37", "image.height=23"])
    R = Runner(kernel_config.shade_config(s))
    f = camera_frame(s)
    w, h, x0, y0, tw, th = 37, 23, 11, 5, 9, 7
    o, d = R.out4(tw * th), R.out4(tw * th)
    R.named("generate_rays", (tw * th,), position=f.position, forward=f.forward, right=f.right, up=f.up,
            tan_half_fov=f.tan_half_fov, width=w, height=h, x0=x0, y0=y0, tile_w=tw, origins=o,
            dirs=d)
    _, rd = ref.generate_rays(f, w, h)
    want = rd.reshape(h, w, 4)[y0:y0 + th, x0:x0 + tw].reshape(-1, 4)
    np.testing.assert_allclose(R.get4(d), want, atol=2e-6)
    _, rt = ref.generate_rays(f, w, h, x0, y0, tw, th)
    np.testing.assert_array_equal(rt, want)


def test_padded_launch_leaves_items_past_n_alone():
    # render.launch pads every launch to whole work-groups of one fixed size (so PoCL builds
    # one work-group function whatever the image size); the kernels must stop at n_items
    s = Scene.default()
    R = Runner(kernel_config.shade_config(s))
    f = camera_frame(s)
    w, h = 7, 5                                     # 35 items: not a multiple of the local size
    o = R.buf4(np.full((64 * 2, 4), 123.0))
    d = R.buf4(np.full((64 * 2, 4), 123.0))
    R.named("generate_rays", (w * h,), position=f.position, forward=f.forward, right=f.right, up=f.up,
            tan_half_fov=f.tan_half_fov, width=w, height=h, x0=0, y0=0, tile_w=w, origins=o,
            dirs=d)
    got = R.get4(d)
    assert np.all(got[w * h:] == 123.0)
    np.testing.assert_allclose(got[: w * h], ref.generate_rays(f, w, h)[1], atol=2e-6)
