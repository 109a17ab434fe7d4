import numpy as np
import pytest

from navigation import LayerMesh, average_angles
from tests.conftest import grid_mesh


def test_topology_of_a_grid():
    v, f = grid_mesh(3)
    mesh = LayerMesh(v, f)
    assert mesh.indptr[-1] == 2 * 33  # 33 undirected edges
    assert (mesh.edge_faces == 1).sum() == 2 * 12
    assert mesh.boundary.sum() == 12
    assert not mesh.non_manifold.any()
    row = mesh.indices[mesh.indptr[5] : mesh.indptr[6]]
    assert np.all(np.diff(row) > 0)


def test_non_manifold_edge_and_bowtie_vertex_are_flagged():
    # three faces on edge (0, 1); and two fans meeting at vertex 5 only
    v = np.zeros((10, 3))
    v[:, 0] = np.arange(10)
    f = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4], [5, 6, 7], [5, 8, 9]])
    mesh = LayerMesh(v, f)
    assert mesh.non_manifold[[0, 1, 5]].all()
    assert not mesh.non_manifold[[2, 3, 4, 6, 7, 8, 9]].any()
    angles = average_angles(mesh)
    assert angles[0] == pytest.approx(np.pi) and angles[5] == pytest.approx(np.pi)


def test_faces_repeating_a_vertex_are_left_out():
    v, f = grid_mesh(2)
    f = np.concatenate([f, [[0, 0, 1]]])
    mesh = LayerMesh(v, f)
    assert mesh.n_degenerate_faces == 1
    assert 0 not in mesh.indices[mesh.indptr[0] : mesh.indptr[1]]


def test_far_coordinates_are_shifted_before_float32():
    v, f = grid_mesh(2)
    far = v + np.array([500_000.0, 5_700_000.0, 100.0])
    mesh = LayerMesh(far, f)
    assert mesh.origin.tolist() == [500_000.0, 5_700_000.0, 0.0]
    assert mesh.positions.dtype == np.float32
    assert np.allclose(mesh.positions + mesh.origin, far)


def test_bad_input_is_rejected():
    with pytest.raises(ValueError, match="face indices"):
        LayerMesh(np.zeros((3, 3)), [[0, 1, 3]])
    with pytest.raises(ValueError, match="vertex_normals"):
        LayerMesh(np.zeros((3, 3)), [[0, 1, 2]], vertex_normals=np.zeros((2, 3)))
