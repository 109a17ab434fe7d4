"""Goal poses on the surface against hand-computed frames (mesh_tools MeshGoal axes)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from geometry.pose import (
    MIN_DRAG_M,
    drag_point_on_plane,
    interpolated_normal,
    matrix_from_quaternion,
    quaternion_from_matrix,
    surface_pose,
    yaw_of,
)

S = math.sqrt(0.5)  # sin 45° = cos 45°


def axes(q):
    """Return the pose's x, y, z axes (columns of its rotation matrix)."""
    m = matrix_from_quaternion(q)
    return m[:, 0], m[:, 1], m[:, 2]


def assert_frame(q, x, y, z):
    qx, qy, qz = axes(q)
    np.testing.assert_allclose(qx, x, atol=1e-12)
    np.testing.assert_allclose(qy, y, atol=1e-12)
    np.testing.assert_allclose(qz, z, atol=1e-12)


def assert_proper_frame(q):
    m = matrix_from_quaternion(q)
    np.testing.assert_allclose(m.T @ m, np.eye(3), atol=1e-12)
    assert np.linalg.det(m) == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(np.cross(m[:, 2], m[:, 0]), m[:, 1], atol=1e-12)  # y = z x x
    assert np.linalg.norm(q) == pytest.approx(1.0, abs=1e-15)
    assert q[3] >= 0.0


# ------------------------------------------------------------------------------- surface_pose


def test_floor_drag_along_y_gives_yaw_90_degrees():
    position, q = surface_pose([1.0, 2.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 5.0], [1.0, 3.0, 0.0])
    np.testing.assert_array_equal(position, [1.0, 2.0, 0.0])
    assert position.dtype == np.float64
    assert q.dtype == np.float64
    # x = +y, z = +z, y = z x x = -x: a 90° turn about z.
    np.testing.assert_allclose(q, [0.0, 0.0, S, S], atol=1e-15)
    assert_frame(q, [0, 1, 0], [-1, 0, 0], [0, 0, 1])
    assert yaw_of(q) == pytest.approx(math.pi / 2)
    assert_proper_frame(q)


def test_returned_position_is_a_copy():
    hit = np.array([1.0, 2.0, 0.0])
    position, _ = surface_pose(hit, [0, 0, 1], [0, 0, 5])
    position[0] = 99.0
    assert hit[0] == 1.0


def test_normal_of_either_winding_is_turned_toward_the_camera():
    _, up = surface_pose([0, 0, 0], [0, 0, 1], [0, 0, 5], [1, 0, 0])
    _, flipped = surface_pose([0, 0, 0], [0, 0, -1], [0, 0, 5], [1, 0, 0])
    np.testing.assert_array_equal(up, flipped)
    np.testing.assert_allclose(up, [0, 0, 0, 1], atol=1e-15)


def test_camera_below_the_face_flips_the_normal_down():
    _, q = surface_pose([0, 0, 0], [0, 0, 1], [0.3, 0.2, -5.0], [2, 0, 0])
    # x = +x, z = -z, y = z x x = -y: a half turn about x.
    assert_frame(q, [1, 0, 0], [0, -1, 0], [0, 0, -1])
    np.testing.assert_allclose(q, [1, 0, 0, 0], atol=1e-15)
    assert_proper_frame(q)


def test_normal_length_does_not_matter():
    _, unit = surface_pose([0, 0, 0], [0, 0, 1], [0, 0, 5], [1, 1, 0])
    _, long = surface_pose([0, 0, 0], [0, 0, 37.5], [0, 0, 5], [1, 1, 0])
    np.testing.assert_allclose(unit, long, atol=1e-15)
    assert yaw_of(unit) == pytest.approx(math.pi / 4)


def test_tilted_face_drag_is_projected_into_the_face_plane():
    # A 45° slope rising toward +y; the drag point (0, 1, 0) lies below the plane.
    n = np.array([0.0, -1.0, 1.0]) / math.sqrt(2)
    _, q = surface_pose([0, 0, 0], n, [0, -5, 5], [0, 1, 0])
    # (0,1,0) - ((0,1,0)·n) n = (0, 1/2, 1/2): straight up the slope.
    x = np.array([0, 1, 1]) / math.sqrt(2)
    assert_frame(q, x, [-1, 0, 0], n)  # y = n x x = (-1, 0, 0)
    assert yaw_of(q) == pytest.approx(math.pi / 2)
    assert_proper_frame(q)


def test_drag_point_off_the_plane_only_counts_in_plane():
    n = np.array([0.0, -1.0, 1.0]) / math.sqrt(2)
    hit = np.array([3.0, 4.0, 5.0])
    drag_in_plane = hit + np.array([1.0, 0.5, 0.5])
    _, q_in = surface_pose(hit, n, hit + 10 * n, drag_in_plane)
    _, q_off = surface_pose(hit, n, hit + 10 * n, drag_in_plane + 2.5 * n)
    np.testing.assert_allclose(q_in, q_off, atol=1e-15)
    x, _, z = axes(q_in)
    np.testing.assert_allclose(x, np.array([1.0, 0.5, 0.5]) / math.sqrt(1.5), atol=1e-12)
    np.testing.assert_allclose(z, n, atol=1e-12)


def test_far_coordinates_keep_the_hand_computed_frame():
    hit = np.array([500_000.25, 5_700_000.5, 100.0])
    _, q = surface_pose(hit, [0, 0, 1], hit + np.array([0, 0, 10]), hit - np.array([0, 2, 0]))
    assert_frame(q, [0, -1, 0], [1, 0, 0], [0, 0, 1])
    assert yaw_of(q) == pytest.approx(-math.pi / 2)


@pytest.mark.parametrize(
    "drag",
    [
        None,
        [0.0, 0.0, 0.0],  # zero length: mouse up where it went down
        [0.0004, 0.0003, 0.0],  # 0.5 mm < 1 mm
        [0.0, 0.0, 3.0],  # along the normal: no direction in the plane
        [0.0002, 0.0, -7.0],  # mostly along the normal, 0.2 mm in the plane
    ],
)
def test_degenerate_drags_use_world_x(drag):
    _, q = surface_pose([0, 0, 0], [0, 0, 1], [1, 1, 5], drag)
    np.testing.assert_allclose(q, [0, 0, 0, 1], atol=1e-15)
    assert yaw_of(q) == 0.0


def test_drag_just_over_the_threshold_sets_the_heading():
    _, q = surface_pose([0, 0, 0], [0, 0, 1], [0, 0, 5], [0.0, 1.01 * MIN_DRAG_M, 0.0])
    assert yaw_of(q) == pytest.approx(math.pi / 2)


def test_default_heading_on_a_slope_is_world_x_projected():
    n = np.array([1.0, 0.0, 1.0]) / math.sqrt(2)
    _, q = surface_pose([0, 0, 0], n, [5, 0, 5])
    # (1,0,0) - (1/√2) n = (1/2, 0, -1/2): down the slope, still yaw 0.
    x = np.array([1, 0, -1]) / math.sqrt(2)
    assert_frame(q, x, np.cross(n, x), n)
    assert yaw_of(q) == pytest.approx(0.0)
    assert_proper_frame(q)


def test_default_heading_on_a_wall_facing_x_is_world_y():
    _, q = surface_pose([0, 0, 0], [1, 0, 0], [5, 0, 0])
    # x ∥ n, so x = +y; y = (1,0,0) x (0,1,0) = +z.
    assert_frame(q, [0, 1, 0], [0, 0, 1], [1, 0, 0])
    assert yaw_of(q) == pytest.approx(math.pi / 2)


def test_default_heading_on_a_wall_facing_minus_x_seen_from_behind():
    # Stored normal +x, camera on the -x side: z flips to -x; x = +y; y = (-1,0,0) x (0,1,0) = -z.
    _, q = surface_pose([0, 0, 0], [1, 0, 0], [-5, 0, 0])
    assert_frame(q, [0, 1, 0], [0, 0, -1], [-1, 0, 0])


def test_default_heading_on_a_wall_facing_y_is_world_x():
    _, q = surface_pose([0, 0, 0], [0, 1, 0], [0, 5, 0], None)
    assert_frame(q, [1, 0, 0], [0, 0, -1], [0, 1, 0])


def test_custom_default_heading_and_its_fallback():
    _, q = surface_pose([0, 0, 0], [0, 0, 1], [0, 0, 5], default_heading=[0, -1, 0])
    assert yaw_of(q) == pytest.approx(-math.pi / 2)
    # Parallel to the normal → world +x.
    _, q = surface_pose([0, 0, 0], [0, 0, 1], [0, 0, 5], default_heading=[0, 0, 2])
    assert yaw_of(q) == 0.0


def test_nearly_parallel_default_heading_falls_back():
    n = np.array([1.0, 0.0, 1e-9])
    _, q = surface_pose([0, 0, 0], n, [5, 0, 0])
    x, _, _ = axes(q)
    np.testing.assert_allclose(x, [0, 1, 0], atol=1e-12)


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (([0, 0, 0], [0, 0, 0], [0, 0, 5]), "face_normal"),
        (([0, 0, np.nan], [0, 0, 1], [0, 0, 5]), "hit_point"),
        (([0, 0, 0], [0, 0, 1], [0, np.inf, 5]), "camera_position"),
        (([0, 0, 0], [0, 0, 1], [0, 0, 5], [np.nan, 1, 0]), "drag_point"),
    ],
)
def test_bad_input_raises_value_error(args, match):
    with pytest.raises(ValueError, match=match):
        surface_pose(*args)


def test_random_poses_are_proper_frames_with_the_promised_axes():
    rng = np.random.default_rng(5)
    for _ in range(500):
        hit = rng.normal(size=3) * 100
        normal = rng.normal(size=3)
        cam = hit + rng.normal(size=3) * 10
        drag = hit + rng.normal(size=3)
        _, q = surface_pose(hit, normal, cam, drag)
        assert_proper_frame(q)
        x, _, z = axes(q)
        n = normal / np.linalg.norm(normal)
        assert abs(np.dot(z, n)) == pytest.approx(1.0)
        assert np.dot(z, cam - hit) >= 0.0
        along = (drag - hit) - np.dot(drag - hit, n) * n
        np.testing.assert_allclose(x, along / np.linalg.norm(along), atol=1e-9)


# ------------------------------------------------------------------------- drag_point_on_plane


def test_drag_ray_meets_the_face_plane():
    p = drag_point_on_plane([0, 0, 5], [1, 0, -1], [3, 3, 0], [0, 0, 1])
    np.testing.assert_allclose(p, [5, 0, 0], atol=1e-12)


def test_drag_ray_from_below_meets_the_plane_and_normal_sign_is_irrelevant():
    p = drag_point_on_plane([1, 1, -2], [0, 0, 0.5], [0, 0, 0], [0, 0, -1])
    np.testing.assert_allclose(p, [1, 1, 0], atol=1e-12)


def test_drag_ray_parallel_to_the_plane_misses():
    assert drag_point_on_plane([0, 0, 5], [1, 0, 0], [0, 0, 0], [0, 0, 1]) is None


def test_drag_ray_pointing_away_from_the_plane_misses():
    # The pointer went above the horizon: the plane lies behind the camera along this ray.
    assert drag_point_on_plane([0, 0, 5], [0, 1, 0.2], [0, 0, 0], [0, 0, 1]) is None


def test_drag_on_a_tilted_plane():
    n = np.array([0.0, -1.0, 1.0]) / math.sqrt(2)  # plane z = y through the origin
    p = drag_point_on_plane([0, 0, 4], [0, 1, -1], [0, 0, 0], n)
    np.testing.assert_allclose(p, [0, 2, 2], atol=1e-12)


def test_click_and_drag_on_the_floor_as_the_app_does_it():
    cam = np.array([0.0, -4.0, 3.0])
    hit = np.array([0.0, 0.0, 0.0])
    target = np.array([2.0, 1.0, 0.0])
    drag = drag_point_on_plane(cam, target - cam, hit, [0, 0, 1])
    np.testing.assert_allclose(drag, target, atol=1e-12)
    _, q = surface_pose(hit, [0, 0, 1], cam, drag)
    assert yaw_of(q) == pytest.approx(math.atan2(1.0, 2.0))


def test_drag_that_leaves_the_mesh_falls_back_to_viser_end_position():
    # Camera low over the floor, pointer dragged above the horizon: the ray never meets the
    # plane, so the app passes viser's end_position (on a camera-facing plane) instead.
    cam = np.array([0.0, -10.0, 1.0])
    hit = np.array([0.0, 0.0, 0.0])
    ray = np.array([0.3, 1.0, 0.05])
    assert drag_point_on_plane(cam, ray, hit, [0, 0, 1]) is None
    end_position = np.array([3.0, 0.0, 2.0])
    _, q = surface_pose(hit, [0, 0, 1], cam, end_position)
    assert_frame(q, [1, 0, 0], [0, 1, 0], [0, 0, 1])


# -------------------------------------------------------------------------- interpolated_normal

TRI = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
TRI_NORMALS = np.array([[0.0, 0.0, 1.0], [S, 0.0, S], [0.0, S, S]])


def test_interpolated_normal_at_a_corner_is_that_vertex_normal():
    for i in range(3):
        n = interpolated_normal(TRI, TRI_NORMALS, [0, 1, 2], TRI[i])
        np.testing.assert_allclose(n, TRI_NORMALS[i], atol=1e-12)


def test_interpolated_normal_on_an_edge_and_at_the_centroid():
    n = interpolated_normal(TRI, TRI_NORMALS, [0, 1, 2], [0.5, 0.0, 0.0])
    mid = (TRI_NORMALS[0] + TRI_NORMALS[1]) / 2
    np.testing.assert_allclose(n, mid / np.linalg.norm(mid), atol=1e-12)
    n = interpolated_normal(TRI, TRI_NORMALS, [0, 1, 2], [1 / 3, 1 / 3, 0.2])  # above the plane
    total = TRI_NORMALS.sum(axis=0)
    np.testing.assert_allclose(n, total / np.linalg.norm(total), atol=1e-12)


def test_interpolated_normal_uses_the_face_ids_into_the_vertex_arrays():
    vertices = np.vstack([np.full((2, 3), 9.0), TRI])
    normals = np.vstack([np.full((2, 3), 0.3), TRI_NORMALS])
    n = interpolated_normal(vertices, normals, np.array([2, 3, 4], dtype=np.int32), TRI[1])
    np.testing.assert_allclose(n, TRI_NORMALS[1], atol=1e-12)


def test_interpolated_normal_clamps_points_just_outside():
    n = interpolated_normal(TRI, TRI_NORMALS, [0, 1, 2], [-1e-12, 0.0, 0.0])
    np.testing.assert_allclose(n, TRI_NORMALS[0], atol=1e-9)
    n = interpolated_normal(TRI, TRI_NORMALS, [0, 1, 2], [2.0, -1.0, 0.0])  # far beyond corner 1
    np.testing.assert_allclose(n, TRI_NORMALS[1], atol=1e-12)


def test_interpolated_normal_falls_back_to_the_flat_normal_when_the_blend_cancels():
    normals = np.array([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    n = interpolated_normal(TRI, normals, [0, 1, 2], [0.5, 0.0, 0.0])
    np.testing.assert_allclose(n, [0, 0, 1], atol=1e-12)


def test_interpolated_normal_on_a_degenerate_face_averages_the_corners():
    line = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    n = interpolated_normal(line, TRI_NORMALS, [0, 1, 2], [1.0, 0.0, 0.0])
    total = TRI_NORMALS.sum(axis=0)
    np.testing.assert_allclose(n, total / np.linalg.norm(total), atol=1e-12)


def test_interpolated_normal_feeds_surface_pose():
    n = interpolated_normal(TRI, TRI_NORMALS, [0, 1, 2], [1.0, 0.0, 0.0])
    _, q = surface_pose([1, 0, 0], n, [5, 0, 5], [1, 1, 0])
    _, _, z = axes(q)
    np.testing.assert_allclose(z, [S, 0, S], atol=1e-12)


# ------------------------------------------------------------------------------- quaternions


@pytest.mark.parametrize(
    ("q", "matrix"),
    [
        ([0, 0, 0, 1], np.eye(3)),
        ([0, 0, S, S], [[0, -1, 0], [1, 0, 0], [0, 0, 1]]),  # +90° about z
        ([1, 0, 0, 0], [[1, 0, 0], [0, -1, 0], [0, 0, -1]]),  # 180° about x
        ([0, 1, 0, 0], [[-1, 0, 0], [0, 1, 0], [0, 0, -1]]),  # 180° about y
        ([0, 0, 1, 0], [[-1, 0, 0], [0, -1, 0], [0, 0, 1]]),  # 180° about z
        ([0.5, 0.5, 0.5, 0.5], [[0, 0, 1], [1, 0, 0], [0, 1, 0]]),  # 120° about (1,1,1)
    ],
)
def test_hand_computed_quaternions(q, matrix):
    np.testing.assert_allclose(matrix_from_quaternion(q), matrix, atol=1e-15)
    np.testing.assert_allclose(quaternion_from_matrix(matrix), q, atol=1e-15)


def test_quaternion_round_trips_cover_every_branch():
    rng = np.random.default_rng(7)
    qs = rng.normal(size=(2000, 4))
    # Near-half-turns exercise the branches where w is small and x, y or z dominates.
    qs[:300, 3] *= 1e-3
    for q in qs:
        q = q / np.linalg.norm(q)
        q = q if q[3] >= 0 else -q
        back = quaternion_from_matrix(matrix_from_quaternion(q))
        np.testing.assert_allclose(back, q, atol=1e-12)
        m = matrix_from_quaternion(q)
        np.testing.assert_allclose(matrix_from_quaternion(back), m, atol=1e-12)


def test_quaternion_sign_is_canonical():
    np.testing.assert_allclose(
        quaternion_from_matrix(matrix_from_quaternion([0, 0, -S, -S])), [0, 0, S, S], atol=1e-15
    )


def test_matrix_from_quaternion_normalises_and_rejects_zero():
    np.testing.assert_allclose(matrix_from_quaternion([0, 0, 0, 2.0]), np.eye(3))
    with pytest.raises(ValueError, match="non-zero"):
        matrix_from_quaternion([0, 0, 0, 0])
    with pytest.raises(ValueError, match="finite"):
        matrix_from_quaternion([0, 0, np.nan, 1])
    with pytest.raises(ValueError, match="finite"):
        quaternion_from_matrix(np.full((3, 3), np.nan))


# -------------------------------------------------------------------------------------- yaw_of


@pytest.mark.parametrize(
    ("q", "yaw"),
    [
        ([0, 0, 0, 1], 0.0),
        ([0, 0, S, S], math.pi / 2),
        ([0, 0, -S, S], -math.pi / 2),
        ([0, 0, 1, 0], math.pi),
        ([1, 0, 0, 0], 0.0),  # upside down, still heading +x
        ([0, math.sin(math.pi / 8), 0, math.cos(math.pi / 8)], 0.0),  # pitched 45° down
    ],
)
def test_yaw_of_hand_computed(q, yaw):
    assert yaw_of(q) == pytest.approx(yaw, abs=1e-12)


def test_yaw_of_vertical_heading_is_nan():
    # -90° about y turns x to +z: a goal on a wall dragged straight up has no heading in xy.
    assert math.isnan(yaw_of([0, -S, 0, S]))
