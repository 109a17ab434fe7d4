"""What a cost layer answers: per-vertex costs and the vertices it marks lethal."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt


@dataclass(frozen=True, eq=False)
class LayerResult:
    """Carry one layer's per-vertex costs together with its lethal mask.

    Attributes
    ----------
    cost : float32 [N]; +inf = lethal by construction (labels), NaN = unknown
    lethal : bool [N]; for thresholded layers ``cost > threshold`` (strict, NaN never lethal)
    """

    cost: npt.NDArray[np.float32]
    lethal: npt.NDArray[np.bool_]


def threshold_result(cost: npt.NDArray[np.floating], threshold: float) -> LayerResult:
    """Return ``cost`` as float32 with mesh_navigation's lethal rule ``cost > threshold``."""
    cost = np.ascontiguousarray(cost, dtype=np.float32)
    return LayerResult(cost, cost > np.float32(threshold))
