"""Label export: class ids .npy + classes JSON, instance ids, and the face-coloured PLY."""

from __future__ import annotations

import io
import json

import numpy as np
import pytest
import trimesh

from storage import (
    UNLABELLED_COLOR,
    Instance,
    LabelClass,
    MapData,
    MapDocument,
    MapFormatError,
    label_arrays,
    label_files_bytes,
    label_instance_ids,
    ply_with_face_colors,
    write_label_files,
    write_ply_with_face_colors,
)
from tests.conftest import grid_mesh
from tests.storage.conftest import full_map

UTM = (500_000.0, 5_700_000.0, 0.0)


def expected_class_ids(data: MapData) -> np.ndarray:
    """The class id of every face, computed face by face (the slow, obvious way)."""
    order = list(data.classes)
    out = np.full(data.n_faces, -1, dtype=np.int32)
    for f, iid in enumerate(data.face_labels):
        inst = data.instances.get(int(iid))
        if inst is not None and inst.class_name in order:
            out[f] = order.index(inst.class_name)
    return out


def read_ply(payload: bytes) -> trimesh.Trimesh:
    mesh = trimesh.load(io.BytesIO(payload), file_type="ply", process=False)
    assert isinstance(mesh, trimesh.Trimesh)
    return mesh


def test_class_ids_follow_the_class_display_order(labelled_map):
    class_ids, info = label_arrays(labelled_map)
    assert class_ids.dtype == np.int32 and class_ids.shape == (labelled_map.n_faces,)
    np.testing.assert_array_equal(class_ids, expected_class_ids(labelled_map))
    # the fixture: stairs on 3..19, grass/1 on 40..44, grass/north on 2, 60, 90
    assert set(np.flatnonzero(class_ids == 0)) == set(range(3, 20))
    assert set(np.flatnonzero(class_ids == 1)) == {*range(40, 45), 2, 60, 90}
    assert not (class_ids == 2).any()

    assert info["format"] == "meshmark-face-labels" and info["version"] == 1
    assert info["faces"] == labelled_map.n_faces
    assert info["vertices"] == labelled_map.n_vertices
    assert info["unlabelled"] == -1
    assert info["labelled_faces"] == 17 + 8
    assert [c["name"] for c in info["classes"]] == ["stairs", "grass", "empty"]
    assert [c["id"] for c in info["classes"]] == [0, 1, 2]
    stairs, grass, empty = info["classes"]
    assert stairs["color"] == [200, 10, 10] and stairs["faces"] == 17
    assert stairs["instances"] == [{"instance_id": 0, "name": "1", "faces": 17}]
    assert grass["faces"] == 8
    assert grass["instances"] == [
        {"instance_id": 1, "name": "1", "faces": 5},
        {"instance_id": 2, "name": "north", "faces": 3},
        {"instance_id": 5, "name": "unused", "faces": 0},
    ]
    assert empty == {"id": 2, "name": "empty", "color": [1, 2, 3], "faces": 0, "instances": []}
    assert json.loads(json.dumps(info)) == info  # JSON-able as it is


def test_instance_ids_are_the_map_ids_listed_in_the_json(labelled_map):
    instance_ids = label_instance_ids(labelled_map)
    np.testing.assert_array_equal(instance_ids, labelled_map.face_labels)
    _, info = label_arrays(labelled_map)
    listed = {i["instance_id"]: i["faces"] for c in info["classes"] for i in c["instances"]}
    for iid in np.unique(instance_ids[instance_ids >= 0]):
        assert listed[int(iid)] == int(np.count_nonzero(instance_ids == iid))


def test_faces_of_unknown_instances_or_classes_count_as_unlabelled():
    v, f = grid_mesh(2)
    labels = np.array([0, 1, 7, -1, 2, 0, -1, 1], dtype=np.int32)
    data = MapData(
        vertices=v,
        faces=f,
        face_labels=labels,
        classes={"a": LabelClass("a", (1, 2, 3))},
        instances={0: Instance("a", "1"), 1: Instance("gone", "1")},
    )
    class_ids, info = label_arrays(data)
    np.testing.assert_array_equal(class_ids, [0, -1, -1, -1, -1, 0, -1, -1])
    np.testing.assert_array_equal(label_instance_ids(data), [0, -1, -1, -1, -1, 0, -1, -1])
    assert info["labelled_faces"] == 2
    assert info["classes"][0]["instances"] == [{"instance_id": 0, "name": "1", "faces": 2}]


def test_an_unlabelled_map_exports_all_minus_one():
    v, f = grid_mesh(3)
    class_ids, info = label_arrays(MapData(vertices=v, faces=f))
    np.testing.assert_array_equal(class_ids, np.full(len(f), -1, np.int32))
    assert info["classes"] == [] and info["labelled_faces"] == 0
    mesh = read_ply(ply_with_face_colors(MapData(vertices=v, faces=f)))
    np.testing.assert_array_equal(
        mesh.visual.face_colors, np.tile([*UNLABELLED_COLOR, 255], (len(f), 1))
    )


def test_written_files_load_back(labelled_map, tmp_path):
    npy, js, inst = tmp_path / "x.npy", tmp_path / "x.json", tmp_path / "x_instances.npy"
    info = write_label_files(labelled_map, npy, js, instances_path=inst)
    loaded = np.load(npy, allow_pickle=False)
    assert loaded.dtype == np.int32
    np.testing.assert_array_equal(loaded, expected_class_ids(labelled_map))
    assert json.loads(js.read_text(encoding="utf-8")) == info
    np.testing.assert_array_equal(np.load(inst), labelled_map.face_labels)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.json", "x.npy", "x_instances.npy"]

    # the browser's bytes are the same files
    npy_bytes, text = label_files_bytes(labelled_map)
    assert npy_bytes == npy.read_bytes()
    assert text == js.read_text(encoding="utf-8")


def test_writing_into_a_missing_folder_names_the_file_and_leaves_nothing(labelled_map, tmp_path):
    target = tmp_path / "no" / "such" / "labels.npy"
    with pytest.raises(MapFormatError, match=r"labels\.npy"):
        write_label_files(labelled_map, target, tmp_path / "labels.json")
    assert not list(tmp_path.iterdir())


def test_a_failed_write_keeps_the_earlier_files(labelled_map, tmp_path):
    npy, js = tmp_path / "x.npy", tmp_path / "x.json"
    npy.write_bytes(b"old npy")
    (tmp_path / "blocker").mkdir()
    with pytest.raises(MapFormatError):
        write_label_files(labelled_map, npy, js, instances_path=tmp_path / "blocker")
    assert npy.read_bytes() == b"old npy"  # nothing replaced: every file or none
    assert not js.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["blocker", "x.npy"]  # no temp files


def test_the_same_name_twice_is_refused(labelled_map, tmp_path):
    with pytest.raises(MapFormatError, match="distinct"):
        write_label_files(labelled_map, tmp_path / "x", tmp_path / "x")


def test_ply_keeps_utm_vertices_face_order_and_class_colours(tmp_path):
    data = full_map(16, offset=UTM)
    data.vertices[:, :2] += np.random.default_rng(1).random((data.n_vertices, 2)) * 1e-3
    mesh = read_ply(ply_with_face_colors(data))

    assert mesh.vertices.dtype == np.float64
    np.testing.assert_array_equal(mesh.vertices, data.vertices)  # bit-exact, not float32
    assert np.abs(mesh.vertices - data.vertices.astype(np.float32)).max() > 0.01
    np.testing.assert_array_equal(mesh.faces, data.faces)

    class_ids, info = label_arrays(data)
    palette = {c["id"]: c["color"] for c in info["classes"]}
    expected = np.array(
        [[*palette[k], 255] if k >= 0 else [*UNLABELLED_COLOR, 255] for k in class_ids],
        dtype=np.uint8,
    )
    np.testing.assert_array_equal(mesh.visual.face_colors, expected)

    path = tmp_path / "labels.ply"
    write_ply_with_face_colors(data, path)
    assert path.read_bytes() == ply_with_face_colors(data)


def test_ply_header_lists_the_classes_as_comments():
    data = full_map()
    data.classes["wéird\nname"] = LabelClass("wéird\nname", (4, 5, 6))
    payload = ply_with_face_colors(data)
    header = payload[: payload.index(b"end_header")].decode("ascii").splitlines()
    assert 'comment class 0 "stairs" 200 10 10' in header
    assert 'comment class 3 "w\\u00e9ird\\nname" 4 5 6' in header
    assert header[1] == "format binary_little_endian 1.0"
    assert "property double x" in header


def test_a_document_snapshot_exports_the_current_labels():
    v, f = grid_mesh(4, size=4.0)
    doc = MapDocument(MapData(vertices=np.asarray(v) + UTM, faces=f))
    doc.add_class("road", (10, 20, 30))
    road = doc.add_instance("road", "1")
    doc.add_class("tree", (200, 100, 0))
    tree = doc.add_instance("tree", "a")
    tree_b = doc.add_instance("tree", "b")
    doc.label_faces(range(0, 10), road)
    doc.label_faces([11, 12], tree)
    doc.label_faces([20], tree_b)
    doc.label_faces([5], -1)

    class_ids, info = label_arrays(doc.snapshot())
    expected = np.full(doc.n_faces, -1, np.int32)
    expected[[0, 1, 2, 3, 4, 6, 7, 8, 9]] = 0
    expected[[11, 12, 20]] = 1
    np.testing.assert_array_equal(class_ids, expected)
    assert [(c["name"], c["faces"]) for c in info["classes"]] == [("road", 9), ("tree", 3)]
    assert [i["faces"] for i in info["classes"][1]["instances"]] == [2, 1]
