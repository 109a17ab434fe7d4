"""Rubber-band selection: the faces inside a screen rectangle, all of them or only those seen.

What counts as inside:

- ``through``: every face some part of which lies beyond the camera's near plane and projects
  into the rectangle (an exact convex-polygon overlap test, resolution-independent; a face
  crossing the near plane is clipped to it first). Faces hidden behind others count too.
- ``visible``: a face counts when some part of it inside the rectangle is seen at the client's
  canvas resolution: it is the nearest surface at the centre of at least one canvas pixel in
  the rectangle (a z-buffer of face ids), or, for a face that wins no pixel centre (smaller
  than a pixel, or a sliver), its centroid lies in the rectangle and is not occluded, i.e. no
  other face covers the centroid's screen position while nearer there by more than
  ``depth_tolerance`` (relative). A face hidden behind another never counts. Back faces are
  not culled: a surface seen from behind is still seen, as by a ray cast.

How the centroid test stays fast at 1M faces: away from depth edges, a centroid lying on the
surface the z-buffer saw (within 0.1 % of the bilinear interpolation of the four pixel samples
around it) is seen and one behind all four samples is hidden; everything else (depth edges,
thin occluders, faces near them) gets the exact test, an irregular z-buffer over those
centroids. What this approximates: a face hidden by less than about 0.2 % of its depth (a
sub-pixel bump in front of it) may count as seen, and a face seen only through a hole smaller
than a pixel, in a surface without depth edges, may not.

Pixels: the rectangle holds the pixels whose centres ``((i + 0.5) / width, (j + 0.5) / height)``
lie in it, corners included (viser reports pointer positions at pixel centres).
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from selection._mesh_input import mesh_arrays
from selection._zbuffer import faces_meeting_rect, project_vertices, visible_faces
from selection.camera import CameraModel

#: Relative depth slack of the exact centroid test: a face nearer than a centroid by at most
#: this fraction of its depth does not hide it (nearly coincident surfaces both count).
DEFAULT_DEPTH_TOLERANCE = 1e-4
#: How far (relative depth) a centroid may lie off the bilinear z-buffer surface and still be
#: taken as seen without the exact test. Sub-pixel bumps stay within it; an occluder nearer by
#: more than about twice this shows up as a depth jump and sends its neighbourhood to the exact
#: test. Smaller is stricter and slower.
_SURFACE_CONSISTENCY = 1e-3


class RectMode(enum.StrEnum):
    """Which faces a rubber band takes: all under it, or only those the camera sees."""

    THROUGH = "through"
    VISIBLE = "visible"


@dataclass(frozen=True)
class ScreenRect:
    """A rubber-band rectangle in normalised OpenCV screen coordinates, as viser sends it.

    (0, 0) is the top-left corner of the canvas and (1, 1) the bottom-right; x grows to the
    right, y downwards.
    """

    #: (x, y) of the top-left corner, 0..1.
    min_xy: tuple[float, float]
    #: (x, y) of the bottom-right corner, 0..1.
    max_xy: tuple[float, float]

    def __post_init__(self) -> None:
        lo = tuple(float(v) for v in self.min_xy)
        hi = tuple(float(v) for v in self.max_xy)
        if len(lo) != 2 or len(hi) != 2 or not all(map(math.isfinite, lo + hi)):
            raise ValueError(f"rect corners must be finite (x, y) pairs, got {lo}, {hi}")
        if lo[0] > hi[0] or lo[1] > hi[1]:
            raise ValueError(f"rect min corner {lo} lies beyond its max corner {hi}")
        object.__setattr__(self, "min_xy", lo)
        object.__setattr__(self, "max_xy", hi)

    @classmethod
    def from_corners(cls, a: npt.ArrayLike, b: npt.ArrayLike) -> ScreenRect:
        """Build the rectangle spanned by two opposite corners given in any order."""
        pa = np.asarray(a, dtype=np.float64).reshape(2)
        pb = np.asarray(b, dtype=np.float64).reshape(2)
        lo, hi = np.minimum(pa, pb), np.maximum(pa, pb)
        return cls((float(lo[0]), float(lo[1])), (float(hi[0]), float(hi[1])))

    def pixel_range(self, width: int, height: int) -> tuple[int, int, int, int]:
        """Return (i0, j0, i1, j1): the inclusive pixel columns and rows whose centres lie inside.

        Empty when i0 > i1 or j0 > j1.
        """
        eps = 1e-9  # pointer positions are pixel centres; keep them despite rounding
        i0 = max(math.ceil(self.min_xy[0] * width - 0.5 - eps), 0)
        i1 = min(math.floor(self.max_xy[0] * width - 0.5 + eps), width - 1)
        j0 = max(math.ceil(self.min_xy[1] * height - 0.5 - eps), 0)
        j1 = min(math.floor(self.max_xy[1] * height - 0.5 + eps), height - 1)
        return i0, j0, i1, j1


class RectSelector:
    """Select faces under screen rectangles for one geometry, reusing what does not move.

    Holds the float64 vertices and face centroids, so each gesture only projects and
    rasterises. Immutable; safe to use from several threads.

    Parameters
    ----------
    vertices_local : float [N, 3]
        Vertex positions, in the frame the cameras will be given in (usually the mesh's local
        frame: use ``CameraModel.shifted(origin)`` for a world-frame camera).
    faces : int [F, 3]
    """

    def __init__(self, vertices_local: npt.ArrayLike, faces: npt.ArrayLike) -> None:
        vertices, faces_i32 = mesh_arrays(vertices_local, faces)
        self._vertices = vertices
        self._faces = faces_i32
        self._centroids = (
            vertices[faces_i32[:, 0]] + vertices[faces_i32[:, 1]] + vertices[faces_i32[:, 2]]
        ) / 3.0
        for array in (self._vertices, self._faces, self._centroids):
            array.flags.writeable = False

    def select(
        self,
        camera: CameraModel,
        rect: ScreenRect,
        *,
        mode: RectMode | str = RectMode.VISIBLE,
        depth_tolerance: float = DEFAULT_DEPTH_TOLERANCE,
    ) -> npt.NDArray[np.int32]:
        """Return the ids of the faces the rectangle selects, ascending (see the module doc).

        Parameters
        ----------
        camera : CameraModel
            The client's camera, in the frame of ``vertices_local``; ``width`` and ``height``
            set the resolution at which ``visible`` is judged (use the canvas's CSS size).
        rect : ScreenRect
        mode : "through" or "visible"
        depth_tolerance : float
            ``visible`` only: relative depth slack of the centroid test for faces smaller
            than a pixel.

        Returns
        -------
        int32 [k]
        """
        mode = RectMode(mode)
        w, h = camera.width, camera.height
        t = camera.tan_half_fov
        view = (
            w / (2.0 * t * camera.aspect),  # fx
            h / (2.0 * t),  # fy
            w / 2.0,  # cx
            h / 2.0,  # cy
            float(camera.near),
            rect.min_xy[0] * w,  # the rect in pixel coordinates
            rect.min_xy[1] * h,
            rect.max_xy[0] * w,
            rect.max_xy[1] * h,
        )
        proj = project_vertices(self._vertices, camera.position, camera.rotation, view)
        if mode is RectMode.THROUGH:
            return np.flatnonzero(faces_meeting_rect(self._faces, proj, view)).astype(np.int32)
        seen = visible_faces(
            self._faces,
            self._centroids,
            proj,
            camera.position,
            camera.rotation,
            view,
            rect.pixel_range(w, h),
            float(depth_tolerance),
            _SURFACE_CONSISTENCY,
        )
        return np.flatnonzero(seen).astype(np.int32)


def select_rect(
    vertices_local: npt.ArrayLike,
    faces: npt.ArrayLike,
    camera: CameraModel,
    rect: ScreenRect,
    *,
    mode: RectMode | str = RectMode.VISIBLE,
    depth_tolerance: float = DEFAULT_DEPTH_TOLERANCE,
) -> npt.NDArray[np.int32]:
    """Return the ids of the faces a rubber band selects (one-off; see ``RectSelector``).

    Build a ``RectSelector`` once per geometry instead when selecting repeatedly.
    """
    return RectSelector(vertices_local, faces).select(
        camera, rect, mode=mode, depth_tolerance=depth_tolerance
    )
