import math

import numpy as np
import pytest

from selection import CameraModel
from selection.camera import rotation_from_wxyz, wxyz_from_rotation


def random_camera(rng, *, width=1280, height=720, far=False):
    q = rng.normal(size=4)
    position = rng.normal(size=3) * 10
    if far:
        position += [500_000.0, 5_700_000.0, 100.0]
    fov = rng.uniform(0.3, 2.0)
    return CameraModel(position, q / np.linalg.norm(q), fov, width / height, width, height)


def test_known_projections():
    # identity rotation: the camera looks along world +z, x right, y down
    cam = CameraModel(np.zeros(3), np.array([1.0, 0, 0, 0]), math.radians(90), 2.0, 200, 100)
    uv, depth = cam.project([[0, 0, 5], [10, 0, 5], [0, 5, 5], [-10, -5, 5], [0, 0, -5]])
    np.testing.assert_allclose(uv[:4], [[0.5, 0.5], [1.0, 0.5], [0.5, 1.0], [0, 0]], atol=1e-15)
    np.testing.assert_allclose(depth, [5, 5, 5, 5, -5])
    assert np.isnan(uv[4]).all()  # behind the camera

    # looking down from 10 m above the origin with world +y up on screen
    cam = CameraModel.look_at(
        [0, 0, 10], [0, 0, 0], up=[0, 1, 0], fov=math.radians(60), width=640, height=480
    )
    uv, depth = cam.project([[0, 0, 0], [1, 0, 0], [0, 1, 0]])
    t = math.tan(math.radians(30))
    np.testing.assert_allclose(depth, [10, 10, 10])
    np.testing.assert_allclose(uv[0], [0.5, 0.5])
    np.testing.assert_allclose(uv[1], [0.5 + 1 / (2 * 10 * t * 640 / 480), 0.5])  # +x: right
    np.testing.assert_allclose(uv[2], [0.5, 0.5 - 1 / (2 * 10 * t)])  # +y: up on screen


def test_rays_follow_viser_click_formula():
    """d_cam = ((2u-1) tan(fov/2) aspect, (2v-1) tan(fov/2), 1), d = R(wxyz) d_cam / |.|"""
    rng = np.random.default_rng(0)
    for _ in range(20):
        cam = random_camera(rng)
        uv = rng.random((50, 2))
        origins, directions = cam.rays(uv)
        t = math.tan(cam.fov / 2)
        d_cam = np.stack(
            [(2 * uv[:, 0] - 1) * t * cam.aspect, (2 * uv[:, 1] - 1) * t, np.ones(50)], axis=1
        )
        expected = d_cam @ rotation_from_wxyz(cam.wxyz).T
        expected /= np.linalg.norm(expected, axis=1)[:, None]
        np.testing.assert_allclose(directions, expected, atol=1e-14)
        np.testing.assert_array_equal(origins, np.broadcast_to(cam.position, origins.shape))


def test_rotation_matches_viser_convention():
    """R_world_camera from wxyz as viser's own SO3 computes it."""
    tf = pytest.importorskip("viser.transforms")
    rng = np.random.default_rng(1)
    for _ in range(20):
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        np.testing.assert_allclose(rotation_from_wxyz(q), tf.SO3(q).as_matrix(), atol=1e-12)
        back = wxyz_from_rotation(tf.SO3(q).as_matrix())
        np.testing.assert_allclose(back, q if q[0] >= 0 else -q, atol=1e-12)


@pytest.mark.parametrize("far", [False, True], ids=["local", "utm"])
def test_project_and_rays_round_trip(far):
    rng = np.random.default_rng(2)
    for _ in range(10):
        cam = random_camera(rng, far=far)
        uv = rng.random((100, 2))
        origins, directions = cam.rays(uv)
        points = origins + rng.uniform(0.5, 50.0, (100, 1)) * directions
        uv_back, depth = cam.project(points)
        assert (depth > 0).all()
        np.testing.assert_allclose(uv_back, uv, atol=1e-9 if far else 1e-12)


def test_shifted_camera_sees_the_same_screen():
    rng = np.random.default_rng(3)
    cam = random_camera(rng, far=True)
    origin = np.array([500_000.0, 5_700_000.0, 0.0])
    local = cam.shifted(origin)
    points = cam.position + rng.normal(size=(20, 3)) * 30
    uv_world, depth_world = cam.project(points)
    uv_local, depth_local = local.project(points - origin)
    np.testing.assert_allclose(uv_local, uv_world, atol=1e-9)
    np.testing.assert_allclose(depth_local, depth_world, atol=1e-6)


def test_camera_validation():
    with pytest.raises(ValueError, match="fov"):
        CameraModel(np.zeros(3), [1, 0, 0, 0], 0.0, 1.0, 10, 10)
    with pytest.raises(ValueError, match="quaternion"):
        CameraModel(np.zeros(3), [0, 0, 0, 0], 1.0, 1.0, 10, 10)
    with pytest.raises(ValueError, match="positive"):
        CameraModel(np.zeros(3), [1, 0, 0, 0], 1.0, 1.0, 0, 10)
    cam = CameraModel([1, 2, 3], [2, 0, 0, 0], 1.0, 1.0, 10, 10)
    np.testing.assert_allclose(cam.rotation, np.eye(3))  # normalised
    with pytest.raises(ValueError, match="read-only"):
        cam.position[0] = 5.0  # read-only
