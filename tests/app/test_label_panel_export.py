"""The Labels panel's Export group without a browser: a real app, a client that keeps downloads."""

from __future__ import annotations

import io
import json
from collections.abc import Callable, Iterator
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
import trimesh
import viser

from app.label_panel import EXPORT_IDS, EXPORT_PLY
from static import demo_map_path
from storage import UNLABELLED_COLOR, MapDocument, load_map


class DownloadingClient:
    """Stands in for the browser: records what ``send_file_download`` would save."""

    def __init__(self) -> None:
        self.files: dict[str, bytes] = {}
        self.immediate: list[bool] = []

    def send_file_download(self, name: str, content: bytes, save_immediately: bool = False):
        self.files[name] = content
        self.immediate.append(save_immediately)


@pytest.fixture
def start(tmp_path) -> Iterator[Callable[[MapDocument], Any]]:
    from app.server import MeshmarkApp

    started: list[tuple[Any, Any]] = []

    def start_(doc: MapDocument) -> Any:
        server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
        app = MeshmarkApp(server, doc, data_dir=tmp_path)
        started.append((app, server))
        return app

    yield start_
    for app, server in started:
        app.close()
        server.stop()


def click(app: Any, option: str) -> DownloadingClient:
    client = DownloadingClient()
    event = viser.GuiEvent(client=client, client_id=0, target=SimpleNamespace(value=option))
    app.label_panel._export(event)  # type: ignore[arg-type]
    return client


@pytest.fixture
def labelled_demo() -> MapDocument:
    doc = load_map(demo_map_path())
    with doc.gesture():
        doc.add_class("keepout", (255, 0, 0))
        iid = doc.add_instance("keepout", "1")
    doc.label_faces(np.arange(0, 400), iid)
    return doc


def test_class_ids_download_as_npy_and_json(start, labelled_demo):
    app = start(labelled_demo)
    client = click(app, EXPORT_IDS)
    stem = demo_map_path().stem
    assert sorted(client.files) == [f"{stem}_labels.json", f"{stem}_labels.npy"]
    assert client.immediate == [True, True]
    class_ids = np.load(io.BytesIO(client.files[f"{stem}_labels.npy"]), allow_pickle=False)
    expected = np.full(labelled_demo.n_faces, -1, np.int32)
    expected[:400] = 0
    np.testing.assert_array_equal(class_ids, expected)
    info = json.loads(client.files[f"{stem}_labels.json"].decode("utf-8"))
    assert [(c["name"], c["faces"]) for c in info["classes"]] == [("keepout", 400)]


def test_ply_downloads_with_face_colours(start, labelled_demo):
    app = start(labelled_demo)
    client = click(app, EXPORT_PLY)
    (name,) = client.files
    assert name == f"{demo_map_path().stem}_labels.ply"
    mesh = trimesh.load(io.BytesIO(client.files[name]), file_type="ply", process=False)
    np.testing.assert_array_equal(mesh.vertices, labelled_demo.vertices)
    np.testing.assert_array_equal(mesh.faces, labelled_demo.faces)
    colors = mesh.visual.face_colors
    assert (colors[:400] == [255, 0, 0, 255]).all()
    assert (colors[400:] == [*UNLABELLED_COLOR, 255]).all()
