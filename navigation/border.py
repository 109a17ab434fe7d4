"""Border: a fixed cost on the vertices at the edge of the map."""

from __future__ import annotations

import numpy as np

from navigation.layer_mesh import LayerMesh
from navigation.layer_result import LayerResult, threshold_result

THRESHOLD = 0.5
BORDER_COST = 1.0


def border(
    mesh: LayerMesh, *, threshold: float = THRESHOLD, border_cost: float = BORDER_COST
) -> LayerResult:
    """Return lvr2's ``calcBorderCosts``: ``border_cost`` on vertices touching a boundary edge.

    A boundary edge is used by exactly one face; every other vertex costs 0.

    Returns
    -------
    LayerResult, cost float32 [N]
    """
    cost = np.where(mesh.boundary, np.float32(border_cost), np.float32(0.0)).astype(np.float32)
    return threshold_result(cost, threshold)
