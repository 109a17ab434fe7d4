"""Reading every HDF5 layout: real maps from ../shared/data and generated ones for the rest."""

from __future__ import annotations

import h5py
import numpy as np
import pytest

from storage import inspect_map, load_map, save_map
from storage.hdf5_read import read_hdf5
from tests.conftest import grid_mesh

REAL_MAPS = {
    # path: (layout, vertices, faces, layers)
    "terrain/botanical_garden.h5": (
        "legacy",
        21090,
        31198,
        {"average_angles", "height_diff", "roughness"},
    ),
    "terrain/floor_is_lava.h5": (
        "flat",
        8100,
        15960,
        {"average_angles", "border", "freespace", "height_diff", "roughness"},
    ),
    "tray.h5": (
        "flat",
        1257,
        2416,
        {"average_angles", "border", "freespace", "height_diff", "roughness"},
    ),
    "tray_s4.h5": ("flat", 1313, 2560, {"average_angles", "border", "height_diff", "roughness"}),
    "floor_is_lava_s3.h5": (
        "flat",
        2817,
        5504,
        {"average_angles", "border", "height_diff", "roughness"},
    ),
}


@pytest.mark.realdata
@pytest.mark.parametrize("name", sorted(REAL_MAPS))
def test_real_maps_load_exactly(shared_data, name):
    layout, n, nf, layers = REAL_MAPS[name]
    path = shared_data / name
    doc = load_map(path)
    assert doc.meta["layout"] == layout
    assert (doc.n_vertices, doc.n_faces) == (n, nf)
    assert set(doc.layers) == layers
    with h5py.File(path, "r") as f:
        group = f["meshes/mesh"] if layout == "legacy" else f["mesh/channels"]
        vertices = group["vertices"][()]
        faces = group["indices" if layout == "legacy" else "face_indices"][()]
        # vertices exactly as stored (unreferenced ones too), faces in file order
        np.testing.assert_array_equal(doc.vertices, vertices)
        np.testing.assert_array_equal(doc.faces, faces)
        for layer in layers:
            stored = (group[f"vertex_attributes/{layer}"] if layout == "legacy" else group[layer])[
                ()
            ].ravel()
            np.testing.assert_array_equal(doc.layers[layer].view(np.uint32), stored.view(np.uint32))


@pytest.mark.realdata
def test_nan_and_infinities_in_real_layers_are_kept(shared_data):
    garden = load_map(shared_data / "terrain/botanical_garden.h5")
    assert np.isnan(garden.layers["average_angles"]).sum() == 111
    assert np.isneginf(garden.layers["height_diff"]).sum() == 213
    lava = load_map(shared_data / "terrain/floor_is_lava.h5")
    assert np.isposinf(lava.layers["freespace"]).sum() == 4632
    info = inspect_map(shared_data / "terrain/botanical_garden.h5")
    stats = {s.name: s for s in info.layers}
    assert stats["average_angles"].nan == 111 and stats["height_diff"].neg_inf == 213
    assert stats["height_diff"].min == 0.0 and stats["height_diff"].max == pytest.approx(0.4)


@pytest.mark.realdata
@pytest.mark.parametrize(
    "name", ["terrain/floor_is_lava.h5", "tray.h5", "tray_s4.h5", "floor_is_lava_s3.h5"]
)
def test_2024_channels_maps_convert_to_the_current_layout(shared_data, tmp_path, name):
    source = load_map(shared_data / name)
    assert "lvr2 >= 25.1" in " ".join(source.meta["notes"])
    out = tmp_path / "converted.h5"
    save_map(source, out)
    with h5py.File(out, "r") as f:
        assert "channels" not in f["mesh"]
        assert f["mesh"].attrs["IO"] == "MeshIO"
        assert f["mesh/geometry/vertices"].dtype == np.float32
        assert f["mesh/geometry/face_indices"].dtype == np.uint32
        for layer in source.layers:
            assert f[f"mesh/vertex_attributes/{layer}"].shape == (source.n_vertices, 1)
        with h5py.File(shared_data / name, "r") as src:
            np.testing.assert_allclose(
                f["mesh/vertex_attributes/vertex_normals"][()],
                src["mesh/channels/vertex_normals"][()],
                atol=1e-6,
            )
    converted = load_map(out)
    assert converted.meta["layout"] == "current"
    np.testing.assert_array_equal(converted.vertices, source.vertices)
    np.testing.assert_array_equal(converted.faces, source.faces)
    for layer, values in source.layers.items():
        np.testing.assert_array_equal(
            converted.layers[layer].view(np.uint32), values.view(np.uint32)
        )


# ------------------------------------------------------------------- generated layouts


def test_old_hdf5mapio_layout(tmp_path):
    """mesh_tools' HDF5MapIO: flat 1-D geometry, /attributes, /labels, one H5IM texture."""
    v, f = grid_mesh(4)
    n = len(v)
    path = tmp_path / "mapio.h5"
    rng = np.random.default_rng(0)
    with h5py.File(path, "w") as h:
        h["geometry/vertices"] = v.astype(np.float32).ravel()
        h["geometry/faces"] = f.astype(np.uint32).ravel()
        h["attributes/normals"] = np.tile([0, 0, 1], n).astype(np.float32)
        h["attributes/rgb_colors"] = rng.integers(0, 255, 3 * n, dtype=np.uint8)
        h["attributes/roughness"] = np.linspace(0, 1, n, dtype=np.float32)
        h["attributes/height_difference"] = np.linspace(1, 2, n, dtype=np.float32)
        h.create_group("clustersets")
        h["textures/images/0"] = rng.integers(0, 255, (4, 6, 3), dtype=np.uint8)
        h["textures/coords"] = rng.random(2 * n, dtype=np.float32)
        h["labels/stairs/1"] = np.array([0, 1, 2], dtype=np.uint32)
        h["labels/stairs/2"] = np.array([5], dtype=np.uint32)
    doc = load_map(path)
    assert doc.meta["layout"] == "hdf5mapio"
    np.testing.assert_array_equal(doc.vertices, v.astype(np.float32))
    np.testing.assert_array_equal(doc.faces, f)
    assert set(doc.layers) == {"roughness", "height_difference"}
    with h5py.File(path, "r") as h:
        np.testing.assert_array_equal(doc.vertex_colors.ravel(), h["attributes/rgb_colors"][()])
    assert doc.texture is not None and doc.texture.image.startswith(b"\x89PNG")
    assert doc.texture.uv.shape == (n, 2)
    stairs = {doc.instances[i].name: i for i in doc.instances}
    assert sorted(stairs) == ["1", "2"]
    np.testing.assert_array_equal(np.flatnonzero(doc.face_labels == stairs["1"]), [0, 1, 2])
    assert list(doc.classes) == ["stairs"]


def test_part_found_by_content_with_any_dtypes(tmp_path):
    """A part not called 'mesh', float64 vertices, flat int64 faces, [N] float64 layers."""
    v, f = grid_mesh(3)
    path = tmp_path / "odd.h5"
    with h5py.File(path, "w") as h:
        h["robot/terrain/geometry/vertices"] = v  # float64
        h["robot/terrain/geometry/face_indices"] = f.astype(np.int64).ravel()
        h["robot/terrain/vertex_attributes/cost"] = np.arange(len(v), dtype=np.float64)
        h["robot/terrain/vertex_attributes/mask"] = np.ones((len(v), 1), dtype=np.uint8)
        h["robot/terrain/vertex_attributes/wide"] = np.ones((len(v), 2), dtype=np.float32)
        h["robot/terrain/face_attributes/face_normals"] = np.zeros((len(f), 3), np.float32)
        h["robot/terrain/face_attributes/slope"] = np.zeros((len(f), 1), np.float32)
        h["robot/terrain/labels/keepout/a"] = np.array([[1, 2]], dtype=np.uint64)  # any rank
    doc = load_map(path)
    assert doc.meta["layout"] == "current" and doc.meta["part"] == "/robot/terrain"
    np.testing.assert_array_equal(doc.vertices, v)  # float64 kept
    np.testing.assert_array_equal(doc.faces, f)
    assert set(doc.layers) == {"cost", "mask"}
    assert doc.layers["cost"].dtype == np.float32
    assert any("slope" in w and "per-face" in w for w in doc.warnings)
    assert any("uint8" in w for w in doc.warnings)
    assert any("wide" in item for item in doc.meta["ignored"])
    assert np.flatnonzero(doc.face_labels >= 0).tolist() == [1, 2]


def test_several_parts_take_the_first_with_faces_and_warn(tmp_path):
    v, f = grid_mesh(2)
    path = tmp_path / "two.h5"
    with h5py.File(path, "w") as h:
        h["a/channels/vertices"] = np.zeros((0, 3), np.float32)
        h["a/channels/face_indices"] = np.zeros((0, 3), np.uint32)
        h["b/channels/vertices"] = v.astype(np.float32)
        h["b/channels/face_indices"] = f.astype(np.uint32)
    doc = load_map(path)
    assert doc.meta["part"] == "/b" and doc.n_faces == len(f)
    assert any("2 meshes" in w for w in doc.warnings)


def test_labels_under_the_flat_layout_and_overlaps(tmp_path):
    v, f = grid_mesh(3)
    path = tmp_path / "flat.h5"
    with h5py.File(path, "w") as h:
        h["mesh/channels/vertices"] = v.astype(np.float32)
        h["mesh/channels/face_indices"] = f.astype(np.uint32)
        h["mesh/labels/grass/1"] = np.array([[0], [1], [2]], dtype=np.uint32)
        h["mesh/labels/grass/2"] = np.array([[2], [3]], dtype=np.uint32)  # face 2 twice
        h["mesh/labels/wall/1"] = np.array([[4], [99]], dtype=np.uint32)  # 99 out of range
        h["mesh/labels/my_class/x"] = np.array([5], dtype=np.uint32)
    doc = load_map(path)
    ids = {doc.instances[i].full_name: i for i in doc.instances}
    assert doc.face_labels[2] == ids["grass_2"]  # the last one read wins
    assert doc.face_labels[4] == ids["wall_1"]
    text = " ".join(doc.warnings)
    assert "1 faces belong to more than one label instance" in text
    assert "1 label face ids are outside" in text
    assert "my_class" in text and "'_'" in text


def test_meshmark_origin_is_added_back(tmp_path):
    v, f = grid_mesh(2)
    path = tmp_path / "o.h5"
    with h5py.File(path, "w") as h:
        h["mesh/geometry/vertices"] = v.astype(np.float32)
        h["mesh/geometry/face_indices"] = f.astype(np.uint32)
        h["meshmark/origin"] = np.array([[1000.0, 2000.0, 3.0]])
    data = read_hdf5(path)
    np.testing.assert_array_equal(data.vertices, v + np.array([1000.0, 2000.0, 3.0]))
    np.testing.assert_array_equal(data.meta["origin"], [1000.0, 2000.0, 3.0])
    assert "(1000.000, 2000.000, 3.000)" in inspect_map(path).to_text()


def test_the_file_is_closed_after_loading(tmp_path, labelled_map):
    path = tmp_path / "m.h5"
    save_map(labelled_map, path)
    load_map(path)
    with h5py.File(path, "a") as h:  # would fail if a read handle were still open
        h.attrs["touched"] = 1
