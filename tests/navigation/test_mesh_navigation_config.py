import math

import pytest
import yaml

from navigation import (
    LayerConfig,
    LayerConfigError,
    LayerStack,
    export_mesh_navigation_config,
)


def stack():
    s = LayerStack()
    spec = s.config.spec("labels").with_params(classes={"keepout": "lethal", "gravel": 0.4})
    s.config = s.config.with_layer(spec)
    return s


def test_whole_graph_is_exported_in_mesh_navigation_terms():
    text = export_mesh_navigation_config(stack(), "labels")
    mesh_map = yaml.safe_load(text)["mesh_map"]
    assert mesh_map["layers"] == list(LayerConfig.default().names)
    assert mesh_map["default_layer"] == "final"
    assert mesh_map["labels"] == {
        "type": "mesh_layers/SteepnessLayer",
        "combination_weight": 1.0,
        "threshold": 1.0,
    }
    assert mesh_map["height_diff"]["type"] == "mesh_layers/HeightDiffLayer"
    assert mesh_map["height_diff"]["radius"] == 0.3
    assert mesh_map["static_combination"]["type"] == "mesh_layers/AvgCombinationLayer"
    assert mesh_map["final"] == {
        "type": "mesh_layers/MaxCombinationLayer",
        "inputs": ["static_inflation", "label_inflation", "labels"],
        "combination_weight": 1.0,
    }
    assert mesh_map["label_inflation"]["inputs"] == ["labels"]
    assert mesh_map["label_inflation"]["inscribed_value"] == 0.99
    assert "vertex_attributes/labels" in text


def test_every_number_is_a_yaml_float_for_ros2_doubles():
    s = stack()
    infl = s.config.spec("static_inflation").with_params(lethal_value=math.inf)
    s.config = s.config.with_layer(infl)
    s.config = s.config.with_layer(s.config.spec("border").with_params(border_cost=2))
    mesh_map = yaml.safe_load(export_mesh_navigation_config(s, "labels"))["mesh_map"]
    assert mesh_map["static_inflation"]["lethal_value"] == math.inf
    for name in mesh_map["layers"]:
        for key, value in mesh_map[name].items():
            if key not in ("type", "inputs", "repulsive_field"):
                assert isinstance(value, float), (name, key)


def test_the_exported_graph_reads_back_as_the_same_graph():
    s = stack()
    mesh_map = yaml.safe_load(export_mesh_navigation_config(s, "labels"))["mesh_map"]
    back = LayerConfig.from_dict(mesh_map)
    assert back.order == s.config.order
    assert back.spec("height_diff") == s.config.spec("height_diff")
    assert back.spec("static_inflation") == s.config.spec("static_inflation")


def test_label_layer_alone():
    text = export_mesh_navigation_config(stack(), "labels", whole_graph=False)
    mesh_map = yaml.safe_load(text)["mesh_map"]
    assert list(mesh_map) == ["labels"]
    assert "add 'labels' to mesh_map.layers" in text


def test_label_layer_must_be_a_label_layer_with_a_threshold_mesh_navigation_accepts():
    with pytest.raises(LayerConfigError, match="not a label layer"):
        export_mesh_navigation_config(stack(), "height_diff")
    s = stack()
    s.config = s.config.with_layer(s.config.spec("labels").with_params(threshold=5.0))
    with pytest.raises(LayerConfigError, match="threshold"):
        export_mesh_navigation_config(s, "labels")


def test_out_of_range_parameters_of_other_layers_are_flagged_in_comments():
    s = stack()
    s.config = s.config.with_layer(s.config.spec("height_diff").with_params(radius=1.5))
    text = export_mesh_navigation_config(s, "labels")
    assert "WARNING: mesh_navigation rejects radius outside [0.02, 1.0]" in text
