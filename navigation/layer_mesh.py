"""The mesh as every cost layer sees it: float32 local positions, normals and 1-ring topology."""

from __future__ import annotations

from functools import cached_property

import numba as nb
import numpy as np
import numpy.typing as npt

from geometry import local_origin, vertex_normals
from navigation import _kernels


class LayerMesh:
    """Hold the arrays and derived topology the layers share, computed once and on demand.

    Positions are shifted by :func:`geometry.local_origin` in float64 and then cast to float32
    (what lvr2 computes in), so far-away (UTM) maps keep millimetres. Topology follows lvr2's
    half-edge mesh on the stored indices: faces that repeat a vertex id are left out.

    Parameters
    ----------
    vertices : float [N, 3], world coordinates
    faces : int [F, 3], vertex ids
    vertex_normals : float [N, 3] or None
        Normals to use (e.g. the ones stored in the map, as mesh_navigation does); None computes
        lvr2's unweighted vertex normals.
    """

    def __init__(
        self,
        vertices: npt.ArrayLike,
        faces: npt.ArrayLike,
        vertex_normals: npt.ArrayLike | None = None,
    ) -> None:
        world = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
        self.faces: npt.NDArray[np.int32] = np.ascontiguousarray(faces, dtype=np.int32).reshape(
            -1, 3
        )
        if len(self.faces) and (self.faces.min() < 0 or self.faces.max() >= len(world)):
            raise ValueError(f"face indices must lie in [0, {len(world)})")
        #: float64 [3], subtracted from the world coordinates
        self.origin: npt.NDArray[np.float64] = local_origin(world)
        #: float32 [N, 3], local frame
        self.positions: npt.NDArray[np.float32] = np.ascontiguousarray(
            world - self.origin, dtype=np.float32
        )
        self._world = world
        self._normals_in = None if vertex_normals is None else np.asarray(vertex_normals)
        if self._normals_in is not None and self._normals_in.shape != world.shape:
            raise ValueError(f"vertex_normals must have shape {world.shape}")

    @property
    def n_vertices(self) -> int:
        """Return the vertex count."""
        return len(self.positions)

    @cached_property
    def normals(self) -> npt.NDArray[np.float32]:
        """Return float32 [N, 3] vertex normals (given, or lvr2's unweighted ones)."""
        if self._normals_in is not None:
            return np.ascontiguousarray(self._normals_in, dtype=np.float32)
        return np.ascontiguousarray(vertex_normals(self._world, self.faces), dtype=np.float32)

    @cached_property
    def _csr(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
        return _kernels.build_vertex_csr(self.faces, self.n_vertices)

    @property
    def indptr(self) -> npt.NDArray[np.int64]:
        """Return the 1-ring CSR row pointers, int64 [N + 1]."""
        return self._csr[0]

    @property
    def indices(self) -> npt.NDArray[np.int32]:
        """Return the 1-ring CSR neighbour ids, int32, sorted within each row."""
        return self._csr[1]

    @property
    def edge_faces(self) -> npt.NDArray[np.int32]:
        """Return, per CSR entry, how many faces use that edge (1 = boundary, > 2 non-manifold)."""
        return self._csr[2]

    @property
    def n_degenerate_faces(self) -> int:
        """Return how many faces repeat a vertex id and are left out of the topology."""
        return int(self._csr[3])

    @cached_property
    def _vertex_faces(self) -> tuple[np.ndarray, np.ndarray]:
        return _kernels.build_vertex_faces(self.faces, self.n_vertices)

    @property
    def vf_indptr(self) -> npt.NDArray[np.int64]:
        """Return the vertex -> incident faces CSR row pointers, int64 [N + 1]."""
        return self._vertex_faces[0]

    @property
    def vf_faces(self) -> npt.NDArray[np.int32]:
        """Return the vertex -> incident faces CSR face ids, int32."""
        return self._vertex_faces[1]

    @cached_property
    def boundary(self) -> npt.NDArray[np.bool_]:
        """Return bool [N]: the vertex touches an edge used by exactly one face."""
        rows = np.repeat(np.arange(self.n_vertices), np.diff(self.indptr))
        mask = np.zeros(self.n_vertices, dtype=bool)
        mask[rows[self.edge_faces == 1]] = True
        return mask

    @cached_property
    def non_manifold(self) -> npt.NDArray[np.bool_]:
        """Return bool [N]: an incident edge has > 2 faces, or the faces form > 1 fan."""
        return _kernels.non_manifold_vertices(
            self.indptr, self.indices, self.edge_faces, self.vf_indptr, self.vf_faces, self.faces
        )

    @staticmethod
    def workers() -> int:
        """Return how many parallel workers the kernels split the vertices over."""
        return max(1, nb.get_num_threads())
