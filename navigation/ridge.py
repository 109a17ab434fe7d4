"""Ridge: how far the normal-offset surface spreads around a vertex (mesh_navigation)."""

from __future__ import annotations

import numpy as np

from navigation import _kernels
from navigation.layer_mesh import LayerMesh
from navigation.layer_result import LayerResult, threshold_result

RADIUS = 0.3
THRESHOLD = 0.3
#: A vertex without neighbours in the radius gets ``threshold + EMPTY_MARGIN`` (lethal).
EMPTY_MARGIN = 0.1


def ridge(mesh: LayerMesh, *, radius: float = RADIUS, threshold: float = THRESHOLD) -> LayerResult:
    """Return the mean ``|(p_u + n_u) - (p_v + n_v)|`` over v's 3-D ball flood (v excluded).

    Returns
    -------
    LayerResult, cost float32 [N] in metres
    """
    cost = _kernels.ridge(
        mesh.indptr,
        mesh.indices,
        mesh.positions,
        mesh.normals,
        float(radius) ** 2,
        np.float32(threshold + EMPTY_MARGIN),
        mesh.workers(),
    )
    return threshold_result(cost, threshold)
