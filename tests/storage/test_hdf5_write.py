"""The HDF5 writer: the current layout exactly, round trips, far origins, atomic saves."""

from __future__ import annotations

import os
from pathlib import Path

import h5py
import numpy as np
import pytest

from geometry import face_normals, vertex_normals
from storage import MapData, MapFormatError, load_map, save_map
from tests.conftest import grid_mesh
from tests.storage.conftest import assert_same_map, float32_rounded, full_map


def _datasets(f: h5py.File) -> dict[str, h5py.Dataset]:
    found = {}

    def visit(name: str, obj: object) -> None:
        if isinstance(obj, h5py.Dataset):
            found[name] = obj

    f.visititems(visit)
    return found


def _is_vlen_utf8_scalar(attrs: h5py.AttributeManager, key: str) -> bool:
    aid = attrs.get_id(key)
    t = aid.get_type()
    return (
        aid.shape == ()
        and isinstance(t, h5py.h5t.TypeStringID)
        and t.is_variable_str()
        and t.get_cset() == h5py.h5t.CSET_UTF8
    )


def test_schema_is_the_current_layout(tmp_path, labelled_map):
    """Open the written file with h5py alone and check every path, dtype, shape and attribute."""
    path = tmp_path / "map.h5"
    save_map(labelled_map, path)
    n, nf = labelled_map.n_vertices, labelled_map.n_faces
    with h5py.File(path, "r") as f:
        assert f["version"].dtype == np.int32 and f["version"].shape == () and f["version"][()] == 1
        mesh = f["mesh"]
        assert mesh.attrs["IO"] == "MeshIO" and mesh.attrs["CLASS"] == "MeshBuffer"
        assert _is_vlen_utf8_scalar(mesh.attrs, "IO") and _is_vlen_utf8_scalar(mesh.attrs, "CLASS")

        expected = {
            "mesh/geometry/vertices": (np.float32, (n, 3)),
            "mesh/geometry/face_indices": (np.uint32, (nf, 3)),
            "mesh/geometry/vertex_normals": (np.float32, (n, 3)),
            "mesh/geometry/vertex_colors": (np.uint8, (n, 3)),
            "mesh/geometry/texture_coordinates": (np.float32, (n, 2)),
            "mesh/vertex_attributes/roughness": (np.float32, (n, 1)),
            "mesh/vertex_attributes/height": (np.float32, (n, 1)),
            "mesh/vertex_attributes/vertex_normals": (np.float32, (n, 3)),
            "mesh/vertex_attributes/vertex_colors": (np.uint8, (n, 3)),
            "mesh/face_attributes/face_normals": (np.float32, (nf, 3)),
            "mesh/labels/stairs/1": (np.uint32, (17, 1)),
            "mesh/labels/grass/1": (np.uint32, (5, 1)),
            "mesh/labels/grass/north": (np.uint32, (3, 1)),
            "meshmark/classes/names": (object, (3, 1)),
            "meshmark/classes/colors": (np.uint8, (3, 3)),
            "meshmark/instances/ids": (np.int32, (4, 1)),
            "meshmark/instances/classes": (object, (4, 1)),
            "meshmark/instances/names": (object, (4, 1)),
            "meshmark/goals/names": (object, (2, 1)),
            "meshmark/goals/frame_ids": (object, (2, 1)),
            "meshmark/goals/positions": (np.float64, (2, 3)),
            "meshmark/goals/orientations_xyzw": (np.float64, (2, 4)),
            "meshmark/texture": (np.uint8, (len(labelled_map.texture.image), 1)),
            "version": (np.int32, ()),
        }
        datasets = _datasets(f)
        assert set(datasets) == set(expected)
        for name, (dtype, shape) in expected.items():
            ds = datasets[name]
            assert ds.shape == shape, name
            if dtype is object:
                assert h5py.check_string_dtype(ds.dtype).encoding == "utf-8", name
            else:
                assert ds.dtype == dtype, name
            assert ds.compression in ("gzip", None), name  # never lzf / Blosc
            assert name == "version" or ds.ndim == 2, name
        assert not any("edge" in name for name in datasets)
        assert f["meshmark/texture"].attrs["mime_type"] == "image/png"
        assert f["mesh/geometry/vertices"].compression == "gzip"
        # the /mesh/labels groups need no attributes; face ids sorted
        stairs = f["mesh/labels/stairs/1"][()].ravel()
        np.testing.assert_array_equal(stairs, np.arange(3, 20))
        north = f["mesh/labels/grass/north"][()].ravel()
        np.testing.assert_array_equal(north, [2, 60, 90])


def test_a_reader_that_knows_only_the_current_layout_finds_everything(tmp_path, labelled_map):
    path = tmp_path / "map.h5"
    save_map(labelled_map, path)
    src = labelled_map
    with h5py.File(path, "r") as f:
        g = f["mesh"]
        vertices = g["geometry/vertices"][()]
        faces = g["geometry/face_indices"][()]
        np.testing.assert_array_equal(vertices, src.vertices.astype(np.float32))
        np.testing.assert_array_equal(faces, src.faces)
        for name, values in src.layers.items():
            stored = g[f"vertex_attributes/{name}"][()].ravel()
            np.testing.assert_array_equal(stored.view(np.uint32), values.view(np.uint32))
        np.testing.assert_array_equal(g["vertex_attributes/vertex_colors"][()], src.vertex_colors)
        clusters = {
            f"{c}_{i}": ds[()].ravel() for c, grp in g["labels"].items() for i, ds in grp.items()
        }
        assert set(clusters) == {"stairs_1", "grass_1", "grass_north"}
        for iid, inst in src.instances.items():
            expected = np.flatnonzero(src.face_labels == iid)
            if len(expected):
                np.testing.assert_array_equal(clusters[inst.full_name], expected)
        fn = g["face_attributes/face_normals"][()]
        np.testing.assert_allclose(fn, face_normals(vertices, faces), atol=1e-6)
        vn = g["vertex_attributes/vertex_normals"][()]
        np.testing.assert_allclose(vn, vertex_normals(vertices, faces), atol=1e-6)
        np.testing.assert_array_equal(vn, g["geometry/vertex_normals"][()])


def test_round_trip_keeps_everything(tmp_path, labelled_map):
    path = tmp_path / "map.h5"
    save_map(labelled_map, path)
    doc = load_map(path)
    assert doc.warnings == []
    assert doc.meta["layout"] == "current"
    assert_same_map(float32_rounded(labelled_map), doc.snapshot())
    # and once more, from the loaded document, to a second file
    save_map(doc, tmp_path / "again.h5")
    assert_same_map(doc.snapshot(), load_map(tmp_path / "again.h5").snapshot())


def test_utm_coordinates_round_trip_below_a_millimetre(tmp_path):
    data = full_map(offset=(500_000.123, 5_700_000.456, 100.789))
    path = tmp_path / "utm.h5"
    notes = save_map(data, path)
    assert any("origin (500000, 5700000, 0)" in n for n in notes)
    with h5py.File(path, "r") as f:
        origin = f["meshmark/origin"][()]
        assert origin.dtype == np.float64 and origin.shape == (1, 3)
        np.testing.assert_array_equal(origin.ravel(), [500_000.0, 5_700_000.0, 0.0])
        assert np.abs(f["mesh/geometry/vertices"][()]).max() < 10_000  # stored locally
    doc = load_map(path)
    assert np.abs(doc.vertices - data.vertices).max() < 1e-3
    np.testing.assert_array_equal(doc.origin, [500_000.0, 5_700_000.0, 0.0])
    assert_same_map(data, doc.snapshot(), atol=1e-3)
    # a second save keeps the same origin and does not drift
    save_map(doc, tmp_path / "again.h5")
    again = load_map(tmp_path / "again.h5")
    np.testing.assert_array_equal(again.vertices, doc.vertices)


def test_save_notes_say_what_other_tools_will_not_see(tmp_path, labelled_map):
    notes = save_map(labelled_map, tmp_path / "m.h5")
    assert len(notes) == 1 and "texture" in notes[0] and "ignore" in notes[0]
    from storage import Instance

    labelled_map.instances[9] = Instance("grass", "big_one")
    notes = save_map(labelled_map, tmp_path / "m.h5")
    assert any("'_'" in n and "big_one" in n for n in notes)
    labelled_map.texture = None
    labelled_map.instances.pop(9)
    assert save_map(labelled_map, tmp_path / "m.h5") == []


def test_near_origin_maps_store_no_origin(tmp_path, labelled_map):
    save_map(labelled_map, tmp_path / "m.h5")
    with h5py.File(tmp_path / "m.h5", "r") as f:
        assert "meshmark/origin" not in f


@pytest.mark.parametrize(
    "name",
    ["a/b", "vertex_normals", "vertex_colors", "cost_idx", ".", "..", "", "texture_coordinates"],
)
def test_layer_names_hdf5_cannot_hold_or_that_clash_survive(tmp_path, name):
    v, f = grid_mesh(3)
    values = np.arange(len(v), dtype=np.float32)
    data = MapData(v, f, layers={name: values, "plain": values + 1})
    save_map(data, tmp_path / "m.h5")
    with h5py.File(tmp_path / "m.h5", "r") as h:
        va = h["mesh/vertex_attributes"]
        assert va["vertex_normals"].shape == (len(v), 3)  # geometry is never overwritten
        assert all(ds.shape[1] in (1, 3) for ds in va.values())
        assert "plain" in va
    doc = load_map(tmp_path / "m.h5")
    assert set(doc.layers) == {name, "plain"}
    np.testing.assert_array_equal(doc.layers[name], values)


def test_compression_none_writes_contiguous_datasets(tmp_path, labelled_map):
    save_map(labelled_map, tmp_path / "raw.h5", compression=None)
    with h5py.File(tmp_path / "raw.h5", "r") as f:
        assert all(ds.compression is None for ds in _datasets(f).values())
    assert_same_map(float32_rounded(labelled_map), load_map(tmp_path / "raw.h5").snapshot())


@pytest.mark.parametrize("compression", ["lzf", "blosc", "gzip9"])
def test_other_compressions_are_refused(tmp_path, labelled_map, compression):
    with pytest.raises(ValueError, match="lzf or Blosc"):
        save_map(labelled_map, tmp_path / "m.h5", compression=compression)
    assert not (tmp_path / "m.h5").exists()


def test_label_names_hdf5_cannot_hold_are_refused(tmp_path, labelled_map):
    from storage import LabelClass

    labelled_map.classes["a/b"] = LabelClass("a/b", (1, 1, 1))
    with pytest.raises(MapFormatError, match=r"m\.h5.*'a/b'"):
        save_map(labelled_map, tmp_path / "m.h5")


def test_save_only_writes_hdf5_names(tmp_path, labelled_map):
    with pytest.raises(MapFormatError, match=r"m\.ply.*\.h5"):
        save_map(labelled_map, tmp_path / "m.ply")


# ------------------------------------------------------------------------- atomic saves


def _leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.endswith(".tmp"))


def test_a_failure_midway_leaves_the_old_file_untouched(tmp_path, labelled_map):
    """A goal name HDF5 cannot encode fails after all geometry has been written."""
    from storage import Goal

    path = tmp_path / "map.h5"
    save_map(labelled_map, path)
    before = path.read_bytes()
    labelled_map.goals.append(Goal("bad\udc80name", (0, 0, 0), (0, 0, 0, 1)))
    with pytest.raises(MapFormatError, match=r"map\.h5: cannot be written"):
        save_map(labelled_map, path)
    assert path.read_bytes() == before
    assert _leftovers(tmp_path) == []
    load_map(path)  # still a good map


def test_saving_onto_a_folder_fails_cleanly(tmp_path, labelled_map):
    target = tmp_path / "folder.h5"
    target.mkdir()
    with pytest.raises(MapFormatError, match=r"folder\.h5: is a folder"):
        save_map(labelled_map, target)
    assert target.is_dir() and _leftovers(tmp_path) == []


def test_saving_into_a_missing_folder_fails_cleanly(tmp_path, labelled_map):
    with pytest.raises(MapFormatError, match=r"map\.h5: cannot be written"):
        save_map(labelled_map, tmp_path / "missing" / "map.h5")


@pytest.mark.skipif(os.geteuid() == 0, reason="root may write into read-only folders")
def test_a_read_only_folder_fails_cleanly(tmp_path, labelled_map):
    path = tmp_path / "map.h5"
    save_map(labelled_map, path)
    before = path.read_bytes()
    tmp_path.chmod(0o555)
    try:
        with pytest.raises(MapFormatError, match=r"map\.h5: cannot be written"):
            save_map(labelled_map, path)
    finally:
        tmp_path.chmod(0o755)
    assert path.read_bytes() == before


def test_saving_over_the_file_the_document_came_from(tmp_path, labelled_map):
    path = tmp_path / "map.h5"
    save_map(labelled_map, path)
    doc = load_map(path)
    iid = doc.add_instance("stairs", "2")
    doc.label_faces([0, 1], iid)
    save_map(doc, doc.path)
    again = load_map(path)
    assert again.face_labels[0] == iid and again.instances[iid].name == "2"
    assert _leftovers(tmp_path) == []


def test_saving_keeps_the_old_file_mode(tmp_path, labelled_map):
    path = tmp_path / "map.h5"
    save_map(labelled_map, path)
    path.chmod(0o640)
    save_map(labelled_map, path)
    assert path.stat().st_mode & 0o777 == 0o640


def test_faces_with_unknown_instance_ids_are_not_saved(tmp_path, labelled_map):
    labelled_map.face_labels[100] = 42  # no instance 42
    save_map(labelled_map, tmp_path / "m.h5")
    assert load_map(tmp_path / "m.h5").face_labels[100] == -1
