import threading

import numpy as np
import pytest

from storage import (
    DocumentChanged,
    DocumentError,
    Goal,
    LabelNameError,
    MapData,
    MapDocument,
    name_problem,
)
from tests.conftest import grid_mesh


def make_doc(n: int = 8) -> MapDocument:
    v, f = grid_mesh(n)
    return MapDocument(MapData(v, f, layers={"h": v[:, 2].astype(np.float32)}))


def state(doc: MapDocument):
    return (
        doc.face_labels.copy(),
        dict(doc.classes),
        dict(doc.instances),
        {k: v.copy() for k, v in doc.layers.items()},
        doc.goals,
    )


def same(a, b) -> bool:
    return (
        np.array_equal(a[0], b[0])
        and a[1] == b[1]
        and a[2] == b[2]
        and a[3].keys() == b[3].keys()
        and all(np.array_equal(a[3][k], b[3][k], equal_nan=True) for k in a[3])
        and a[4] == b[4]
    )


EDITS = {
    "label": lambda d, iid: d.label_faces([0, 1, 2, 5], iid),
    "erase": lambda d, iid: (d.label_faces([0, 1], iid), d.label_faces([1], -1)),
    "add class": lambda d, iid: d.add_class("stairs", (1, 2, 3)),
    "recolour": lambda d, iid: d.recolor_class("grass", (9, 9, 9)),
    "rename class": lambda d, iid: d.rename_class("grass", "lawn"),
    "delete class": lambda d, iid: (d.label_faces([3, 4], iid), d.delete_class("grass")),
    "add instance": lambda d, iid: d.add_instance("grass", "2"),
    "rename instance": lambda d, iid: d.rename_instance(iid, "7"),
    "delete instance": lambda d, iid: (d.label_faces([6], iid), d.delete_instance(iid)),
    "layer add": lambda d, iid: d.set_layer("new", np.arange(d.n_vertices)),
    "layer replace": lambda d, iid: d.set_layer("h", np.full(d.n_vertices, np.nan)),
    "layer remove": lambda d, iid: d.set_layer("h", None),
    "goals": lambda d, iid: d.set_goals([Goal("g", (1.0, 2.0, 3.0), (0.0, 0.0, 0.0, 1.0))]),
}


@pytest.mark.parametrize("edit", EDITS)
def test_every_edit_undoes_and_redoes_exactly(edit):
    doc = make_doc()
    doc.add_class("grass", (0, 200, 0))
    iid = doc.add_instance("grass", "1")
    doc.label_faces([10, 11], iid)
    before = state(doc)
    with doc.gesture():
        EDITS[edit](doc, iid)
    after = state(doc)
    assert not same(before, after), "the edit changed nothing"
    assert doc.undo()
    assert same(state(doc), before)
    assert doc.redo()
    assert same(state(doc), after)


def test_gesture_is_one_undo_step_and_new_edit_clears_redo():
    doc = make_doc()
    doc.add_class("c", (1, 1, 1))
    iid = doc.add_instance("c", "a")
    doc.begin_gesture()
    for k in range(10):  # a brush stroke: many drag events
        doc.label_faces([k], iid)
    doc.commit_gesture()
    assert (doc.face_labels[:10] == iid).all()
    assert doc.undo()
    assert (doc.face_labels == -1).all()
    assert doc.redo()
    doc.undo()
    doc.label_faces([50], iid)
    assert not doc.redo()


def test_history_keeps_at_least_100_steps():
    doc = make_doc(12)
    doc.add_class("c", (1, 1, 1))
    iid = doc.add_instance("c", "a")
    for k in range(150):
        doc.label_faces([k], iid)
    undone = 0
    while doc.undo():
        undone += 1
    assert undone >= 100
    assert (doc.face_labels[150 - undone : 150] == -1).all()


def test_failed_gesture_is_rolled_back():
    doc = make_doc()
    doc.add_class("c", (1, 1, 1))
    iid = doc.add_instance("c", "a")

    def gesture_that_fails() -> None:
        with doc.gesture():
            doc.label_faces([1, 2], iid)
            doc.label_faces([10**6], iid)  # out of range

    with pytest.raises(DocumentError):
        gesture_that_fails()
    assert (doc.face_labels == -1).all()


def test_noop_edits_record_nothing():
    doc = make_doc()
    doc.add_class("c", (1, 1, 1))
    iid = doc.add_instance("c", "a")
    doc.label_faces([1], iid)
    events = []
    doc.subscribe(events.append)
    assert doc.label_faces([1], iid) is None
    assert events == []


def test_label_atom_holds_only_changed_faces():
    doc = make_doc()
    doc.add_class("c", (1, 1, 1))
    iid = doc.add_instance("c", "a")
    doc.label_faces([1, 2], iid)
    atom = doc.label_faces([1, 2, 3, 3], iid)
    assert atom.face_ids.tolist() == [3]
    assert atom.old_ids.tolist() == [-1]


def test_names_follow_the_mesh_tools_rule():
    doc = make_doc()
    for bad in ["", " x", "a_b", "a/b"]:
        assert name_problem(bad) is not None
        with pytest.raises(LabelNameError):
            doc.add_class(bad, (1, 1, 1))
    assert "_" in name_problem("a_b")
    doc.add_class("stairs", (1, 1, 1))
    with pytest.raises(LabelNameError):
        doc.add_instance("stairs", "1_2")
    with pytest.raises(DocumentError):
        doc.add_class("stairs", (2, 2, 2))


def test_events_carry_the_atom():
    doc = make_doc()
    events = []
    doc.subscribe(events.append)
    doc.add_class("c", (1, 1, 1))
    iid = doc.add_instance("c", "a")
    doc.label_faces([4, 5], iid)
    assert isinstance(events[-1], DocumentChanged)
    assert events[-1].atom.face_ids.tolist() == [4, 5]
    doc.undo()
    assert events[-1].replay


def test_concurrent_label_edits_lose_nothing():
    doc = make_doc(40)  # 3200 faces
    doc.add_class("c", (1, 1, 1))
    a = doc.add_instance("c", "a")
    b = doc.add_instance("c", "b")
    faces = np.arange(doc.n_faces)

    def work(iid: int, ids: np.ndarray) -> None:
        for chunk in np.array_split(ids, 200):
            with doc.gesture():
                doc.label_faces(chunk, iid)

    threads = [
        threading.Thread(target=work, args=(a, faces[0::2])),
        threading.Thread(target=work, args=(b, faces[1::2])),
    ]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert (doc.face_labels[0::2] == a).all()
    assert (doc.face_labels[1::2] == b).all()
    assert doc.instance_face_counts() == {a: 1600, b: 1600}
    steps = 0
    while doc.undo():
        steps += 1
    assert steps == doc.history.max_steps  # 400 gestures were recorded, the newest kept
    # every undone gesture reverted exactly its own 8 faces
    assert (doc.face_labels >= 0).sum() == 3200 - 8 * steps


def test_snapshot_is_independent_of_later_edits():
    doc = make_doc()
    doc.add_class("c", (1, 1, 1))
    iid = doc.add_instance("c", "a")
    snap = doc.snapshot()
    doc.label_faces([0], iid)
    assert snap.face_labels[0] == -1
    assert "c" in snap.classes


def test_settings_survive_save_and_load(tmp_path):
    from storage import load_map, save_map

    doc = make_doc()
    settings = {"layers": {"default_layer": "final"}, "class_costs": {"keepout": "lethal"}}
    doc.meta_update(settings=settings)
    save_map(doc, tmp_path / "m.h5")
    assert load_map(tmp_path / "m.h5").meta["settings"] == settings


def test_changed_settings_count_as_unsaved_edits():
    doc = make_doc()
    doc.meta_update(source_name="x.h5")
    assert not doc.dirty
    doc.meta_update(settings={"class_costs": {"keepout": "lethal"}})
    assert doc.dirty
