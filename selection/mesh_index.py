"""The Embree index of one mesh geometry: where a ray first meets the surface."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from embreex import rtcore_scene
from embreex.mesh_construction import TriangleMesh

from geometry import local_origin, vertex_face_incidence
from selection._mesh_input import mesh_arrays
from selection._ray_kernels import GRAZED, refine_hit, refine_hits, shift_ray, shift_rays

#: Embree's "no limit" ray length (what embreex itself uses).
_FAR = np.float32(1e37)
#: How many times a ray that grazes ridge after ridge is cast again beyond the last one.
_RECASTS = 8


@dataclass(frozen=True, eq=False)
class PickResult:
    """Say which face each ray hits first and how far along the ray it is."""

    #: int32 [n]: the first face hit, -1 on a miss.
    face_ids: npt.NDArray[np.int32]
    #: float64 [n]: ray parameter t of the hit (hit = origin + t * direction, so metres for a
    #: unit direction), computed in float64; +inf on a miss.
    distances: npt.NDArray[np.float64]

    def __iter__(self) -> Iterator[npt.NDArray]:
        # lets callers write ``face_ids, distances = index.pick(...)``
        return iter((self.face_ids, self.distances))

    def __len__(self) -> int:
        return len(self.face_ids)


class _Scratch(threading.local):
    """Per-thread float32 buffers for single-ray picks (callbacks run on a thread pool)."""

    def __init__(self) -> None:
        self.origins32 = np.empty((1, 3), np.float32)
        self.directions32 = np.empty((1, 3), np.float32)
        self.far = np.full(1, _FAR, np.float32)


class MeshIndex:
    """Answer ray queries on one immutable mesh with Embree, exact to float64 at UTM scale.

    Vertices are shifted to a float64 local origin before the float32 cast, so precision does
    not depend on how far the map lies from 0; rays are shifted the same way, in float64.
    Embree's float32 answer is then checked in float64 and corrected near face edges
    (``refine_hits``), so the face agrees with a float64 ray–triangle test.

    Construction builds and commits the BVH (embreex does it on the first query, so the
    constructor fires one), which takes about a second at 1M faces: build it off the UI thread.
    The index is immutable and safe to query from several threads at once.

    Parameters
    ----------
    vertices : float [N, 3]
        Vertex positions in the caller's frame (e.g. world/UTM); kept as float64.
    faces : int [F, 3]
        Vertex ids of each triangle; face ids in results index these rows.
    origin : float [3], optional
        The float64 point subtracted before the float32 cast; by default
        ``geometry.local_origin(vertices)``. Pass the document's origin to share it.
    """

    def __init__(
        self,
        vertices: npt.ArrayLike,
        faces: npt.ArrayLike,
        *,
        origin: npt.ArrayLike | None = None,
    ) -> None:
        vertices, faces_i32 = mesh_arrays(vertices, faces)
        shift = local_origin(vertices) if origin is None else np.asarray(origin, np.float64)
        self._origin = np.array(shift, dtype=np.float64).reshape(3)
        self._vertices_local = np.ascontiguousarray(vertices - self._origin)
        self._faces = faces_i32
        incidence = vertex_face_incidence(faces_i32, len(vertices))
        self._incidence_ptr = incidence.indptr.astype(np.int64)
        self._incidence_ids = incidence.indices.astype(np.int32)
        for array in (self._origin, self._vertices_local, self._faces):
            array.flags.writeable = False
        self._scene = rtcore_scene.EmbreeScene(robust=True)
        if len(faces_i32):
            TriangleMesh(self._scene, self._vertices_local.astype(np.float32), faces_i32)
        # embreex commits the BVH on the first run: do it now, not on the first click.
        self._scene.run(np.zeros((1, 3), np.float32), np.ones((1, 3), np.float32))
        self._scratch = _Scratch()

    @property
    def origin(self) -> npt.NDArray[np.float64]:
        """The float64 origin subtracted from vertices and rays before the float32 cast."""
        return self._origin

    @property
    def n_faces(self) -> int:
        """Number of faces indexed."""
        return len(self._faces)

    def pick(self, origins: npt.ArrayLike, directions: npt.ArrayLike) -> PickResult:
        """Return the first face each ray hits and the distance to it.

        Parameters
        ----------
        origins : float64 [n, 3] or [3]
            Ray origins in the frame of ``vertices`` (not shifted: the index does that in
            float64).
        directions : float64 [n, 3], [1, 3] or [3]
            Ray directions (any non-zero length; one row is shared by all rays).

        Returns
        -------
        PickResult
            ``face_ids`` int32 [n] (-1 = miss) and ``distances`` float64 [n] (+inf = miss) in
            units of the direction's length; n = 1 for a single ray given as shape (3,).
        """
        if (
            type(origins) is np.ndarray
            and origins.shape == (3,)
            and origins.dtype == np.float64
            and type(directions) is np.ndarray
            and directions.shape == (3,)
            and directions.dtype == np.float64
        ):
            return self._pick_one(origins, directions)
        o, d = self._rays(origins, directions)
        return self._pick_many(o, d)

    def _pick_many(
        self, o: npt.NDArray[np.float64], d: npt.NDArray[np.float64], recasts: int = _RECASTS
    ) -> PickResult:
        """Pick [n, 3] rays (directions [n, 3] or [1, 3]), recasting rays that graze a ridge."""
        n = len(o)
        o32 = np.empty((n, 3), np.float32)
        d32 = np.empty((len(d), 3), np.float32)
        shift_rays(o, d, self._origin, o32, d32)
        face_ids = self._scene.run(o32, d32, np.full(n, _FAR, np.float32))
        embree_ids = face_ids.copy()
        distances = np.empty(n, np.float64)
        refine_hits(
            face_ids,
            o,
            d,
            self._origin,
            self._vertices_local,
            self._faces,
            self._incidence_ptr,
            self._incidence_ids,
            distances,
        )
        grazed = np.flatnonzero(face_ids == GRAZED)
        if len(grazed) and recasts == 0:
            # a ray running along a ridge: keep the face float32 found on it
            face_ids[grazed] = embree_ids[grazed]
        elif len(grazed):
            # Float32 stopped these rays at a ridge that they pass by in float64: look beyond it,
            # skipping a hair (1e-6 of the distance, at least 0.1 mm) so the ridge is not hit again.
            d_g = d[grazed] if len(d) == n else d
            length = np.linalg.norm(d_g, axis=1)
            skip = distances[grazed] + np.maximum(1e-6 * distances[grazed], 1e-4 / length)
            beyond = self._pick_many(o[grazed] + skip[:, None] * d_g, d_g, recasts - 1)
            face_ids[grazed] = beyond.face_ids
            distances[grazed] = beyond.distances + skip
        return PickResult(face_ids, distances)

    def _pick_one(self, o: npt.NDArray[np.float64], d: npt.NDArray[np.float64]) -> PickResult:
        """Pick one [3] ray with per-thread buffers: the click path, a few microseconds."""
        s = self._scratch
        shift_ray(o, d, self._origin, s.origins32, s.directions32)
        face_ids = self._scene.run(s.origins32, s.directions32, s.far)
        distances = np.empty(1, np.float64)
        refine_hit(
            face_ids,
            o,
            d,
            self._origin,
            self._vertices_local,
            self._faces,
            self._incidence_ptr,
            self._incidence_ids,
            distances,
        )
        if face_ids[0] == GRAZED:
            return self._pick_many(o.reshape(1, 3), d.reshape(1, 3))
        return PickResult(face_ids, distances)

    def occluded(
        self,
        origins: npt.ArrayLike,
        directions: npt.ArrayLike,
        max_distances: npt.ArrayLike,
    ) -> npt.NDArray[np.bool_]:
        """Say whether anything lies on each ray before ``max_distances`` (Embree's cheap query).

        Parameters
        ----------
        origins, directions : float64 [n, 3] or [3]
            As in ``pick``.
        max_distances : float [n] or scalar
            Ray parameter up to which to look (in units of the direction's length); pass a
            little less than the distance to a target point to ask "is the point visible?".

        Returns
        -------
        bool [n]
            True where some face is hit with ``0 <= t < max_distances`` (float32 precision).
        """
        o, d = self._rays(origins, directions)
        n = len(o)
        o32 = np.empty((n, 3), np.float32)
        d32 = np.empty((len(d), 3), np.float32)
        shift_rays(o, d, self._origin, o32, d32)
        tfar = np.empty(n, np.float32)
        tfar[:] = np.minimum(np.asarray(max_distances, np.float64), float(_FAR))
        return self._scene.run(o32, d32, tfar, query="OCCLUDED") >= 0

    def hit_points(
        self,
        origins: npt.ArrayLike,
        directions: npt.ArrayLike,
        result: PickResult | None = None,
    ) -> npt.NDArray[np.float64]:
        """Return where each ray first hits the surface, in the frame of ``vertices``.

        Parameters
        ----------
        origins, directions : float64 [n, 3] or [3]
            As in ``pick``.
        result : PickResult, optional
            The ``pick`` answer for these rays, to avoid casting them twice.

        Returns
        -------
        float64 [n, 3]
            ``origin + t * direction`` (computed in float64); NaN rows for misses.
        """
        o, d = self._rays(origins, directions)
        if result is None:
            result = self.pick(o, d)
        t = np.where(result.face_ids >= 0, result.distances, np.nan)
        return o + t[:, None] * d

    @staticmethod
    def _rays(
        origins: npt.ArrayLike, directions: npt.ArrayLike
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """Return rays as C-contiguous float64 [n, 3] (directions: [n, 3] or one shared row)."""
        o = np.ascontiguousarray(np.atleast_2d(origins), dtype=np.float64)
        d = np.ascontiguousarray(np.atleast_2d(directions), dtype=np.float64)
        if o.ndim != 2 or o.shape[1] != 3 or d.ndim != 2 or d.shape[1] != 3:
            raise ValueError(
                f"rays must have shape (n, 3) or (3,), got {np.shape(origins)} and "
                f"{np.shape(directions)}"
            )
        if len(d) not in (1, len(o)):
            raise ValueError(f"{len(d)} directions for {len(o)} ray origins")
        return o, d
