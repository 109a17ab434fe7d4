"""Height difference: how far the surface around a vertex spreads along its "up" direction."""

from __future__ import annotations

from enum import StrEnum

from navigation import _kernels
from navigation.layer_mesh import LayerMesh
from navigation.layer_result import LayerResult, threshold_result

RADIUS = 0.3
THRESHOLD = 0.185


class HeightDiffMode(StrEnum):
    """Which "up" the height difference is measured along."""

    #: lvr2 >= 2026-03 (current mesh_navigation): n_v . p over the tangent-plane disc of n_v.
    NORMAL = "normal"
    #: lvr2 before 2026-03 (the 2024 maps): z over the xy-disc.
    VERTICAL = "vertical"


def height_diff(
    mesh: LayerMesh,
    *,
    radius: float = RADIUS,
    threshold: float = THRESHOLD,
    mode: HeightDiffMode | str = HeightDiffMode.NORMAL,
) -> LayerResult:
    """Return lvr2's ``calcVertexHeightDifferences``: the range of heights around each vertex.

    The heights are ``n . p`` over {v} and ``visitLocalVertexNeighborhoodPlane(v, n, radius)``,
    with n the vertex normal (``NORMAL``) or +z (``VERTICAL``). A vertex is lethal when the
    range exceeds ``threshold``.

    Returns
    -------
    LayerResult, cost float32 [N] in metres
    """
    mode = HeightDiffMode(mode)
    kind = _kernels.PLANE if mode is HeightDiffMode.NORMAL else _kernels.DISC_XY
    cost = _kernels.height_diff(
        mesh.indptr,
        mesh.indices,
        mesh.positions,
        mesh.normals,
        kind,
        float(radius) ** 2,
        mesh.workers(),
    )
    return threshold_result(cost, threshold)
