import dataclasses
import itertools
import json
import math

import numpy as np
import pytest
import yaml

from navigation import (
    ClassCost,
    HeightDiffMode,
    InflationMethod,
    LayerConfig,
    LayerConfigError,
    LayerMesh,
    LayerSpec,
    LayerStack,
    LayerType,
    NavigationError,
    height_diff,
    inflation,
)
from tests.conftest import grid_mesh

CLASSES = {"keepout": "lethal", "gravel": {"mode": "cost", "value": 0.4}, "lawn": "free"}

# the mesh_map section of the mesh_navigation tutorial (HEAD d38038e), without the obstacle
# layers meshmark does not model
TUTORIAL = """
mesh_map:
  mesh_part: '/'
  layers: [border, height_diff, roughness, static_combination, static_inflation]
  default_layer: 'static_inflation'
  height_diff: {type: 'mesh_layers/HeightDiffLayer', combination_weight: 1.0, threshold: 0.2}
  border: {type: 'mesh_layers/BorderLayer', combination_weight: 1.0, border_cost: 1.0,
           threshold: 0.2}
  roughness: {type: 'mesh_layers/RoughnessLayer', combination_weight: 1.0, threshold: 0.8}
  static_combination:
    type: 'mesh_layers/AvgCombinationLayer'
    inputs: ['height_diff', 'border', 'roughness']
  static_inflation:
    type: 'mesh_layers/InflationLayer'
    inputs: ['static_combination']
    combination_weight: 1.0
    inflation_radius: 1.5
    inscribed_radius: 0.4
    lethal_value: .inf
    inscribed_value: 1.0
    repulsive_field: false
    cost_scaling_factor: 2.0
"""


def terrain(n=24, seed=0):
    rng = np.random.default_rng(seed)
    v, f = grid_mesh(n, 2.4, z=lambda x, y: 0.3 * np.sin(2 * x) + np.where(x > 1.6, 0.3, 0.0))
    v[:, 2] += rng.normal(0, 0.01, len(v))
    labels = np.full(len(f), -1, np.int32)
    labels[100:160] = 0
    labels[400:430] = 1
    labels[600:700] = 2
    return v, f, labels, {0: "keepout", 1: "gravel", 2: "lawn"}


def stack_with_classes():
    stack = LayerStack()
    spec = stack.config.spec("labels").with_params(classes=CLASSES)
    stack.config = stack.config.with_layer(spec)
    return stack


def test_default_config_round_trips_through_dict_json_and_yaml():
    config = stack_with_classes().config
    d = config.to_dict()
    assert LayerConfig.from_dict(d) == config
    assert LayerConfig.from_dict(json.loads(json.dumps(d))) == config
    assert LayerConfig.from_dict(yaml.safe_load(yaml.safe_dump(d))) == config
    assert d["layers"][0] == "height_diff" and d["default_layer"] == "final"
    assert d["height_diff"] == {
        "type": "height_diff",
        "threshold": 0.185,
        "radius": 0.3,
        "mode": "normal",
        "combination_weight": 1.0,
    }
    assert d["labels"]["classes"]["gravel"] == {"mode": "cost", "value": 0.4}


def test_mesh_navigation_tutorial_config_is_read():
    config = LayerConfig.from_dict(yaml.safe_load(TUTORIAL))
    assert config.spec("static_combination").type is LayerType.SUM
    infl = config.spec("static_inflation")
    assert infl.type is LayerType.INFLATION and infl.params.lethal_value == math.inf
    assert infl.params.inflation_radius == 1.5 and infl.inputs == ("static_combination",)
    assert config.spec("height_diff").params.radius == 0.3  # the default
    assert config.order.index("static_combination") > config.order.index("roughness")


def test_order_puts_inputs_first():
    config = LayerConfig(
        (
            LayerSpec("final", LayerType.MAX, inputs=("infl", "b")),
            LayerSpec("infl", LayerType.INFLATION, inputs=("b",)),
            LayerSpec("b", LayerType.BORDER),
        )
    )
    assert config.order == ("b", "infl", "final")
    assert config.downstream(["infl"]) == {"infl", "final"}


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"x": {"type": "border"}}, "listed but has no settings"),
        ({"b": {"type": "obstacle"}}, "unknown type"),
        ({"b": {"type": "border", "radius": 0.3}}, "no parameter 'radius'"),
        ({"b": {"type": "border", "threshold": "high"}}, "must be a number"),
        ({"b": {"type": "border", "combination_weight": 2.0}}, r"\[0, 1\]"),
        ({"b": {"type": "border", "inputs": ["s"]}}, "takes no inputs"),
        ({"s": {"type": "sum", "inputs": ["nope"]}}, "unknown input"),
        ({"s": {"type": "sum", "inputs": ["s"]}}, "cycle"),
        ({"s": {"type": "inflation", "inputs": ["b", "b"]}}, "exactly one input"),
        ({"default_layer": "nope"}, "default_layer"),
        ({"b": {"type": "height_diff", "mode": "sideways"}}, "normal, vertical"),
        ({"b": {"type": "inflation", "inputs": ["s"], "inscribed_radius": 1.0}}, "inscribed"),
    ],
)
def test_bad_configs_are_rejected_with_a_reason(change, message):
    d = {"layers": ["b", "s"], "b": {"type": "border"}, "s": {"type": "sum", "inputs": ["b"]}}
    d.update(change)
    if "x" in change:
        d["layers"].append("y")
    with pytest.raises(LayerConfigError, match=message):
        LayerConfig.from_dict(d)


def test_layer_names_must_be_dataset_and_parameter_names():
    with pytest.raises(LayerConfigError, match="letter"):
        LayerSpec("bad name", LayerType.BORDER)
    with pytest.raises(LayerConfigError, match="inscribed_radius"):
        LayerSpec("i", LayerType.INFLATION, inputs=("b",)).with_params(inscribed_radius=1.0)


def test_compute_all_returns_every_layer_with_report_and_progress():
    v, f, labels, instances = terrain()
    calls = []
    result = stack_with_classes().compute_all(
        v,
        f,
        face_labels=labels,
        instance_classes=instances,
        progress=lambda frac, msg: calls.append((frac, msg)),
    )
    names = LayerConfig.default().order
    assert tuple(result.layers) == names == result.computed
    assert result.default_layer == "final"
    for name in names:
        assert result.costs[name].dtype == np.float32 and result.costs[name].shape == (len(v),)
        assert result.lethal[name].dtype == bool
    assert calls[0][0] == 0.0 and calls[-1] == (1.0, "done")
    assert all(a[0] <= b[0] for a, b in itertools.pairwise(calls))
    report = result.report
    assert set(report.seconds) == {"topology", *names}
    assert report.nan_counts == dict.fromkeys(names, 0)
    assert report.replaced_nan == {
        "static_combination": dict.fromkeys(("height_diff", "roughness", "steepness", "border"), 0),
        "final": {"static_inflation": 0, "label_inflation": 0, "labels": 0},
    }
    # keepout faces are lethal and +inf in the final layer; gravel counts with its cost
    keepout = np.unique(f[labels == 0])
    assert np.all(result.costs["labels"][keepout] == math.inf)
    assert np.all(result.costs["final"][keepout] == math.inf)
    assert result.lethal["final"][keepout].all()
    gravel = np.setdiff1d(np.unique(f[labels == 1]), np.unique(f[np.isin(labels, [0])]))
    assert np.all(result.costs["final"][gravel] >= 0.4)
    # the pieces are the plain functions
    mesh = LayerMesh(v, f)
    assert np.array_equal(result.costs["height_diff"], height_diff(mesh).cost)
    lethal = result.lethal["static_combination"]
    assert np.array_equal(result.costs["static_inflation"], inflation(mesh, lethal).cost)
    expect = np.zeros(len(v), np.float32)
    for name in ("height_diff", "roughness", "steepness", "border"):
        expect += result.costs[name]
    assert np.allclose(result.costs["static_combination"], expect)
    assert report.lethal_counts["static_combination"] == int(
        np.count_nonzero(
            result.lethal["height_diff"]
            | result.lethal["roughness"]
            | result.lethal["steepness"]
            | result.lethal["border"]
        )
    )


def test_update_labels_recomputes_only_the_label_branch_and_equals_a_full_run():
    v, f, labels, instances = terrain()
    stack = stack_with_classes()
    first = stack.compute_all(v, f, face_labels=labels, instance_classes=instances)
    edited = labels.copy()
    edited[800:900] = 0  # paint keepout
    edited[100:130] = -1  # erase part of it
    update = stack.update_labels(edited)
    assert update.computed == ("labels", "label_inflation", "final")
    assert set(update.report.seconds) == set(update.computed)
    for name in ("height_diff", "static_inflation"):
        assert update.layers[name] is first.layers[name]  # reused, not recomputed
    fresh = stack_with_classes().compute_all(v, f, face_labels=edited, instance_classes=instances)
    for name in fresh.layers:
        assert np.array_equal(update.costs[name], fresh.costs[name]), name
        assert np.array_equal(update.lethal[name], fresh.lethal[name]), name
    assert not np.array_equal(update.costs["final"], first.costs["final"])


def test_update_labels_can_change_class_settings():
    v, f, labels, instances = terrain()
    stack = stack_with_classes()
    stack.compute_all(v, f, face_labels=labels, instance_classes=instances)
    result = stack.update_labels(labels, class_costs={"keepout": 0.2, "gravel": "lethal"})
    assert stack.config.spec("labels").params.classes["keepout"] == ClassCost.from_value(0.2)
    keepout = np.unique(f[labels == 0])
    gravel = np.unique(f[labels == 1])
    assert np.all(result.costs["labels"][gravel] == math.inf)
    assert result.costs["labels"][np.setdiff1d(keepout, gravel)].max() == pytest.approx(0.2)


def test_update_layer_recomputes_it_and_its_dependents():
    v, f, labels, instances = terrain()
    stack = stack_with_classes()
    stack.compute_all(v, f, face_labels=labels, instance_classes=instances)
    spec = stack.config.spec("height_diff").with_params(mode="vertical", radius=0.2)
    result = stack.update_layer(spec)
    assert result.computed == ("height_diff", "static_combination", "static_inflation", "final")
    assert stack.config.spec("height_diff").params.mode is HeightDiffMode.VERTICAL
    mesh = LayerMesh(v, f)
    expect = height_diff(mesh, radius=0.2, mode="vertical").cost
    assert np.array_equal(result.costs["height_diff"], expect)
    infl = stack.config.spec("label_inflation").with_params(method="dijkstra")
    assert stack.update_layer(infl).computed == ("label_inflation", "final")
    assert stack.config.spec("label_inflation").params.method is InflationMethod.DIJKSTRA


def test_nan_in_inputs_is_reported_and_replaced_by_the_default():
    v, f, labels, instances = terrain()
    normals = LayerMesh(v, f).normals.copy()
    normals[[5, 50]] = np.nan
    result = stack_with_classes().compute_all(
        v, f, vertex_normals=normals, face_labels=labels, instance_classes=instances
    )
    report = result.report
    assert report.nan_counts["steepness"] == 2
    assert report.replaced_nan["static_combination"]["steepness"] == 2
    assert np.all(result.costs["static_combination"][[5, 50]] == math.inf)
    assert not np.isnan(result.costs["final"]).any()
    assert any("steepness" in w and "NaN" in w for w in report.warnings)


def test_stored_layers_are_used_as_given():
    v, f, _, _ = terrain(6)
    config = LayerConfig(
        (
            LayerSpec("from_file", LayerType.STORED, LayerSpec("x", LayerType.STORED).params),
            LayerSpec("b", LayerType.BORDER),
            LayerSpec("s", LayerType.SUM, inputs=("from_file", "b")),
        )
    )
    config = config.with_layer(config.spec("from_file").with_params(threshold=0.5))
    data = np.linspace(0, 1, len(v))
    result = LayerStack(config).compute_all(v, f, stored={"from_file": data})
    assert np.allclose(result.costs["from_file"], data)
    assert np.array_equal(result.lethal["from_file"], data.astype(np.float32) > 0.5)
    with pytest.raises(NavigationError, match="no data"):
        LayerStack(config).compute_all(v, f)


def test_updates_need_a_computed_stack():
    with pytest.raises(NavigationError, match="compute_all"):
        LayerStack().update_labels(np.zeros(2, np.int32))
    assert LayerStack().result is None


def test_result_property_gives_the_current_layers():
    v, f, labels, instances = terrain(6)
    stack = stack_with_classes()
    stack.compute_all(v, f, face_labels=labels[: len(f)], instance_classes=instances)
    assert tuple(stack.result.layers) == stack.config.order
    assert stack.result.computed == stack.config.order


def test_specs_are_frozen_and_params_checked():
    spec = LayerSpec("h", LayerType.HEIGHT_DIFF)
    with pytest.raises(dataclasses.FrozenInstanceError):
        spec.name = "x"
    with pytest.raises(LayerConfigError, match="radius"):
        spec.with_params(radius=0)
    with pytest.raises(LayerConfigError, match="no parameter"):
        spec.with_params(border_cost=1.0)
