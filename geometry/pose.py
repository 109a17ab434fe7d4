"""6-D poses on a mesh surface, set the way the RViz MeshGoal tool sets them (mesh_tools).

Axes of a goal pose (mesh_tools ``MeshGoalTool::onPoseSet``, ROS convention, not Ogre's):

- z = the flat normal of the hit face, flipped toward the camera when it faces away;
- x = the drag direction, i.e. the drag point projected into the face plane minus the hit point;
- y = z x x (right-handed).

A drag shorter than ``MIN_DRAG_M`` (1 mm, as in mesh_tools) or one that runs along the normal has
no direction in the plane; then the heading is ``DEFAULT_HEADING`` (world +x) projected into the
face plane, or world +y when +x is (nearly) parallel to the normal. On a level floor a plain
click therefore gives yaw 0, the ROS convention for "no heading".

Quaternions are ``(x, y, z, w)`` as in ``geometry_msgs/Quaternion`` (viser uses ``wxyz``).
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

#: Drags shorter than this (in the face plane) set no heading; mesh_tools ignores < 1 mm too.
MIN_DRAG_M = 1e-3
#: Heading of a goal placed without a usable drag: world +x, projected into the face plane.
DEFAULT_HEADING = (1.0, 0.0, 0.0)
#: Used when the default heading is (nearly) parallel to the normal, e.g. on a wall facing +x.
FALLBACK_HEADING = (0.0, 1.0, 0.0)

# A heading whose projection into the plane is shorter than this (per unit length) is treated as
# parallel to the normal: the direction of such a tiny projection is numerically meaningless.
_PARALLEL_TOL = 1e-6


def _unit(v: npt.ArrayLike, what: str) -> npt.NDArray[np.float64]:
    """Return ``v`` as a float64 unit 3-vector, or raise ValueError naming ``what``."""
    a = np.asarray(v, dtype=np.float64).reshape(3)
    length = float(np.linalg.norm(a))
    if not math.isfinite(length) or length == 0.0:
        raise ValueError(f"{what} must be a finite non-zero 3-vector, got {a.tolist()}")
    return a / length


def _point(p: npt.ArrayLike, what: str) -> npt.NDArray[np.float64]:
    """Return ``p`` as a finite float64 3-vector, or raise ValueError naming ``what``."""
    a = np.array(p, dtype=np.float64).reshape(3)
    if not np.isfinite(a).all():
        raise ValueError(f"{what} must be finite, got {a.tolist()}")
    return a


def _in_plane(v: npt.NDArray[np.float64], n: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """Return the part of ``v`` that lies in the plane with unit normal ``n``."""
    return v - np.dot(v, n) * n


def drag_point_on_plane(
    ray_origin: npt.ArrayLike,
    ray_direction: npt.ArrayLike,
    plane_point: npt.ArrayLike,
    plane_normal: npt.ArrayLike,
) -> npt.NDArray[np.float64] | None:
    """Intersect the pointer ray of a drag with the face plane, as mesh_tools does for the heading.

    Parameters
    ----------
    ray_origin, ray_direction : float [3], world frame
        The screen ray under the pointer (camera position and any non-zero direction).
    plane_point, plane_normal : float [3], world frame
        The hit point p0 and the normal n of the face that was clicked.

    Returns
    -------
    float64 [3] or None
        The intersection point; None when the ray runs parallel to the plane or meets it only
        behind the camera. The caller then passes viser's ``end_position`` (a point on a
        camera-facing plane) to ``surface_pose``, which projects it into the face plane.
    """
    o = _point(ray_origin, "ray_origin")
    d = _unit(ray_direction, "ray_direction")
    p0 = _point(plane_point, "plane_point")
    n = _unit(plane_normal, "plane_normal")
    denom = float(np.dot(d, n))
    if abs(denom) < 1e-9:
        return None
    t = float(np.dot(p0 - o, n)) / denom
    if t < 0.0:
        return None
    return o + t * d


def surface_pose(
    hit_point: npt.ArrayLike,
    face_normal: npt.ArrayLike,
    camera_position: npt.ArrayLike,
    drag_point: npt.ArrayLike | None = None,
    *,
    default_heading: npt.ArrayLike = DEFAULT_HEADING,
    min_drag: float = MIN_DRAG_M,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Turn a click (and optional drag) on a face into a goal pose like the MeshGoal tool.

    Parameters
    ----------
    hit_point : float [3], world frame
        Where the click ray hit the face; becomes the position.
    face_normal : float [3], world frame
        The flat face normal (any length, either orientation). Pass ``interpolated_normal(...)``
        instead for a smoothly varying z axis.
    camera_position : float [3], world frame
        The normal is flipped when it points away from here: ``dot(cam - p, n) < 0``.
    drag_point : float [3] or None, world frame
        Any point along the drag direction; it is projected into the face plane, so the result
        of ``drag_point_on_plane`` and viser's off-plane ``end_position`` both work. None, a
        drag shorter than ``min_drag`` in the plane, or one along the normal → default heading.
    default_heading : float [3], world frame
        Heading used without a usable drag, projected into the plane; world +x by default,
        world +y when it is (nearly) parallel to the normal.
    min_drag : float, metres
        Shorter drags (measured in the plane) set no heading.

    Returns
    -------
    position : float64 [3]
        ``hit_point``, world frame.
    orientation_xyzw : float64 [4]
        Unit quaternion of the frame (x = heading, y = z x x, z = normal toward the camera),
        with w >= 0.
    """
    p = _point(hit_point, "hit_point")
    n = _unit(face_normal, "face_normal")
    cam = _point(camera_position, "camera_position")
    if np.dot(cam - p, n) < 0.0:
        n = -n

    x = None
    if drag_point is not None:
        along = _in_plane(_point(drag_point, "drag_point") - p, n)
        length = float(np.linalg.norm(along))
        if length >= min_drag:
            x = along / length
    if x is None:
        x = _default_heading(n, default_heading)
    y = np.cross(n, x)
    y /= np.linalg.norm(y)
    return p, quaternion_from_matrix(np.column_stack([x, y, n]))


def _default_heading(
    n: npt.NDArray[np.float64], default_heading: npt.ArrayLike
) -> npt.NDArray[np.float64]:
    """Return the first of (default, world +x, world +y) that is not parallel to ``n``, in-plane."""
    for candidate in (default_heading, DEFAULT_HEADING, FALLBACK_HEADING):
        along = _in_plane(_unit(candidate, "default_heading"), n)
        length = float(np.linalg.norm(along))
        if length > _PARALLEL_TOL:
            return along / length
    raise AssertionError("unreachable: world +x and +y cannot both be parallel to a unit normal")


def interpolated_normal(
    vertices: npt.ArrayLike,
    vertex_normals: npt.ArrayLike,
    face: npt.ArrayLike,
    point: npt.ArrayLike,
) -> npt.NDArray[np.float64]:
    """Blend the hit face's vertex normals at ``point``: the smooth alternative to the flat normal.

    Parameters
    ----------
    vertices : float [N, 3], world frame
    vertex_normals : float [N, 3]
    face : int [3]
        The vertex ids of the hit face (``faces[face_id]``).
    point : float [3], world frame
        The hit point; it is projected into the face plane and its barycentric weights are
        clamped to the triangle, so points a rounding error outside still work.

    Returns
    -------
    float64 [3]
        Unit normal; the flat face normal when the blend cancels out (or the face is degenerate
        and its corners' normals cancel).
    """
    ids = np.asarray(face, dtype=np.int64).reshape(3)
    tri = np.asarray(vertices, dtype=np.float64)[ids]
    normals = np.asarray(vertex_normals, dtype=np.float64)[ids]
    weights = _barycentric(tri, _point(point, "point"))
    blended = weights @ normals
    length = float(np.linalg.norm(blended))
    if length > 1e-12:
        return blended / length
    flat = np.cross(tri[1] - tri[0], tri[2] - tri[0])
    flat_length = float(np.linalg.norm(flat))
    if flat_length > 0.0:
        return flat / flat_length
    return np.array([0.0, 0.0, 1.0])  # lvr2's normal for a degenerate face


def _barycentric(
    tri: npt.NDArray[np.float64], point: npt.NDArray[np.float64]
) -> npt.NDArray[np.float64]:
    """Return barycentric weights of ``point`` in ``tri`` [3, 3], clamped and summing to 1."""
    e1, e2, r = tri[1] - tri[0], tri[2] - tri[0], point - tri[0]
    d11, d12, d22 = np.dot(e1, e1), np.dot(e1, e2), np.dot(e2, e2)
    det = d11 * d22 - d12 * d12
    if det <= 1e-30 * max(d11 * d22, 1e-300):
        return np.full(3, 1.0 / 3.0)  # degenerate triangle: no meaningful position inside it
    r1, r2 = np.dot(r, e1), np.dot(r, e2)
    b1 = (d22 * r1 - d12 * r2) / det
    b2 = (d11 * r2 - d12 * r1) / det
    w = np.clip(np.array([1.0 - b1 - b2, b1, b2]), 0.0, None)
    return w / w.sum()


def quaternion_from_matrix(rotation: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """Convert a rotation matrix (columns = the frame's axes in world) to a ROS quaternion.

    Parameters
    ----------
    rotation : float [3, 3]
        Proper rotation matrix; small deviations from orthonormality are tolerated.

    Returns
    -------
    float64 [4]
        Unit quaternion ``(x, y, z, w)`` with ``w >= 0`` (the sign is fixed so that equal
        rotations give equal quaternions).
    """
    m = np.asarray(rotation, dtype=np.float64).reshape(3, 3)
    if not np.isfinite(m).all():
        raise ValueError("rotation matrix must be finite")
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    # Shepperd's method: divide by the largest of 4w², 4x², 4y², 4z² for accuracy.
    if trace > 0.0:
        s = 2.0 * math.sqrt(trace + 1.0)
        q = [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, s / 4]
    elif m[0, 0] >= m[1, 1] and m[0, 0] >= m[2, 2]:
        s = 2.0 * math.sqrt(max(1.0 + m[0, 0] - m[1, 1] - m[2, 2], 0.0))
        q = [s / 4, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s, (m[2, 1] - m[1, 2]) / s]
    elif m[1, 1] >= m[2, 2]:
        s = 2.0 * math.sqrt(max(1.0 + m[1, 1] - m[0, 0] - m[2, 2], 0.0))
        q = [(m[0, 1] + m[1, 0]) / s, s / 4, (m[1, 2] + m[2, 1]) / s, (m[0, 2] - m[2, 0]) / s]
    else:
        s = 2.0 * math.sqrt(max(1.0 + m[2, 2] - m[0, 0] - m[1, 1], 0.0))
        q = [(m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, s / 4, (m[1, 0] - m[0, 1]) / s]
    quat = np.array(q)
    quat /= np.linalg.norm(quat)
    if quat[3] < 0.0:
        quat = -quat
    return quat


def matrix_from_quaternion(orientation_xyzw: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """Return the rotation matrix of a ROS quaternion (normalised first); columns = x, y, z axes.

    Raises
    ------
    ValueError
        When the quaternion is zero or not finite.
    """
    x, y, z, w = _unit4(orientation_xyzw)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def _unit4(q: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """Return ``q`` as a float64 unit 4-vector, or raise ValueError."""
    a = np.asarray(q, dtype=np.float64).reshape(4)
    length = float(np.linalg.norm(a))
    if not math.isfinite(length) or length == 0.0:
        raise ValueError(f"quaternion must be finite and non-zero, got {a.tolist()}")
    return a / length


def yaw_of(orientation_xyzw: npt.ArrayLike) -> float:
    """Return the heading shown in the goal list: the angle of the pose's x axis in the xy-plane.

    Returns
    -------
    float
        ``atan2(x_y, x_x)`` in radians, in [-pi, pi], counter-clockwise from world +x; NaN when
        the x axis is (nearly) vertical, e.g. a goal on a wall dragged straight up.
    """
    x_axis = matrix_from_quaternion(orientation_xyzw)[:, 0]
    if math.hypot(x_axis[0], x_axis[1]) < 1e-9:
        return math.nan
    return math.atan2(x_axis[1], x_axis[0])
