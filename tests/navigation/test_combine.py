import math

import numpy as np
import pytest

from navigation import CombineInput, LayerResult, maximum, weighted_sum


def res(cost, lethal=None):
    cost = np.asarray(cost, np.float32)
    return LayerResult(cost, np.zeros(len(cost), bool) if lethal is None else np.asarray(lethal))


def test_weighted_sum_does_not_divide_by_the_weights():
    a = CombineInput("a", res([1.0, 2.0, 0.0]), weight=0.5)
    b = CombineInput("b", res([1.0, 1.0, 3.0], [False, True, False]), weight=1.0)
    result, report = weighted_sum([a, b])
    assert result.cost.tolist() == pytest.approx([1.5, 2.0, 3.0])
    assert result.lethal.tolist() == [False, True, False]
    assert report.total_nan == 0 and report.nan_counts == {"a": 0, "b": 0}


def test_max_is_at_least_zero_and_unites_lethal_sets():
    a = CombineInput("a", res([-1.0, 0.2, 0.5], [True, False, False]), weight=0.1)
    b = CombineInput("b", res([-2.0, 0.7, 0.1], [False, False, True]))
    result, _ = maximum([a, b])
    assert result.cost.tolist() == pytest.approx([0.0, 0.7, 0.5])  # weights do not apply
    assert result.lethal.tolist() == [True, False, True]


def test_nan_becomes_the_input_default_and_is_reported():
    a = CombineInput("height_diff", res([np.nan, 1.0, np.nan]), default=math.inf)
    b = CombineInput("inflation", res([0.5, np.nan, 0.0]), default=0.0)
    result, report = weighted_sum([a, b])
    assert result.cost.tolist() == [math.inf, 1.0, math.inf]
    assert report.nan_counts == {"height_diff": 2, "inflation": 1}
    assert report.total_nan == 3
    result, report = maximum([a, b])
    assert result.cost.tolist() == [math.inf, 1.0, math.inf]
    assert report.total_nan == 3
    assert not np.isnan(result.cost).any()


def test_zero_weight_input_is_left_out_so_inf_does_not_become_nan():
    a = CombineInput("labels", res([math.inf, 0.0]), weight=0.0)
    b = CombineInput("border", res([0.0, 1.0]))
    result, report = weighted_sum([a, b])
    assert result.cost.tolist() == [0.0, 1.0]
    assert report.skipped == ("labels",)


def test_inputs_must_agree():
    with pytest.raises(ValueError, match="at least one"):
        weighted_sum([])
    with pytest.raises(ValueError, match="length"):
        maximum([CombineInput("a", res([1.0])), CombineInput("b", res([1.0, 2.0]))])
