"""Synthetic surfaces with known answers for height_diff, roughness, steepness, ridge, border."""

import math

import numpy as np
import pytest

from navigation import (
    HeightDiffMode,
    LayerMesh,
    average_angles,
    border,
    height_diff,
    ridge,
    roughness,
    steepness,
)
from tests.conftest import grid_mesh

MODES = list(HeightDiffMode)


@pytest.mark.parametrize("mode", MODES)
def test_flat_plane_is_free(mode):
    mesh = LayerMesh(*grid_mesh(10, 1.0, z=lambda x, y: 0.7 + 0 * x))
    assert np.all(height_diff(mesh, mode=mode).cost == 0)
    assert np.allclose(roughness(mesh).cost, 0)
    assert np.allclose(average_angles(mesh), 0)
    assert np.allclose(steepness(mesh).cost, 0)
    assert not steepness(mesh).lethal.any()


@pytest.mark.parametrize("mode", MODES)
def test_step_of_height_h_gives_h_at_the_step(mode):
    h = 0.12
    v, f = grid_mesh(10, 1.0, z=lambda x, y: np.where(x > 0.55, h, 0.0))
    mesh = LayerMesh(v, f)
    result = height_diff(mesh, radius=0.25, threshold=0.1, mode=mode)
    x = v[:, 0]
    # x = 0.4 has only flat faces (so a vertical normal) and sees x = 0.6 within 0.25
    near = np.isclose(x, 0.4)
    far = (x < 0.25) | (x > 0.85)
    assert np.allclose(result.cost[near], h, atol=1e-6)
    assert np.all(result.cost[far] == 0)
    assert result.lethal[near].all() and not result.lethal[far].any()
    if mode is HeightDiffMode.VERTICAL:
        assert result.cost.max() <= h + 1e-6  # along tilted normals the range may exceed h


def test_tilted_plane():
    alpha = 0.2
    v, f = grid_mesh(10, 1.0, z=lambda x, y: math.tan(alpha) * x)
    mesh = LayerMesh(v, f)
    assert np.allclose(steepness(mesh).cost, alpha, atol=1e-6)
    assert np.all(steepness(mesh, threshold=0.19).lethal)
    assert not steepness(mesh, threshold=0.21).lethal.any()
    # along its own normal a plane is flat; vertically it rises by tan(alpha) per metre
    assert np.allclose(height_diff(mesh, mode="normal").cost, 0, atol=1e-5)
    vertical = height_diff(mesh, radius=0.25, mode="vertical").cost
    interior = (v[:, 0] > 0.3) & (v[:, 0] < 0.7)
    assert np.allclose(vertical[interior], 2 * 0.2 * math.tan(alpha), atol=1e-5)
    assert np.allclose(roughness(mesh).cost, 0, atol=1e-3)


def test_roughness_is_the_mean_of_average_angles_over_vertex_and_ball():
    rng = np.random.default_rng(0)
    v, f = grid_mesh(8, 0.8)
    v[:, 2] = rng.normal(0, 0.005, len(v))
    mesh = LayerMesh(v, f)
    angles = average_angles(mesh)
    got = roughness(mesh, radius=0.15, angles=angles).cost
    # interior vertex of a 0.1 grid: the 0.15 ball flood holds its 8 surrounding vertices
    # (measured in 3-D, the noise is small enough to keep all of them)
    vid = 4 * 9 + 4
    ring = [vid + d for d in (-10, -9, -8, -1, 1, 8, 9, 10)]
    assert got[vid] == pytest.approx(np.mean(angles[[vid, *ring]]), rel=1e-5)
    # average angle itself: mean acos over the 1-ring edges
    n = mesh.normals.astype(np.float64)
    nbrs = mesh.indices[mesh.indptr[vid] : mesh.indptr[vid + 1]]
    expect = np.mean(np.arccos(np.clip(n[nbrs] @ n[vid], -1, 1)))
    assert angles[vid] == pytest.approx(expect, abs=1e-6)


def test_nan_normals_give_zero_edge_angles_and_nan_steepness():
    v, f = grid_mesh(2)
    normals = np.tile([0.0, 0.0, 1.0], (len(v), 1))
    normals[4] = np.nan
    mesh = LayerMesh(v, f, vertex_normals=normals)
    assert np.all(average_angles(mesh) == 0)
    s = steepness(mesh)
    assert np.isnan(s.cost[4]) and not s.lethal[4]


def test_ridge_on_a_flat_grid_is_the_mean_neighbour_distance():
    mesh = LayerMesh(*grid_mesh(4, 0.4))
    cost = ridge(mesh, radius=0.15).cost
    assert cost[12] == pytest.approx((4 * 0.1 + 4 * math.sqrt(0.02)) / 8, rel=1e-6)


def test_ridge_vertex_without_neighbours_is_lethal():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 5, 5]], float)
    result = ridge(LayerMesh(v, [[0, 1, 2]]), radius=0.3, threshold=0.3)
    assert result.cost == pytest.approx([0.4, 0.4, 0.4, 0.4])
    assert result.lethal.all()


def test_border_on_a_grid():
    v, f = grid_mesh(5)
    result = border(LayerMesh(v, f), border_cost=0.7, threshold=0.5)
    on_edge = (np.isclose(v[:, 0], 0) | np.isclose(v[:, 0], 1)) | (
        np.isclose(v[:, 1], 0) | np.isclose(v[:, 1], 1)
    )
    assert on_edge.sum() == 20
    assert np.array_equal(result.cost, np.where(on_edge, 0.7, 0).astype(np.float32))
    assert np.array_equal(result.lethal, on_edge)
    assert not border(LayerMesh(v, f), border_cost=0.5, threshold=0.5).lethal.any()  # strict


def test_results_are_float32():
    mesh = LayerMesh(*grid_mesh(3))
    for result in (height_diff(mesh), roughness(mesh), steepness(mesh), ridge(mesh), border(mesh)):
        assert result.cost.dtype == np.float32 and result.lethal.dtype == bool
        assert result.cost.shape == (16,)
