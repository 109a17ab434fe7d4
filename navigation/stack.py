"""The layer graph: which cost layers to compute, with what parameters, fed by which inputs.

It mirrors mesh_navigation's ``mesh_map`` parameters: a list of layer names, each layer with a
``type``, its parameters and optional ``inputs``, computed in topological order, plus a
``default_layer``. ``LayerConfig`` is the plain, dict-convertible description (YAML config files
and the GUI edit it); ``LayerStack`` computes it on a mesh and keeps the results, so a label
edit recomputes only the label layers and what depends on them.

Dict form (YAML)::

    layers: [height_diff, roughness, steepness, border, static_combination,
             static_inflation, labels, label_inflation, final]
    default_layer: final
    height_diff: {type: height_diff, threshold: 0.185, radius: 0.3, mode: normal}
    static_combination: {type: sum, inputs: [height_diff, roughness, steepness, border]}
    static_inflation: {type: inflation, inputs: [static_combination], inflation_radius: 0.4}
    labels:      {type: labels, threshold: 1.0,
                  classes: {keepout: lethal, gravel: {mode: cost, value: 0.4}, lawn: free}}
    label_inflation: {type: inflation, inputs: [labels]}
    final:       {type: max, inputs: [static_inflation, label_inflation, labels]}

A ``mesh_map:`` wrapper is accepted, and mesh_navigation type names (``mesh_layers/...Layer``)
are read as their meshmark types.
"""

from __future__ import annotations

import dataclasses
import math
import re
import time
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

import numpy as np
import numpy.typing as npt

from navigation.border import BORDER_COST, border
from navigation.border import THRESHOLD as BORDER_THRESHOLD
from navigation.combine import CombineInput, CombineReport, maximum, weighted_sum
from navigation.errors import LayerConfigError, NavigationError
from navigation.height_diff import RADIUS as HEIGHT_DIFF_RADIUS
from navigation.height_diff import THRESHOLD as HEIGHT_DIFF_THRESHOLD
from navigation.height_diff import HeightDiffMode, height_diff
from navigation.inflation import (
    COST_SCALING_FACTOR,
    INFLATION_RADIUS,
    INSCRIBED_RADIUS,
    INSCRIBED_VALUE,
    LETHAL_VALUE,
    InflationMethod,
    inflation,
)
from navigation.labels import THRESHOLD as LABEL_THRESHOLD
from navigation.labels import ClassCost, label_costs
from navigation.layer_mesh import LayerMesh
from navigation.layer_result import LayerResult, threshold_result
from navigation.ridge import RADIUS as RIDGE_RADIUS
from navigation.ridge import THRESHOLD as RIDGE_THRESHOLD
from navigation.ridge import ridge
from navigation.roughness import RADIUS as ROUGHNESS_RADIUS
from navigation.roughness import THRESHOLD as ROUGHNESS_THRESHOLD
from navigation.roughness import average_angles, roughness
from navigation.steepness import THRESHOLD as STEEPNESS_THRESHOLD
from navigation.steepness import steepness

#: Called with (fraction done 0..1, what is being computed).
Progress = Callable[[float, str], None]

_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


class LayerType(StrEnum):
    """The kinds of layer a stack can hold."""

    HEIGHT_DIFF = "height_diff"
    ROUGHNESS = "roughness"
    STEEPNESS = "steepness"
    RIDGE = "ridge"
    BORDER = "border"
    LABELS = "labels"  #: label classes -> costs (meshmark's own)
    STORED = "stored"  #: a per-vertex layer given as data (e.g. read from the map file)
    INFLATION = "inflation"
    SUM = "sum"  #: mesh_navigation's AvgCombinationLayer (a weighted sum)
    MAX = "max"  #: mesh_navigation's MaxCombinationLayer


#: mesh_navigation plugin type of each layer type (labels and stored layers are read back
#: through SteepnessLayer, whose readLayer() loads ``vertex_attributes/<layer name>``).
MESH_NAVIGATION_TYPES: dict[LayerType, str] = {
    LayerType.HEIGHT_DIFF: "mesh_layers/HeightDiffLayer",
    LayerType.ROUGHNESS: "mesh_layers/RoughnessLayer",
    LayerType.STEEPNESS: "mesh_layers/SteepnessLayer",
    LayerType.RIDGE: "mesh_layers/RidgeLayer",
    LayerType.BORDER: "mesh_layers/BorderLayer",
    LayerType.LABELS: "mesh_layers/SteepnessLayer",
    LayerType.STORED: "mesh_layers/SteepnessLayer",
    LayerType.INFLATION: "mesh_layers/InflationLayer",
    LayerType.SUM: "mesh_layers/AvgCombinationLayer",
    LayerType.MAX: "mesh_layers/MaxCombinationLayer",
}
_FROM_MESH_NAVIGATION = {
    v: k for k, v in MESH_NAVIGATION_TYPES.items() if k not in (LayerType.LABELS, LayerType.STORED)
}
#: Parameters mesh_navigation has but meshmark does not model; accepted and dropped.
_MESH_NAVIGATION_ONLY = frozenset({"repulsive_field", "min_contour_size"})

#: mesh_navigation's ``defaultValue()`` per type: the cost of a vertex the layer has no value
#: for. Combinations use it for NaN.
DEFAULT_VALUES: dict[LayerType, float] = {
    LayerType.HEIGHT_DIFF: math.inf,
    LayerType.ROUGHNESS: math.inf,
    LayerType.STEEPNESS: math.inf,
    LayerType.RIDGE: math.inf,
    LayerType.BORDER: math.inf,
    LayerType.LABELS: math.inf,
    LayerType.STORED: math.inf,
    LayerType.INFLATION: 0.0,
    LayerType.SUM: 0.0,
    LayerType.MAX: 0.0,
}


# ---------------------------------------------------------------------------------------------
# per-type parameters
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class HeightDiffParams:
    """Set the height difference layer (mesh_navigation defaults)."""

    threshold: float = HEIGHT_DIFF_THRESHOLD
    radius: float = HEIGHT_DIFF_RADIUS
    mode: HeightDiffMode = HeightDiffMode.NORMAL
    combination_weight: float = 1.0


@dataclass(frozen=True)
class RoughnessParams:
    """Set the roughness layer (mesh_navigation defaults)."""

    threshold: float = ROUGHNESS_THRESHOLD
    radius: float = ROUGHNESS_RADIUS
    combination_weight: float = 1.0


@dataclass(frozen=True)
class SteepnessParams:
    """Set the steepness layer (mesh_navigation defaults)."""

    threshold: float = STEEPNESS_THRESHOLD
    combination_weight: float = 1.0


@dataclass(frozen=True)
class RidgeParams:
    """Set the ridge layer (mesh_navigation defaults)."""

    threshold: float = RIDGE_THRESHOLD
    radius: float = RIDGE_RADIUS
    combination_weight: float = 1.0


@dataclass(frozen=True)
class BorderParams:
    """Set the border layer (mesh_navigation defaults)."""

    threshold: float = BORDER_THRESHOLD
    border_cost: float = BORDER_COST
    combination_weight: float = 1.0


@dataclass(frozen=True)
class LabelParams:
    """Set the label layer: what each class costs, and the lethal threshold for finite costs."""

    threshold: float = LABEL_THRESHOLD
    classes: dict[str, ClassCost] = field(default_factory=dict)
    combination_weight: float = 1.0


@dataclass(frozen=True)
class StoredParams:
    """Set a layer given as data; lethal where ``cost > threshold`` (+inf: never by threshold)."""

    threshold: float = math.inf
    combination_weight: float = 1.0


@dataclass(frozen=True)
class InflationParams:
    """Set the inflation layer (mesh_navigation defaults)."""

    inscribed_radius: float = INSCRIBED_RADIUS
    inflation_radius: float = INFLATION_RADIUS
    lethal_value: float = LETHAL_VALUE
    inscribed_value: float = INSCRIBED_VALUE
    cost_scaling_factor: float = COST_SCALING_FACTOR
    method: InflationMethod = InflationMethod.FMM
    combination_weight: float = 1.0


@dataclass(frozen=True)
class CombinationParams:
    """Set a combination layer; its own weight only counts where it feeds another sum."""

    combination_weight: float = 1.0


LayerParams = (
    HeightDiffParams
    | RoughnessParams
    | SteepnessParams
    | RidgeParams
    | BorderParams
    | LabelParams
    | StoredParams
    | InflationParams
    | CombinationParams
)

PARAMS_BY_TYPE: dict[LayerType, type] = {
    LayerType.HEIGHT_DIFF: HeightDiffParams,
    LayerType.ROUGHNESS: RoughnessParams,
    LayerType.STEEPNESS: SteepnessParams,
    LayerType.RIDGE: RidgeParams,
    LayerType.BORDER: BorderParams,
    LayerType.LABELS: LabelParams,
    LayerType.STORED: StoredParams,
    LayerType.INFLATION: InflationParams,
    LayerType.SUM: CombinationParams,
    LayerType.MAX: CombinationParams,
}


def _convert(name: str, value: Any, default: Any) -> Any:
    """Return ``value`` read as the type of the field's default (enum, classes or float)."""
    if isinstance(default, StrEnum):
        try:
            return type(default)(value)
        except ValueError:
            choices = ", ".join(m.value for m in type(default))
            raise LayerConfigError(f"{name} must be one of {choices}, got {value!r}") from None
    if isinstance(default, dict):  # label classes
        if not isinstance(value, Mapping):
            raise LayerConfigError(f"{name} must map class names to settings")
        return {str(k): ClassCost.from_value(v) for k, v in value.items()}
    if isinstance(value, bool) or not isinstance(value, int | float | str):
        raise LayerConfigError(f"{name} must be a number, got {value!r}")
    try:
        return float(value)
    except ValueError:
        raise LayerConfigError(f"{name} must be a number, got {value!r}") from None


def _validate_params(layer: str, params: LayerParams) -> None:
    """Raise LayerConfigError for values no layer can work with."""
    values = dataclasses.asdict(params)
    w = values["combination_weight"]
    if not 0.0 <= w <= 1.0:  # mesh_navigation declares the range 0..1
        raise LayerConfigError(f"{layer}: combination_weight must be in [0, 1], got {w}")
    if "radius" in values and not (values["radius"] > 0 and math.isfinite(values["radius"])):
        raise LayerConfigError(f"{layer}: radius must be > 0, got {values['radius']}")
    if "threshold" in values and math.isnan(values["threshold"]):
        raise LayerConfigError(f"{layer}: threshold must be a number")
    if isinstance(params, InflationParams):
        if not 0 <= params.inscribed_radius <= params.inflation_radius:
            raise LayerConfigError(f"{layer}: need 0 <= inscribed_radius <= inflation_radius")
        if params.cost_scaling_factor < 0:
            raise LayerConfigError(f"{layer}: cost_scaling_factor must be >= 0")
    if isinstance(params, BorderParams) and not params.border_cost >= 0:
        raise LayerConfigError(f"{layer}: border_cost must be >= 0")


def params_to_dict(params: LayerParams) -> dict[str, Any]:
    """Return the parameters as plain values (enums as strings, classes as dicts)."""
    out: dict[str, Any] = {}
    for f in dataclasses.fields(params):
        value = getattr(params, f.name)
        if isinstance(value, StrEnum):
            value = value.value
        elif isinstance(value, dict):
            value = {k: c.to_dict() for k, c in value.items()}
        out[f.name] = value
    return out


# ---------------------------------------------------------------------------------------------
# graph
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class LayerSpec:
    """Describe one node of the layer graph: name, type, parameters and input layers."""

    name: str
    type: LayerType
    params: LayerParams = None  # type: ignore[assignment]  # None = the type's defaults
    inputs: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if not _NAME.match(self.name):
            raise LayerConfigError(
                f"layer name {self.name!r} must start with a letter and use only letters, "
                "digits and _ (it names the HDF5 dataset and the ROS parameters)"
            )
        object.__setattr__(self, "type", LayerType(self.type))
        object.__setattr__(self, "inputs", tuple(self.inputs))
        expected = PARAMS_BY_TYPE[self.type]
        if self.params is None:
            object.__setattr__(self, "params", expected())
        if not isinstance(self.params, expected):
            raise LayerConfigError(f"{self.name}: a {self.type} layer takes {expected.__name__}")
        _validate_params(self.name, self.params)
        if self.type is LayerType.INFLATION and len(self.inputs) != 1:
            raise LayerConfigError(f"{self.name}: an inflation layer needs exactly one input")
        if self.type in (LayerType.SUM, LayerType.MAX) and not self.inputs:
            raise LayerConfigError(f"{self.name}: a combination needs at least one input")
        combining = (LayerType.INFLATION, LayerType.SUM, LayerType.MAX)
        if self.type not in combining and self.inputs:
            raise LayerConfigError(f"{self.name}: a {self.type} layer takes no inputs")

    def with_params(self, **changes: Any) -> LayerSpec:
        """Return a copy with some parameters changed (values are converted and checked)."""
        defaults = PARAMS_BY_TYPE[self.type]()
        converted = {}
        for key, value in changes.items():
            if not hasattr(defaults, key):
                raise LayerConfigError(f"{self.name}: {self.type} has no parameter {key!r}")
            converted[key] = _convert(f"{self.name}.{key}", value, getattr(defaults, key))
        return dataclasses.replace(self, params=dataclasses.replace(self.params, **converted))

    @classmethod
    def from_dict(cls, name: str, values: Mapping[str, Any]) -> LayerSpec:
        """Read ``{"type": ..., "inputs": [...], <param>: <value>, ...}``."""
        if "type" not in values:
            raise LayerConfigError(f"layer {name!r} has no type")
        raw_type = str(values["type"])
        try:
            layer_type = _FROM_MESH_NAVIGATION.get(raw_type) or LayerType(raw_type)
        except ValueError:
            known = ", ".join(t.value for t in LayerType)
            raise LayerConfigError(
                f"layer {name!r}: unknown type {raw_type!r} (known: {known})"
            ) from None
        defaults = PARAMS_BY_TYPE[layer_type]()
        params = {}
        for key, value in values.items():
            if key in ("type", "inputs") or key in _MESH_NAVIGATION_ONLY:
                continue
            if not hasattr(defaults, key):
                raise LayerConfigError(f"layer {name!r}: {layer_type} has no parameter {key!r}")
            params[key] = _convert(f"{name}.{key}", value, getattr(defaults, key))
        inputs = values.get("inputs") or ()
        if isinstance(inputs, str):
            inputs = (inputs,)
        return cls(name, layer_type, dataclasses.replace(defaults, **params), tuple(inputs))

    def to_dict(self) -> dict[str, Any]:
        """Return the dict form read by :meth:`from_dict`."""
        out: dict[str, Any] = {"type": self.type.value}
        if self.inputs:
            out["inputs"] = list(self.inputs)
        out.update(params_to_dict(self.params))
        return out


@dataclass(frozen=True)
class LayerConfig:
    """Describe the whole layer graph; checked on creation (names, inputs, no cycles)."""

    layers: tuple[LayerSpec, ...]
    default_layer: str | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "layers", tuple(self.layers))
        names = [s.name for s in self.layers]
        dupes = sorted({n for n in names if names.count(n) > 1})
        if dupes:
            raise LayerConfigError(f"layer names must be unique: {', '.join(dupes)}")
        for spec in self.layers:
            missing = [i for i in spec.inputs if i not in names]
            if missing:
                raise LayerConfigError(f"{spec.name}: unknown input layer(s) {missing}")
        if self.default_layer is not None and self.default_layer not in names:
            raise LayerConfigError(f"default_layer {self.default_layer!r} is not a layer")
        self.order  # raises on cycles  # noqa: B018

    @property
    def names(self) -> tuple[str, ...]:
        """Return the layer names in configuration order."""
        return tuple(s.name for s in self.layers)

    @property
    def order(self) -> tuple[str, ...]:
        """Return the names in computation order: inputs first, otherwise config order."""
        specs = {s.name: s for s in self.layers}
        done: list[str] = []
        state: dict[str, int] = {}

        def visit(name: str, path: tuple[str, ...]) -> None:
            if state.get(name) == 2:
                return
            if state.get(name) == 1:
                raise LayerConfigError(f"layer inputs form a cycle: {' -> '.join((*path, name))}")
            state[name] = 1
            for dep in specs[name].inputs:
                visit(dep, (*path, name))
            state[name] = 2
            done.append(name)

        for spec in self.layers:
            visit(spec.name, ())
        return tuple(done)

    def spec(self, name: str) -> LayerSpec:
        """Return the layer called ``name``."""
        for s in self.layers:
            if s.name == name:
                return s
        raise LayerConfigError(f"no layer named {name!r}")

    def downstream(self, names: Iterable[str]) -> set[str]:
        """Return ``names`` and every layer that depends on them, directly or not."""
        out = set(names)
        for name in self.order:
            if any(i in out for i in self.spec(name).inputs):
                out.add(name)
        return out

    def of_type(self, layer_type: LayerType) -> tuple[str, ...]:
        """Return the names of the layers of one type, in configuration order."""
        return tuple(s.name for s in self.layers if s.type is layer_type)

    def with_layer(self, spec: LayerSpec) -> LayerConfig:
        """Return a copy with ``spec`` replacing the layer of the same name (or appended)."""
        if spec.name in self.names:
            layers = tuple(spec if s.name == spec.name else s for s in self.layers)
        else:
            layers = (*self.layers, spec)
        return LayerConfig(layers, self.default_layer)

    @classmethod
    def from_dict(cls, values: Mapping[str, Any]) -> LayerConfig:
        """Read the mesh_map-style dict (see the module docstring)."""
        if "mesh_map" in values and isinstance(values["mesh_map"], Mapping):
            values = values["mesh_map"]
        names = values.get("layers")
        if not isinstance(names, list | tuple) or not names:
            raise LayerConfigError("the config needs a non-empty list 'layers'")
        specs = []
        for name in names:
            body = values.get(name)
            if not isinstance(body, Mapping):
                raise LayerConfigError(f"layer {name!r} is listed but has no settings")
            specs.append(LayerSpec.from_dict(str(name), body))
        default = values.get("default_layer")
        return cls(tuple(specs), None if default in (None, "") else str(default))

    def to_dict(self) -> dict[str, Any]:
        """Return the dict form read by :meth:`from_dict`."""
        out: dict[str, Any] = {"layers": list(self.names)}
        if self.default_layer is not None:
            out["default_layer"] = self.default_layer
        for spec in self.layers:
            out[spec.name] = spec.to_dict()
        return out

    @classmethod
    def default(cls) -> LayerConfig:
        """Return meshmark's default graph, shaped like the mesh_navigation tutorial's.

        The geometric layers are summed and the union of their lethal vertices inflated
        (``static_inflation``). Labels play the part of the tutorial's obstacle layer: they
        get their own inflation, so a label edit recomputes only the label branch. ``final``
        is the maximum of both inflations and the label costs, so a class's fixed cost
        counts even where nothing is lethal.
        """
        geometric = ("height_diff", "roughness", "steepness", "border")
        return cls(
            (
                LayerSpec("height_diff", LayerType.HEIGHT_DIFF),
                LayerSpec("roughness", LayerType.ROUGHNESS),
                LayerSpec("steepness", LayerType.STEEPNESS),
                LayerSpec("border", LayerType.BORDER),
                LayerSpec("static_combination", LayerType.SUM, inputs=geometric),
                LayerSpec("static_inflation", LayerType.INFLATION, inputs=("static_combination",)),
                LayerSpec("labels", LayerType.LABELS),
                LayerSpec("label_inflation", LayerType.INFLATION, inputs=("labels",)),
                LayerSpec(
                    "final", LayerType.MAX, inputs=("static_inflation", "label_inflation", "labels")
                ),
            ),
            default_layer="final",
        )


# ---------------------------------------------------------------------------------------------
# computation
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class LayerReport:
    """Say what a computation found, for the user: NaN, lethal counts, repairs, timings."""

    #: layer -> NaN vertices in its costs
    nan_counts: dict[str, int]
    #: combination layer -> input -> NaN vertices replaced by that input's default value
    replaced_nan: dict[str, dict[str, int]]
    #: layer -> lethal vertices
    lethal_counts: dict[str, int]
    #: layer -> seconds, for the layers computed in this call
    seconds: dict[str, float]
    warnings: tuple[str, ...] = ()


@dataclass(frozen=True, eq=False)
class StackResult:
    """Carry every layer's result after a computation, with its report."""

    layers: dict[str, LayerResult]
    report: LayerReport
    default_layer: str | None
    computed: tuple[str, ...]  #: the layers (re)computed in this call, in order

    @property
    def costs(self) -> dict[str, npt.NDArray[np.float32]]:
        """Return layer name -> float32 [N] costs."""
        return {k: r.cost for k, r in self.layers.items()}

    @property
    def lethal(self) -> dict[str, npt.NDArray[np.bool_]]:
        """Return layer name -> bool [N] lethal mask."""
        return {k: r.lethal for k, r in self.layers.items()}


class LayerStack:
    """Compute a layer graph on one mesh and keep the results for cheap partial updates.

    Not thread-safe: one job at a time (app runs it on its job executor).
    """

    def __init__(self, config: LayerConfig | None = None) -> None:
        self.config = LayerConfig.default() if config is None else config
        self.mesh: LayerMesh | None = None
        self._results: dict[str, LayerResult] = {}
        self._combine_reports: dict[str, CombineReport] = {}
        self._angles: npt.NDArray[np.float32] | None = None
        self._face_labels: npt.NDArray[np.int32] | None = None
        self._instance_classes: dict[int, str] = {}
        self._stored: dict[str, npt.NDArray[np.float32]] = {}

    @classmethod
    def from_dict(cls, values: Mapping[str, Any]) -> LayerStack:
        """Return a stack for the dict form of :class:`LayerConfig`."""
        return cls(LayerConfig.from_dict(values))

    def to_dict(self) -> dict[str, Any]:
        """Return the configuration's dict form."""
        return self.config.to_dict()

    # -- entry points ------------------------------------------------------------------------

    def compute_all(
        self,
        vertices: npt.ArrayLike,
        faces: npt.ArrayLike,
        *,
        vertex_normals: npt.ArrayLike | None = None,
        face_labels: npt.ArrayLike | None = None,
        instance_classes: Mapping[int, str] | None = None,
        stored: Mapping[str, npt.ArrayLike] | None = None,
        progress: Progress | None = None,
    ) -> StackResult:
        """Compute every layer of the graph on a mesh.

        Parameters
        ----------
        vertices : float [N, 3], world frame
        faces : int [F, 3]
        vertex_normals : float [N, 3] or None; None computes lvr2's normals. Pass the map's
            stored normals to get what mesh_navigation computes from that file.
        face_labels : int32 [F] instance id per face (-1 = unlabelled), or None
        instance_classes : instance id -> class name
        stored : layer name -> float [N] data for ``stored`` layers
        progress : called with (fraction, message) before each step
        """
        t0 = time.perf_counter()
        self._report_progress(progress, 0.0, "preparing mesh topology")
        self.mesh = LayerMesh(vertices, faces, vertex_normals)
        n_faces = len(self.mesh.faces)
        self._angles = None
        self._results = {}
        self._combine_reports = {}
        self._set_labels(face_labels, instance_classes, n_faces)
        self._stored = {
            k: np.asarray(v, dtype=np.float32).reshape(-1) for k, v in (stored or {}).items()
        }
        _ = self.mesh.indptr, self.mesh.boundary  # topology, timed as its own step
        seconds = {"topology": time.perf_counter() - t0}
        return self._run(self.config.order, progress, seconds)

    def update_labels(
        self,
        face_labels: npt.ArrayLike,
        *,
        instance_classes: Mapping[int, str] | None = None,
        class_costs: Mapping[str, Any] | None = None,
        progress: Progress | None = None,
    ) -> StackResult:
        """Recompute the label layers and what depends on them after a label edit.

        ``class_costs`` (class name -> setting, see :meth:`ClassCost.from_value`), when given,
        replaces the classes of every label layer. Geometric layers are reused as they are.
        """
        self._require_mesh()
        if class_costs is not None:
            classes = {str(k): ClassCost.from_value(v) for k, v in class_costs.items()}
            config = self.config
            for name in config.of_type(LayerType.LABELS):
                spec = config.spec(name)
                params = dataclasses.replace(spec.params, classes=classes)
                config = config.with_layer(dataclasses.replace(spec, params=params))
            self.config = config
        if instance_classes is None:
            instance_classes = self._instance_classes
        self._set_labels(face_labels, instance_classes, len(self.mesh.faces))
        dirty = self.config.downstream(self.config.of_type(LayerType.LABELS))
        return self._run([n for n in self.config.order if n in dirty], progress, {})

    def update_layer(self, spec: LayerSpec, *, progress: Progress | None = None) -> StackResult:
        """Replace one layer's settings (or add a layer) and recompute it and its dependents."""
        self._require_mesh()
        self.config = self.config.with_layer(spec)
        dirty = self.config.downstream([spec.name])
        return self._run([n for n in self.config.order if n in dirty], progress, {})

    @property
    def result(self) -> StackResult | None:
        """Return the results of the last computation (None before ``compute_all``)."""
        if not self._results:
            return None
        return self._result(tuple(self._results), {}, [])

    # -- internals ---------------------------------------------------------------------------

    def _require_mesh(self) -> LayerMesh:
        if self.mesh is None:
            raise NavigationError("compute the layers once (compute_all) before updating them")
        return self.mesh

    @staticmethod
    def _report_progress(progress: Progress | None, fraction: float, message: str) -> None:
        if progress is not None:
            progress(fraction, message)

    def _set_labels(
        self, face_labels: npt.ArrayLike | None, instance_classes: Mapping[int, str] | None, n: int
    ) -> None:
        if face_labels is None:
            self._face_labels = np.full(n, -1, dtype=np.int32)
        else:
            labels = np.ascontiguousarray(face_labels, dtype=np.int32).reshape(-1)
            if len(labels) != n:
                raise ValueError(f"face_labels has {len(labels)} entries for {n} faces")
            self._face_labels = labels
        self._instance_classes = {int(k): str(v) for k, v in (instance_classes or {}).items()}

    def _run(
        self, names: list[str] | tuple[str, ...], progress: Progress | None, seconds: dict
    ) -> StackResult:
        warnings: list[str] = []
        for i, name in enumerate(names):
            self._report_progress(progress, i / max(1, len(names)), f"computing {name}")
            t0 = time.perf_counter()
            self._results[name] = self._compute(self.config.spec(name), warnings)
            seconds[name] = time.perf_counter() - t0
        self._report_progress(progress, 1.0, "done")
        # layers dropped from the config disappear from the results
        for stale in set(self._results) - set(self.config.names):
            del self._results[stale]
            self._combine_reports.pop(stale, None)
        return self._result(tuple(names), seconds, warnings)

    def _result(self, computed: tuple[str, ...], seconds: dict, warnings: list) -> StackResult:
        mesh = self._require_mesh()
        notes = list(warnings)
        if mesh.n_degenerate_faces:
            notes.insert(0, f"{mesh.n_degenerate_faces} faces repeat a vertex id and were ignored")
        nan_counts = {k: int(np.count_nonzero(np.isnan(r.cost))) for k, r in self._results.items()}
        for name, count in nan_counts.items():
            if count:
                notes.append(f"layer {name!r} has {count} NaN values")
        for name, rep in self._combine_reports.items():
            for inp, count in rep.nan_counts.items():
                if count and inp in self.config.names:
                    default = DEFAULT_VALUES[self.config.spec(inp).type]
                    notes.append(
                        f"{name!r}: {count} NaN values of {inp!r} counted as its default {default}"
                    )
        report = LayerReport(
            nan_counts=nan_counts,
            replaced_nan={k: dict(r.nan_counts) for k, r in self._combine_reports.items()},
            lethal_counts={k: int(np.count_nonzero(r.lethal)) for k, r in self._results.items()},
            seconds=dict(seconds),
            warnings=tuple(notes),
        )
        ordered = {n: self._results[n] for n in self.config.order if n in self._results}
        return StackResult(ordered, report, self.config.default_layer, computed)

    def _average_angles(self, mesh: LayerMesh, warnings: list[str]) -> npt.NDArray[np.float32]:
        if self._angles is None:
            self._angles = average_angles(mesh)
            bad = int(np.count_nonzero(mesh.non_manifold))
            if bad:
                warnings.append(f"{bad} non-manifold vertices get the average angle pi")
        return self._angles

    def _combine_inputs(self, spec: LayerSpec) -> list[CombineInput]:
        out = []
        for name in spec.inputs:
            src = self.config.spec(name)
            out.append(
                CombineInput(
                    name,
                    self._results[name],
                    weight=src.params.combination_weight,
                    default=DEFAULT_VALUES[src.type],
                )
            )
        return out

    def _compute(self, spec: LayerSpec, warnings: list[str]) -> LayerResult:
        mesh = self._require_mesh()
        p = spec.params
        t = spec.type
        if t is LayerType.HEIGHT_DIFF:
            return height_diff(mesh, radius=p.radius, threshold=p.threshold, mode=p.mode)
        if t is LayerType.ROUGHNESS:
            angles = self._average_angles(mesh, warnings)
            return roughness(mesh, radius=p.radius, threshold=p.threshold, angles=angles)
        if t is LayerType.STEEPNESS:
            return steepness(mesh, threshold=p.threshold)
        if t is LayerType.RIDGE:
            return ridge(mesh, radius=p.radius, threshold=p.threshold)
        if t is LayerType.BORDER:
            return border(mesh, threshold=p.threshold, border_cost=p.border_cost)
        if t is LayerType.LABELS:
            return label_costs(
                mesh.faces,
                mesh.n_vertices,
                self._face_labels,
                self._instance_classes,
                p.classes,
                threshold=p.threshold,
            )
        if t is LayerType.STORED:
            data = self._stored.get(spec.name)
            if data is None:
                raise NavigationError(
                    f"layer {spec.name!r} is a stored layer but no data was given"
                )
            if len(data) != mesh.n_vertices:
                raise NavigationError(
                    f"stored layer {spec.name!r} has {len(data)} values for {mesh.n_vertices} "
                    "vertices"
                )
            return threshold_result(data, p.threshold)
        if t is LayerType.INFLATION:
            return inflation(
                mesh,
                self._results[spec.inputs[0]].lethal,
                inscribed_radius=p.inscribed_radius,
                inflation_radius=p.inflation_radius,
                lethal_value=p.lethal_value,
                inscribed_value=p.inscribed_value,
                cost_scaling_factor=p.cost_scaling_factor,
                method=p.method,
            )
        combine = weighted_sum if t is LayerType.SUM else maximum
        result, report = combine(self._combine_inputs(spec))
        self._combine_reports[spec.name] = report
        return result
