"""The Goals folder without a browser: creating, listing, editing and undoing goals, and roles."""

from __future__ import annotations

import math

import numpy as np
import pytest

from geometry.pose import matrix_from_quaternion, yaw_of
from storage import MapData, MapDocument
from tests.app.conftest import wait_until


def floor_doc() -> MapDocument:
    v = np.array([[0, 0, 0], [4, 0, 0], [4, 3, 0], [0, 3, 0]], dtype=np.float64)
    return MapDocument(MapData(v, np.array([[0, 1, 2], [0, 2, 3]]), meta={"source_name": "f"}))


def start(make_app):
    running = make_app(floor_doc())
    return running.app.goals_panel, running.app.doc


def names(doc) -> list[str]:
    return [g.name for g in doc.goals]


def listed(panel, *texts: str) -> bool:
    content = panel.listing.content
    return all(t in content for t in texts)


def test_add_goal_sets_pose_and_name(make_app):
    panel, doc = start(make_app)
    a = panel.add_goal(0, np.array([1.0, 0.5, 0.0]), None, None)
    b = panel.add_goal(1, np.array([1.0, 2.0, 0.0]), np.array([1.0, 5.0, 0.3]), None)
    assert names(doc) == ["goal1", "goal2"]
    assert a.position == (1.0, 0.5, 0.0)
    assert yaw_of(a.orientation_xyzw) == 0.0  # no drag: world +x
    assert math.degrees(yaw_of(b.orientation_xyzw)) == pytest.approx(90.0)  # dragged +y
    for goal in (a, b):
        z = matrix_from_quaternion(goal.orientation_xyzw)[:, 2]
        assert np.allclose(z, [0, 0, 1])  # the face normal toward the (overhead) eye
    wait_until(lambda: listed(panel, "goal1", "goal2", "yaw 0°", "yaw 90°"), msg="not listed")
    wait_until(lambda: panel.selected.options == ("goal1", "goal2"), msg="dropdown not updated")
    doc.undo()
    assert names(doc) == ["goal1"]
    wait_until(lambda: "goal2" not in panel.listing.content, msg="undo not shown in the list")


def test_rename_reorder_delete_are_undoable(make_app):
    panel, doc = start(make_app)
    for x in (1.0, 2.0, 3.0):
        panel.add_goal(0, np.array([x, 0.5, 0.0]), None, None)
    wait_until(lambda: panel.selected.options == ("goal1", "goal2", "goal3"), msg="not listed")
    panel.selected.value = "goal2"
    panel.new_name.value = " dock "
    panel._rename()
    assert names(doc) == ["goal1", "dock", "goal3"]
    assert panel.selected.value == "dock" and panel.new_name.value == ""
    panel._order("Up")
    assert names(doc) == ["dock", "goal1", "goal3"]
    panel._order("Up")  # already first: nothing changes
    assert names(doc) == ["dock", "goal1", "goal3"]
    panel._order("Down")
    panel._order("Down")
    assert names(doc) == ["goal1", "goal3", "dock"]
    panel._order("Delete")
    assert names(doc) == ["goal1", "goal3"]
    wait_until(lambda: panel.selected.value == "goal3", msg="selection not moved off the deleted")
    for expected in (
        ["goal1", "goal3", "dock"],
        ["goal1", "dock", "goal3"],
        ["dock", "goal1", "goal3"],
        ["goal1", "dock", "goal3"],
        ["goal1", "goal2", "goal3"],
        ["goal1", "goal2"],
    ):
        assert doc.undo()
        assert names(doc) == expected
    wait_until(lambda: listed(panel, "goal1", "goal2") and "dock" not in panel.listing.content)


def test_roles_follow_renames_and_vanish_with_their_goal(make_app):
    panel, doc = start(make_app)
    panel.add_goal(0, np.array([1.0, 0.5, 0.0]), None, None)
    panel.add_goal(0, np.array([2.0, 0.5, 0.0]), None, None)
    wait_until(lambda: panel.selected.options == ("goal1", "goal2"), msg="not listed")
    panel.selected.value = "goal2"
    panel._role("Use as start")
    panel.selected.value = "goal1"
    panel._role("Use as goal")
    wait_until(lambda: listed(panel, "goal2</b> (start)", "goal1</b> (goal)"), msg="no roles")

    panel.selected.value = "goal2"
    panel.new_name.value = "dock"
    panel._rename()
    assert panel.start_name == "dock"
    wait_until(lambda: listed(panel, "dock</b> (start)"), msg="the role did not follow the name")

    # Deleting the start goal drops the role: a new goal that gets a free name is no start.
    panel.selected.value = "dock"
    panel._order("Delete")
    assert panel.start_name is None and panel.goal_name == "goal1"
    panel.add_goal(0, np.array([3.0, 0.5, 0.0]), None, None)
    panel.new_name.value = "dock"
    panel.selected.value = "goal2"
    panel._rename()  # the same name the start goal had
    assert names(doc) == ["goal1", "dock"]
    assert panel.start_name is None
    wait_until(lambda: listed(panel, "dock</b>:", "goal1</b> (goal)"), msg="list not refreshed")
    assert "(start)" not in panel.listing.content


def test_import_appends_goals_with_unique_names(make_app):
    from types import SimpleNamespace

    from viser._gui_handles import UploadedFile

    from storage import Goal, goals_to_yaml

    panel, doc = start(make_app)
    panel.add_goal(0, np.array([1.0, 0.5, 0.0]), None, None)  # goal1
    pose = ((2.0, 1.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    text = goals_to_yaml([Goal("goal1", *pose), Goal("dock", *pose), Goal("dock", *pose)])

    def upload() -> None:
        panel.upload._impl.value = UploadedFile("more.yaml", text.encode())
        panel._import(SimpleNamespace(client=None))

    upload()
    assert names(doc) == ["goal1", "goal1 (imported)", "dock", "dock (imported)"]
    upload()  # again: every name is still unique, so selecting by name stays unambiguous
    assert len(set(names(doc))) == len(doc.goals) == 7
    assert names(doc)[4:] == ["goal1 (imported 2)", "dock (imported 2)", "dock (imported 3)"]
    assert doc.undo() and len(doc.goals) == 4  # one import is one undoable change
