"""load_map on files that are not maps: always a MapFormatError naming the file, never a raw one."""

from __future__ import annotations

import shutil

import h5py
import numpy as np
import pytest

from storage import READERS, MapFormatError, load_map, read_map_data, save_map
from tests.conftest import grid_mesh
from tests.storage.conftest import png_bytes


def _current_map(path, vertices, faces, *, faces_dtype=np.uint32) -> None:
    with h5py.File(path, "w") as h:
        h["mesh/geometry/vertices"] = np.asarray(vertices, np.float32)
        h["mesh/geometry/face_indices"] = np.asarray(faces).astype(faces_dtype)


def _fails(path, *words: str) -> MapFormatError:
    with pytest.raises(MapFormatError) as info:
        load_map(path)
    message = str(info.value)
    assert message.startswith(f"{path.name}: "), message
    for word in words:
        assert word in message, message
    return info.value


def test_registry_knows_every_format():
    assert {".h5", ".hdf5", ".ply", ".obj", ".glb", ".gltf", ".stl", ".off"} <= set(READERS)


def test_truncated_hdf5(tmp_path, labelled_map):
    good = tmp_path / "good.h5"
    save_map(labelled_map, good)
    blob = good.read_bytes()
    for fraction in (0.1, 0.5, 0.9):
        cut = tmp_path / f"cut{int(fraction * 100)}.h5"
        cut.write_bytes(blob[: int(len(blob) * fraction)])
        _fails(cut, "truncated or damaged")


def test_truncated_real_map(tmp_path, shared_data):
    blob = (shared_data / "terrain/floor_is_lava.h5").read_bytes()
    cut = tmp_path / "floor_is_lava.h5"
    cut.write_bytes(blob[: len(blob) // 2])
    _fails(cut, "truncated or damaged")


def test_random_bytes_named_h5(tmp_path):
    path = tmp_path / "noise.h5"
    path.write_bytes(np.random.default_rng(0).bytes(4096))
    _fails(path, "not an HDF5 file")


def test_hdf5_without_a_mesh(tmp_path):
    path = tmp_path / "table.h5"
    with h5py.File(path, "w") as h:
        h["data/values"] = np.arange(10)
    _fails(path, "holds no mesh")


@pytest.mark.parametrize(("bad", "dtype"), [(9, np.uint32), (-1, np.int32), (2**31, np.int64)])
def test_face_index_out_of_range(tmp_path, bad, dtype):
    v, f = grid_mesh(2)
    f = f.astype(np.int64)
    f[3, 1] = bad
    path = tmp_path / "oob.h5"
    _current_map(path, v, f, faces_dtype=dtype)
    _fails(path, "face 3 refers to vertex", "only 9 vertices")


def test_empty_meshes(tmp_path, shared_data):
    path = tmp_path / "empty.h5"
    _current_map(path, np.zeros((0, 3)), np.zeros((0, 3)))
    _fails(path, "empty")
    points = tmp_path / "points.h5"
    _current_map(points, np.zeros((4, 3)), np.zeros((0, 3)))
    _fails(points, "4 vertices but no faces")
    _fails(shared_data / "defects/empty.ply", "empty")


def test_non_finite_vertices_used_by_faces_are_refused(tmp_path):
    v, f = grid_mesh(2)
    v[4] = [np.nan, 0.0, np.inf]
    path = tmp_path / "nan.h5"
    _current_map(path, v, f)
    _fails(path, "vertex 4", "non-finite")


def test_non_finite_unused_vertices_are_kept_with_a_warning(tmp_path):
    v, f = grid_mesh(2)
    v = np.vstack([v, [[np.nan, np.nan, np.nan]]])
    path = tmp_path / "spare.h5"
    _current_map(path, v, f)
    doc = load_map(path)
    assert doc.n_vertices == len(v) and np.isnan(doc.vertices[-1]).all()
    assert any("no face uses" in w for w in doc.warnings)


@pytest.mark.parametrize("suffix", [".obj", ".ply", ".stl", ".glb", ".gltf", ".off", ".h5"])
def test_a_png_under_a_mesh_name(tmp_path, suffix):
    path = tmp_path / f"picture{suffix}"
    path.write_bytes(png_bytes(16))
    _fails(path)


@pytest.mark.parametrize("suffix", [".obj", ".ply", ".stl", ".glb", ".gltf", ".off"])
def test_text_under_a_mesh_name(tmp_path, suffix):
    path = tmp_path / f"notes{suffix}"
    path.write_text("this is not a mesh\n")
    _fails(path)


@pytest.mark.parametrize("suffix", [".obj", ".ply", ".h5"])
def test_empty_files(tmp_path, suffix):
    path = tmp_path / f"nothing{suffix}"
    path.write_bytes(b"")
    _fails(path, "empty")


def test_unknown_suffix_missing_file_and_folder(tmp_path):
    odd = tmp_path / "map.xyz"
    odd.write_text("1 2 3\n")
    _fails(odd, "unknown file type '.xyz'", ".ply")
    _fails(tmp_path / "missing.h5", "no such file")
    folder = tmp_path / "maps.h5"
    folder.mkdir()
    _fails(folder, "folder")


def test_obj_face_referring_to_a_missing_vertex(tmp_path):
    path = tmp_path / "oob.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n")
    _fails(path, "vertex")


def test_ply_face_referring_to_a_missing_vertex(tmp_path):
    path = tmp_path / "oob.ply"
    path.write_text(
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n"
    )
    _fails(path, "face 0 refers to vertex", "only 3 vertices")


def test_an_hdf5_map_under_another_suffix_is_still_read(tmp_path, labelled_map):
    good = tmp_path / "m.h5"
    save_map(labelled_map, good)
    renamed = tmp_path / "m.ply"
    shutil.copy(good, renamed)
    assert read_map_data(renamed).meta["layout"] == "current"
