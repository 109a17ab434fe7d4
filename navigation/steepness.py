"""Steepness: the angle between a vertex normal and the vertical."""

from __future__ import annotations

import numpy as np

from navigation.layer_mesh import LayerMesh
from navigation.layer_result import LayerResult, threshold_result

THRESHOLD = 0.3


def steepness(mesh: LayerMesh, *, threshold: float = THRESHOLD) -> LayerResult:
    """Return mesh_navigation's SteepnessLayer: ``acos(n_z)`` per vertex.

    n_z is clipped to [-1, 1] so rounding in a unit normal cannot give NaN; a NaN normal stays
    NaN (unknown, and never lethal).

    Returns
    -------
    LayerResult, cost float32 [N] in radians (0 = flat, pi/2 = vertical wall)
    """
    nz = mesh.normals[:, 2]
    cost = np.arccos(np.clip(nz, np.float32(-1.0), np.float32(1.0)))
    return threshold_result(cost, threshold)
