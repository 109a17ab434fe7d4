import numpy as np

from geometry import (
    boundary_vertex_mask,
    edge_face_counts,
    face_adjacency,
    face_normals,
    local_origin,
    lvr2_normals,
    vertex_adjacency,
    vertex_normals,
)
from tests.conftest import grid_mesh


def test_grid_edges_boundary_and_adjacency():
    v, f = grid_mesh(3)
    edges, counts = edge_face_counts(f)
    # 3x3 cells: 2*3*4 axis edges + 9 diagonals
    assert len(edges) == 24 + 9
    assert (counts == 1).sum() == 12  # the square's perimeter
    border = boundary_vertex_mask(f, len(v))
    assert border.sum() == 12 and not border[5] and not border[6]
    fa = face_adjacency(f)
    assert fa.shape == (18, 18) and (fa != fa.T).nnz == 0
    assert fa.sum() == 2 * (33 - 12)  # every interior edge joins two faces
    va = vertex_adjacency(f, len(v))
    assert va.sum() == 2 * len(edges)


def test_normals_follow_lvr2_convention():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 5, 5]], float)
    f = np.array([[0, 1, 2], [0, 0, 1]])  # second face degenerate
    fn = face_normals(v, f)
    assert np.allclose(fn, [[0, 0, 1], [0, 0, 1]])
    vn = vertex_normals(v, f)
    assert np.allclose(vn[3], [0, 0, 1])  # unreferenced vertex -> +z
    assert np.allclose(np.linalg.norm(vn, axis=1), 1)


def test_local_origin_only_for_far_coordinates():
    v, _ = grid_mesh(2, size=100.0)
    assert not local_origin(v).any()
    far = v + np.array([500_000.3, 5_700_000.7, 100.0])
    o = local_origin(far)
    assert o[0] % 1000 == 0 and abs(o[0] - 500_000) <= 1000 and abs(o[1] - 5_700_000) <= 1000
    assert np.abs(far - o).max() < 2000


def test_normals_match_a_row_wise_reference_with_lvr2_fallbacks():
    v, f = grid_mesh(6, z=lambda x, y: x * y)
    v = np.vstack([v, [[5.0, 5.0, 5.0]]])  # an unused vertex: +z
    f = np.vstack([f, [[0, 0, 1]]])  # a degenerate face: +z
    cross = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    length = np.linalg.norm(cross, axis=1, keepdims=True)
    ref_fn = np.where(length > 0, cross / np.where(length > 0, length, 1), [0.0, 0.0, 1.0])
    ref_vn = np.zeros_like(v)
    for corner in range(3):  # unweighted sum over faces, per corner (a repeated id counts twice)
        np.add.at(ref_vn, f[:, corner], ref_fn)
    ref_vn = np.array([n / np.linalg.norm(n) if np.linalg.norm(n) else [0, 0, 1] for n in ref_vn])
    fn, vn = lvr2_normals(v, f, dtype=np.float32)
    assert fn.dtype == np.float32
    assert vn.dtype == np.float32
    np.testing.assert_allclose(fn, ref_fn, atol=1e-7)
    np.testing.assert_allclose(vn, ref_vn, atol=1e-7)
    np.testing.assert_array_equal(face_normals(v, f), lvr2_normals(v, f)[0])
    np.testing.assert_array_equal(vn[-1], [0, 0, 1])
    np.testing.assert_array_equal(fn[-1], [0, 0, 1])
