"""``inspect_map``: what ``meshmark info`` prints."""

from __future__ import annotations

import json

import pytest

from storage import inspect_map, save_map
from tests.storage.conftest import full_map


def test_inspect_a_labelled_map(tmp_path, labelled_map):
    path = tmp_path / "m.h5"
    save_map(labelled_map, path)
    info = inspect_map(path)
    assert (info.format, info.layout) == ("hdf5", "current")
    assert (info.vertices, info.faces) == (labelled_map.n_vertices, labelled_map.n_faces)
    rough = {s.name: s for s in info.layers}["roughness"]
    assert (rough.nan, rough.pos_inf, rough.neg_inf) == (2, 1, 1)
    classes = {c.name: c for c in info.classes}
    assert classes["stairs"].faces == 17 and classes["stairs"].color == (200, 10, 10)
    assert classes["grass"].instances == {"1": 5, "north": 3, "unused": 0}
    assert classes["empty"].instances == {}
    assert info.labelled_faces == 25 and info.goals == 2
    assert info.texture.startswith("image/png") and info.vertex_colors
    assert info.origin is None and info.warnings == []
    json.dumps(info.to_dict())
    text = info.to_text()
    for words in ("layout current", "roughness", "2 NaN", "1 +inf", "1 -inf", "stairs", "north: 3"):
        assert words in text, text


def test_inspect_shows_the_origin(tmp_path):
    path = tmp_path / "utm.h5"
    save_map(full_map(offset=(500_000.0, 5_700_000.0, 0.0)), path)
    info = inspect_map(path)
    assert info.origin == (500_000.0, 5_700_000.0, 0.0)
    assert "origin" in info.to_text()


@pytest.mark.realdata
def test_inspect_a_2024_map(shared_data):
    info = inspect_map(shared_data / "terrain/floor_is_lava.h5")
    text = info.to_text()
    assert info.layout == "flat" and "lvr2 >= 25.1" in text
    assert "freespace" in text and "4,632 +inf" in text
    assert any("edge_distances" in item for item in info.ignored)
