"""Goal poses as YAML or JSON that a ROS user can hand to ``geometry_msgs/PoseStamped`` as they are.

Shape (YAML shown; the JSON file holds the same mapping)::

    # meshmark goal poses ...              (comment lines, YAML only)
    format: meshmark-goals
    version: 1
    coordinates: world frame of the map file (its vertex coordinates plus /meshmark/origin, if any)
    origin: [500000.0, 5700000.0, 0.0]     # only when the map stores shifted vertices
    goals:
    - name: dock
      pose_stamped:                        # exactly a geometry_msgs/msg/PoseStamped
        header:
          frame_id: map
          stamp: {sec: 0, nanosec: 0}
        pose:
          position: {x: 1.5, y: -2.0, z: 0.25}
          orientation: {x: 0.0, y: 0.0, z: 0.7071067811865476, w: 0.7071067811865476}

Each ``pose_stamped`` feeds ``rosidl_runtime_py.set_message_fields(PoseStamped(), item)``, or
``ros2 topic pub /goal_pose geometry_msgs/msg/PoseStamped "<that mapping>"``, unchanged; the
name sits beside it because PoseStamped has no field for it.

Coordinates: positions are in the map file's world frame, i.e. the coordinates meshmark shows.
When a far-away (UTM) map stores its vertices relative to ``/meshmark/origin``, mesh_navigation
sees the stored coordinates: subtract ``origin`` (written when the caller passes it) first.

Floats are written with ``repr``, so export then import gives back identical goals. Reading is
strict about the pose and lenient elsewhere:

- the top level is the mapping above or just the ``goals`` list; unknown keys are ignored;
  ``format``/``version``, when present, must be ours (a newer version is refused);
- an item is ``{name, pose_stamped}`` or a bare PoseStamped with an optional ``name``; a missing
  name becomes ``goal <n>``, a missing header or ``frame_id`` becomes ``map``; stamps are ignored;
- position x, y, z and orientation x, y, z, w are required finite numbers (not text, not bools);
- the quaternion is kept bit for bit when its norm is 1 within ``1e-6``, normalised when within
  ``0.01`` (tf2's tolerance, for hand-written values like 0.7071), refused otherwise (so a zero
  quaternion is refused).

Every problem raises ``MapFormatError(source, problem)`` naming the goal and the field.
"""

from __future__ import annotations

import json
import math
import numbers
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import yaml

from storage.errors import MapFormatError
from storage.model import Goal

FORMAT = "meshmark-goals"
VERSION = 1
COORDINATES = "world frame of the map file (its vertex coordinates plus /meshmark/origin, if any)"
DEFAULT_FRAME_ID = "map"

#: Quaternions whose norm is within this of 1 are kept exactly (float32 storage stays inside).
UNIT_EXACT_TOL = 1e-6
#: Quaternions within this of unit norm are normalised; tf2 uses the same tolerance.
UNIT_NORMALISE_TOL = 0.01

_YAML_HEADER = """\
# meshmark goal poses. Each `pose_stamped` is a geometry_msgs/msg/PoseStamped, e.g.
#   rosidl_runtime_py.set_message_fields(PoseStamped(), goal["pose_stamped"])
# Positions are in the world frame of the map file (its vertex coordinates, plus
# /meshmark/origin when the file has one); header.frame_id names the ROS frame.
"""
_YAML_ORIGIN_NOTE = """\
# This map stores its vertices relative to `origin` (float32 precision): mesh_navigation
# sees (world - origin), so subtract `origin` from the positions before sending them.
"""


# --------------------------------------------------------------------------------- writing


def goal_problem(goal: Goal) -> str | None:
    """Return why ``goal`` cannot be saved or exported, or None when it is fine."""
    if not isinstance(goal.name, str):
        return f"the name must be text, got {goal.name!r}"
    if not isinstance(goal.frame_id, str):
        return f"the frame id must be text, got {goal.frame_id!r}"
    position, orientation = tuple(goal.position), tuple(goal.orientation_xyzw)
    if len(position) != 3 or len(orientation) != 4:
        return "a goal needs 3 position and 4 orientation values"
    if not all(_is_number(v) and math.isfinite(float(v)) for v in position):
        return f"the position is not 3 finite numbers: {list(position)}"
    if not all(_is_number(v) and math.isfinite(float(v)) for v in orientation):
        return f"the orientation is not 4 finite numbers: {list(orientation)}"
    return _quaternion_problem([float(v) for v in orientation])


def goals_to_dict(
    goals: Iterable[Goal], *, origin: Sequence[float] | None = None
) -> dict[str, Any]:
    """Build the exported mapping (see the module docstring), shared by YAML and JSON.

    Parameters
    ----------
    goals : goal poses in list order, world frame of the map file
    origin : float [3] or None
        The map's ``/meshmark/origin``; written (when not zero) so ROS users can shift back.

    Returns
    -------
    dict
        Plain Python values only. Quaternions within ``UNIT_EXACT_TOL`` of unit norm are
        written as they are (so an import gives back identical goals), others normalised.

    Raises
    ------
    ValueError
        When a goal is not finite or its quaternion is not a unit quaternion within 0.01.
    """
    doc: dict[str, Any] = {"format": FORMAT, "version": VERSION, "coordinates": COORDINATES}
    if origin is not None and any(float(v) != 0.0 for v in origin):
        doc["origin"] = [float(v) for v in origin]
    items = []
    for i, goal in enumerate(goals):
        problem = goal_problem(goal)
        if problem is not None:
            raise ValueError(f"goal {i + 1} ({goal.name!r}): {problem}")
        x, y, z = (float(v) for v in goal.position)
        qx, qy, qz, qw = _normalised(tuple(float(v) for v in goal.orientation_xyzw))
        items.append(
            {
                "name": goal.name,
                "pose_stamped": {
                    "header": {"frame_id": goal.frame_id, "stamp": {"sec": 0, "nanosec": 0}},
                    "pose": {
                        "position": {"x": x, "y": y, "z": z},
                        "orientation": {"x": qx, "y": qy, "z": qz, "w": qw},
                    },
                },
            }
        )
    doc["goals"] = items
    return doc


def goals_to_yaml(goals: Iterable[Goal], *, origin: Sequence[float] | None = None) -> str:
    """Export goals as YAML: a commented list of named ``geometry_msgs/PoseStamped``."""
    doc = goals_to_dict(goals, origin=origin)
    header = _YAML_HEADER + (_YAML_ORIGIN_NOTE if "origin" in doc else "")
    body = yaml.safe_dump(
        doc, sort_keys=False, default_flow_style=None, allow_unicode=True, width=100
    )
    return header + body


def goals_to_json(goals: Iterable[Goal], *, origin: Sequence[float] | None = None) -> str:
    """Export goals as JSON with the same structure as the YAML export."""
    doc = goals_to_dict(goals, origin=origin)
    return json.dumps(doc, indent=2, ensure_ascii=False, allow_nan=False) + "\n"


# --------------------------------------------------------------------------------- reading


def goals_from_yaml(text: str | bytes, source: str | Path = "<goals YAML>") -> list[Goal]:
    """Import goals from YAML written by ``goals_to_yaml`` or by hand (see the module docstring).

    Raises
    ------
    MapFormatError
        Naming ``source`` and the problem: not YAML, wrong shape, a missing or bad field.
    """
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise MapFormatError(source, f"not valid YAML: {_yaml_problem(exc)}") from exc
    except UnicodeDecodeError as exc:
        raise MapFormatError(source, f"not UTF-8 text ({exc.reason})") from exc
    return goals_from_dict(data, source)


def goals_from_json(text: str | bytes, source: str | Path = "<goals JSON>") -> list[Goal]:
    """Import goals from JSON with the structure of ``goals_to_json``.

    Raises
    ------
    MapFormatError
        Naming ``source`` and the problem: not JSON, wrong shape, a missing or bad field.
    """
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise MapFormatError(
            source, f"not valid JSON: {exc.msg} at line {exc.lineno}, column {exc.colno}"
        ) from exc
    except UnicodeDecodeError as exc:
        raise MapFormatError(source, f"not UTF-8 text ({exc.reason})") from exc
    return goals_from_dict(data, source)


def goals_from_dict(data: Any, source: str | Path = "<goals>") -> list[Goal]:
    """Turn an already parsed export (mapping or bare list) into goals, checking every field.

    Raises
    ------
    MapFormatError
        Naming ``source`` and the problem.
    """
    if data is None:
        raise MapFormatError(source, "the file is empty; expected a mapping with a 'goals' list")
    if isinstance(data, dict):
        fmt = data.get("format", FORMAT)
        if fmt != FORMAT:
            raise MapFormatError(source, f"format is {fmt!r}, expected {FORMAT!r}")
        version = data.get("version", VERSION)
        if not isinstance(version, int) or isinstance(version, bool) or version < 1:
            raise MapFormatError(source, f"version must be a positive integer, got {version!r}")
        if version > VERSION:
            raise MapFormatError(
                source,
                f"written by a newer meshmark (version {version}); this one reads version "
                f"{VERSION}",
            )
        if "goals" not in data:
            raise MapFormatError(source, "no 'goals' list at the top level")
        items = data["goals"]
        items = [] if items is None else items
    else:
        items = data
    if not isinstance(items, list):
        raise MapFormatError(
            source, f"'goals' must be a list of goals, got {_kind(items)} ({_short(items)})"
        )
    goals = []
    for i, item in enumerate(items):
        try:
            goals.append(_goal_from_item(item, i))
        except _FieldError as exc:
            raise MapFormatError(source, f"{_which(item, i)}: {exc}") from None
    return goals


class _FieldError(Exception):
    """A problem with one field of one goal; turned into a MapFormatError by the caller."""


def _goal_from_item(item: Any, index: int) -> Goal:
    """Read one goal item: ``{name, pose_stamped}`` or a bare PoseStamped with a name."""
    if not isinstance(item, dict):
        raise _FieldError(f"expected a mapping with 'name' and 'pose_stamped', got {_kind(item)}")
    if "pose_stamped" in item:
        msg, prefix = _mapping(item["pose_stamped"], "pose_stamped"), "pose_stamped."
    elif "pose" in item:
        msg, prefix = item, ""
    else:
        raise _FieldError("missing 'pose_stamped' (a geometry_msgs/PoseStamped mapping)")

    name = item.get("name", f"goal {index + 1}")
    if not isinstance(name, str):
        raise _FieldError(f"name must be text, got {_short(name)} (quote it in YAML)")

    frame_id = DEFAULT_FRAME_ID
    if msg.get("header") is not None:
        header = _mapping(msg["header"], prefix + "header")
        frame_id = header.get("frame_id", DEFAULT_FRAME_ID)
        if not isinstance(frame_id, str):
            raise _FieldError(f"{prefix}header.frame_id must be text, got {_short(frame_id)}")

    pose = _mapping(_required(msg, "pose", prefix), prefix + "pose")
    where = prefix + "pose."
    position = _mapping(_required(pose, "position", where), where + "position")
    orientation = _mapping(_required(pose, "orientation", where), where + "orientation")
    xyz = tuple(_number(position, key, where + "position") for key in "xyz")
    xyzw = tuple(_number(orientation, key, where + "orientation") for key in "xyzw")
    problem = _quaternion_problem(xyzw)
    if problem is not None:
        raise _FieldError(f"{where}orientation: {problem}")
    return Goal(name, (xyz[0], xyz[1], xyz[2]), _normalised(xyzw), frame_id)


def _required(mapping: dict[str, Any], key: str, where: str) -> Any:
    """Return ``mapping[key]`` or say which field is missing."""
    if key not in mapping:
        raise _FieldError(f"missing '{where}{key}'")
    return mapping[key]


def _mapping(value: Any, where: str) -> dict[str, Any]:
    """Return ``value`` if it is a mapping, else say which field should have been one."""
    if not isinstance(value, dict):
        raise _FieldError(f"'{where}' must be a mapping, got {_kind(value)} ({_short(value)})")
    return value


def _number(mapping: dict[str, Any], key: str, where: str) -> float:
    """Return ``mapping[key]`` as a finite float, or say what is wrong with it."""
    value = _required(mapping, key, where + ".")
    if not _is_number(value):
        raise _FieldError(f"'{where}.{key}' must be a number, got {_kind(value)} ({_short(value)})")
    try:
        result = float(value)
    except OverflowError:  # an integer too large for a float
        result = math.inf
    if not math.isfinite(result):
        raise _FieldError(f"'{where}.{key}' must be finite, got {result}")
    return result


def _is_number(value: Any) -> bool:
    """Tell real numbers (numpy's too) from bools (YAML ``yes``/``true``) and text."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _quaternion_problem(xyzw: Sequence[float]) -> str | None:
    """Return why ``xyzw`` is not (close to) a unit quaternion, or None."""
    norm = math.sqrt(sum(v * v for v in xyzw))
    if norm == 0.0:
        return "the quaternion is zero, which is no rotation at all (identity is x=y=z=0, w=1)"
    if abs(norm - 1.0) > UNIT_NORMALISE_TOL:
        return f"not a unit quaternion (norm {norm:.6g}, expected 1 within {UNIT_NORMALISE_TOL})"
    return None


def _normalised(xyzw: Sequence[float]) -> tuple[float, float, float, float]:
    """Return ``xyzw`` unchanged when unit within ``UNIT_EXACT_TOL``, else divided by its norm."""
    norm = math.sqrt(sum(v * v for v in xyzw))
    if abs(norm - 1.0) > UNIT_EXACT_TOL:
        xyzw = [v / norm for v in xyzw]
    return (xyzw[0], xyzw[1], xyzw[2], xyzw[3])


def _which(item: Any, index: int) -> str:
    """Name a goal in a message: its position in the list and, if readable, its name."""
    name = item.get("name") if isinstance(item, dict) else None
    return f"goal {index + 1} ({name!r})" if isinstance(name, str) else f"goal {index + 1}"


def _kind(value: Any) -> str:
    """Describe a parsed value's type in the words of the file, not of Python."""
    if value is None:
        return "nothing"
    if isinstance(value, bool):
        return "true/false"
    if isinstance(value, str):
        return "text"
    if isinstance(value, int | float):
        return "a number"
    if isinstance(value, list):
        return "a list"
    if isinstance(value, dict):
        return "a mapping"
    return type(value).__name__


def _short(value: Any, limit: int = 40) -> str:
    """Return ``repr(value)`` cut to ``limit`` characters for error messages."""
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _yaml_problem(exc: yaml.YAMLError) -> str:
    """Say what the YAML parser disliked and where (1-based line and column)."""
    problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
    mark = getattr(exc, "problem_mark", None)
    if mark is None:
        return problem
    return f"{problem} at line {mark.line + 1}, column {mark.column + 1}"
