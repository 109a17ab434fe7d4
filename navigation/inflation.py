"""Inflation: costs that fade with geodesic distance from lethal vertices (mesh_navigation)."""

from __future__ import annotations

from enum import StrEnum

import numpy as np
import numpy.typing as npt

from navigation import _kernels
from navigation.layer_mesh import LayerMesh
from navigation.layer_result import LayerResult

INSCRIBED_RADIUS = 0.25
INFLATION_RADIUS = 0.4
LETHAL_VALUE = 1.0
INSCRIBED_VALUE = 0.99
COST_SCALING_FACTOR = 1.0


class InflationMethod(StrEnum):
    """How the distance from the lethal vertices is propagated."""

    #: mesh_navigation's triangle wavefront with Kimmel & Sethian's update as published
    #: (exact for plane fronts), plus edge steps so that lone lethal vertices spread too.
    FMM = "fmm"
    #: mesh_navigation's wavefront and update exactly as written (b9f2851), for comparison
    #: with the robot: ``a^2 sin`` for ``a^2 sin^2`` overestimates distances on skewed
    #: triangles, and a lethal vertex without a lethal neighbour does not spread.
    FMM_MESH_NAVIGATION = "fmm_mesh_navigation"
    #: shortest paths along mesh edges (an upper bound of the geodesic distance).
    DIJKSTRA = "dijkstra"


def inflation_distances(
    mesh: LayerMesh,
    seeds: npt.NDArray[np.bool_],
    *,
    max_distance: float = INFLATION_RADIUS,
    method: InflationMethod | str = InflationMethod.FMM,
) -> npt.NDArray[np.float64]:
    """Return the distance of every vertex from the ``seeds`` vertices, propagated ~max_distance.

    See :class:`InflationMethod`. Propagation stops past ``max_distance``; vertices beyond it
    may carry a value larger than max_distance or +inf.

    Returns
    -------
    float64 [N], metres; 0 on seeds, +inf where the wave never arrived
    """
    seed_ids = np.flatnonzero(np.asarray(seeds, dtype=bool)).astype(np.int32)
    if len(seed_ids) == 0:
        return np.full(mesh.n_vertices, np.inf)
    method = InflationMethod(method)
    if method is not InflationMethod.DIJKSTRA:
        return _kernels.fmm_distances(
            mesh.positions,
            mesh.faces,
            mesh.indptr,
            mesh.indices,
            mesh.vf_indptr,
            mesh.vf_faces,
            seed_ids,
            max_distance,
            method is InflationMethod.FMM_MESH_NAVIGATION,
        )
    return _kernels.edge_distances(
        mesh.positions, mesh.indptr, mesh.indices, seed_ids, max_distance
    )


def fading(
    distances: npt.NDArray[np.floating],
    *,
    inscribed_radius: float = INSCRIBED_RADIUS,
    inflation_radius: float = INFLATION_RADIUS,
    lethal_value: float = LETHAL_VALUE,
    inscribed_value: float = INSCRIBED_VALUE,
    cost_scaling_factor: float = COST_SCALING_FACTOR,
) -> npt.NDArray[np.float32]:
    """Return mesh_navigation's ``InflationLayer::fading`` of distances (costmap_2d's decay).

    d == 0: lethal_value; 0 < d <= inscribed_radius: inscribed_value;
    inscribed_radius < d <= inflation_radius: inscribed_value * exp(-factor * (d - inscribed));
    beyond (and +inf): 0.

    Returns
    -------
    float32, same shape as ``distances``
    """
    d = np.asarray(distances, dtype=np.float64)
    with np.errstate(invalid="ignore", over="ignore"):  # d = +inf lands in the "beyond" branch
        decay = inscribed_value * np.exp(-cost_scaling_factor * (d - inscribed_radius))
    cost = np.where(d > inscribed_radius, decay, inscribed_value)
    cost = np.where(d > inflation_radius, 0.0, cost)
    cost = np.where(d <= 0.0, lethal_value, cost)
    return cost.astype(np.float32)


def inflation(
    mesh: LayerMesh,
    lethal: npt.NDArray[np.bool_],
    *,
    inscribed_radius: float = INSCRIBED_RADIUS,
    inflation_radius: float = INFLATION_RADIUS,
    lethal_value: float = LETHAL_VALUE,
    inscribed_value: float = INSCRIBED_VALUE,
    cost_scaling_factor: float = COST_SCALING_FACTOR,
    method: InflationMethod | str = InflationMethod.FMM,
) -> LayerResult:
    """Return mesh_navigation's InflationLayer over the lethal vertices of its input layer.

    The lethal mask passes through unchanged (the layer has no threshold of its own).

    Returns
    -------
    LayerResult, cost float32 [N]
    """
    lethal = np.asarray(lethal, dtype=bool)
    d = inflation_distances(mesh, lethal, max_distance=inflation_radius, method=method)
    cost = fading(
        d,
        inscribed_radius=inscribed_radius,
        inflation_radius=inflation_radius,
        lethal_value=lethal_value,
        inscribed_value=inscribed_value,
        cost_scaling_factor=cost_scaling_factor,
    )
    return LayerResult(cost, lethal.copy())
