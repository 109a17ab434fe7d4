import numpy as np

from storage.polygons import fan_triangulate, split_seams


def test_fan_triangulation_keeps_polygons_in_place():
    tri = fan_triangulate([[0, 1, 2, 3], [1, 4, 2], [5, 6], [0, 1, 2, 3, 4]])
    np.testing.assert_array_equal(
        tri.faces, [[0, 1, 2], [0, 2, 3], [1, 4, 2], [0, 1, 2], [0, 2, 3], [0, 3, 4]]
    )
    np.testing.assert_array_equal(tri.source, [0, 0, 1, 3, 3, 3])
    assert (tri.short, tri.polygons) == (1, 2)


def test_fan_triangulation_of_arrays_and_nothing():
    np.testing.assert_array_equal(
        fan_triangulate(np.array([[0, 1, 2, 3]])).faces, [[0, 1, 2], [0, 2, 3]]
    )
    tris = np.array([[0, 1, 2], [2, 1, 3]])
    np.testing.assert_array_equal(fan_triangulate(tris).faces, tris)
    assert fan_triangulate([]).faces.shape == (0, 3)


def test_split_seams_copies_only_vertices_with_two_uvs():
    faces = np.array([[0, 1, 2], [2, 1, 3]])
    uv = np.array([[[0, 0], [1, 0], [0, 1]], [[0, 1], [1, 0.5], [1, 1]]])
    new_faces, source, new_uv = split_seams(faces, uv)
    np.testing.assert_array_equal(new_faces, [[0, 1, 2], [2, 3, 4]])
    np.testing.assert_array_equal(source, [0, 1, 2, 1, 3])
    np.testing.assert_allclose(new_uv[new_faces], uv)
