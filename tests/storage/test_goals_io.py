"""Goal export/import as PoseStamped-shaped YAML and JSON: exact round trips, clear errors."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import yaml

from geometry.pose import surface_pose
from storage.errors import MapFormatError
from storage.goals_io import (
    COORDINATES,
    goal_problem,
    goals_from_dict,
    goals_from_json,
    goals_from_yaml,
    goals_to_dict,
    goals_to_json,
    goals_to_yaml,
)
from storage.model import Goal

S = math.sqrt(0.5)


def _tricky_goals() -> list[Goal]:
    rng = np.random.default_rng(11)
    goals = [
        Goal("dock", (1.5, -2.0, 0.25), (0.0, 0.0, S, S)),
        Goal("yes", (5e-324, 1e16, -0.0), (0.0, 0.0, 0.0, 1.0), "odom"),
        Goal("null", (0.1 + 0.2, -1.7976931348623157e308, 2.5e-310), (1.0, 0.0, 0.0, 0.0)),
        Goal("1.5", (500_000.123456789, 5_700_000.987654321, 101.0000001), (0.5, 0.5, 0.5, 0.5)),
        Goal("", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), ""),
        Goal("  spaced  ", (1.0, 2.0, 3.0), (0.0, 0.0, 0.0, 1.0)),
        Goal("a: b # c", (1.0, 2.0, 3.0), (0.0, 0.0, 0.0, 1.0), "frame with space"),
        Goal("two\nlines", (1.0, 2.0, 3.0), (0.0, 0.0, 0.0, 1.0)),
        Goal("Ümlaut ✓ 'q' \"dq\"", (1.0, 2.0, 3.0), (0.0, 0.0, 0.0, 1.0)),
        Goal("- [x]", (1.0, 2.0, 3.0), (0.0, 0.0, 0.0, 1.0)),
    ]
    for i in range(20):  # poses as the goal tool makes them: full-precision random floats
        position, q = surface_pose(
            rng.normal(size=3) * 50,
            rng.normal(size=3),
            rng.normal(size=3) * 100,
            rng.normal(size=3),
        )
        goals.append(Goal(f"tool {i}", tuple(position.tolist()), tuple(q.tolist())))
    # A quaternion stored as float32 is unit only to ~1e-7: it must still come back as is.
    unit = np.array([0.1, 0.2, 0.3, 0.9]) / np.linalg.norm([0.1, 0.2, 0.3, 0.9])
    q32 = tuple(float(v) for v in unit.astype(np.float32))
    assert 1e-9 < abs(math.fsum(v * v for v in q32) - 1.0) < 1e-6
    goals.append(Goal("float32-ish", (1.0, 2.0, 3.0), q32))
    return goals


def _bits(goals: list[Goal]) -> list[tuple]:
    """Compare floats by repr so that -0.0 vs 0.0 and the last bit count."""
    return [
        (g.name, g.frame_id, [repr(v) for v in g.position], [repr(v) for v in g.orientation_xyzw])
        for g in goals
    ]


# ----------------------------------------------------------------------------- round trips


def test_yaml_round_trip_is_identical():
    goals = _tricky_goals()
    back = goals_from_yaml(goals_to_yaml(goals))
    assert back == goals
    assert _bits(back) == _bits(goals)
    assert all(type(v) is float for g in back for v in (*g.position, *g.orientation_xyzw))


def test_json_round_trip_is_identical():
    goals = _tricky_goals()
    back = goals_from_json(goals_to_json(goals))
    assert back == goals
    assert _bits(back) == _bits(goals)


def test_export_import_export_gives_the_same_text():
    goals = _tricky_goals()
    text = goals_to_yaml(goals, origin=(500_000.0, 5_700_000.0, 0.0))
    assert goals_to_yaml(goals_from_yaml(text), origin=(500_000.0, 5_700_000.0, 0.0)) == text
    text = goals_to_json(goals)
    assert goals_to_json(goals_from_json(text)) == text


def test_yaml_and_json_hold_the_same_structure():
    goals = _tricky_goals()
    assert yaml.safe_load(goals_to_yaml(goals)) == json.loads(goals_to_json(goals))


def test_empty_goal_list_round_trips():
    assert goals_from_yaml(goals_to_yaml([])) == []
    assert goals_from_json(goals_to_json([])) == []


def test_numpy_scalars_export_as_plain_floats():
    goal = Goal(
        "np",
        tuple(np.array([1.25, 2.5, 3.0])),
        tuple(np.array([0.0, 0.0, 0.0, 1.0], dtype=np.float32)),
    )
    back = goals_from_yaml(goals_to_yaml([goal]))
    assert back == [Goal("np", (1.25, 2.5, 3.0), (0.0, 0.0, 0.0, 1.0))]
    assert goals_from_json(goals_to_json([goal])) == back


def test_tuple_from_the_document_is_accepted():
    goals = tuple(_tricky_goals()[:2])
    assert goals_from_yaml(goals_to_yaml(goals)) == list(goals)


# ------------------------------------------------------------------------------ the shape


def test_yaml_shape_is_a_list_of_named_pose_stamped():
    text = goals_to_yaml([Goal("dock", (1.5, -2.0, 0.25), (0.0, 0.0, S, S))])
    assert text.startswith("# meshmark goal poses")
    assert "geometry_msgs/msg/PoseStamped" in text
    doc = yaml.safe_load(text)
    assert doc == {
        "format": "meshmark-goals",
        "version": 1,
        "coordinates": COORDINATES,
        "goals": [
            {
                "name": "dock",
                "pose_stamped": {
                    "header": {"frame_id": "map", "stamp": {"sec": 0, "nanosec": 0}},
                    "pose": {
                        "position": {"x": 1.5, "y": -2.0, "z": 0.25},
                        "orientation": {"x": 0.0, "y": 0.0, "z": S, "w": S},
                    },
                },
            }
        ],
    }
    # Leaves are written flow style, the way `ros2 topic echo` users read them.
    assert "position: {x: 1.5, y: -2.0, z: 0.25}" in text
    assert "stamp: {sec: 0, nanosec: 0}" in text


def test_origin_is_written_only_when_the_map_is_shifted():
    goals = [Goal("a", (1.0, 2.0, 3.0), (0.0, 0.0, 0.0, 1.0))]
    plain = goals_to_yaml(goals)
    assert "origin" not in yaml.safe_load(plain)
    assert goals_to_yaml(goals, origin=(0.0, 0.0, 0.0)) == plain
    shifted = goals_to_yaml(goals, origin=np.array([500_000.0, 5_700_000.0, 0.0]))
    assert yaml.safe_load(shifted)["origin"] == [500_000.0, 5_700_000.0, 0.0]
    assert "subtract `origin`" in shifted
    assert json.loads(goals_to_json(goals, origin=(1.0, 0.0, 0.0)))["origin"] == [1.0, 0.0, 0.0]
    # The origin is informational: importing gives the same world-frame goals.
    assert goals_from_yaml(shifted) == goals


def test_json_is_strict_json():
    text = goals_to_json(_tricky_goals())
    json.loads(text, parse_constant=lambda c: pytest.fail(f"non-standard constant {c}"))
    assert text.endswith("\n")


# ---------------------------------------------------------------------- lenient reading


def test_bare_list_of_items_and_of_pose_stamped_messages():
    text = """
- name: a
  pose_stamped:
    header: {frame_id: odom}
    pose:
      position: {x: 1, y: 2, z: 3}
      orientation: {x: 0, y: 0, z: 0, w: 1}
- header: {frame_id: map, stamp: {sec: 17, nanosec: 5}}
  pose:
    position: {x: 4.0, y: 5.0, z: 6.0}
    orientation: {x: 0.0, y: 0.0, z: 0.7071, w: 0.7071}
"""
    a, b = goals_from_yaml(text)
    assert a == Goal("a", (1.0, 2.0, 3.0), (0.0, 0.0, 0.0, 1.0), "odom")
    assert all(type(v) is float for v in a.position)
    assert b.name == "goal 2"
    assert b.frame_id == "map"
    # A hand-written 0.7071 is normalised, not refused.
    assert b.orientation_xyzw == pytest.approx((0.0, 0.0, S, S), abs=1e-12)
    assert math.fsum(v * v for v in b.orientation_xyzw) == pytest.approx(1.0, abs=1e-15)


def test_missing_header_means_frame_map_and_unknown_keys_are_ignored():
    text = """
comment: written by hand
goals:
- name: x
  colour: red
  pose_stamped:
    pose:
      position: {x: 0.0, y: 0.0, z: 0.0}
      orientation: {x: 0.0, y: 0.0, z: 0.0, w: 1.0}
"""
    assert goals_from_yaml(text) == [Goal("x", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), "map")]


def test_goals_null_is_an_empty_list():
    assert goals_from_yaml("goals:\n") == []


def test_bytes_are_accepted():
    goals = _tricky_goals()[:3]
    assert goals_from_yaml(goals_to_yaml(goals).encode()) == goals
    assert goals_from_json(goals_to_json(goals).encode()) == goals


def test_goals_from_dict_takes_parsed_data():
    goals = _tricky_goals()[:3]
    assert goals_from_dict(goals_to_dict(goals)) == goals


# ------------------------------------------------------------------------------- errors

GOOD_ITEM = """
- name: a
  pose_stamped:
    header: {frame_id: map, stamp: {sec: 0, nanosec: 0}}
    pose:
      position: {x: 1.0, y: 2.0, z: 3.0}
      orientation: {x: 0.0, y: 0.0, z: 0.0, w: 1.0}
"""


def _with_second(position: str = "", orientation: str = "") -> str:
    position = position or "{x: 1.0, y: 2.0, z: 3.0}"
    orientation = orientation or "{x: 0.0, y: 0.0, z: 0.0, w: 1.0}"
    return (
        "goals:"
        + GOOD_ITEM
        + f"""- name: b
  pose_stamped:
    header: {{frame_id: map}}
    pose:
      position: {position}
      orientation: {orientation}
"""
    )


def _yaml_error(text: str, source: str = "goals.yaml") -> str:
    with pytest.raises(MapFormatError) as info:
        goals_from_yaml(text, source)
    err = info.value
    assert str(err).startswith(f"{source}: ")
    assert err.problem in str(err)
    return err.problem


def test_good_fixture_is_good():
    assert len(goals_from_yaml(_with_second())) == 2


def test_not_yaml():
    problem = _yaml_error("goals: [unclosed\n  - {x: 1", "my goals.yaml")
    assert problem.startswith("not valid YAML")
    assert "line" in problem


def test_not_json():
    with pytest.raises(MapFormatError, match=r"^g\.json: not valid JSON: .* line 1, column"):
        goals_from_json('{"goals": [', "g.json")
    with pytest.raises(MapFormatError, match=r"expected a mapping with a 'goals' list"):
        goals_from_json("null", "g.json")


def test_not_utf8():
    with pytest.raises(MapFormatError, match="not UTF-8"):
        goals_from_json(b'{"goals": "\x80"}', "g.json")
    with pytest.raises(MapFormatError, match="not valid YAML"):
        goals_from_yaml(b"goals: \x80", "g.yaml")


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("", "the file is empty"),
        ("just some words", "'goals' must be a list of goals, got text ('just some words')"),
        ("goals: 3", "'goals' must be a list of goals, got a number (3)"),
        ("poses: []", "no 'goals' list at the top level"),
        ("format: nav2-waypoints\ngoals: []", "format is 'nav2-waypoints', expected"),
        ("version: 2\ngoals: []", "written by a newer meshmark (version 2)"),
        ("version: one\ngoals: []", "version must be a positive integer, got 'one'"),
        ("goals: [5]", "goal 1: expected a mapping with 'name' and 'pose_stamped', got a number"),
        ("goals: [{name: a}]", "goal 1 ('a'): missing 'pose_stamped'"),
        ("goals: [{name: a, pose_stamped: []}]", "goal 1 ('a'): 'pose_stamped' must be a mapping"),
        ("goals: [{name: a, pose_stamped: {header: {}}}]", "missing 'pose_stamped.pose'"),
    ],
)
def test_shape_errors(text, expected):
    assert expected in _yaml_error(text)


@pytest.mark.parametrize(
    ("position", "orientation", "expected"),
    [
        ("{x: 1.0, y: 2.0}", "", "goal 2 ('b'): missing 'pose_stamped.pose.position.z'"),
        ("", "{x: 0.0, y: 0.0, z: 0.0}", "goal 2 ('b'): missing 'pose_stamped.pose.orientation.w'"),
        ("[1.0, 2.0, 3.0]", "", "'pose_stamped.pose.position' must be a mapping, got a list"),
        ("{x: '1.0', y: 2, z: 3}", "", "'pose_stamped.pose.position.x' must be a number, got text"),
        ("{x: 1, y: true, z: 3}", "", "'pose_stamped.pose.position.y' must be a number, got true"),
        ("{x: 1, y: 2, z: }", "", "'pose_stamped.pose.position.z' must be a number, got nothing"),
        ("{x: .nan, y: 2, z: 3}", "", "'pose_stamped.pose.position.x' must be finite, got nan"),
        ("{x: 1, y: -.inf, z: 3}", "", "'pose_stamped.pose.position.y' must be finite, got -inf"),
        ("{x: 1, y: 2, z: 1" + "0" * 400 + "}", "", "position.z' must be finite, got inf"),
        ("", "{x: 0, y: 0, z: 0, w: .inf}", "'pose_stamped.pose.orientation.w' must be finite"),
        ("", "{x: 0, y: 0, z: 0, w: 0}", "orientation: the quaternion is zero"),
        ("", "{x: 0, y: 0, z: 0, w: 2}", "orientation: not a unit quaternion (norm 2,"),
        ("", "{x: 0, y: 0, z: 0.7, w: 0.7}", "not a unit quaternion (norm 0.989949"),
    ],
)
def test_field_errors_name_the_goal_and_the_field(position, orientation, expected):
    assert expected in _yaml_error(_with_second(position, orientation))


def test_name_and_frame_must_be_text():
    text = GOOD_ITEM.replace("name: a", "name: 12")
    assert "goal 1: name must be text, got 12 (quote it in YAML)" in _yaml_error(text)
    text = GOOD_ITEM.replace("frame_id: map", "frame_id: [map]")
    assert "goal 1 ('a'): pose_stamped.header.frame_id must be text" in _yaml_error(text)


def test_json_non_finite_numbers_are_refused():
    doc = goals_to_dict([Goal("a", (1.0, 2.0, 3.0), (0.0, 0.0, 0.0, 1.0))])
    text = json.dumps(doc).replace('"x": 1.0', '"x": NaN')
    with pytest.raises(MapFormatError, match=r"goal 1 \('a'\): .*position\.x' must be finite"):
        goals_from_json(text, "g.json")


def test_default_source_names_say_what_was_read():
    with pytest.raises(MapFormatError, match=r"^<goals YAML>: "):
        goals_from_yaml("goals: 1")
    with pytest.raises(MapFormatError, match=r"^<goals JSON>: "):
        goals_from_json("[1]")


# ---------------------------------------------------------------------------- writing checks


@pytest.mark.parametrize(
    ("goal", "expected"),
    [
        (Goal("a", (1.0, math.nan, 0.0), (0.0, 0.0, 0.0, 1.0)), "position is not 3 finite"),
        (Goal("a", (1.0, 0.0), (0.0, 0.0, 0.0, 1.0)), "3 position and 4 orientation"),  # type: ignore[arg-type]
        (Goal("a", (1.0, 2.0, 0.0), (0.0, 0.0, 0.0, math.inf)), "orientation is not 4 finite"),
        (Goal("a", (1.0, 2.0, 0.0), (0.0, 0.0, 0.0, 0.0)), "quaternion is zero"),
        (Goal("a", (1.0, 2.0, 0.0), (0.0, 0.0, 0.0, 1.5)), "not a unit quaternion"),
        (Goal(7, (1.0, 2.0, 0.0), (0.0, 0.0, 0.0, 1.0)), "name must be text"),  # type: ignore[arg-type]
        (Goal("a", ("1", 2.0, 0.0), (0.0, 0.0, 0.0, 1.0)), "position is not 3 finite"),  # type: ignore[arg-type]
    ],
)
def test_export_refuses_goals_it_could_not_read_back(goal, expected):
    assert expected in goal_problem(goal)
    with pytest.raises(ValueError, match=expected):
        goals_to_yaml([Goal("ok", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)), goal])
    with pytest.raises(ValueError, match=r"^goal 2 "):
        goals_to_json([Goal("ok", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)), goal])


def test_export_normalises_a_slightly_off_quaternion():
    goal = Goal("a", (0.0, 0.0, 0.0), (0.0, 0.0, 0.7071, 0.7071))
    assert goal_problem(goal) is None
    (back,) = goals_from_yaml(goals_to_yaml([goal]))
    assert back.orientation_xyzw == pytest.approx((0.0, 0.0, S, S), abs=1e-12)
