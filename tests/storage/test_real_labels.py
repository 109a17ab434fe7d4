"""A labelled real map saved by meshmark reloads with the same labels (issue 4, done-when)."""

from __future__ import annotations

import h5py
import numpy as np
import pytest

from geometry import face_adjacency
from selection import flood_faces
from storage import load_map, save_map

pytestmark = pytest.mark.realdata


@pytest.mark.parametrize(
    "name", ["terrain/floor_is_lava.h5", "terrain/botanical_garden.h5", "tray.h5"]
)
def test_labelled_real_map_round_trips(shared_data, tmp_path, name):
    doc = load_map(shared_data / name)
    rng = np.random.default_rng(7)
    adjacency = face_adjacency(doc.faces)
    with doc.gesture():
        doc.add_class("keepout", (200, 0, 0))
        doc.add_class("grass", (0, 180, 0))
        a = doc.add_instance("keepout", "1")
        b = doc.add_instance("grass", "1")
        c = doc.add_instance("grass", "2")
        for iid in (a, b, c):
            seed = int(rng.integers(doc.n_faces))
            region = flood_faces(adjacency, seed)[:500]
            doc.label_faces(region, iid)
    out = tmp_path / "labelled.h5"
    save_map(doc, out)
    again = load_map(out)
    names = {i: inst.full_name for i, inst in doc.instances.items()}
    names_again = {i: inst.full_name for i, inst in again.instances.items()}
    as_names = lambda labels, table: np.array([table.get(int(i), "") for i in labels])  # noqa: E731
    assert (as_names(doc.face_labels, names) == as_names(again.face_labels, names_again)).all()
    assert again.classes["keepout"].color == (200, 0, 0)
    np.testing.assert_array_equal(again.faces, doc.faces)
    for layer, values in doc.layers.items():
        np.testing.assert_array_equal(again.layers[layer], values)
    # what the RViz map display reads: /mesh/labels/<class>/<instance> = uint32 [n, 1] face ids
    with h5py.File(out, "r") as f:
        stored = f["mesh/labels/grass/2"][()]
        assert stored.dtype == np.uint32
        assert stored.shape[1] == 1
        assert set(stored.ravel()) == set(np.flatnonzero(doc.face_labels == c))
