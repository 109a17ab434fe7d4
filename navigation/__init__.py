"""Cost layers as mesh_navigation computes them: arrays in, arrays out."""

from navigation.border import border
from navigation.combine import CombineInput, CombineReport, maximum, weighted_sum
from navigation.errors import LayerConfigError, NavigationError
from navigation.height_diff import HeightDiffMode, height_diff
from navigation.inflation import InflationMethod, fading, inflation, inflation_distances
from navigation.labels import LETHAL_COST, ClassCost, LabelCostMode, face_costs, label_costs
from navigation.layer_mesh import LayerMesh
from navigation.layer_result import LayerResult, threshold_result
from navigation.mesh_navigation_config import export_mesh_navigation_config
from navigation.neighborhoods import local_neighborhood, plane_neighborhood
from navigation.ridge import ridge
from navigation.roughness import average_angles, roughness
from navigation.stack import (
    DEFAULT_VALUES,
    MESH_NAVIGATION_TYPES,
    BorderParams,
    CombinationParams,
    HeightDiffParams,
    InflationParams,
    LabelParams,
    LayerConfig,
    LayerReport,
    LayerSpec,
    LayerStack,
    LayerType,
    Progress,
    RidgeParams,
    RoughnessParams,
    StackResult,
    SteepnessParams,
    StoredParams,
)
from navigation.steepness import steepness

__all__ = [
    "DEFAULT_VALUES",
    "LETHAL_COST",
    "MESH_NAVIGATION_TYPES",
    "BorderParams",
    "ClassCost",
    "CombinationParams",
    "CombineInput",
    "CombineReport",
    "HeightDiffMode",
    "HeightDiffParams",
    "InflationMethod",
    "InflationParams",
    "LabelCostMode",
    "LabelParams",
    "LayerConfig",
    "LayerConfigError",
    "LayerMesh",
    "LayerReport",
    "LayerResult",
    "LayerSpec",
    "LayerStack",
    "LayerType",
    "NavigationError",
    "Progress",
    "RidgeParams",
    "RoughnessParams",
    "StackResult",
    "SteepnessParams",
    "StoredParams",
    "average_angles",
    "border",
    "export_mesh_navigation_config",
    "face_costs",
    "fading",
    "height_diff",
    "inflation",
    "inflation_distances",
    "label_costs",
    "local_neighborhood",
    "maximum",
    "plane_neighborhood",
    "ridge",
    "roughness",
    "steepness",
    "threshold_result",
    "weighted_sum",
]
