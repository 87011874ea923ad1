"""camera.fit (pyjulia4d/pipeline/framing.py): a quick first pass frames the set, keeping the view
direction."""
import numpy as np
import pytest

from pyjulia4d.geometry.camera import camera_frame
from pyjulia4d.pipeline.framing import fit_camera, to_scene
from pyjulia4d.geometry.camera import to_world
from pyjulia4d.opencl.executor import render
from pyjulia4d.scene.model import Scene

SPECK = ["fractal.c=-0.803762,-0.40615,0,0", "fractal.max_iter=8", "camera.position=-2,1,5,8",
         "image.width=96", "image.height=72"]


def test_to_scene_inverts_to_world():
    s = Scene.default().with_overrides(["slice.normal=0.3,0,0.2,1", "slice.distance=0.1"])
    x = np.array([0.3, -1.2, 0.7, 0.05])
    np.testing.assert_allclose(to_world(s, to_scene(s, x)), x, atol=1e-12)


def test_fit_frames_a_speck_and_keeps_the_view_direction():
    s = Scene.default().with_overrides(SPECK)
    before = render(s)
    assert before.hit_fraction < 0.05                     # README's example: a speck
    fitted, rec = fit_camera(s.with_overrides(["camera.fit=true"]), lambda sc, o: render(sc, outputs=o))
    assert rec["probe_hits"] > 0 and fitted.camera.fit is False
    np.testing.assert_allclose(camera_frame(fitted).forward, camera_frame(s).forward, atol=1e-9)
    after = render(fitted)
    assert 0.15 < after.hit_fraction < 0.8
    border = np.concatenate([after.alpha[0], after.alpha[-1], after.alpha[:, 0], after.alpha[:, -1]])
    assert np.mean(border > 0) < 0.02                     # not cut off by the frame


def test_fit_through_render():
    s = Scene.default().with_overrides(["fractal.c=-1,0.2,0,0", "camera.fit=true", "image.width=64",
                                        "image.height=48"])
    r = render(s)
    border = np.concatenate([r.alpha[0], r.alpha[-1], r.alpha[:, 0], r.alpha[:, -1]])
    assert r.hit_fraction > 0.1 and np.mean(border > 0) < 0.05


def test_fit_keeps_the_slice():
    """The pass looks in the camera's own hyperplane (the slice): slice.distance still moves
    the section the picture shows, and the fitted camera stays in it."""
    for d in (-0.6, 0.3):
        s = Scene.from_dict({"camera": {"fit": True}}, [f"slice.distance={d}", "image.width=64", "image.height=48"])
        r = render(s)
        w = r.position[..., 3][r.status == 1]
        assert w.size > 100 and np.allclose(w, d, atol=1e-6)
        assert abs(r.scene.camera.position[3]) < 1e-9 and abs(r.scene.camera.target[3]) < 1e-9



def test_a_pass_with_one_hit_frames_it_at_a_pixel_of_the_pass():
    """A set the pass sees in one pixel: the camera goes no nearer than where half that
    pixel fills the view (it had gone to 1e-6 from its target, a camera with no direction,
    which the scene's checks refused), and the framed scene renders."""
    import dataclasses
    from pyjulia4d.pipeline.framing import PROBE

    s = Scene.default().with_overrides(["camera.fit=true", "image.width=64", "image.height=48"])
    point = np.array([0.1, -0.2, 0.3, 0.0])
    seen = {}

    def one_hit(probe, outputs):
        seen["eye"] = to_world(probe, probe.camera.position)
        real = render(probe, outputs=outputs)
        pos = np.full_like(real.position, np.nan)
        pos[20, 30] = point
        return dataclasses.replace(real, position=pos)

    fitted, rec = fit_camera(s, one_hit)
    assert rec["probe_hits"] == 1
    fr = camera_frame(fitted)
    eye, target = to_world(fitted, fitted.camera.position), to_world(fitted, fitted.camera.target)
    np.testing.assert_allclose(target, point, atol=1e-6)
    tan_v = fr.tan_half_fov
    z = float((point - seen["eye"]) @ fr.forward)           # the hit's depth in the pass
    want = z * tan_v / PROBE[1] / (s.camera.margin * min(tan_v, tan_v * 64 / 48))
    assert np.linalg.norm(eye - target) == pytest.approx(want, rel=1e-6)
    r = render(fitted)
    assert r.scene.camera == fitted.camera


@pytest.mark.parametrize("extra, fill", [([], 0.9), (["camera.margin=0.5"], 0.5)])
def test_the_framed_set_is_centred_within_its_margin(extra, fill):
    """camera.fit centres what it frames: the set's extents in the picture even about its
    middle (to a pixel or two: the pass is 96x72), filling camera.margin of the half-width or
    half-height, whichever binds."""
    from pyjulia4d import render as render_scene

    w, h = 160, 120
    r = render_scene(Scene.from_dict({"image": {"width": w, "height": h}}).with_overrides(extra))
    ys, xs = np.nonzero(r.alpha > 0)
    left, right, top, bottom = xs.min(), w - 1 - xs.max(), ys.min(), h - 1 - ys.max()
    assert abs(left - right) <= 2 and abs(top - bottom) <= 2, (left, right, top, bottom)
    share = max((xs.max() - xs.min() + 1) / w, (ys.max() - ys.min() + 1) / h)
    assert abs(share - fill) <= 0.04, share


def test_a_hand_placed_camera_that_loses_the_set_is_told_of_fit():
    # camera.position turns camera.fit off; where the set then covers under 1 % of the picture,
    # the closing line says so and how to frame it, and says nothing where the set is in view
    from pathlib import Path

    from pyjulia4d.app.output import closing_line

    far = Scene.from_dict({}, ["image.width=64", "image.height=48", "camera.position=20,20,-20,0"])
    got = render(far)
    line = closing_line(Path("x.png"), far, got, "", False)
    assert got.hit_fraction < 0.01 and "of the picture: --set camera.fit=true frames it" in line
    near = Scene.default().with_overrides(["image.width=64", "image.height=48"])
    assert "camera.fit" not in closing_line(Path("x.png"), near, render(near), "", False)
