"""Write a layer graph as mesh_navigation ``mesh_map`` parameters, so labels reach the robot.

mesh_navigation reads no labels. But every geometric layer plugin first calls ``readLayer()``,
which loads ``/<part>/vertex_attributes/<layer name>`` from the map file and uses it as-is
(only the lethal set is recomputed, as ``cost > threshold``); it computes the layer only when
that dataset is missing. So a label cost layer saved under a name, plus a geometric layer of
that name in the config, counts in planning. meshmark uses ``mesh_layers/SteepnessLayer`` as
that reader: its only parameter is ``threshold`` (range 0.01..3.1415, the widest), and should
the dataset be missing, its fallback computation (steepness) is the cheapest.
"""

from __future__ import annotations

import math

from navigation.errors import LayerConfigError
from navigation.height_diff import HeightDiffMode
from navigation.inflation import InflationMethod
from navigation.stack import MESH_NAVIGATION_TYPES, LayerConfig, LayerSpec, LayerStack, LayerType

#: (min, max) that mesh_navigation declares per parameter (mesh_layers/include/*.h, b9f2851).
_RANGES: dict[LayerType, dict[str, tuple[float, float]]] = {
    LayerType.HEIGHT_DIFF: {"threshold": (0.05, 1.0), "radius": (0.02, 1.0)},
    LayerType.ROUGHNESS: {"threshold": (0.01, 3.1415), "radius": (0.02, 1.0)},
    LayerType.STEEPNESS: {"threshold": (0.01, 3.1415)},
    LayerType.RIDGE: {"radius": (0.01, 1.0)},
    LayerType.BORDER: {"threshold": (0.05, 1.0), "border_cost": (0.02, 10.0)},
    LayerType.LABELS: {"threshold": (0.01, 3.1415)},
    LayerType.STORED: {"threshold": (0.01, 3.1415)},
    LayerType.INFLATION: {"cost_scaling_factor": (0.0, 5.0)},
}
_EXPORTED = {
    LayerType.HEIGHT_DIFF: ("threshold", "radius"),
    LayerType.ROUGHNESS: ("threshold", "radius"),
    LayerType.STEEPNESS: ("threshold",),
    LayerType.RIDGE: ("threshold", "radius"),
    LayerType.BORDER: ("threshold", "border_cost"),
    LayerType.LABELS: ("threshold",),
    LayerType.STORED: ("threshold",),
    LayerType.INFLATION: (
        "inflation_radius",
        "inscribed_radius",
        "lethal_value",
        "inscribed_value",
        "cost_scaling_factor",
    ),
    LayerType.SUM: (),
    LayerType.MAX: (),
}


def _yaml_float(value: float) -> str:
    """Return a YAML float ROS 2 reads as a double (never an integer literal)."""
    if math.isinf(value):
        return ".inf" if value > 0 else "-.inf"
    if math.isnan(value):
        return ".nan"
    text = repr(float(value))
    return text if any(c in text for c in ".e") else text + ".0"


def _layer_lines(spec: LayerSpec, label_layer: str) -> list[str]:
    p = spec.params
    lines = [f"  {spec.name}:"]
    if spec.type in (LayerType.LABELS, LayerType.STORED):
        what = "label costs" if spec.type is LayerType.LABELS else "a precomputed layer"
        lines += [
            f"    # {what}: meshmark saves /mesh/vertex_attributes/{spec.name} (float32 [N,1],",
            "    # +inf = lethal). SteepnessLayer's readLayer() loads that dataset by this layer",
            "    # name and uses it as-is; it would compute steepness only if it were missing.",
        ]
        if spec.name == label_layer and p.threshold < max(
            (c.cost for c in getattr(p, "classes", {}).values() if math.isfinite(c.cost)),
            default=0.0,
        ):
            lines.append("    # note: some finite class costs exceed the threshold -> lethal there")
    if spec.type is LayerType.HEIGHT_DIFF and p.mode is HeightDiffMode.VERTICAL:
        lines += [
            "    # meshmark used the vertical (2024) variant; HeightDiffLayer computes the",
            "    # normal-plane one, so save this layer into the map to have it read as-is.",
        ]
    if spec.type is LayerType.INFLATION and p.method is InflationMethod.DIJKSTRA:
        lines.append("    # meshmark used edge distances; InflationLayer always uses its wavefront")
    lines.append(f"    type: '{MESH_NAVIGATION_TYPES[spec.type]}'")
    if spec.inputs:
        lines.append("    inputs: [" + ", ".join(f"'{i}'" for i in spec.inputs) + "]")
    lines.append(f"    combination_weight: {_yaml_float(p.combination_weight)}")
    ranges = _RANGES.get(spec.type, {})
    for key in _EXPORTED[spec.type]:
        value = float(getattr(p, key))
        lo, hi = ranges.get(key, (-math.inf, math.inf))
        if not lo <= value <= hi:
            if spec.name == label_layer:
                raise LayerConfigError(
                    f"{spec.name}: mesh_navigation accepts a {key} in [{lo}, {hi}], got {value}"
                )
            lines.append(f"    # WARNING: mesh_navigation rejects {key} outside [{lo}, {hi}]")
        lines.append(f"    {key}: {_yaml_float(value)}")
    if spec.type is LayerType.INFLATION:
        lines.append("    repulsive_field: false")
    return lines


def export_mesh_navigation_config(
    stack: LayerStack | LayerConfig, label_layer_name: str, *, whole_graph: bool = True
) -> str:
    """Return the ``mesh_map:`` YAML block that makes mesh_navigation plan with the labels.

    The label layer must be saved in the map as ``/mesh/vertex_attributes/<label_layer_name>``
    (the stack's label layer of that name). With ``whole_graph`` the whole stack is written in
    mesh_navigation's terms (types, inputs, weights, thresholds, default_layer); otherwise only
    the label layer's block, to be added to an existing config and to a combination's inputs.
    Paste the block under ``<move_base_flex node>: ros__parameters:``.

    Raises
    ------
    LayerConfigError
        If ``label_layer_name`` is not a label or stored layer of the stack, or its threshold
        lies outside what SteepnessLayer accepts (0.01..3.1415).
    """
    config = stack.config if isinstance(stack, LayerStack) else stack
    spec = config.spec(label_layer_name)
    if spec.type not in (LayerType.LABELS, LayerType.STORED):
        raise LayerConfigError(f"{label_layer_name!r} is a {spec.type} layer, not a label layer")
    header = [
        "# mesh_navigation layer graph exported by meshmark.",
        "# Paste under <move_base_flex node>: ros__parameters:",
        "# Every geometric layer whose dataset /mesh/vertex_attributes/<layer name> exists in the",
        "# map file is read from it as-is instead of being computed.",
    ]
    lines: list[str] = [*header, "mesh_map:"]
    specs = config.layers if whole_graph else (spec,)
    if whole_graph:
        lines.append("  layers:")
        lines += [f"    - {s.name}" for s in specs]
        if config.default_layer is not None:
            lines.append(f"  default_layer: '{config.default_layer}'")
    else:
        lines.append(f"  # add '{spec.name}' to mesh_map.layers and to a combination's inputs")
    for s in specs:
        lines += _layer_lines(s, label_layer_name)
    return "\n".join(lines) + "\n"
