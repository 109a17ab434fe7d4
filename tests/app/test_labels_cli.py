"""``meshmark export-labels`` as a script runs it: a real subprocess on a saved labelled map."""

from __future__ import annotations

import io
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import trimesh

from app.labels_cli import output_paths
from storage import UNLABELLED_COLOR, MapData, MapDocument, load_map, save_map
from tests.conftest import grid_mesh

MESHMARK = [sys.executable, "-m", "app.cli"]
UTM = np.array([500_123.25, 5_700_456.75, 312.5])


def run(*args: str | Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [*MESHMARK, "export-labels", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )


@pytest.fixture
def site(tmp_path: Path) -> Path:
    """A 12 x 12 grid at UTM coordinates: road (2 instances), tree, an empty class; saved."""
    v, f = grid_mesh(12, size=24.0, z=lambda x, y: 0.1 * np.sin(x) * y)
    doc = MapDocument(MapData(vertices=v + UTM, faces=f))
    doc.add_class("road", (10, 20, 30))
    road_a = doc.add_instance("road", "a")
    road_b = doc.add_instance("road", "b")
    doc.add_class("tree", (200, 100, 0))
    tree = doc.add_instance("tree", "1")
    doc.add_class("water", (0, 0, 255))
    doc.label_faces(np.arange(0, 30), road_a)
    doc.label_faces(np.arange(100, 110), road_b)
    doc.label_faces([200, 201, 287], tree)
    path = tmp_path / "site.h5"
    save_map(doc, path)
    return path


def expected_class_ids(n_faces: int) -> np.ndarray:
    ids = np.full(n_faces, -1, dtype=np.int32)
    ids[0:30] = 0
    ids[100:110] = 0
    ids[[200, 201, 287]] = 1
    return ids


def test_export_writes_npy_json_and_ply(site, tmp_path):
    out = tmp_path / "out" / "site_labels"
    out.parent.mkdir()
    result = run(site, out, "--ply")
    assert result.returncode == 0, result.stderr
    paths = output_paths(out)
    assert sorted(p.name for p in out.parent.iterdir()) == [
        "site_labels.json",
        "site_labels.npy",
        "site_labels.ply",
    ]
    doc = load_map(site)
    class_ids = np.load(paths["npy"], allow_pickle=False)
    assert class_ids.dtype == np.int32
    np.testing.assert_array_equal(class_ids, expected_class_ids(doc.n_faces))

    info = json.loads(paths["json"].read_text(encoding="utf-8"))
    assert info["format"] == "meshmark-face-labels"
    assert info["faces"] == doc.n_faces == 288
    assert info["labelled_faces"] == 43
    road, tree, water = info["classes"]
    assert (road["id"], road["name"], road["color"], road["faces"]) == (0, "road", [10, 20, 30], 40)
    assert [(i["name"], i["faces"]) for i in road["instances"]] == [("a", 30), ("b", 10)]
    assert (tree["id"], tree["faces"], water["faces"]) == (1, 3, 0)
    assert water["instances"] == []

    mesh = trimesh.load(io.BytesIO(paths["ply"].read_bytes()), file_type="ply", process=False)
    np.testing.assert_array_equal(mesh.vertices, doc.vertices)  # float64 world frame, exact
    assert np.abs(mesh.vertices - (grid_mesh(12, size=24.0)[0] + UTM))[:, :2].max() < 1e-6
    np.testing.assert_array_equal(mesh.faces, doc.faces)
    colors = mesh.visual.face_colors
    np.testing.assert_array_equal(colors[class_ids == 0], np.tile([10, 20, 30, 255], (40, 1)))
    np.testing.assert_array_equal(colors[class_ids == 1], np.tile([200, 100, 0, 255], (3, 1)))
    np.testing.assert_array_equal(
        colors[class_ids == -1], np.tile([*UNLABELLED_COLOR, 255], (245, 1))
    )

    assert "43 of 288 faces labelled" in result.stdout
    assert "road" in result.stdout and "water" in result.stdout
    for path in paths["npy"], paths["json"], paths["ply"]:
        assert f"wrote {path}" in result.stdout


def test_without_ply_only_npy_and_json_are_written(site, tmp_path):
    result = run(site, tmp_path / "plain.npy", "--instances")  # a suffix on the stem is dropped
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "plain.npy").is_file() and (tmp_path / "plain.json").is_file()
    assert not (tmp_path / "plain.ply").exists() and not (tmp_path / "plain.npy.npy").exists()
    instance_ids = np.load(tmp_path / "plain_instances.npy")
    np.testing.assert_array_equal(instance_ids, load_map(site).face_labels)


@pytest.mark.parametrize(
    ("name", "content", "problem"),
    [
        ("notes.txt", b"not a mesh\n", "unknown file type '.txt'"),
        ("broken.h5", b"this is not HDF5 at all", "broken.h5"),
        ("photo.ply", b"\x89PNG\r\n\x1a\n" + b"\0" * 32, "is a PNG image"),
    ],
)
def test_a_file_that_is_no_map_exits_2_naming_it(tmp_path, name, content, problem):
    bad = tmp_path / name
    bad.write_bytes(content)
    result = run(bad, tmp_path / "out")
    assert result.returncode == 2
    assert name in result.stderr and problem in result.stderr
    assert "Traceback" not in result.stderr
    assert not list(tmp_path.glob("out*"))


def test_a_missing_map_and_an_unwritable_target_exit_2(site, tmp_path):
    missing = run(tmp_path / "nothing.h5", tmp_path / "out")
    assert missing.returncode == 2
    assert "nothing.h5: no such file" in missing.stderr

    unwritable = run(site, tmp_path / "no" / "folder" / "labels")
    assert unwritable.returncode == 2
    assert "labels.npy" in unwritable.stderr and "cannot be written" in unwritable.stderr
    assert "Traceback" not in unwritable.stderr
