import math

import numpy as np
import pytest

from navigation import InflationMethod, LayerMesh, fading, inflation, inflation_distances
from tests.conftest import grid_mesh

FMM, VERBATIM, DIJKSTRA = (
    InflationMethod.FMM,
    InflationMethod.FMM_MESH_NAVIGATION,
    InflationMethod.DIJKSTRA,
)


@pytest.fixture(scope="module")
def grid():
    v, f = grid_mesh(40, 4.0)  # 0.1 m cells
    return v, LayerMesh(v, f)


def test_fading_follows_mesh_navigation():
    d = np.array([0.0, 1e-6, 0.1, 0.25, 0.3, 0.4, 0.41, np.inf])
    got = fading(d)
    expect = [1.0, 0.99, 0.99, 0.99, 0.99 * math.exp(-0.05), 0.99 * math.exp(-0.15), 0, 0]
    assert got.dtype == np.float32
    assert got == pytest.approx(expect, rel=1e-6)
    lethal_inf = fading(d, lethal_value=math.inf, cost_scaling_factor=2.0)
    assert lethal_inf[0] == math.inf and lethal_inf[4] == pytest.approx(0.99 * math.exp(-0.1))


@pytest.mark.parametrize("method", [FMM, DIJKSTRA])
def test_distances_from_a_straight_line_on_a_grid(grid, method):
    v, mesh = grid
    seeds = np.isclose(v[:, 0], 2.0)
    d = inflation_distances(mesh, seeds, max_distance=1.0, method=method)
    true = np.abs(v[:, 0] - 2.0)
    near = true <= 0.9
    assert np.allclose(d[near], true[near], atol=1e-6)
    assert np.all(d[true > 1.15] == np.inf)  # propagation stops past max_distance


def test_fmm_is_exact_for_a_front_along_the_triangle_diagonals(grid):
    v, mesh = grid
    g = (v[:, 0] - v[:, 1]) / math.sqrt(2)
    d = inflation_distances(mesh, np.isclose(g, 0), max_distance=1.0, method=FMM)
    near = np.abs(g) <= 0.7
    assert np.allclose(d[near], np.abs(g[near]), atol=1e-6)
    edges = inflation_distances(mesh, np.isclose(g, 0), max_distance=1.0, method=DIJKSTRA)
    assert np.max(edges[near] - np.abs(g[near])) > 0.1  # edge paths zig-zag


def test_costs_at_known_distances_on_a_grid(grid):
    v, mesh = grid
    lethal = np.isclose(v[:, 0], 2.0)
    result = inflation(mesh, lethal)  # defaults: inscribed 0.25, inflation 0.4
    x = v[:, 0]
    cost = result.cost
    assert np.all(cost[lethal] == 1.0)
    assert np.allclose(cost[np.isclose(x, 2.2)], 0.99)
    assert np.allclose(cost[np.isclose(x, 1.7)], 0.99 * math.exp(-0.05), rtol=1e-5)
    assert np.allclose(cost[np.isclose(x, 2.35)], 0.99 * math.exp(-0.1), rtol=1e-5)
    assert np.all(cost[np.abs(x - 2.0) > 0.45] == 0)
    assert np.array_equal(result.lethal, lethal) and result.lethal is not lethal


def test_lone_lethal_vertex_spreads_except_in_mesh_navigation_verbatim(grid):
    v, mesh = grid
    seeds = np.zeros(len(v), bool)
    seeds[20 * 41 + 20] = True
    true = np.hypot(v[:, 0] - 2, v[:, 1] - 2)
    fmm = inflation_distances(mesh, seeds, max_distance=0.5, method=FMM)
    ring = true <= 0.1 + 1e-9  # reached along edges
    assert np.allclose(fmm[ring], true[ring], atol=1e-6)
    assert np.all(fmm[true <= 0.5] >= true[true <= 0.5] - 1e-6)
    assert np.all(fmm[true <= 0.5] <= true[true <= 0.5] * 1.25)  # first order near a point
    verbatim = inflation_distances(mesh, seeds, max_distance=0.5, method=VERBATIM)
    assert np.isfinite(verbatim).sum() == 1  # mesh_navigation needs two fixed face corners


def test_mesh_navigation_verbatim_update_overestimates(grid):
    v, mesh = grid
    seeds = np.isclose(v[:, 0], 2.0)
    verbatim = inflation_distances(mesh, seeds, max_distance=1.0, method=VERBATIM)
    true = np.abs(v[:, 0] - 2.0)
    near = true <= 0.8
    assert np.all(verbatim[near] >= true[near] - 1e-6)
    assert np.max(verbatim[near] - true[near]) > 0.03  # its sin where sin^2 belongs


def test_no_lethal_vertices_means_no_inflation(grid):
    _, mesh = grid
    result = inflation(mesh, np.zeros(mesh.n_vertices, bool))
    assert np.all(result.cost == 0) and not result.lethal.any()


def test_geodesic_not_euclidean_around_a_wall():
    # a 1 m tall fin in the middle of a strip: the far side is 2 m away over the fin
    xs = np.array([0.0, 0.1, 0.2, 0.2, 0.2, 0.3, 0.4])
    zs = np.array([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
    v, f = [], []
    for i, (x, z) in enumerate(zip(xs, zs, strict=True)):
        v += [[x, 0.0, z], [x, 0.1, z]]
        if i:
            a, b, c, d = 2 * i - 2, 2 * i - 1, 2 * i, 2 * i + 1
            f += [[a, c, d], [a, d, b]]
    v = np.array(v)
    mesh = LayerMesh(v, np.array(f))
    seeds = np.isclose(v[:, 0], 0.0)
    d = inflation_distances(mesh, seeds, max_distance=5.0)
    assert d[-1] == pytest.approx(0.4 + 2.0, abs=1e-5)
