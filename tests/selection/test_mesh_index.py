import numpy as np
import pytest

from selection import MeshIndex, PickResult
from tests.conftest import grid_mesh
from tests.selection.oracles import agreement, brute_force_pick, bumpy_terrain

UTM = np.array([500_000.0, 5_700_000.0, 100.0])


def random_rays(vertices, faces, n, rng):
    """Rays like clicks and drags: at face interiors, at shared edges, off the map, upward."""
    lo, hi = vertices.min(0), vertices.max(0)
    centre = (lo + hi) / 2
    span = float((hi - lo)[:2].max())
    origins = centre + rng.uniform([-span, -span, 0.6 * span], [span, span, 1.2 * span], (n, 3))
    targets = np.empty((n, 3))
    kind = rng.integers(0, 5, n)
    tri = vertices[faces[rng.integers(0, len(faces), n)]]
    w = rng.dirichlet([1, 1, 1], n)
    targets[:] = np.einsum("ij,ijk->ik", w, tri)  # 0: inside a face
    # 1, 2: on a shared edge, or a hair (1e-7 .. 1e-4 m) beside it
    edge_w = rng.uniform(0.05, 0.95, n)[:, None]
    on_edge = tri[:, 0] * edge_w + tri[:, 2] * (1 - edge_w)  # (a, d) is shared by both halves
    offset = rng.normal(size=(n, 3)) * (10.0 ** rng.uniform(-7, -4, n))[:, None]
    targets[kind == 1] = on_edge[kind == 1]
    targets[kind == 2] = on_edge[kind == 2] + offset[kind == 2]
    # 3: off the map (misses), 4: a vertex
    targets[kind == 3] = (
        centre + np.array([3 * span, 0.0, 0.0]) + rng.normal(size=(int((kind == 3).sum()), 3))
    )
    targets[kind == 4] = tri[kind == 4, 1]
    directions = targets - origins
    up = rng.random(n) < 0.05  # pointing away from the surface: misses
    directions[up] = -directions[up]
    directions *= rng.uniform(0.2, 3.0, n)[:, None]  # any length, not only unit
    return origins, directions


@pytest.mark.parametrize("utm", [False, True], ids=["local", "utm"])
def test_pick_agrees_with_float64_brute_force(utm):
    vertices, faces = bumpy_terrain(utm=utm)
    rng = np.random.default_rng(1)
    origins, directions = random_rays(vertices, faces, 1500, rng)
    result = MeshIndex(vertices, faces).pick(origins, directions)
    ref_ids, ref_t = brute_force_pick(vertices, faces, origins, directions)
    agree, grazing = agreement(
        vertices, faces, origins, directions, result.face_ids, ref_ids, ref_t
    )
    bad = ~(agree | grazing)
    assert not bad.any(), f"{bad.sum()} rays disagree: {np.flatnonzero(bad)[:10]}"
    # rays aimed within a hair of the outer edge or of a ridge may go either way; few do
    assert grazing.mean() < 0.01
    assert (ref_ids < 0).sum() > 50  # misses were tested
    same = (ref_ids >= 0) & (result.face_ids == ref_ids)
    # distances: float64 accuracy, in units of the direction's length
    np.testing.assert_allclose(result.distances[same], ref_t[same], rtol=1e-9, atol=1e-9)
    assert np.isinf(result.distances[result.face_ids < 0]).all()


def test_float32_approaches_fail_at_utm_coordinates():
    """trimesh shifts rays after casting them to float32; an unshifted Embree scene too."""
    trimesh = pytest.importorskip("trimesh")
    from embreex import rtcore_scene
    from embreex.mesh_construction import TriangleMesh

    vertices, faces = bumpy_terrain(utm=True)
    rng = np.random.default_rng(2)
    origins, directions = random_rays(vertices, faces, 600, rng)
    hit = brute_force_pick(vertices, faces, origins, directions)
    keep = hit[0] >= 0
    origins, directions, ref_ids, ref_t = origins[keep], directions[keep], *(h[keep] for h in hit)

    def agree(face_ids):
        ok, grazing = agreement(vertices, faces, origins, directions, face_ids, ref_ids, ref_t)
        return (ok | grazing).mean()

    mesh = trimesh.Trimesh(vertices, faces, process=False)
    trimesh_ids = mesh.ray.intersects_first(origins, directions)
    scene = rtcore_scene.EmbreeScene()
    TriangleMesh(scene, vertices.astype(np.float32), faces)
    raw_ids = scene.run(origins.astype(np.float32), directions.astype(np.float32))
    ours = MeshIndex(vertices, faces).pick(origins, directions).face_ids
    assert agree(ours) == 1.0
    assert agree(trimesh_ids) < 0.8
    assert agree(raw_ids) < 0.8


def test_single_ray_and_result_shapes():
    vertices, faces = grid_mesh(4)
    index = MeshIndex(vertices, faces)
    r = index.pick(np.array([0.1, 0.2, 1.0]), np.array([0.0, 0.0, -1.0]))
    assert isinstance(r, PickResult)
    assert r.face_ids.dtype == np.int32 and r.face_ids.shape == (1,)
    assert r.distances.shape == (1,) and r.distances[0] == pytest.approx(1.0)
    # the same ray given as lists and as [1, 3]: same answer
    ids, dist = index.pick([[0.1, 0.2, 1.0]], [[0.0, 0.0, -2.0]])
    assert ids[0] == r.face_ids[0] and dist[0] == pytest.approx(0.5)
    # one direction shared by many origins
    many = index.pick(np.array([[0.1, 0.2, 1.0], [0.9, 0.9, 1.0], [5.0, 5.0, 1.0]]), [0, 0, -1.0])
    assert many.face_ids[0] == r.face_ids[0] and many.face_ids[2] == -1
    assert np.isinf(many.distances[2])
    assert len(index.pick(np.zeros((0, 3)), np.zeros((0, 3)))) == 0


def test_single_ray_is_thread_safe():
    from concurrent.futures import ThreadPoolExecutor

    vertices, faces = bumpy_terrain()
    index = MeshIndex(vertices, faces)
    rng = np.random.default_rng(3)
    origins, directions = random_rays(vertices, faces, 400, rng)
    expected = index.pick(origins, directions).face_ids

    def one(i):
        return int(index.pick(origins[i].copy(), directions[i].copy()).face_ids[0])

    with ThreadPoolExecutor(8) as pool:
        got = list(pool.map(one, range(len(origins))))
    assert got == expected.tolist()


def test_origin_shift_and_shared_origin():
    vertices, faces = bumpy_terrain(utm=True)
    index = MeshIndex(vertices, faces)
    assert index.origin[0] == 500_000.0 and index.origin[1] == 5_700_000.0
    shared = MeshIndex(vertices, faces, origin=UTM)
    np.testing.assert_array_equal(shared.origin, UTM)
    o = vertices[faces[100]].mean(0) + np.array([0.0, 0.0, 30.0])
    d = np.array([0.0, 0.0, -1.0])
    assert index.pick(o, d).face_ids[0] == shared.pick(o, d).face_ids[0] == 100


def test_hit_points_and_occluded():
    vertices, faces = grid_mesh(4, z=lambda x, y: 0.0 * x)
    index = MeshIndex(vertices, faces)
    origins = np.array([[0.3, 0.4, 2.0], [3.0, 3.0, 2.0]])
    directions = np.array([[0.0, 0.0, -2.0], [0.0, 0.0, -1.0]])
    points = index.hit_points(origins, directions)
    np.testing.assert_allclose(points[0], [0.3, 0.4, 0.0])
    assert np.isnan(points[1]).all()
    # the floor is 1 unit of this (length-2) direction away
    np.testing.assert_array_equal(index.occluded(origins[:1], directions[:1], 1.01), [True])
    np.testing.assert_array_equal(index.occluded(origins[:1], directions[:1], 0.99), [False])
    np.testing.assert_array_equal(index.occluded(origins, directions, [2.0, 2.0]), [True, False])


def test_rejects_bad_input():
    vertices, faces = grid_mesh(2)
    with pytest.raises(ValueError, match="faces refer"):
        MeshIndex(vertices, faces + 100)
    index = MeshIndex(vertices, faces)
    with pytest.raises(ValueError, match="rays must have shape"):
        index.pick(np.zeros((2, 2)), np.zeros((2, 2)))
    with pytest.raises(ValueError, match="directions for"):
        index.pick(np.zeros((3, 3)), np.ones((2, 3)))


def test_empty_mesh_misses_everything():
    index = MeshIndex(np.zeros((0, 3)), np.zeros((0, 3), np.int32))
    r = index.pick(np.zeros(3), np.array([0.0, 0.0, 1.0]))
    assert r.face_ids[0] == -1 and np.isinf(r.distances[0])
