"""The explorer's camera moves (pyjulia4d/geometry/navigate.py) against their definition: rotations
of the camera's orthonormal frame (Ödegaard & Wennergren §4) about the target, in one plane each."""
import math

import numpy as np
import pytest

from pyjulia4d.geometry import navigate
from pyjulia4d.geometry.camera import camera_frame
from pyjulia4d.scene.checks import SceneError
from pyjulia4d.scene.model import Camera, Scene

CAMERAS = [Camera(), Camera(position=(0.3, -2.0, 1.1, 0.7), target=(0.1, 0.2, -0.1, 0.3), up=(0.2, 0.0, 1.0, 0.1),
                            limbo=(0.1, 0.3, 0.0, 1.0), fov=30.0)]
# float64 rotations of unit vectors: agreement to a few ulps of the coordinates
TOL = 1e-12


def distance(cam):
    return float(np.linalg.norm(np.subtract(cam.target, cam.position)))


@pytest.mark.parametrize("cam", CAMERAS)
@pytest.mark.parametrize("yaw,pitch", [(10.0, 0.0), (0.0, -25.0), (-73.0, 41.0), (180.0, 89.0)])
def test_orbit_keeps_the_target_and_distance_and_turns_by_the_angle(cam, yaw, pitch):
    f0, r0, u0, l0, d0 = navigate.frame(cam)
    moved = navigate.orbit(cam, yaw, pitch)
    f1, r1, u1, l1, d1 = navigate.frame(moved)
    assert moved.target == cam.target and not moved.fit
    assert d1 == pytest.approx(d0, rel=TOL)
    # the view stays in the 3D space of (f, r, u): limbo is untouched
    assert np.allclose(l1, l0, atol=TOL) and abs(f1 @ l0) < TOL
    # the angle between the old and new view directions: yaw then pitch, cos = cos(yaw) cos(pitch)
    assert f1 @ f0 == pytest.approx(math.cos(math.radians(yaw)) * math.cos(math.radians(pitch)), abs=1e-12)
    # positive yaw moves the camera right, positive pitch moves it up
    step = np.subtract(moved.position, cam.position)
    if yaw and abs(yaw) < 180:
        assert math.copysign(1, step @ r0) == math.copysign(1, yaw)
    if pitch and not yaw:
        assert math.copysign(1, step @ u0) == math.copysign(1, pitch)


@pytest.mark.parametrize("cam", CAMERAS)
def test_a_full_turn_comes_back(cam):
    moved = cam
    for _ in range(36):
        moved = navigate.orbit(moved, 10.0, 0.0)
    assert np.allclose(moved.position, cam.position, atol=1e-9)
    moved = cam
    for _ in range(4):
        moved = navigate.turn_w(moved, 90.0)
    assert np.allclose(moved.position, cam.position, atol=1e-9)


@pytest.mark.parametrize("cam", CAMERAS)
def test_turn_w_turns_the_view_towards_limbo(cam):
    f0, r0, u0, l0, d0 = navigate.frame(cam)
    moved = navigate.turn_w(cam, 30.0)
    f1, r1, u1, l1, d1 = navigate.frame(moved)
    assert d1 == pytest.approx(d0, rel=TOL)
    # in the plane (f, limbo) only: right and up are unchanged
    assert np.allclose(r1, r0, atol=1e-12) and np.allclose(u1, u0, atol=1e-12)
    assert f1 @ f0 == pytest.approx(math.cos(math.radians(30.0)), abs=1e-12)
    assert f1 @ l0 == pytest.approx(-math.sin(math.radians(30.0)), abs=1e-12)


def test_turn_w_from_the_default_camera_leaves_the_w_0_space():
    moved = navigate.turn_w(Camera(), 45.0)
    assert abs(moved.position[3]) > 0.5


@pytest.mark.parametrize("factor", [0.5, 2.0, 1e-9])
def test_zoom_slides_along_the_view(factor):
    cam = CAMERAS[1]
    moved = navigate.zoom(cam, factor)
    assert distance(moved) == pytest.approx(max(navigate.MIN_DISTANCE, distance(cam) * factor), rel=1e-9)
    assert np.allclose(navigate.frame(moved)[0], navigate.frame(cam)[0], atol=1e-9)


@pytest.mark.parametrize("factor", [0.0, -1.0, float("nan"), float("inf")])
def test_zoom_refuses_a_bad_factor(factor):
    with pytest.raises(SceneError):
        navigate.zoom(Camera(), factor)


def test_a_move_past_the_coordinate_range_is_refused():
    with pytest.raises(SceneError, match="camera.position"):
        navigate.zoom(Camera(), 1e7)


def test_pitch_stops_short_of_the_pole():
    moved = navigate.orbit(Camera(), 0.0, 500.0)
    f0, _, _, _, _ = navigate.frame(Camera())
    f1, _, u1, _, _ = navigate.frame(moved)
    assert f1 @ f0 == pytest.approx(math.cos(math.radians(navigate.MAX_PITCH)), abs=1e-12)


def test_the_moved_camera_renders_the_same_frame():
    """The scene's own frame (geometry/camera.py) of a moved camera is navigate's frame."""
    cam = navigate.turn_w(navigate.orbit(CAMERAS[1], 33.0, -12.0), 17.0)
    fr = camera_frame(Scene(camera=cam))
    f, r, u, l, d = navigate.frame(cam)
    assert np.allclose(fr.forward, f, atol=1e-12) and np.allclose(fr.up, u, atol=1e-12)
    assert np.allclose(fr.right, r, atol=1e-12)
