import doctest

import numpy as np
import pytest
from scipy.sparse.csgraph import connected_components

import selection.grow
from geometry import face_adjacency
from selection import flood_faces
from tests.conftest import grid_mesh


def test_flood_reaches_the_whole_connected_mesh():
    _, f = grid_mesh(10)
    adjacency = face_adjacency(f)
    ids = flood_faces(adjacency, 37)
    np.testing.assert_array_equal(ids, np.arange(len(f)))
    assert ids.dtype == np.int32


def test_flood_stays_within_the_mask_and_matches_components():
    v, f = grid_mesh(12)
    adjacency = face_adjacency(f)
    centroids = v[f].mean(1)
    within = np.abs(centroids[:, 0] - 0.5) > 0.1  # a gap down the middle splits the grid
    left = int(np.flatnonzero(within & (centroids[:, 0] < 0.5))[0])
    ids = flood_faces(adjacency, left, within=within)
    assert (centroids[ids, 0] < 0.5).all() and within[ids].all()
    sub = adjacency[within][:, within]
    _, labels = connected_components(sub, directed=False)
    kept = np.flatnonzero(within)
    expected = kept[labels == labels[np.searchsorted(kept, left)]]
    np.testing.assert_array_equal(ids, expected)
    # a seed outside the mask grows nothing
    outside = int(np.flatnonzero(~within)[0])
    assert len(flood_faces(adjacency, outside, within=within)) == 0


def test_flood_separate_pieces():
    v, f = grid_mesh(3)
    faces = np.concatenate([f, f + len(v)])  # two copies side by side, not joined
    ids = flood_faces(face_adjacency(faces), len(f) + 1)
    np.testing.assert_array_equal(ids, np.arange(len(f), 2 * len(f)))


def test_flood_input_checks():
    _, f = grid_mesh(3)
    adjacency = face_adjacency(f)
    with pytest.raises(ValueError, match="seed face"):
        flood_faces(adjacency, len(f))
    with pytest.raises(ValueError, match="mask"):
        flood_faces(adjacency, 0, within=np.ones(3, bool))


def test_docstring_examples():
    assert doctest.testmod(selection.grow).failed == 0
