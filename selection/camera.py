"""The pinhole camera a browser client sees through, in viser's conventions."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt


def rotation_from_wxyz(wxyz: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """Return the 3x3 rotation matrix of a (w, x, y, z) quaternion (normalised first).

    Raises
    ------
    ValueError
        When the quaternion is zero or not finite.
    """
    q = np.asarray(wxyz, dtype=np.float64).reshape(4)
    length = float(np.linalg.norm(q))
    if not math.isfinite(length) or length == 0.0:
        raise ValueError(f"quaternion must be finite and non-zero, got {q.tolist()}")
    w, x, y, z = q / length
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def wxyz_from_rotation(rotation: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """Return the unit (w, x, y, z) quaternion of a rotation matrix, with w >= 0."""
    m = np.asarray(rotation, dtype=np.float64).reshape(3, 3)
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    # Shepperd's method: divide by the largest of 4w², 4x², 4y², 4z² for accuracy.
    if trace > 0.0:
        s = 2.0 * math.sqrt(trace + 1.0)
        q = [s / 4, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s]
    elif m[0, 0] >= m[1, 1] and m[0, 0] >= m[2, 2]:
        s = 2.0 * math.sqrt(max(1.0 + m[0, 0] - m[1, 1] - m[2, 2], 0.0))
        q = [(m[2, 1] - m[1, 2]) / s, s / 4, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s]
    elif m[1, 1] >= m[2, 2]:
        s = 2.0 * math.sqrt(max(1.0 + m[1, 1] - m[0, 0] - m[2, 2], 0.0))
        q = [(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, s / 4, (m[1, 2] + m[2, 1]) / s]
    else:
        s = 2.0 * math.sqrt(max(1.0 + m[2, 2] - m[0, 0] - m[1, 1], 0.0))
        q = [(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, s / 4]
    quat = np.array(q)
    quat /= np.linalg.norm(quat)
    return -quat if quat[0] < 0.0 else quat


@dataclass(frozen=True, eq=False)
class CameraModel:
    """Turn a client's view into rays and projections, exactly as viser's renderer does.

    Axes follow viser (OpenCV): the camera looks along its +z, +x points right on screen, +y
    down. Screen coordinates are normalised OpenCV image coordinates: (0, 0) is the top-left
    corner of the canvas, (1, 1) the bottom-right, (0.5, 0.5) the centre; the centre of pixel
    column i is at ``(i + 0.5) / width`` (viser's ``screen_pos`` convention).

    All positions are in one frame, the "world" of whoever built the camera (viser's scene
    frame, or a mesh's local frame after ``shifted``); the mesh given to a query must be in
    the same frame.
    """

    #: float64 [3], world frame: the centre of projection (viser ``camera.position``).
    position: npt.NDArray[np.float64]
    #: float64 [4]: R_world_camera as (w, x, y, z) (viser ``camera.wxyz``), OpenCV axes.
    wxyz: npt.NDArray[np.float64]
    #: Vertical field of view, radians (viser ``camera.fov``).
    fov: float
    #: Width / height of the canvas (viser ``camera.aspect``).
    aspect: float
    #: Canvas width in pixels: the resolution at which "visible" is judged.
    width: int
    #: Canvas height in pixels.
    height: int
    #: Near clipping distance along +z, metres; nothing closer counts as in front of the camera.
    near: float = 1e-3
    #: float64 [3, 3] R_world_camera: columns are the camera's x, y, z axes in world.
    rotation: npt.NDArray[np.float64] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        position = np.array(self.position, dtype=np.float64).reshape(3)
        wxyz = np.array(self.wxyz, dtype=np.float64).reshape(4)
        rotation = rotation_from_wxyz(wxyz)
        for array in (position, wxyz, rotation):
            array.flags.writeable = False
        if not np.isfinite(position).all():
            raise ValueError(f"camera position must be finite, got {position.tolist()}")
        if not 0.0 < self.fov < math.pi:
            raise ValueError(f"vertical fov must lie in (0, pi) radians, got {self.fov}")
        if not (self.aspect > 0.0 and self.width > 0 and self.height > 0):
            raise ValueError(
                f"aspect and canvas size must be positive, got {self.aspect}, "
                f"{self.width}x{self.height}"
            )
        if not self.near > 0.0:
            raise ValueError(f"near must be positive, got {self.near}")
        object.__setattr__(self, "position", position)
        object.__setattr__(self, "wxyz", wxyz)
        object.__setattr__(self, "rotation", rotation)

    @classmethod
    def look_at(
        cls,
        position: npt.ArrayLike,
        target: npt.ArrayLike,
        *,
        up: npt.ArrayLike = (0.0, 0.0, 1.0),
        fov: float,
        width: int,
        height: int,
        near: float = 1e-3,
    ) -> CameraModel:
        """Build a camera at ``position`` looking at ``target`` with ``up`` pointing up on screen.

        The aspect is ``width / height``, as viser reports it.
        """
        position = np.asarray(position, dtype=np.float64).reshape(3)
        forward = np.asarray(target, dtype=np.float64).reshape(3) - position
        forward /= np.linalg.norm(forward)
        right = np.cross(forward, np.asarray(up, dtype=np.float64))
        length = np.linalg.norm(right)
        if length < 1e-12:
            raise ValueError("the up direction is parallel to the viewing direction")
        right /= length
        down = np.cross(forward, right)
        rotation = np.stack([right, down, forward], axis=1)
        return cls(position, wxyz_from_rotation(rotation), fov, width / height, width, height, near)

    def shifted(self, origin: npt.ArrayLike) -> CameraModel:
        """Return this camera in a frame whose origin sits at ``origin`` (e.g. a mesh's local one).

        The subtraction is done in float64, so a UTM-scale camera keeps its precision.
        """
        return CameraModel(
            self.position - np.asarray(origin, dtype=np.float64).reshape(3),
            self.wxyz,
            self.fov,
            self.aspect,
            self.width,
            self.height,
            self.near,
        )

    @property
    def tan_half_fov(self) -> float:
        """Return tan(fov / 2): half the screen height at unit depth."""
        return math.tan(self.fov / 2.0)

    def rays(
        self, screen_xy: npt.ArrayLike
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """Return the world rays through normalised screen points, as viser's clicks report them.

        ``d_cam = ((2u - 1) tan(fov/2) aspect, (2v - 1) tan(fov/2), 1)``, rotated to world and
        normalised; every ray starts at the camera position.

        Parameters
        ----------
        screen_xy : float [n, 2] or [2]
            Normalised OpenCV screen coordinates (u right, v down, 0..1).

        Returns
        -------
        origins : float64 [n, 3], world frame
        directions : float64 [n, 3], world frame, unit length
        """
        uv = np.atleast_2d(np.asarray(screen_xy, dtype=np.float64))
        t = self.tan_half_fov
        d_cam = np.empty((len(uv), 3))
        d_cam[:, 0] = (2.0 * uv[:, 0] - 1.0) * t * self.aspect
        d_cam[:, 1] = (2.0 * uv[:, 1] - 1.0) * t
        d_cam[:, 2] = 1.0
        d_world = d_cam @ self.rotation.T
        d_world /= np.linalg.norm(d_world, axis=1)[:, None]
        return np.broadcast_to(self.position, d_world.shape).copy(), d_world

    def to_camera(self, points_world: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Return points in the camera frame (OpenCV axes): ``R^T (p - position)``."""
        p = np.atleast_2d(np.asarray(points_world, dtype=np.float64))
        return (p - self.position) @ self.rotation

    def project(
        self, points_world: npt.ArrayLike
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """Return where points land on screen and how far in front of the camera they are.

        ``u = 0.5 + x_c / (2 z_c tan(fov/2) aspect)``, ``v = 0.5 + y_c / (2 z_c tan(fov/2))``.

        Parameters
        ----------
        points_world : float [n, 3] or [3]

        Returns
        -------
        screen_xy : float64 [n, 2]
            Normalised OpenCV screen coordinates; NaN for points not in front of the camera
            (depth <= 0). Values outside 0..1 are off-screen.
        depth : float64 [n]
            Camera-frame z (distance along the viewing axis, not along the ray), metres.
        """
        pc = self.to_camera(points_world)
        depth = pc[:, 2]
        t = self.tan_half_fov
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = np.where(depth > 0.0, 0.5 / (depth * t), np.nan)
        screen_xy = np.empty((len(pc), 2))
        screen_xy[:, 0] = 0.5 + pc[:, 0] * inv / self.aspect
        screen_xy[:, 1] = 0.5 + pc[:, 1] * inv
        return screen_xy, depth
