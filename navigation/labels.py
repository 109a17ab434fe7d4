"""Label costs: turn the annotated classes into a per-vertex cost layer a robot can read."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from enum import StrEnum
from typing import Any

import numpy as np
import numpy.typing as npt

from navigation import _kernels
from navigation.errors import LayerConfigError
from navigation.layer_result import LayerResult, threshold_result

#: The stored cost of a lethal class. mesh_navigation marks it lethal for any threshold,
#: turns its edges into infinite weights, and seeds inflation from it.
LETHAL_COST = math.inf
THRESHOLD = 1.0


class LabelCostMode(StrEnum):
    """What a label class means for the robot."""

    FREE = "free"  #: no cost (0)
    COST = "cost"  #: a fixed cost ``value``
    LETHAL = "lethal"  #: never drive here (+inf)


@dataclass(frozen=True)
class ClassCost:
    """Say how one label class counts in planning: free, a fixed cost, or lethal."""

    mode: LabelCostMode = LabelCostMode.FREE
    value: float = 0.0  #: the cost for ``COST`` (ignored otherwise), >= 0 and finite

    def __post_init__(self) -> None:
        object.__setattr__(self, "mode", LabelCostMode(self.mode))
        if self.mode is LabelCostMode.COST and not (math.isfinite(self.value) and self.value >= 0):
            raise LayerConfigError(f"a class cost must be finite and >= 0, got {self.value}")

    @property
    def cost(self) -> float:
        """Return the per-vertex cost this setting stands for."""
        if self.mode is LabelCostMode.LETHAL:
            return LETHAL_COST
        return float(self.value) if self.mode is LabelCostMode.COST else 0.0

    def to_dict(self) -> dict[str, Any]:
        """Return ``{"mode": ..., "value": ...}`` (value only for ``cost``)."""
        if self.mode is LabelCostMode.COST:
            return {"mode": self.mode.value, "value": float(self.value)}
        return {"mode": self.mode.value}

    @classmethod
    def from_value(cls, value: Any) -> ClassCost:
        """Read ``"lethal"``, ``"free"``, a number (a cost) or ``{"mode": .., "value": ..}``."""
        if isinstance(value, ClassCost):
            return value
        if isinstance(value, str):
            try:
                return cls(LabelCostMode(value))
            except ValueError:
                raise LayerConfigError(
                    f"unknown class setting {value!r} (use free, cost or lethal)"
                ) from None
        if isinstance(value, int | float) and not isinstance(value, bool):
            return cls(LabelCostMode.COST, float(value))
        if isinstance(value, Mapping):
            unknown = set(value) - {"mode", "value"}
            if unknown:
                raise LayerConfigError(f"unknown class setting keys: {sorted(unknown)}")
            try:
                mode = LabelCostMode(value.get("mode", LabelCostMode.COST))
            except ValueError:
                raise LayerConfigError(f"unknown class mode {value.get('mode')!r}") from None
            return cls(mode, float(value.get("value", 0.0)))
        raise LayerConfigError(f"cannot read a class setting from {value!r}")


def face_costs(
    face_labels: npt.ArrayLike,
    instance_classes: Mapping[int, str],
    class_costs: Mapping[str, ClassCost],
) -> npt.NDArray[np.float32]:
    """Return each face's class cost (0 for unlabelled faces and classes without a setting).

    Returns
    -------
    float32 [F]
    """
    labels = np.asarray(face_labels, dtype=np.int32).reshape(-1)
    top = int(labels.max(initial=-1))
    lut = np.zeros(top + 2, dtype=np.float32)  # last slot serves label -1
    for instance_id, class_name in instance_classes.items():
        setting = class_costs.get(class_name)
        if setting is not None and 0 <= instance_id <= top:
            lut[instance_id] = setting.cost
    return lut[np.where(labels >= 0, labels, top + 1)]


def label_costs(
    faces: npt.ArrayLike,
    n_vertices: int,
    face_labels: npt.ArrayLike,
    instance_classes: Mapping[int, str],
    class_costs: Mapping[str, ClassCost],
    *,
    threshold: float = THRESHOLD,
) -> LayerResult:
    """Return the label layer: per vertex, the largest class cost among its faces.

    Parameters
    ----------
    faces : int [F, 3]
    face_labels : int32 [F], instance id per face, -1 = unlabelled
    instance_classes : instance id -> class name (instances not listed count as unlabelled)
    class_costs : class name -> setting (classes not listed are free)
    threshold : lethal when ``cost > threshold``; lethal classes are +inf, so always lethal

    Returns
    -------
    LayerResult, cost float32 [N]: 0 free, the class value, or +inf (lethal)
    """
    f = np.ascontiguousarray(faces, dtype=np.int32).reshape(-1, 3)
    fc = face_costs(face_labels, instance_classes, class_costs)
    if len(fc) != len(f):
        raise ValueError(f"face_labels has {len(fc)} entries for {len(f)} faces")
    return threshold_result(_kernels.vertex_max_of_faces(f, fc, int(n_vertices)), threshold)
