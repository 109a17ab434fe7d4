import math

import numpy as np
import pytest

from navigation import ClassCost, LabelCostMode, LayerConfigError, face_costs, label_costs
from tests.conftest import grid_mesh

CLASSES = {
    "keepout": ClassCost(LabelCostMode.LETHAL),
    "gravel": ClassCost(LabelCostMode.COST, 0.4),
    "lawn": ClassCost(LabelCostMode.FREE),
    "bog": ClassCost(LabelCostMode.COST, 1.5),
}


def test_vertices_take_the_largest_cost_of_their_faces():
    v, f = grid_mesh(2)  # faces 0..3 lower-left triangles, 4..7 upper-right
    labels = np.full(len(f), -1, np.int32)
    labels[0] = 7  # keepout
    labels[3] = 2  # gravel
    labels[5] = 3  # lawn
    instances = {7: "keepout", 2: "gravel", 3: "lawn"}
    result = label_costs(f, len(v), labels, instances, CLASSES)
    expect = np.zeros(len(v), np.float32)
    expect[f[3]] = 0.4
    expect[f[0]] = math.inf
    assert np.array_equal(result.cost, expect)
    assert np.array_equal(result.lethal, np.isinf(expect))
    assert result.cost.dtype == np.float32


def test_finite_costs_above_the_threshold_are_lethal_too():
    v, f = grid_mesh(1)
    labels = np.array([0, -1], np.int32)
    result = label_costs(f, len(v), labels, {0: "bog"}, CLASSES, threshold=1.0)
    assert result.cost.max() == pytest.approx(1.5)
    assert np.array_equal(result.lethal, result.cost > 1.0)


def test_unknown_instances_and_classes_without_setting_are_free():
    labels = np.array([0, 1, 5, -1], np.int32)
    got = face_costs(labels, {0: "gravel", 1: "unset"}, CLASSES)
    assert got.tolist() == pytest.approx([0.4, 0.0, 0.0, 0.0])


def test_class_cost_settings_read_and_write():
    assert ClassCost.from_value("lethal").cost == math.inf
    assert ClassCost.from_value(0.3) == ClassCost(LabelCostMode.COST, 0.3)
    assert ClassCost.from_value({"mode": "free"}).cost == 0.0
    c = ClassCost.from_value({"mode": "cost", "value": 2})
    assert ClassCost.from_value(c.to_dict()) == c
    assert ClassCost(LabelCostMode.LETHAL).to_dict() == {"mode": "lethal"}
    for bad in ("deadly", {"mode": "cost", "value": -1}, {"weight": 1}, True, None):
        with pytest.raises(LayerConfigError):
            ClassCost.from_value(bad)


def test_label_array_must_match_faces():
    v, f = grid_mesh(1)
    with pytest.raises(ValueError, match="face_labels"):
        label_costs(f, len(v), np.zeros(3, np.int32), {}, {})
