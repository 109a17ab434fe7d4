"""The Cost layers panel without a browser: a real app and server, the demo map, real jobs."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest

from app.cost_layers import LayerSettingsError
from static import demo_map_path
from storage import MapDocument, load_map

TIMEOUT_S = 60.0


def wait_for(pred: Callable[[], Any], timeout: float = TIMEOUT_S, msg: str = "") -> Any:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = pred()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError(f"timed out after {timeout:.0f}s: {msg}")


@pytest.fixture
def start(tmp_path) -> Iterator[Callable[..., Any]]:
    import viser

    from app.server import MeshmarkApp

    started: list[tuple[Any, Any]] = []

    def start_(doc: MapDocument | None = None) -> Any:
        server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
        app = MeshmarkApp(server, doc or load_map(demo_map_path()), data_dir=tmp_path)
        started.append((app, server))
        return app

    yield start_
    for app, server in started:
        app.close()
        server.stop()


def labelled_demo() -> tuple[MapDocument, int]:
    doc = load_map(demo_map_path())
    with doc.gesture():
        doc.add_class("keepout", (255, 0, 0))
        iid = doc.add_instance("keepout", "1")
    return doc, iid


def vertices_of(doc: MapDocument, face_ids: np.ndarray) -> np.ndarray:
    mask = np.zeros(doc.n_vertices, dtype=bool)
    mask[doc.faces[face_ids].ravel()] = True
    return mask


def test_compute_adds_the_layers_as_one_undo_step(start):
    app = start()
    doc = app.doc
    before = {k: np.array(v) for k, v in doc.layers.items()}
    panel = app.layers_panel
    result = panel.compute().result(TIMEOUT_S)
    assert result is not None
    for name in panel.settings.config.names:
        assert doc.layers[name].shape == (doc.n_vertices,)
    assert "steepness" in app.display_panel.layer.options
    assert "NaN: none" in panel.status.content
    assert doc.meta["settings"]["layers"]["layers"] == list(panel.settings.config.names)

    assert doc.undo()
    assert "steepness" not in doc.layers and "final" not in doc.layers
    assert sorted(doc.layers) == sorted(before)
    for name, values in before.items():
        assert np.array_equal(doc.layers[name], values)
    wait_for(
        lambda: "steepness" not in app.display_panel.layer.options,
        msg="the dropdown still offers a layer the undo removed",
    )


def test_label_edits_and_class_costs_update_the_label_layer(start):
    doc, iid = labelled_demo()
    app = start(doc)
    panel = app.layers_panel
    panel.set_class_cost("keepout", "lethal")
    panel.compute().result(TIMEOUT_S)
    assert not doc.layers["labels"].any()

    faces = np.arange(300, 600)
    doc.label_faces(faces, iid)
    lethal = vertices_of(doc, faces)
    wait_for(
        lambda: np.isposinf(doc.layers["labels"][lethal]).all(),
        timeout=10,
        msg="the label layer did not follow the label edit",
    )
    assert not np.isinf(doc.layers["labels"][~lethal]).any()
    assert np.isposinf(doc.layers["final"][lethal]).all()
    assert np.allclose(doc.layers["label_inflation"][lethal], 1.0)
    # derived data: the edit is one undo step, the label layer is not a step of its own
    assert doc.undo()
    wait_for(
        lambda: not doc.layers["labels"].any(),
        timeout=10,
        msg="undoing the label edit did not clear the label layer",
    )
    assert doc.redo()
    wait_for(lambda: np.isposinf(doc.layers["labels"][lethal]).all(), timeout=10)

    panel.set_class_cost("keepout", 0.4)
    wait_for(
        lambda: np.allclose(doc.layers["labels"][lethal], 0.4),
        timeout=10,
        msg="the class cost change did not reach the label layer",
    )
    assert doc.meta["settings"]["class_costs"]["keepout"] == {"mode": "cost", "value": 0.4}


def test_a_renamed_class_keeps_its_cost(start):
    doc, _ = labelled_demo()
    app = start(doc)
    panel = app.layers_panel
    panel.set_class_cost("keepout", "lethal")
    doc.rename_class("keepout", "nogo")
    wait_for(lambda: "nogo" in panel.settings.class_costs, timeout=10)
    assert panel.settings.class_costs["nogo"].mode.value == "lethal"
    assert app.doc.meta["settings"]["class_costs"]["nogo"] == {"mode": "lethal"}


def test_parameters_are_checked_and_saved_with_the_map(start, tmp_path):
    from storage import save_map

    app = start()
    panel = app.layers_panel
    panel.set_param("height_diff", "mode", "vertical")
    panel.set_param("static_inflation", "inflation_radius", 0.6)
    with pytest.raises(LayerSettingsError, match="radius"):
        panel.set_param("roughness", "radius", -1.0)
    with pytest.raises(LayerSettingsError, match="inscribed_radius"):
        panel.set_param("static_inflation", "inscribed_radius", 2.0)
    panel.label_name.value = "keepout_cost"  # as if typed: runs the callback
    assert panel.settings.label_layer == "keepout_cost"
    assert "keepout_cost:" in panel.export_text()
    panel.label_name.value = "no good"
    assert "letters" in panel.name_note.content
    assert panel.settings.label_layer == "keepout_cost"

    path = tmp_path / "with_settings.h5"
    save_map(app.doc, path)
    reopened = load_map(path)
    app.install(reopened)
    settings = panel.settings
    assert settings.label_layer == "keepout_cost"
    assert panel.label_name.value == "keepout_cost"
    assert settings.config.spec("height_diff").params.mode.value == "vertical"
    assert settings.config.spec("static_inflation").params.inflation_radius == 0.6
    assert settings.config.spec("roughness").params.radius == 0.3


def test_a_bad_parameter_typed_in_the_panel_is_put_back(start):
    app = start()
    panel = app.layers_panel
    radius = panel.param_widget("height_diff", "radius")
    radius.value = -2.0  # the guarded callback refuses it and shows the value in force
    assert radius.value == 0.3
    assert panel.settings.config.spec("height_diff").params.radius == 0.3
