"""The brush: the faces within a radius of a point on the surface, along a drag.

What counts as inside the brush: a face whose **centroid** lies within the radius (a 3-D
ball) of the brush centre, the mesh analogue of painting the pixels whose centre is inside the
brush disc. The labelled patch then matches the drawn circle (about pi r^2 on a flat surface)
instead of growing by a ring of partly covered faces, and a face is in or out without
ambiguity. The seed face (the face under the cursor) is always taken, so a brush smaller than
a face still labels that face.

Two modes:

- ``connected=False``, "all in the ball": every face whose centroid is in the ball, also
  faces on another layer of the surface (the far side of a thin wall, a floor under a ramp).
- ``connected=True``, "connected only": the faces in the ball reachable from the seed face
  by stepping across shared edges without leaving the ball (a flood fill over face
  adjacency), so only the layer under the cursor is painted.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
import scipy.sparse as sp

from geometry import face_adjacency
from selection._kernels import ball_faces, brush_flood, build_grid, nearest_in_ball
from selection._mesh_input import mesh_arrays

#: Aim for about this many centroids per occupied grid cell.
_FACES_PER_CELL = 8


class BrushIndex:
    """Answer brush queries on one immutable mesh: centroids, adjacency and a centroid grid.

    Building it costs a second or two at 1M faces (mostly face adjacency, which you can pass
    in when you already have it); each brush step then costs well under a millisecond for
    ~10k faces.

    Parameters
    ----------
    vertices : float [N, 3]
        Vertex positions in any frame (float64, so UTM coordinates are fine); brush centres
        are given in the same frame.
    faces : int [F, 3]
    adjacency : scipy.sparse matrix [F, F], optional
        Face adjacency over shared edges (``geometry.face_adjacency(faces)``, computed when
        not given).
    """

    def __init__(
        self,
        vertices: npt.ArrayLike,
        faces: npt.ArrayLike,
        *,
        adjacency: sp.spmatrix | sp.sparray | None = None,
    ) -> None:
        v, f = mesh_arrays(vertices, faces)
        self._centroids = np.ascontiguousarray((v[f[:, 0]] + v[f[:, 1]] + v[f[:, 2]]) / 3.0)
        adjacency = face_adjacency(f) if adjacency is None else sp.csr_matrix(adjacency)
        if adjacency.shape != (len(f), len(f)):
            raise ValueError(f"adjacency is {adjacency.shape}, expected ({len(f)}, {len(f)})")
        self._indptr = adjacency.indptr.astype(np.int64)
        self._indices = adjacency.indices.astype(np.int32)
        self._lo, self._cell, self._dims = _grid_shape(v, f, self._centroids)
        self._cell_start, self._cell_faces = build_grid(
            self._centroids, self._lo, self._cell, self._dims
        )
        for array in (self._centroids, self._indptr, self._indices):
            array.flags.writeable = False

    @property
    def n_faces(self) -> int:
        """Number of faces indexed."""
        return len(self._centroids)

    @property
    def centroids(self) -> npt.NDArray[np.float64]:
        """float64 [F, 3] face centroids (read-only), in the frame of ``vertices``."""
        return self._centroids

    def nearest_faces(self, points: npt.ArrayLike, max_distance: float) -> npt.NDArray[np.int32]:
        """Return, per point, the face with the nearest centroid within ``max_distance``, or -1.

        Parameters
        ----------
        points : float [k, 3] or [3]
        max_distance : float
            Search radius, metres.
        """
        p = _points(points)
        if self.n_faces == 0:
            return np.full(len(p), -1, np.int32)
        return nearest_in_ball(
            self._cell_start, self._cell_faces, self._lo, self._cell, self._dims,
            self._centroids, p, float(max_distance),
        )  # fmt: skip


def brush_faces(
    index: BrushIndex,
    center_points: npt.ArrayLike,
    radius: float,
    *,
    seed_face: int | npt.ArrayLike | None = None,
    connected: bool = True,
) -> npt.NDArray[np.int32]:
    """Return the faces a brush of ``radius`` paints at one or more points (see module doc).

    Parameters
    ----------
    index : BrushIndex
    center_points : float [3] or [k, 3]
        Brush centres on the surface (e.g. pick hit points, or ``stroke_points`` along a
        drag), in the frame of the index's vertices. The result is the union over all of
        them.
    radius : float
        Brush radius, metres (>= 0).
    seed_face : int, int [k] or None
        The face under each centre (from the pick). ``connected=True`` floods from it; both
        modes always include it. None: the face with the nearest centroid in the ball.
    connected : bool
        True: only faces reachable from the seed through the ball; False: all in the ball.

    Returns
    -------
    int32 [m]
        Face ids, ascending, no repeats.

    Examples
    --------
    >>> import numpy as np
    >>> v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], float)
    >>> index = BrushIndex(v, [[0, 1, 3], [0, 3, 2]])
    >>> brush_faces(index, [0.7, 0.3, 0.0], 0.1, seed_face=0).tolist()
    [0]
    >>> brush_faces(index, [0.5, 0.5, 0.0], 1.0, seed_face=0).tolist()
    [0, 1]
    """
    if not isinstance(index, BrushIndex):
        raise TypeError(
            f"brush_faces needs a BrushIndex (built once per geometry), got {type(index).__name__}"
        )
    radius = float(radius)
    if not (radius >= 0.0 and math.isfinite(radius)):
        raise ValueError(f"brush radius must be a finite number >= 0, got {radius}")
    centers = _points(center_points)
    if seed_face is None:
        seeds = (
            index.nearest_faces(centers, radius)
            if index.n_faces
            else np.full(len(centers), -1, np.int32)
        )
    else:
        seeds = np.broadcast_to(np.asarray(seed_face, dtype=np.int32).ravel(), len(centers))
        seeds = np.ascontiguousarray(seeds)
        if len(seeds) and seeds.max(initial=-1) >= index.n_faces:
            raise ValueError(f"seed face {seeds.max()} does not exist ({index.n_faces} faces)")
    if index.n_faces == 0 or len(centers) == 0:
        return np.zeros(0, np.int32)
    if connected:
        ids = brush_flood(index._indptr, index._indices, index._centroids, centers, radius, seeds)
    else:
        ids = ball_faces(
            index._cell_start, index._cell_faces, index._lo, index._cell, index._dims,
            index._centroids, centers, radius, seeds,
        )  # fmt: skip
    ids.sort()
    return ids


def stroke_points(
    p0: npt.ArrayLike | None, p1: npt.ArrayLike, spacing: float
) -> npt.NDArray[np.float64]:
    """Return brush positions that fill the gap between two drag events, at most ``spacing`` apart.

    viser throttles drag updates (about 50 ms), so a fast stroke jumps; brushing at every
    returned point paints a continuous band. Works in any dimension: 3-D surface points for
    ball mode, or 2-D screen positions to pick at (which also gives each sample its seed face
    for connected mode, and keeps the samples on the surface).

    Parameters
    ----------
    p0 : float [d] or None
        The previous brush position (already painted); None at the start of a stroke.
    p1 : float [d]
        The new position.
    spacing : float
        Largest step between samples (e.g. half the brush radius), > 0.

    Returns
    -------
    float64 [k, d]
        Evenly spaced points after ``p0`` up to and including ``p1`` (just ``p1`` when ``p0``
        is None or the points coincide).

    Examples
    --------
    >>> stroke_points([0.0, 0.0], [1.0, 0.0], 0.4).tolist()
    [[0.3333333333333333, 0.0], [0.6666666666666666, 0.0], [1.0, 0.0]]
    """
    end = np.asarray(p1, dtype=np.float64).ravel()
    if not spacing > 0.0:
        raise ValueError(f"stroke spacing must be > 0, got {spacing}")
    if p0 is None:
        return end[None, :].copy()
    start = np.asarray(p0, dtype=np.float64).ravel()
    if start.shape != end.shape:
        raise ValueError(f"stroke points differ in dimension: {start.shape} and {end.shape}")
    steps = max(1, math.ceil(float(np.linalg.norm(end - start)) / spacing))
    t = np.arange(1, steps + 1, dtype=np.float64)[:, None] / steps
    return start + t * (end - start)


def _points(points: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """Return points as finite C-contiguous float64 [k, 3]."""
    p = np.ascontiguousarray(np.atleast_2d(np.asarray(points, dtype=np.float64)))
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"points must have shape (3,) or (k, 3), got {np.shape(points)}")
    if not np.isfinite(p).all():
        raise ValueError("brush points must be finite")
    return p


def _grid_shape(
    vertices: npt.NDArray[np.float64],
    faces: npt.NDArray[np.int32],
    centroids: npt.NDArray[np.float64],
) -> tuple[npt.NDArray[np.float64], float, npt.NDArray[np.int64]]:
    """Choose a uniform grid over the centroids: ~8 per occupied cell, at most F cells."""
    n = len(centroids)
    if n == 0:
        return np.zeros(3), 1.0, np.ones(3, np.int64)
    lo = centroids.min(axis=0)
    extent = np.maximum(centroids.max(axis=0) - lo, 1e-9)
    e1 = vertices[faces[:, 1]] - vertices[faces[:, 0]]
    e2 = vertices[faces[:, 2]] - vertices[faces[:, 0]]
    mean_area = float(np.linalg.norm(np.cross(e1, e2), axis=1).mean()) / 2.0
    # a surface: ~cell^2 / area faces per cell; cap the dense cell count at F
    cell = max(math.sqrt(_FACES_PER_CELL * mean_area), (float(np.prod(extent)) / n) ** (1 / 3))
    cell = max(cell, float(extent.max()) / 1e6, 1e-9)
    dims = np.minimum(np.floor(extent / cell).astype(np.int64) + 1, 1 << 20)
    while int(np.prod(dims)) > max(n, 1):
        cell *= 1.25
        dims = np.floor(extent / cell).astype(np.int64) + 1
    return lo, cell, dims
