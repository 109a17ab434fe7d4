"""The demo map shipped in static/: current layout, the tutorial's geometry and cost layers."""

from __future__ import annotations

import h5py
import numpy as np
import pytest

from static import demo_map_path
from storage import load_map


def test_demo_map_is_a_current_layout_map():
    path = demo_map_path()
    assert path.is_file() and path.name == "demo_floor_is_lava.h5"
    assert (path.parent / "LICENSE-floor_is_lava.txt").is_file()
    doc = load_map(path)
    assert doc.meta["layout"] == "current" and doc.warnings == []
    assert (doc.n_vertices, doc.n_faces) == (8100, 15960)
    assert set(doc.layers) == {"average_angles", "border", "freespace", "height_diff", "roughness"}
    assert np.isposinf(doc.layers["freespace"]).sum() == 4632
    with h5py.File(path, "r") as f:
        assert f["mesh"].attrs["IO"] == "MeshIO" and "channels" not in f["mesh"]


@pytest.mark.realdata
def test_demo_map_matches_the_tutorial_file(shared_data):
    demo = load_map(demo_map_path())
    source = load_map(shared_data / "terrain/floor_is_lava.h5")
    np.testing.assert_array_equal(demo.vertices, source.vertices)
    np.testing.assert_array_equal(demo.faces, source.faces)
    for name, values in source.layers.items():
        np.testing.assert_array_equal(demo.layers[name].view(np.uint32), values.view(np.uint32))


def _content(path):
    """Every dataset and attribute of a file: what the writer decides, not library bytes."""
    items = {}

    def visit(name, obj):
        attrs = {k: str(v) for k, v in obj.attrs.items()}
        if isinstance(obj, h5py.Dataset):
            items[name] = (obj.dtype.str, obj.shape, obj.compression, obj[()].tobytes(), attrs)
        else:
            items[name] = attrs

    with h5py.File(path, "r") as f:
        f.visititems(visit)
        items["/"] = {k: str(v) for k, v in f.attrs.items()}
    return items


@pytest.mark.realdata
def test_demo_map_is_what_save_map_writes_today(shared_data, tmp_path):
    """When this fails after a writer change, regenerate (see static/README.md):
    meshmark convert ../shared/data/terrain/floor_is_lava.h5 static/demo_floor_is_lava.h5
    """
    from storage import save_map

    fresh = tmp_path / "demo.h5"
    save_map(load_map(shared_data / "terrain/floor_is_lava.h5"), fresh)
    assert _content(fresh) == _content(demo_map_path())
