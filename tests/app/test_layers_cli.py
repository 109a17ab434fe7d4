"""``meshmark layers`` as a script runs it: a real subprocess on real map files."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

from app.layers_cli import default_out
from static import demo_map_path
from storage import load_map, save_map

MESHMARK = [sys.executable, "-m", "app.cli"]
DEFAULT_LAYERS = (
    "height_diff",
    "roughness",
    "steepness",
    "border",
    "static_combination",
    "static_inflation",
    "labels",
    "label_inflation",
    "final",
)


def run(*args: str | Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [*MESHMARK, "layers", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )


def boundary_vertices(faces: np.ndarray, n: int) -> np.ndarray:
    """Return a mask of the vertices on an edge that belongs to one face only."""
    edges = np.sort(faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    mask = np.zeros(n, dtype=bool)
    mask[unique[counts == 1].ravel()] = True
    return mask


@pytest.fixture
def demo(tmp_path: Path) -> Path:
    path = tmp_path / "demo.h5"
    shutil.copyfile(demo_map_path(), path)
    return path


def test_layers_are_computed_and_saved_in_place(demo):
    result = run(demo)
    assert result.returncode == 0, result.stderr
    assert "] 100% done" in result.stderr and "[###" in result.stderr  # the progress bar
    assert "NaN: none" in result.stdout
    assert f"wrote {demo}" in result.stdout

    doc = load_map(demo)
    for name in DEFAULT_LAYERS:
        assert name in doc.layers, name
        assert doc.layers[name].shape == (doc.n_vertices,)
        assert not np.isnan(doc.layers[name]).any(), name
    on_border = boundary_vertices(doc.faces, doc.n_vertices)
    assert on_border.any()
    border = doc.layers["border"]
    assert np.array_equal(border[on_border], np.ones(on_border.sum(), np.float32))
    assert not border[~on_border].any()
    assert doc.layers["height_diff"].min() >= 0
    steep = doc.layers["steepness"]
    assert steep.min() >= 0 and steep.max() <= np.pi / 2 + 1e-5
    inflation = doc.layers["static_inflation"]
    assert inflation.min() >= 0 and inflation.max() <= 1.0
    assert not doc.layers["labels"].any()  # no labels yet: all free
    assert doc.meta["settings"]["layers"]["layers"] == list(DEFAULT_LAYERS)


def test_a_lethal_class_is_inf_in_the_label_layer(demo, tmp_path):
    doc = load_map(demo)
    doc.add_class("keepout", (255, 0, 0))
    iid = doc.add_instance("keepout", "1")
    doc.add_class("gravel", (0, 200, 0))
    gravel = doc.add_instance("gravel", "1")
    keepout_faces = np.arange(0, 400)
    doc.label_faces(keepout_faces, iid)
    doc.label_faces(np.arange(5000, 5400), gravel)
    save_map(doc, demo)
    config = tmp_path / "layers.yaml"
    config.write_text(
        "layers: [labels, label_inflation]\n"
        "labels: {type: labels, threshold: 1.0, classes: {keepout: lethal, "
        "gravel: {mode: cost, value: 0.4}}}\n"
        "label_inflation: {type: inflation, inputs: [labels], inflation_radius: 0.4}\n"
    )
    out = tmp_path / "out.h5"
    yaml_out = tmp_path / "mesh_navigation.yaml"
    result = run(
        demo, "--config", config, "--out", out, "--label-layer", "keepout_cost",
        "--export-yaml", yaml_out,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr

    saved = load_map(out)
    cost = saved.layers["keepout_cost"]
    lethal = np.zeros(saved.n_vertices, dtype=bool)
    lethal[saved.faces[keepout_faces].ravel()] = True
    assert np.isposinf(cost[lethal]).all()
    assert not np.isinf(cost[~lethal]).any()
    gravel_vertices = np.zeros(saved.n_vertices, dtype=bool)
    gravel_vertices[saved.faces[5000:5400].ravel()] = True
    assert np.allclose(cost[gravel_vertices & ~lethal], 0.4)
    assert not cost[~lethal & ~gravel_vertices].any()
    inflated = saved.layers["label_inflation"]
    assert np.allclose(inflated[lethal], 1.0)  # lethal_value on the lethal vertices
    assert "labels" not in saved.layers  # the label layer was saved under the chosen name
    assert saved.meta["settings"]["class_costs"]["keepout"] == {"mode": "lethal"}
    assert saved.meta["settings"]["label_layer"] == "keepout_cost"

    text = yaml_out.read_text()
    assert "keepout_cost:" in text and "mesh_layers/SteepnessLayer" in text
    with h5py.File(out, "r") as f:
        assert f["mesh/vertex_attributes/keepout_cost"].shape == (saved.n_vertices, 1)


def test_without_config_the_settings_saved_with_the_map_are_used(demo, tmp_path):
    config = tmp_path / "layers.yaml"
    config.write_text("layers: [steepness]\nsteepness: {type: steepness, threshold: 0.5}\n")
    assert run(demo, "--config", config).returncode == 0
    again = run(demo)
    assert again.returncode == 0, again.stderr
    assert "settings saved with the map" in again.stderr
    assert "computed 1 layers" in again.stdout


def test_a_mesh_navigation_parameter_file_is_accepted(demo, tmp_path):
    config = tmp_path / "mbf.yaml"
    config.write_text(
        "move_base_flex:\n"
        "  ros__parameters:\n"
        "    mesh_map:\n"
        "      layers: [height_diff, border, combined]\n"
        "      height_diff: {type: 'mesh_layers/HeightDiffLayer', threshold: 0.3, radius: 0.3}\n"
        "      border: {type: 'mesh_layers/BorderLayer', threshold: 0.5, border_cost: 2.0}\n"
        "      combined:\n"
        "        type: 'mesh_layers/MaxCombinationLayer'\n"
        "        inputs: [height_diff, border]\n"
    )
    result = run(demo, "--config", config)
    assert result.returncode == 0, result.stderr
    doc = load_map(demo)
    on_border = boundary_vertices(doc.faces, doc.n_vertices)
    assert np.all(doc.layers["border"][on_border] == 2.0)
    assert np.all(doc.layers["combined"] >= doc.layers["border"])


@pytest.mark.parametrize(
    ("text", "problem"),
    [
        ("layers: [a]\na: {type: bogus}\n", "unknown type 'bogus'"),
        ("layers: [a\n", "not valid YAML"),
        ("hello: 1\n", "needs a 'layers' list"),
        ("layers: [h]\nh: {type: height_diff, radius: -1}\n", "radius must be > 0"),
    ],
)
def test_a_bad_config_fails_naming_the_file(demo, tmp_path, text, problem):
    config = tmp_path / "broken_layers.yaml"
    config.write_text(text)
    before = demo.read_bytes()
    result = run(demo, "--config", config)
    assert result.returncode == 2
    assert "broken_layers.yaml" in result.stderr
    assert problem in result.stderr
    assert "Traceback" not in result.stderr
    assert demo.read_bytes() == before  # nothing written


def test_a_bad_label_layer_name_is_refused(demo):
    result = run(demo, "--label-layer", "2fast")
    assert result.returncode == 2
    assert "label layer name" in result.stderr and "Traceback" not in result.stderr


def test_out_defaults_to_the_map_or_an_h5_beside_it():
    assert default_out(Path("maps/a.h5")) == Path("maps/a.h5")
    assert default_out(Path("maps/a.ply")) == Path("maps/a.h5")


@pytest.mark.realdata
def test_real_map_matches_its_2024_layers(shared_data, tmp_path):
    """floor_is_lava carries layers mesh_navigation made in 2024 (vertical height diff, r 0.3)."""
    source = shared_data / "terrain" / "floor_is_lava.h5"
    original = load_map(source)
    path = tmp_path / "floor_is_lava.h5"
    shutil.copyfile(source, path)
    config = tmp_path / "layers_2024.yaml"
    config.write_text(
        "layers: [height_diff, roughness, border]\n"
        "height_diff: {type: height_diff, radius: 0.3, mode: vertical}\n"
        "roughness: {type: roughness, radius: 0.3}\n"
        "border: {type: border}\n"
    )
    result = run(path, "--config", config)
    assert result.returncode == 0, result.stderr
    doc = load_map(path)
    assert doc.n_vertices == original.n_vertices
    for name in ("height_diff", "border"):
        err = float(np.max(np.abs(doc.layers[name] - original.layers[name])))
        assert err <= 5e-4, (name, err)
    # normals are recomputed here (the file's are not kept): acos near 1 magnifies rounding
    err = float(np.max(np.abs(doc.layers["roughness"] - original.layers["roughness"])))
    assert err <= 1e-3, err
    assert "NaN: none" in result.stdout
