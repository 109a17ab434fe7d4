"""The Labels panel's Export buttons in a real browser: every file reaches Chromium's downloads."""

from __future__ import annotations

import io
import json

import numpy as np
import pytest
import trimesh

from app.label_panel import EXPORT_IDS, EXPORT_PLY
from storage import MapData, MapDocument
from tests.app.conftest import TIMEOUT_MS
from tests.conftest import grid_mesh

pytestmark = pytest.mark.browser


def labelled_site() -> MapDocument:
    v, f = grid_mesh(10, size=10.0)
    utm = np.array([500_000.0, 5_700_000.0, 0.0])
    doc = MapDocument(MapData(v + utm, f, meta={"source_name": "x.h5"}))
    doc.add_class("road", (10, 20, 30))
    doc.label_faces(np.arange(50), doc.add_instance("road", "1"))
    return doc


def test_export_buttons_download_npy_json_and_ply(make_app, open_page, tmp_path):
    doc = labelled_site()
    running = make_app(doc, data_dir=tmp_path)
    page = open_page(running)

    downloads: list = []
    page.on("download", lambda download: downloads.append(download))

    def wait_for_downloads(n: int) -> None:
        for _ in range(TIMEOUT_MS // 100):
            if len(downloads) >= n:
                return
            page.wait_for_timeout(100)
        raise AssertionError(f"{len(downloads)} downloads arrived, expected {n}")

    page.get_by_role("button", name=EXPORT_IDS).click()
    wait_for_downloads(2)  # .npy and .json (desktop Chrome may ask once to allow several)
    page.get_by_role("button", name=EXPORT_PLY).click()
    wait_for_downloads(3)
    saved = {}
    for download in downloads:
        path = tmp_path / "downloads" / download.suggested_filename
        download.save_as(path)
        saved[download.suggested_filename] = path.read_bytes()

    assert sorted(saved) == ["x_labels.json", "x_labels.npy", "x_labels.ply"]
    class_ids = np.load(io.BytesIO(saved["x_labels.npy"]), allow_pickle=False)
    assert (class_ids[:50] == 0).all() and (class_ids[50:] == -1).all()
    assert json.loads(saved["x_labels.json"])["classes"][0]["faces"] == 50
    mesh = trimesh.load(io.BytesIO(saved["x_labels.ply"]), file_type="ply", process=False)
    np.testing.assert_array_equal(mesh.vertices, doc.vertices)
    assert (mesh.visual.face_colors[:50] == [10, 20, 30, 255]).all()
