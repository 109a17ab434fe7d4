"""Roughness: how much the vertex normals turn from edge to edge around a vertex."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from navigation import _kernels
from navigation.layer_mesh import LayerMesh
from navigation.layer_result import LayerResult, threshold_result

RADIUS = 0.3
THRESHOLD = 0.3


def average_angles(mesh: LayerMesh) -> npt.NDArray[np.float32]:
    """Return lvr2's ``calcAverageVertexAngles``: mean normal angle over each vertex's edges.

    The edge angle is ``acos(n_a . n_b)`` with the dot clipped to [-1, 1] and NaN -> 0. A vertex
    lvr2's half-edge mesh cannot circulate (an incident edge with more than two faces, or more
    than one fan of faces) gets pi, as lvr2 does on its exceptions. A vertex without edges gets
    0 (lvr2 would divide 0 by 0).

    Returns
    -------
    float32 [N], radians
    """
    return _kernels.average_angles(mesh.indptr, mesh.indices, mesh.normals, mesh.non_manifold)


def roughness(
    mesh: LayerMesh,
    *,
    radius: float = RADIUS,
    threshold: float = THRESHOLD,
    angles: npt.NDArray[np.float32] | None = None,
) -> LayerResult:
    """Return lvr2's ``calcVertexRoughness``: mean average angle over {v} and its 3-D ball flood.

    Parameters
    ----------
    angles : float32 [N] or None
        Precomputed :func:`average_angles` (None computes them).

    Returns
    -------
    LayerResult, cost float32 [N] in radians
    """
    if angles is None:
        angles = average_angles(mesh)
    cost = _kernels.ball_mean(
        mesh.indptr,
        mesh.indices,
        mesh.positions,
        np.ascontiguousarray(angles, dtype=np.float32),
        float(radius) ** 2,
        mesh.workers(),
    )
    return threshold_result(cost, threshold)
