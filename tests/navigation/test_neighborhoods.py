import numpy as np
import pytest
from scipy.spatial import cKDTree

from navigation import LayerMesh, local_neighborhood, plane_neighborhood
from tests.conftest import grid_mesh


def lvr2_reference(vertices, faces, v, radius, normal=None):
    """visitLocalVertexNeighborhood(Plane) as lvr2 writes it: a DFS stack, start excluded."""
    nbrs = {i: set() for i in range(len(vertices))}
    for a, b, c in faces:
        nbrs[a] |= {b, c}
        nbrs[b] |= {a, c}
        nbrs[c] |= {a, b}
    p = np.asarray(vertices, dtype=np.float64)
    if normal is not None:
        n = np.asarray(normal, float)
        p = p - np.outer(p @ n, n)
    visited, stack, out = {v}, [v], []
    while stack:
        cur = stack.pop()
        for u in nbrs[cur]:
            if u not in visited and np.sum((p[u] - p[v]) ** 2) < radius**2:
                visited.add(u)
                out.append(u)
                stack.append(u)
    return sorted(out)


def bumpy_mesh(seed=3):
    v, f = grid_mesh(12, 1.2)
    rng = np.random.default_rng(seed)
    v[:, :2] += rng.uniform(-0.03, 0.03, (len(v), 2))
    v[:, 2] = 0.2 * np.sin(5 * v[:, 0]) + rng.normal(0, 0.02, len(v))
    return v, f


@pytest.mark.parametrize("radius", [0.05, 0.15, 0.31])
def test_flood_matches_lvr2_reference(radius):
    v, f = bumpy_mesh()
    mesh = LayerMesh(v, f)
    for vid in (0, 17, 84, 100):
        assert local_neighborhood(mesh, vid, radius).tolist() == lvr2_reference(v, f, vid, radius)
        n = mesh.normals[vid]
        got = plane_neighborhood(mesh, vid, n, radius).tolist()
        assert got == lvr2_reference(v, f, vid, radius, normal=n)


def test_start_vertex_is_not_part_of_its_neighbourhood():
    v, f = grid_mesh(4, 0.4)
    mesh = LayerMesh(v, f)
    ids = local_neighborhood(mesh, 12, 0.15)
    assert 12 not in ids
    assert len(ids) == 8  # 4 axis neighbours at 0.1 and 4 diagonals at 0.141


def test_flood_does_not_cross_a_thin_gap_where_a_ball_query_does():
    # two sheets 5 cm apart, not connected: a ball of 0.25 m reaches the other sheet
    va, fa = grid_mesh(10, 1.0)
    vb = va + np.array([0.0, 0.0, 0.05])
    v = np.concatenate([va, vb])
    f = np.concatenate([fa, fa + len(va)])
    mesh = LayerMesh(v, f)
    start = 60
    flood = local_neighborhood(mesh, start, 0.25)
    ball = cKDTree(v).query_ball_point(v[start], 0.25)
    assert np.all(flood < len(va))
    assert any(i >= len(va) for i in ball)
    assert set(flood) == set(ball) - {start} - set(range(len(va), len(v)))


def test_acceptance_is_measured_from_the_start_vertex_not_along_the_path():
    # a U-turn: 0 -> 1 -> 2 with 2 close to 0 but 1 outside the radius: 2 is never reached
    v = np.array([[0, 0, 0], [1, 0, 0], [0.05, 0.1, 0], [1, 0.1, 0]], float)
    f = np.array([[0, 1, 3], [1, 3, 2]])
    mesh = LayerMesh(v, f)
    assert local_neighborhood(mesh, 0, 0.5).tolist() == []
    assert cKDTree(v).query_ball_point(v[0], 0.5) == [0, 2]


def test_plane_variant_measures_in_the_tangent_plane():
    # a vertical strip: in 3-D the upper vertex is 0.5 m away, in the plane of n = +y it is too,
    # but projected on the plane of n = +z (xy-disc) it coincides with the start
    v = np.array([[0, 0, 0], [0.1, 0, 0], [0, 0, 0.5], [0.1, 0, 0.5]], float)
    f = np.array([[0, 1, 2], [1, 3, 2]])
    mesh = LayerMesh(v, f)
    assert local_neighborhood(mesh, 0, 0.3).tolist() == [1]
    assert plane_neighborhood(mesh, 0, [0, 0, 1], 0.3).tolist() == [1, 2, 3]


def test_bad_arguments_are_rejected():
    mesh = LayerMesh(*grid_mesh(2))
    with pytest.raises(IndexError):
        local_neighborhood(mesh, 99, 0.1)
    with pytest.raises(ValueError, match="radius"):
        local_neighborhood(mesh, 0, -1.0)
