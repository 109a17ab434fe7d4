"""lvr2's radius-bounded vertex neighbourhoods: a flood over mesh edges, not a ball query.

``visitLocalVertexNeighborhood(v, r)`` grows from v over 1-ring edges and accepts a neighbour u
when it is unvisited and ``|p_u - p_v|^2 < r^2`` (a 3-D ball around the *start* vertex); the
start vertex itself is not part of the result. The Plane variant measures the same distance
after projecting both points onto the plane perpendicular to n. Because acceptance needs an
accepted path, the flood never jumps across a thin wall or a gap the way a ball query does.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from navigation import _kernels
from navigation.layer_mesh import LayerMesh


def _check(mesh: LayerMesh, vertex_id: int, radius: float) -> None:
    if not 0 <= vertex_id < mesh.n_vertices:
        raise IndexError(f"vertex {vertex_id} is not in [0, {mesh.n_vertices})")
    if not radius >= 0:
        raise ValueError(f"radius must be >= 0, got {radius}")


def local_neighborhood(mesh: LayerMesh, vertex_id: int, radius: float) -> npt.NDArray[np.int32]:
    """Return the vertex ids lvr2's ``visitLocalVertexNeighborhood`` visits (start excluded).

    Returns
    -------
    int32 [k], sorted
    """
    _check(mesh, vertex_id, radius)
    return _kernels.neighborhood(
        mesh.indptr,
        mesh.indices,
        mesh.positions,
        vertex_id,
        _kernels.BALL,
        np.zeros(3, np.float32),
        float(radius) ** 2,
    )


def plane_neighborhood(
    mesh: LayerMesh, vertex_id: int, normal: npt.ArrayLike, radius: float
) -> npt.NDArray[np.int32]:
    """Return the ids ``visitLocalVertexNeighborhoodPlane`` visits: distances in the plane ⟂ n.

    Parameters
    ----------
    normal : float [3], unit plane normal (lvr2 passes the vertex normal; (0, 0, 1) gives the
        xy-disc of the 2024 height difference)

    Returns
    -------
    int32 [k], sorted
    """
    _check(mesh, vertex_id, radius)
    n = np.asarray(normal, dtype=np.float32).reshape(3)
    return _kernels.neighborhood(
        mesh.indptr, mesh.indices, mesh.positions, vertex_id, _kernels.PLANE, n, float(radius) ** 2
    )
