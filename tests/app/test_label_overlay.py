"""LabelOverlay on a real viser server (port 0, no browser): which nodes exist, what is sent."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
import viser
from viser import _messages

from app.label_overlay import OVERLAY_ROOT, LabelOverlay, morton_chunks
from bench.labels_bench import captured_messages, run, wire_bytes
from bench.terrain import make_terrain
from storage import MapData, MapDocument
from tests.conftest import grid_mesh

RED, BLUE = (230, 30, 30), (30, 30, 230)


@pytest.fixture(scope="module")
def server():
    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    yield server
    server.stop()


@pytest.fixture
def setup(server):
    """A 128x128-cell grid (32k faces, 8 chunks), its overlay, and one instance of 'red'."""
    v, f = grid_mesh(128, size=10.0, z=lambda x, y: 0.1 * np.sin(x) * np.cos(y))
    doc = MapDocument(MapData(v, f))
    overlay = LabelOverlay(server, autoflush=False)
    overlay.show(doc)
    overlay.flush()
    doc.add_class("red", RED)
    iid = doc.add_instance("red", "1")
    chunks, chunk_of = morton_chunks(doc.vertices_local, doc.faces)
    assert len(chunks) >= 6
    yield SimpleNamespace(doc=doc, overlay=overlay, iid=iid, chunks=chunks, chunk_of=chunk_of)
    overlay.close()


def names(overlay: LabelOverlay) -> set[str]:
    return {h.name for h in overlay.handles()}


def node(cls: str, k: int) -> str:
    return f"{OVERLAY_ROOT}/{cls}/{k}"


def disc(doc: MapDocument, centre, radius: float) -> np.ndarray:
    c = doc.vertices[doc.faces].mean(axis=1)[:, :2]
    return np.flatnonzero(((c - centre) ** 2).sum(axis=1) < radius**2)


def touched(messages) -> set[str]:
    return {m.name for m in messages}


def test_nodes_exist_for_the_labelled_chunks_only(setup):
    s = setup
    faces = disc(s.doc, (2.0, 2.0), 1.5)
    with s.doc.gesture():
        s.doc.label_faces(faces, s.iid)
    s.overlay.flush()
    expected = set(np.unique(s.chunk_of[faces]).tolist())
    assert 0 < len(expected) < len(s.chunks)
    assert names(s.overlay) == {node("red", k) for k in expected}
    # Each node draws exactly the chunk's labelled faces with bit-identical base positions.
    for handle in s.overlay.handles():
        k = int(handle.name.rsplit("/", 1)[1])
        ids = np.intersect1d(faces, s.chunks[k].face_ids)  # in chunk (= face id) order
        got = np.asarray(handle.vertices)[np.asarray(handle.faces)]
        assert got.dtype == np.float32
        np.testing.assert_array_equal(got, s.doc.vertices_local[s.doc.faces[ids]])
        assert handle.color == RED


def test_a_second_edit_resends_only_the_touched_chunk(setup):
    s = setup
    first = disc(s.doc, (2.0, 2.0), 1.5)
    with s.doc.gesture():
        s.doc.label_faces(first, s.iid)
    s.overlay.flush()
    before = names(s.overlay)
    # A few unlabelled faces of one chunk that already has a node: a faces-only update.
    k = int(s.chunk_of[first[0]])
    free = np.setdiff1d(s.chunks[k].face_ids, first)[:5]
    with s.doc.gesture():
        s.doc.label_faces(free, s.iid)
    with captured_messages(s.overlay.server) as messages:
        assert s.overlay.flush() == 1
    assert len(messages) == 1
    (msg,) = messages
    assert isinstance(msg, _messages.SceneNodeUpdateMessage)
    assert msg.name == node("red", k)
    assert set(msg.updates) == {"faces"}
    assert len(msg.updates["faces"]) == len(np.intersect1d(s.chunks[k].face_ids, first)) + 5
    raw = msg.updates["faces"].nbytes  # uint32 [n, 3], sent raw; the rest is small msgpack
    assert raw < wire_bytes(messages) < raw + 200
    assert names(s.overlay) == before
    # A stroke into a chunk without labels creates that chunk's node and touches nothing else.
    empty = next(k for k in range(len(s.chunks)) if node("red", k) not in before)
    with s.doc.gesture():
        s.doc.label_faces(s.chunks[empty].face_ids[:3], s.iid)
    with captured_messages(s.overlay.server) as messages:
        assert s.overlay.flush() == 1
    assert touched(messages) == {node("red", empty)}
    assert sum(isinstance(m, _messages.MeshMessage) for m in messages) == 1
    assert names(s.overlay) == before | {node("red", empty)}


def test_a_chunk_dirty_for_one_class_leaves_the_other_classes_node_alone(setup):
    s = setup
    s.doc.add_class("blue", BLUE)
    blue = s.doc.add_instance("blue", "1")
    ids = s.chunks[0].face_ids
    with s.doc.gesture():
        s.doc.label_faces(ids[:100], s.iid)
        s.doc.label_faces(ids[100:200], blue)
    s.overlay.flush()
    with s.doc.gesture():
        s.doc.label_faces(ids[200:210], s.iid)
    with captured_messages(s.overlay.server) as messages:
        s.overlay.flush()
    assert touched(messages) == {node("red", 0)}


def test_deleting_a_class_removes_its_nodes_and_undo_restores_them(setup):
    s = setup
    faces = disc(s.doc, (7.0, 5.0), 2.0)
    with s.doc.gesture():
        s.doc.label_faces(faces, s.iid)
    s.overlay.flush()
    before = names(s.overlay)
    assert len(before) >= 2
    s.doc.delete_class("red")
    with captured_messages(s.overlay.server) as messages:
        s.overlay.flush()
    assert s.overlay.node_count == 0
    removed = {m.name for m in messages if isinstance(m, _messages.RemoveSceneNodeMessage)}
    assert removed == before
    assert s.doc.undo()
    s.overlay.flush()
    assert names(s.overlay) == before


def test_recolouring_a_class_sends_colour_updates_only(setup):
    s = setup
    faces = disc(s.doc, (5.0, 5.0), 2.5)
    with s.doc.gesture():
        s.doc.label_faces(faces, s.iid)
    s.overlay.flush()
    s.doc.recolor_class("red", BLUE)
    with captured_messages(s.overlay.server) as messages:
        assert s.overlay.flush() == s.overlay.node_count
    assert touched(messages) == names(s.overlay)
    for msg in messages:
        assert isinstance(msg, _messages.SceneNodeUpdateMessage)
        assert msg.updates == {"color": BLUE}
    assert all(h.color == BLUE for h in s.overlay.handles())


def test_the_labels_bench_reports_its_keys():
    result = run(make_terrain(40_000), SimpleNamespace(repeats=1))
    assert result["label_apply_ms"] > 0
    assert result["label_apply_nodes"] > 0
    assert 12 < result["label_update_bytes_per_face"] < 1000
    assert result["label_update_nodes_touched_mean"] >= 1
    assert result["label_nodes"] > 0
