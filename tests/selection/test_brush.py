import doctest

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

import selection.brush
from geometry import face_adjacency
from selection import BrushIndex, MeshIndex, brush_faces, stroke_points
from tests.conftest import grid_mesh


def folded_sheet(gap=0.1, length=2.0, step=0.05):
    """A strip folded back over itself: layer 0 at z = 0, layer 1 at z = gap, joined at x = length.

    Returns vertices, faces and the layer of each face (0 bottom, 1 top, -1 the fold).
    """
    s = np.concatenate(
        [
            np.linspace(0.0, length, round(length / step) + 1),
            np.linspace(length, length + gap, 3)[1:],
            np.linspace(length + gap, 2 * length + gap, round(length / step) + 1)[1:],
        ]
    )
    ys = np.linspace(0.0, 1.0, 21)
    gs, gy = np.meshgrid(s, ys)
    x = np.where(gs <= length, gs, np.where(gs <= length + gap, length, 2 * length + gap - gs))
    z = np.clip(gs - length, 0.0, gap)
    vertices = np.stack([x.ravel(), gy.ravel(), z.ravel()], axis=1)
    idx = np.arange(gs.size).reshape(gs.shape)
    a, b, c, d = idx[:-1, :-1], idx[:-1, 1:], idx[1:, :-1], idx[1:, 1:]
    faces = np.concatenate(
        [np.stack([a, b, d], -1).reshape(-1, 3), np.stack([a, d, c], -1).reshape(-1, 3)]
    ).astype(np.int32)
    zc = vertices[faces][:, :, 2].mean(1)
    layer = np.where(zc < 1e-9, 0, np.where(zc > gap - 1e-9, 1, -1))
    return vertices, faces, layer


@pytest.fixture(scope="module")
def sheet():
    vertices, faces, layer = folded_sheet()
    return vertices, faces, layer, BrushIndex(vertices, faces)


def in_ball(index, center, radius):
    return np.flatnonzero(np.linalg.norm(index.centroids - center, axis=1) <= radius)


def connected_in_ball(faces, ids, seed):
    """Reference: the connected component of ``seed`` in the adjacency restricted to ``ids``."""
    adjacency = face_adjacency(faces)
    keep = np.union1d(ids, [seed])
    sub = sp.csr_matrix(adjacency)[keep][:, keep]
    _, labels = connected_components(sub, directed=False)
    return keep[labels == labels[np.searchsorted(keep, seed)]]


def test_ball_takes_both_layers_connected_only_the_seeded_one(sheet):
    vertices, faces, layer, index = sheet
    center = np.array([0.5, 0.5, 0.0])
    # the face under the point on the bottom layer: pick from below
    seed = MeshIndex(vertices, faces).pick(center - [0, 0, 1.0], np.array([0, 0, 1.0]))
    seed = int(seed.face_ids[0])
    assert layer[seed] == 0
    ball = brush_faces(index, center, 0.3, seed_face=seed, connected=False)
    connected = brush_faces(index, center, 0.3, seed_face=seed, connected=True)
    assert set(layer[ball]) == {0, 1}
    assert set(layer[connected]) == {0}
    np.testing.assert_array_equal(ball, in_ball(index, center, 0.3))
    np.testing.assert_array_equal(connected, ball[layer[ball] == 0])
    np.testing.assert_array_equal(connected, connected_in_ball(faces, ball, seed))
    # seeded on the top layer, connected takes the top layer only
    top_seed = int(
        np.flatnonzero(layer == 1)[
            np.argmin(np.linalg.norm(index.centroids[layer == 1] - [0.5, 0.5, 0.1], axis=1))
        ]
    )
    top = brush_faces(index, center + np.array([0, 0, 0.1]), 0.3, seed_face=top_seed)
    assert set(layer[top]) == {1}


def test_connected_matches_reference_on_a_bumpy_grid():
    v, f = grid_mesh(40, 4.0, z=lambda x, y: 0.3 * np.sin(3 * x) * np.cos(2 * y))
    index = BrushIndex(v, f)
    rng = np.random.default_rng(0)
    for _ in range(20):
        seed = int(rng.integers(len(f)))
        center = index.centroids[seed] + rng.normal(0, 0.05, 3)
        radius = float(rng.uniform(0.05, 1.5))
        ball = brush_faces(index, center, radius, seed_face=seed, connected=False)
        expected_ball = np.union1d(in_ball(index, center, radius), [seed])
        np.testing.assert_array_equal(ball, expected_ball)
        connected = brush_faces(index, center, radius, seed_face=seed)
        np.testing.assert_array_equal(connected, connected_in_ball(f, ball, seed))


def test_seed_always_taken_and_default_seed(sheet):
    index = sheet[3]
    center = index.centroids[123] + [0.001, 0.0, 0.0]
    for connected in (True, False):
        assert brush_faces(index, center, 1e-6, seed_face=123, connected=connected).tolist() == [
            123
        ]
    # no seed: the face with the nearest centroid in the ball
    assert 123 in brush_faces(index, center, 0.05)
    assert len(brush_faces(index, center + np.array([0, 0, 5.0]), 0.05)) == 0
    assert index.nearest_faces(center, 0.01).tolist() == [123]
    assert index.nearest_faces([[100.0, 0.0, 0.0]], 1.0).tolist() == [-1]


def test_a_stroke_is_the_union_of_its_dabs(sheet):
    _, _, layer, index = sheet
    p0, p1 = np.array([0.3, 0.3, 0.0]), np.array([1.4, 0.6, 0.0])
    points = stroke_points(p0, p1, 0.1)
    assert len(points) == 12 and np.allclose(points[-1], p1)
    assert np.all(np.linalg.norm(np.diff(np.vstack([p0, points]), axis=0), axis=1) <= 0.1 + 1e-12)
    # the nearest centroid may sit on either layer: seed on the bottom layer explicitly
    bottom = np.flatnonzero(layer == 0)
    seeds = bottom[
        np.argmin(np.linalg.norm(index.centroids[bottom][None] - points[:, None], axis=2), axis=1)
    ]
    stroke = brush_faces(index, points, 0.15, seed_face=seeds)
    dabs = [brush_faces(index, p, 0.15, seed_face=s) for p, s in zip(points, seeds, strict=True)]
    np.testing.assert_array_equal(stroke, np.unique(np.concatenate(dabs)))
    assert set(layer[stroke]) == {0}


def test_stroke_points():
    assert stroke_points(None, [1.0, 2.0], 0.5).tolist() == [[1.0, 2.0]]
    assert stroke_points([1.0, 2.0], [1.0, 2.0], 0.5).tolist() == [[1.0, 2.0]]
    pts = stroke_points([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], 0.25)
    np.testing.assert_allclose(pts[:, 2], [0.25, 0.5, 0.75, 1.0])
    with pytest.raises(ValueError, match="spacing"):
        stroke_points([0, 0], [1, 1], 0.0)
    with pytest.raises(ValueError, match="dimension"):
        stroke_points([0, 0], [1, 1, 1], 0.1)


def test_brush_input_checks(sheet):
    index = sheet[3]
    with pytest.raises(ValueError, match="radius"):
        brush_faces(index, [0, 0, 0], -1.0)
    with pytest.raises(ValueError, match="seed face"):
        brush_faces(index, [0, 0, 0], 1.0, seed_face=10**7)
    with pytest.raises(ValueError, match="finite"):
        brush_faces(index, [np.nan, 0, 0], 1.0)
    with pytest.raises(TypeError, match="BrushIndex"):
        brush_faces(object(), [0, 0, 0], 1.0)
    empty = BrushIndex(np.zeros((0, 3)), np.zeros((0, 3), np.int32))
    assert len(brush_faces(empty, [0, 0, 0], 1.0)) == 0


def test_utm_coordinates_keep_float64_precision():
    v, f = grid_mesh(20, 2.0)
    offset = np.array([500_000.0, 5_700_000.0, 100.0])
    local = BrushIndex(v, f)
    far = BrushIndex(v + offset, f)
    center = np.array([1.0, 1.0, 0.0])
    np.testing.assert_array_equal(
        brush_faces(far, center + offset, 0.33, seed_face=0, connected=False),
        brush_faces(local, center, 0.33, seed_face=0, connected=False),
    )


def test_docstring_examples():
    assert doctest.testmod(selection.brush).failed == 0
