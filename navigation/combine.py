"""Combination layers: mesh_navigation's weighted sum and maximum, with NaN made explicit."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from navigation.layer_result import LayerResult


@dataclass(frozen=True, eq=False)
class CombineInput:
    """Carry one input of a combination: its result, weight and the value that replaces NaN.

    ``default`` is mesh_navigation's ``defaultValue()`` of the input's type (+inf for the
    geometric and label layers, 0 for inflation and combinations): the value it uses for a
    vertex the input has no cost for. meshmark uses it for NaN, too.
    """

    name: str
    result: LayerResult
    weight: float = 1.0
    default: float = math.inf


@dataclass(frozen=True)
class CombineReport:
    """Say what a combination had to repair: NaN vertices per input, replaced by its default."""

    nan_counts: dict[str, int]
    skipped: tuple[str, ...] = ()  #: inputs left out of a sum because their weight is 0

    @property
    def total_nan(self) -> int:
        """Return the number of NaN values replaced over all inputs."""
        return sum(self.nan_counts.values())


def _clean(inp: CombineInput) -> tuple[npt.NDArray[np.float32], int]:
    cost = inp.result.cost
    nan = np.isnan(cost)
    n_nan = int(np.count_nonzero(nan))
    if n_nan:
        cost = np.where(nan, np.float32(inp.default), cost)
    return cost, n_nan


def _lethal_union(inputs: Sequence[CombineInput], n: int) -> npt.NDArray[np.bool_]:
    lethal = np.zeros(n, dtype=bool)
    for inp in inputs:
        lethal |= inp.result.lethal
    return lethal


def _size(inputs: Sequence[CombineInput]) -> int:
    if not inputs:
        raise ValueError("a combination needs at least one input")
    sizes = {len(inp.result.cost) for inp in inputs}
    if len(sizes) != 1:
        raise ValueError(f"combination inputs differ in length: {sorted(sizes)}")
    return sizes.pop()


def weighted_sum(inputs: Sequence[CombineInput]) -> tuple[LayerResult, CombineReport]:
    """Return mesh_navigation's AvgCombinationLayer: ``sum_i w_i * c_i`` (no division by sum w).

    NaN in an input becomes that input's ``default`` and is counted in the report. An input of
    weight 0 is left out entirely (so its +inf cannot turn into 0 * inf = NaN). Lethal sets are
    united; costs of lethal vertices are not overridden.

    Returns
    -------
    (LayerResult with float32 [N] costs, CombineReport)
    """
    n = _size(inputs)
    total = np.zeros(n, dtype=np.float32)
    nan_counts: dict[str, int] = {}
    skipped = []
    for inp in inputs:
        cost, nan_counts[inp.name] = _clean(inp)
        if inp.weight == 0:
            skipped.append(inp.name)
            continue
        total += np.float32(inp.weight) * cost
    return LayerResult(total, _lethal_union(inputs, n)), CombineReport(nan_counts, tuple(skipped))


def maximum(inputs: Sequence[CombineInput]) -> tuple[LayerResult, CombineReport]:
    """Return mesh_navigation's MaxCombinationLayer: ``max(0, max_i c_i)``; lethal sets united.

    Weights do not apply. NaN in an input becomes that input's ``default`` and is counted.

    Returns
    -------
    (LayerResult with float32 [N] costs, CombineReport)
    """
    n = _size(inputs)
    total = np.zeros(n, dtype=np.float32)
    nan_counts: dict[str, int] = {}
    for inp in inputs:
        cost, nan_counts[inp.name] = _clean(inp)
        np.maximum(total, cost, out=total)
    return LayerResult(total, _lethal_union(inputs, n)), CombineReport(nan_counts)
