"""``meshmark goals MAP --format yaml|json`` as a script runs it: a real subprocess, real files."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from storage import (
    Goal,
    MapData,
    MapDocument,
    goals_from_json,
    goals_from_yaml,
    load_map,
    save_map,
)

MESHMARK = [sys.executable, "-m", "app.cli"]
PARSE = {"yaml": goals_from_yaml, "json": goals_from_json}

# Awkward values on purpose: repr round trips, a non-ASCII name, a second frame id, a yaw
# that is not a "nice" angle, and a pose on a wall (x axis vertical).
GOALS = [
    Goal("dock", (1.5, -2.0, 0.25), (0.0, 0.0, 0.0, 1.0)),
    Goal(
        "Ladestation ü #2",
        (0.1 + 0.2, 1e-7, -0.123456789012345),
        (0.0, 0.0, math.sin(0.6), math.cos(0.6)),
        "odom",
    ),
    Goal("wall", (2.0, 0.0, 0.5), (0.5, -0.5, 0.5, 0.5)),
]


def run(*args: str | Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [*MESHMARK, "goals", *map(str, args)],
        capture_output=True,
        text=True,
        encoding="utf-8",
        timeout=120,
        check=False,
    )


def floor(offset=(0.0, 0.0, 0.0)) -> MapData:
    v = np.array([[0, 0, 0], [4, 0, 0], [4, 3, 0], [0, 3, 0]], dtype=np.float64) + offset
    return MapData(v, np.array([[0, 1, 2], [0, 2, 3]]), meta={"source_name": "floor.h5"})


def saved_map(tmp_path: Path, goals, offset=(0.0, 0.0, 0.0), name="goals.h5") -> Path:
    doc = MapDocument(floor(offset))
    if goals:
        doc.set_goals(goals)
    path = tmp_path / name
    save_map(doc, path)
    return path


@pytest.mark.parametrize("fmt", ["yaml", "json"])
def test_prints_the_saved_goals(tmp_path, fmt):
    path = saved_map(tmp_path, GOALS)
    assert list(load_map(path).goals) == GOALS  # the file itself keeps them exactly
    result = run(path, "--format", fmt)
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""  # nothing but the goals on stdout, nothing on stderr
    assert PARSE[fmt](result.stdout, source=f"stdout.{fmt}") == GOALS
    data = (yaml.safe_load if fmt == "yaml" else json.loads)(result.stdout)
    assert data["format"] == "meshmark-goals"
    assert "origin" not in data  # the floor is near zero: no shifted vertices
    assert [g["name"] for g in data["goals"]] == [g.name for g in GOALS]
    ps = data["goals"][1]["pose_stamped"]
    assert ps["header"]["frame_id"] == "odom"
    assert set(ps["pose"]) == {"position", "orientation"}


def test_yaml_is_the_default_format(tmp_path):
    path = saved_map(tmp_path, GOALS)
    result = run(path)
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("#")  # the YAML export's comment header
    assert goals_from_yaml(result.stdout) == GOALS


def test_far_away_map_prints_world_positions_and_its_origin(tmp_path):
    offset = (512_345.0, 5_701_234.0, 87.0)  # UTM-like: stored relative to /meshmark/origin
    goals = [
        Goal("gate", (512_346.25, 5_701_235.5, 87.0), (0.0, 0.0, 0.0, 1.0)),
        Goal("shed", (512_348.125, 5_701_236.75, 87.0), (0.0, 0.0, 1.0, 0.0)),
    ]
    path = saved_map(tmp_path, goals, offset=offset, name="utm.h5")
    doc = load_map(path)
    assert doc.origin.any(), "the test map should store its vertices relative to an origin"
    for fmt in ("yaml", "json"):
        result = run(path, "--format", fmt)
        assert result.returncode == 0, result.stderr
        assert PARSE[fmt](result.stdout) == goals
        data = (yaml.safe_load if fmt == "yaml" else json.loads)(result.stdout)
        assert np.allclose(data["origin"], doc.origin)


@pytest.mark.parametrize("fmt", ["yaml", "json"])
def test_map_without_goals_prints_an_empty_list(tmp_path, fmt):
    path = saved_map(tmp_path, [])
    result = run(path, "--format", fmt)
    assert result.returncode == 0, result.stderr
    assert PARSE[fmt](result.stdout) == []
    data = (yaml.safe_load if fmt == "yaml" else json.loads)(result.stdout)
    assert data["goals"] == []


@pytest.mark.parametrize(
    ("name", "content"),
    [
        ("notes.h5", b"this is not a map\n"),
        ("half.h5", b"\x89HDF\r\n\x1a\n" + b"\0" * 64),
        ("empty.ply", b""),
    ],
)
@pytest.mark.parametrize("fmt", ["yaml", "json"])
def test_bad_file_fails_clearly(tmp_path, name, content, fmt):
    path = tmp_path / name
    path.write_bytes(content)
    result = run(path, "--format", fmt)
    assert result.returncode == 2, (result.stdout, result.stderr)
    assert name in result.stderr
    assert "Traceback" not in result.stderr
    assert result.stdout == ""


def test_missing_file_fails_clearly(tmp_path):
    path = tmp_path / "nowhere.h5"
    result = run(path)
    assert result.returncode == 2, result.stderr
    assert "nowhere.h5" in result.stderr
    assert "Traceback" not in result.stderr


def test_unknown_format_is_a_usage_error(tmp_path):
    path = saved_map(tmp_path, GOALS)
    result = run(path, "--format", "xml")
    assert result.returncode == 2
    assert "--format" in result.stderr
    assert "Traceback" not in result.stderr
