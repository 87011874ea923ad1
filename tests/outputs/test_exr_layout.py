"""EXR layouts (app/exr_layout.py, image.exr) read back with OpenEXR and held to their
conventions: the camera matrices project each hit onto its own pixel, the compositing passes
are premultiplied, their depth is along the view axis with Blender's 1e10 on a miss, normals and
positions share the scene's space - on the c = 0 ball, normals are radial and positions on
its sphere, in a tilted slice too."""
import numpy as np
import OpenEXR
import pytest

import harness
from pyjulia4d import render
from pyjulia4d.app.exr_layout import MISS_DEPTH, camera_matrices
from pyjulia4d.app.output import write_image
from pyjulia4d.scene.model import Scene

W, H = 48, 36
BALL_RADIUS = 4.0 ** (1.0 / 2 ** 12)   # c = 0, 12 iterations, bailout 4 (tests/outputs/test_mesh.py)


def ball(**keys):
    s = Scene.default().replace(**{"fractal.c": [0.0, 0.0, 0.0, 0.0], "image.width": W, "image.height": H,
                                   "camera.position": [1.5, 1.0, -2.5, 0.0], "shading.background": [0.2, 0.3, 0.4],
                                   "image.samples": 4, **keys})
    return s


def written(tmp_path, scene, name="out.exr"):
    result = render(scene, device=harness.device())
    write_image(tmp_path / name, result, {})
    f = OpenEXR.File(str(tmp_path / name), separate_channels=True)
    return result, f.header(), {k: np.asarray(v.pixels) for k, v in f.channels().items()}


def row_apply(m, p):
    """p (..., 3) through a row-vector 4x4 matrix, divided by w."""
    q = np.concatenate([p, np.ones(p.shape[:-1] + (1,))], axis=-1) @ m.astype(np.float64)
    return q[..., :3] / q[..., 3:]


def test_the_default_layout_names_its_spaces_and_carries_the_camera(tmp_path):
    result, hdr, ch = written(tmp_path, ball())
    assert {"R", "G", "B", "A", "Z", "N.X", "P.W"} <= set(ch)
    assert hdr["pyjulia4d.exr_layout"] == "pyjulia4d"
    assert hdr["pyjulia4d.normal_space"].startswith("camera") and hdr["pyjulia4d.position_space"].startswith("world")
    assert hdr["worldToCamera"].shape == (4, 4) and hdr["worldToCamera"].dtype == np.float32


@pytest.mark.parametrize("layout", ["pyjulia4d", "compositing"])
def test_world_to_ndc_puts_every_hit_on_its_own_pixel(tmp_path, layout):
    """A hit lies on its pixel's centre ray: worldToNDC of its point is the pixel centre (to
    float32 rounding of the point, 1e-4 of a pixel), and worldToCamera gives it the depth along
    the view axis."""
    scene = ball(**{"image.exr": layout, "image.samples": 1})
    result, hdr, ch = written(tmp_path, scene)
    hit = np.isfinite(result.bracket)
    p = result.position[hit][:, :3].astype(np.float64)   # the default slice: world = scene
    ndc = row_apply(hdr["worldToNDC"], p)
    y, x = np.nonzero(hit)
    assert np.max(np.abs(ndc[:, 0] * W - (x + 0.5))) < 1e-3
    assert np.max(np.abs(ndc[:, 1] * H - (y + 0.5))) < 1e-3
    cam = row_apply(hdr["worldToCamera"], p)
    f = np.asarray(scene.camera.target[:3]) - np.asarray(scene.camera.position[:3])
    f /= np.linalg.norm(f)
    assert np.allclose(cam[:, 2], (p - scene.camera.position[:3]) @ f, atol=1e-5)
    assert np.all(cam[:, 2] > 0)


def test_the_compositing_passes_follow_blenders_conventions(tmp_path):
    scene = ball(**{"image.exr": "compositing"})
    result, hdr, ch = written(tmp_path, scene)
    names = {f"ViewLayer.{p}.{c}" for p, cs in (("Combined", "RGBA"), ("Depth", "Z"), ("Normal", "XYZ"),
                                                ("Position", "XYZ"), ("Bracket", "Z"), ("Unresolved", "Z"))
             for c in cs}
    assert set(ch) == names
    a = ch["ViewLayer.Combined.A"]
    rgb = np.stack([ch[f"ViewLayer.Combined.{c}"] for c in "RGB"], axis=-1)
    # premultiplied whatever the background: colour minus the background's share
    want = result.color - (1 - result.alpha)[..., None] * np.float32([0.2, 0.3, 0.4])
    assert np.allclose(rgb, want, atol=1e-6)
    assert np.all(rgb[a == 0] == 0)
    assert 0 < np.count_nonzero((a > 0) & (a < 1))   # antialiased edges: partial alpha
    full = a == 1
    assert np.array_equal(rgb[full], result.color[full])   # fully covered pixels: the colour itself
    hit = np.isfinite(result.bracket)
    z = ch["ViewLayer.Depth.Z"]
    assert np.all(z[~hit] == np.float32(MISS_DEPTH))
    pos = np.stack([ch[f"ViewLayer.Position.{c}"] for c in "XYZ"], axis=-1)
    nrm = np.stack([ch[f"ViewLayer.Normal.{c}"] for c in "XYZ"], axis=-1)
    eye = np.asarray(scene.camera.position[:3])
    f = -eye / np.linalg.norm(eye)   # the target is the origin
    assert np.allclose(z[hit], (pos[hit] - eye) @ f, rtol=1e-5)
    assert np.all(pos[~hit] == 0) and np.all(nrm[~hit] == 0)
    # the c = 0 set is a ball: its points on the sphere (to their brackets), its normals radial
    r = np.linalg.norm(pos[hit], axis=-1)
    assert np.all(np.abs(r - BALL_RADIUS) < 1e-4)
    radial = pos[hit] / r[:, None]
    assert np.percentile(np.sum(nrm[hit] * radial, axis=-1), 1) > 0.999
    assert hdr["pyjulia4d.normal_space"] == hdr["pyjulia4d.position_space"]


def test_a_tilted_slice_keeps_normals_and_positions_in_the_scenes_space(tmp_path):
    """The ball cut by a slice at distance d along a tilted normal: a ball of radius
    sqrt(R^2 - d^2) about the slice's origin, in the scene's x, y, z."""
    d = 0.4
    scene = ball(**{"image.exr": "compositing", "image.samples": 1, "slice.normal": [0.3, 0.0, 0.2, 1.0],
                    "slice.distance": d})
    result, hdr, ch = written(tmp_path, scene)
    hit = np.isfinite(result.bracket)
    pos = np.stack([ch[f"ViewLayer.Position.{c}"] for c in "XYZ"], axis=-1)[hit]
    nrm = np.stack([ch[f"ViewLayer.Normal.{c}"] for c in "XYZ"], axis=-1)[hit]
    r = np.linalg.norm(pos, axis=-1)
    assert hit.sum() > 100 and np.all(np.abs(r - np.sqrt(BALL_RADIUS ** 2 - d * d)) < 1e-4)
    assert np.percentile(np.sum(nrm * pos / r[:, None], axis=-1), 1) > 0.999
    ndc = row_apply(hdr["worldToNDC"], pos.astype(np.float64))
    y, x = np.nonzero(hit)
    assert np.max(np.abs(ndc[:, 0] * W - (x + 0.5))) < 1e-3


def test_a_camera_turned_through_w_has_no_3d_matrices(tmp_path):
    scene = ball(**{"camera.position": [1.5, 1.0, -2.5, 0.8], "camera.limbo": [0.0, 0.0, 0.3, 1.0]})
    assert camera_matrices(scene) is None
    _, hdr, _ = written(tmp_path, scene)
    assert "worldToCamera" not in hdr and hdr["pyjulia4d.camera_matrices"].startswith("none")


def test_depth_alone_gives_the_compositing_depth_pass(tmp_path, monkeypatch):
    from pyjulia4d.app.cli import main

    monkeypatch.chdir(tmp_path)
    args = ["render", "--width", "32", "--height", "24", "--set", "fractal.c=0,0,0,0", "--set", "image.exr=compositing"]
    assert main(args + ["--channels", "Z", "-o", "z.exr"]) == 0
    assert main(args + ["-o", "all.exr"]) == 0
    z = OpenEXR.File("z.exr", separate_channels=True).channels()
    full = OpenEXR.File("all.exr", separate_channels=True).channels()
    assert set(z) == {"ViewLayer.Depth.Z", "ViewLayer.Bracket.Z", "ViewLayer.Unresolved.Z"}
    # the same depth pass whatever else the render kept
    assert np.allclose(np.asarray(z["ViewLayer.Depth.Z"].pixels), np.asarray(full["ViewLayer.Depth.Z"].pixels),
                       rtol=1e-6)


def test_compositing_frames_make_a_video_over_black(tmp_path):
    from pyjulia4d.app.video import read_frame

    result, _, ch = written(tmp_path, ball(**{"image.exr": "compositing"}), "f.exr")
    frame = read_frame(tmp_path / "f.exr")
    assert frame.shape == (H, W, 3)
    assert np.all(frame[result.alpha == 0] == 0)
