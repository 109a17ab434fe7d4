"""Mesh formats through trimesh: real files, defects, face order, textures, colours, layers."""

from __future__ import annotations

import logging
import re
import threading
from pathlib import Path

import numpy as np
import pytest
import trimesh

from storage import MapFormatError, inspect_map, load_map, read_map_data
from tests.storage.conftest import png_bytes

REAL_MESHES = {
    # path: (faces, vertices)
    "terrain/botanical_garden_ros.ply": (31198, 21090),
    "botanical_garden_gazebo.ply": (37650, 25033),
    "terrain/floor_is_lava.ply": (15960, 8100),
    "classic/colored_airplane.ply": (10796, 7017),
    "classic/stanford-bunny.obj": (69451, 35947),
    "classic/fandisk.obj": (12946, 6475),
    "classic/armadillo.obj": (99976, 49990),
    "textured/cow_mesh/cow.obj": (5856, 3225),
    "textured/Avocado/Avocado.gltf": (682, 406),
    "textured/CesiumMilkTruck.glb": (3624, 3564),
    "indoor/simple_room.glb": (84, 190),
    "defects/soup.stl": (100, 300),
    "defects/notenoughindices.obj": (1, 3),
    "defects/nancolor.obj": (12, 8),
    "defects/joined_tetrahedra.obj": (8, 5),
    "defects/polygonfaces.obj": (3, 5),
    "defects/wallhole.obj": (66, 92),
    "defects/missing_files_obj/model.obj": (2, 4),
}


@pytest.mark.realdata
@pytest.mark.parametrize("name", sorted(REAL_MESHES))
def test_real_meshes_load(shared_data, name):
    faces, vertices = REAL_MESHES[name]
    doc = load_map(shared_data / name)
    assert (doc.n_faces, doc.n_vertices) == (faces, vertices)
    assert doc.faces.dtype == np.int32 and doc.vertices.dtype == np.float64
    assert np.isfinite(doc.vertices).all()


def _obj_corners(path: Path) -> np.ndarray:
    """Positions of every triangle corner, straight from the text (fan, short faces skipped)."""
    text = re.sub(r"\\\s*\n", " ", path.read_text())
    positions, corners = [], []
    for line in text.splitlines():
        tokens = line.split()
        if not tokens:
            continue
        if tokens[0] == "v":
            positions.append([float(t) for t in tokens[1:4]])
        elif tokens[0] == "f" and len(tokens) >= 4:
            ids = [int(t.split("/")[0]) for t in tokens[1:]]
            ids = [i - 1 if i > 0 else len(positions) + i for i in ids]
            for k in range(1, len(ids) - 1):
                corners.append([positions[ids[0]], positions[ids[k]], positions[ids[k + 1]]])
    return np.array(corners)


@pytest.mark.realdata
@pytest.mark.parametrize(
    "name",
    [
        "textured/cow_mesh/cow.obj",
        "classic/fandisk.obj",
        "defects/wallhole.obj",
        "defects/polygonfaces.obj",
        "defects/notenoughindices.obj",
        "defects/joined_tetrahedra.obj",
    ],
)
def test_obj_face_order_follows_the_file(shared_data, name):
    doc = load_map(shared_data / name)
    np.testing.assert_allclose(doc.vertices[doc.faces], _obj_corners(shared_data / name))


@pytest.mark.realdata
def test_obj_vertices_are_kept_unless_split_at_seams(shared_data):
    bunny = load_map(shared_data / "classic/stanford-bunny.obj")
    assert bunny.n_vertices == 35947  # 1113 unreferenced vertices kept
    cow = load_map(shared_data / "textured/cow_mesh/cow.obj")
    assert any("split at texture seams" in n and "2,930" in n for n in cow.meta["notes"])


@pytest.mark.realdata
@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("defects/notenoughindices.obj", ["skipped 1 face line", "'surface.mtl' not found"]),
        ("defects/polygonfaces.obj", ["1 polygon face", "into 3 triangles", "'surface.mtl'"]),
        (
            "defects/wallhole.obj",
            [
                "13 polygon face",
                "into 66 triangles",
                "'00.mtl' not found",
                "without a texture image",
            ],
        ),
        ("defects/missing_files_obj/model.obj", ["'material_1.png' named in model.mtl not found"]),
        ("defects/nancolor.obj", ["1 vertex colour(s) were NaN"]),
        (
            "terrain/floor_is_lava.ply",
            ["per-face data not read", "quality", "without a texture image"],
        ),
        ("indoor/simple_room.glb", ["without a texture image"]),
        ("textured/CesiumMilkTruck.glb", ["packed into one", "re-encoded as PNG"]),
    ],
)
def test_defects_are_read_with_honest_warnings(shared_data, name, expected):
    doc = load_map(shared_data / name)
    text = " | ".join(doc.warnings)
    for words in expected:
        assert words in text, text


@pytest.mark.realdata
@pytest.mark.parametrize(
    "name",
    [
        "classic/fandisk.obj",
        "classic/armadillo.obj",
        "defects/joined_tetrahedra.obj",
        "terrain/botanical_garden_ros.ply",
        "textured/Avocado/Avocado.gltf",
        "textured/cow_mesh/cow.obj",
        "defects/soup.stl",  # a soup of 100 separate triangles is still a valid mesh
    ],
)
def test_clean_files_give_no_warnings(shared_data, name):
    assert load_map(shared_data / name).warnings == []


@pytest.mark.realdata
def test_defects_that_cannot_be_read(shared_data):
    with pytest.raises(MapFormatError, match=r"empty\.ply: the mesh is empty"):
        load_map(shared_data / "defects/empty.ply")
    with pytest.raises(MapFormatError, match="missing_files_obj: is a folder"):
        load_map(shared_data / "defects/missing_files_obj")


@pytest.mark.realdata
def test_nan_colours_become_grey(shared_data):
    doc = load_map(shared_data / "defects/nancolor.obj")
    assert doc.vertex_colors.dtype == np.uint8 and doc.vertex_colors.shape == (8, 3)
    np.testing.assert_array_equal(doc.vertex_colors[6], [128, 128, 128])
    np.testing.assert_array_equal(doc.vertex_colors[0], [137, 254, 138])


@pytest.mark.realdata
def test_textures_are_kept_byte_exact(shared_data):
    cow = load_map(shared_data / "textured/cow_mesh/cow.obj")
    assert cow.texture.image == (shared_data / "textured/cow_mesh/cow_texture.png").read_bytes()
    assert cow.texture.mime_type == "image/png"
    assert cow.texture.uv.shape == (cow.n_vertices, 2) and cow.texture.uv.dtype == np.float32
    avocado = load_map(shared_data / "textured/Avocado/Avocado.gltf")
    base = (shared_data / "textured/Avocado/Avocado_baseColor.png").read_bytes()
    assert avocado.texture.image == base


@pytest.mark.realdata
def test_ply_layers_and_colours(shared_data):
    plane = load_map(shared_data / "classic/colored_airplane.ply")
    assert plane.n_vertices == 7017  # 1617 unreferenced vertices kept
    assert plane.vertex_colors.shape == (7017, 3)
    np.testing.assert_array_equal(plane.vertex_colors[0], [255, 9, 0])
    assert set(plane.layers) == {"quality"}
    lava = load_map(shared_data / "terrain/floor_is_lava.ply")
    assert lava.layers["quality"].shape == (8100,)


@pytest.mark.realdata
def test_ply_and_h5_of_the_same_garden_agree(shared_data):
    ply = load_map(shared_data / "terrain/botanical_garden_ros.ply")
    h5 = load_map(shared_data / "terrain/botanical_garden.h5")
    np.testing.assert_array_equal(ply.vertices, h5.vertices)
    canon = lambda f: {tuple(np.roll(r, -int(np.argmin(r)))) for r in f}  # noqa: E731
    assert canon(ply.faces) == canon(h5.faces)


# ----------------------------------------------------------------------- generated files


PLY_HEADER = (
    "ply\nformat ascii 1.0\n{comment}element vertex {n}\nproperty float x\nproperty float y\n"
    "property float z\n{vprops}element face {f}\nproperty list uchar int vertex_indices\n"
    "{fprops}end_header\n"
)


def test_ply_mixed_polygons_keep_file_order(tmp_path):
    path = tmp_path / "mixed.ply"
    path.write_text(
        PLY_HEADER.format(comment="", n=5, vprops="property float confidence\n", f=3, fprops="")
        + "0 0 0 1\n1 0 0 2\n1 1 0 3\n0 1 0 4\n2 0 0 5\n"
        + "4 0 1 2 3\n3 1 4 2\n2 0 1\n"
    )
    doc = load_map(path)
    np.testing.assert_array_equal(doc.faces, [[0, 1, 2], [0, 2, 3], [1, 4, 2]])
    np.testing.assert_array_equal(doc.layers["confidence"], [1, 2, 3, 4, 5])
    text = " ".join(doc.warnings)
    assert "skipped 1 face" in text and "1 polygon face" in text


def test_ply_float_colours_with_nan(tmp_path):
    path = tmp_path / "colours.ply"
    path.write_text(
        PLY_HEADER.format(
            comment="",
            n=3,
            vprops="property float red\nproperty float green\nproperty float blue\n",
            f=1,
            fprops="",
        )
        + "0 0 0 1 0 0\n1 0 0 0 1 0\n0 1 0 nan nan nan\n3 0 1 2\n"
    )
    doc = load_map(path)
    np.testing.assert_array_equal(doc.vertex_colors, [[255, 0, 0], [0, 255, 0], [128, 128, 128]])
    assert any("NaN" in w for w in doc.warnings)


def test_ply_texture_with_per_face_uvs_splits_seams(tmp_path):
    image = png_bytes()
    (tmp_path / "tex.png").write_bytes(image)
    path = tmp_path / "textured.ply"
    path.write_text(
        PLY_HEADER.format(
            comment="comment TextureFile tex.png\n",
            n=4,
            vprops="property float h\n",
            f=2,
            fprops="property list uchar float texcoord\n",
        )
        + "0 0 0 10\n1 0 0 11\n1 1 0 12\n0 1 0 13\n"
        # vertex 2 has uv (1, 1) in face 0 and (0.5, 0.5) in face 1: a seam
        + "3 0 1 2 6 0 0 1 0 1 1\n3 0 2 3 6 0 0 0.5 0.5 0 1\n"
    )
    doc = load_map(path)
    assert doc.texture.image == image
    assert doc.n_vertices == 5 and any("seams" in n for n in doc.meta["notes"])
    np.testing.assert_array_equal(doc.faces[0], [0, 1, 2])
    corner_uv = doc.texture.uv[doc.faces]
    np.testing.assert_allclose(corner_uv[1], [[0, 0], [0.5, 0.5], [0, 1]])
    np.testing.assert_allclose(doc.vertices[doc.faces[1]], [[0, 0, 0], [1, 1, 0], [0, 1, 0]])
    # the layer follows its vertex into the copy
    np.testing.assert_array_equal(doc.layers["h"][doc.faces[1]], [10, 12, 13])


def test_obj_with_several_materials_keeps_file_order(tmp_path):
    (tmp_path / "m.mtl").write_text("newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n")
    path = tmp_path / "m.obj"
    path.write_text(
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 2 0 0\n"
        "usemtl red\nf 1 2 3\nusemtl blue\nf 2 4 3\nusemtl red\nf 2 5 4\nf -1 -4 -3\n"
    )
    doc = load_map(path)
    np.testing.assert_array_equal(doc.faces, [[0, 1, 2], [1, 3, 2], [1, 4, 3], [4, 1, 2]])
    assert any("2 materials" in w for w in doc.warnings)


def test_scene_nodes_are_transformed_and_mirrors_keep_winding(tmp_path):
    box = trimesh.creation.box()
    scene = trimesh.Scene()
    scene.add_geometry(box, node_name="a", geom_name="box")
    shift = np.eye(4)
    shift[:3, 3] = [10.0, 0.0, 0.0]
    scene.add_geometry(box, node_name="b", geom_name="box", transform=shift)
    mirror = np.diag([-1.0, 1.0, 1.0, 1.0])
    mirror[:3, 3] = [0.0, 20.0, 0.0]
    scene.add_geometry(box, node_name="c", geom_name="box", transform=mirror)
    path = tmp_path / "scene.glb"
    path.write_bytes(scene.export(file_type="glb"))
    doc = load_map(path)
    assert doc.n_faces == 3 * len(box.faces)
    nf = len(box.faces)
    for k, centre in enumerate([[0, 0, 0], [10, 0, 0], [0, 20, 0]]):
        part = trimesh.Trimesh(doc.vertices, doc.faces[k * nf : (k + 1) * nf], process=False)
        np.testing.assert_allclose(part.bounds.mean(axis=0), centre, atol=1e-9)
        assert part.volume > 0  # outward winding, the mirrored copy included


def test_stl_corners_are_welded(tmp_path):
    box = trimesh.creation.box()
    path = tmp_path / "box.stl"
    path.write_bytes(box.export(file_type="stl"))
    doc = load_map(path)
    assert doc.n_faces == 12 and doc.n_vertices == 8
    np.testing.assert_allclose(doc.vertices[doc.faces], box.vertices[box.faces], atol=1e-6)
    assert any("welded" in n for n in doc.meta["notes"])


def test_off_files(tmp_path):
    path = tmp_path / "quad.off"
    path.write_text("OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n")
    doc = load_map(path)
    assert doc.n_faces == 2 and doc.n_vertices == 4


def test_trimesh_debug_lines_do_not_leak_into_the_log(tmp_path, caplog, shared_data):
    util = logging.getLogger("trimesh.util")
    level = util.level
    with caplog.at_level(logging.INFO):
        read_map_data(shared_data / "defects/notenoughindices.obj")
    assert util.level == level and not util.filters
    assert not [r for r in caplog.records if r.name.startswith("trimesh")]


def test_concurrent_reads_keep_their_own_warnings(shared_data):
    results: dict[str, list[str]] = {}

    def read(name: str) -> None:
        for _ in range(5):
            results[name] = load_map(shared_data / name).warnings

    names = ["defects/notenoughindices.obj", "classic/fandisk.obj", "defects/polygonfaces.obj"]
    threads = [threading.Thread(target=read, args=(n,)) for n in names]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert results["classic/fandisk.obj"] == []
    assert any("skipped 1 face" in w for w in results["defects/notenoughindices.obj"])


def test_inspect_reports_mesh_files(shared_data):
    text = inspect_map(shared_data / "textured/cow_mesh/cow.obj").to_text()
    assert "OBJ" in text and "5,856" in text and "image/png, 78,699 bytes" in text
