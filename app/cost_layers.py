"""The cost layers of an open map: the settings saved with it, and computing them into it.

The GUI and ``meshmark layers`` share this. The settings are the layer graph, the class costs
and the label layer's name; the panel edits them and keeps them in ``doc.meta["settings"]``
(saved under ``/meshmark/settings`` in the HDF5 map), the command line reads them back or
takes a YAML file (meshmark's form or mesh_navigation's ``mesh_map:``).
"""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import yaml

from navigation import (
    ClassCost,
    LayerConfig,
    LayerConfigError,
    LayerStack,
    LayerType,
    NavigationError,
    Progress,
    StackResult,
)
from storage import MapDocument, MapFormatError, MeshmarkError

logger = logging.getLogger(__name__)

#: Where the label layer is saved unless the person names it otherwise.
DEFAULT_LABEL_LAYER = "labels"


class LayerSettingsError(MeshmarkError, ValueError):
    """A layer setting (a parameter, a class cost, the label layer name) cannot be used."""


def rename_layer(config: LayerConfig, old: str, new: str) -> LayerConfig:
    """Return ``config`` with layer ``old`` called ``new``, inputs and default layer included."""
    if old == new:
        return config
    layers = tuple(
        dataclasses.replace(
            spec,
            name=new if spec.name == old else spec.name,
            inputs=tuple(new if i == old else i for i in spec.inputs),
        )
        for spec in config.layers
    )
    default = new if config.default_layer == old else config.default_layer
    return LayerConfig(layers, default)


def with_class_costs(config: LayerConfig, class_costs: Mapping[str, ClassCost]) -> LayerConfig:
    """Return ``config`` whose label layers cost each class as ``class_costs`` says."""
    for name in config.of_type(LayerType.LABELS):
        spec = config.spec(name)
        params = dataclasses.replace(spec.params, classes=dict(class_costs))
        config = config.with_layer(dataclasses.replace(spec, params=params))
    return config


@dataclass(frozen=True)
class LayerSettings:
    """Hold what decides the cost layers of a map besides its geometry and labels."""

    config: LayerConfig = field(default_factory=LayerConfig.default)
    #: class name -> how it counts; classes not listed are free
    class_costs: dict[str, ClassCost] = field(default_factory=dict)

    @property
    def label_layer(self) -> str | None:
        """Return the name the label cost layer is saved under (the first label layer)."""
        names = self.config.of_type(LayerType.LABELS)
        return names[0] if names else None

    def effective_config(self) -> LayerConfig:
        """Return the graph to compute: the config with the class costs in its label layers."""
        return with_class_costs(self.config, self.class_costs)

    def renamed(self, name: str) -> LayerSettings:
        """Return these settings with the label layer saved under ``name``.

        Raises
        ------
        LayerSettingsError
            If there is no label layer, or ``name`` is not a valid, unused layer name.
        """
        old = self.label_layer
        if old is None:
            raise LayerSettingsError("the layer configuration has no label layer to name")
        try:
            return dataclasses.replace(self, config=rename_layer(self.config, old, name.strip()))
        except LayerConfigError as exc:
            raise LayerSettingsError(f"label layer name: {exc}") from None

    # -- persistence ----------------------------------------------------------------------

    def to_dict(self) -> dict[str, Any]:
        """Return the JSON-able form kept in ``doc.meta["settings"]``."""
        return {
            "layers": self.effective_config().to_dict(),
            "class_costs": {k: c.to_dict() for k, c in self.class_costs.items()},
            "label_layer": self.label_layer,
        }

    @classmethod
    def from_dict(cls, values: Mapping[str, Any]) -> LayerSettings:
        """Read :meth:`to_dict`'s form; missing parts take their defaults.

        Raises
        ------
        LayerConfigError
            If a part is there but cannot be read.
        """
        layers = values.get("layers")
        config = LayerConfig.from_dict(layers) if layers else LayerConfig.default()
        raw = values.get("class_costs") or {}
        if not isinstance(raw, Mapping):
            raise LayerConfigError("class_costs must map class names to settings")
        class_costs = {str(k): ClassCost.from_value(v) for k, v in raw.items()}
        if not class_costs:  # a config file names the class costs in its label layer
            for name in config.of_type(LayerType.LABELS):
                class_costs = dict(config.spec(name).params.classes)
                break
        return cls(config, class_costs)

    @classmethod
    def from_meta(cls, meta: Mapping[str, Any]) -> tuple[LayerSettings, str | None]:
        """Return the settings saved with a map (defaults if none) and a problem, if any.

        A map whose saved settings cannot be read still opens: the defaults are used and
        the problem is returned for the person to see.
        """
        settings = meta.get("settings")
        if not isinstance(settings, Mapping) or not settings.get("layers"):
            return cls(), None
        try:
            return cls.from_dict(settings), None
        except (ValueError, TypeError) as exc:  # LayerConfigError is a ValueError
            logger.warning("saved layer settings ignored: %s", exc)
            return cls(), f"the saved cost-layer settings could not be read ({exc}); defaults used"

    @classmethod
    def from_yaml_file(cls, path: Path) -> LayerSettings:
        """Read a layer config file (meshmark's form or mesh_navigation's ``mesh_map:``).

        Raises
        ------
        MapFormatError
            Naming the file, if it cannot be read or describes no valid layer graph.
        """
        try:
            values = yaml.safe_load(Path(path).read_text(encoding="utf-8"))
        except OSError as exc:
            raise MapFormatError(path, f"cannot read the layer config ({exc.strerror})") from None
        except yaml.YAMLError as exc:
            raise MapFormatError(path, f"not valid YAML: {exc}") from None
        if isinstance(values, Mapping):
            values = _find_mesh_map(values) or values
        if not isinstance(values, Mapping) or "layers" not in values:
            raise MapFormatError(path, "a layer config needs a 'layers' list (or 'mesh_map:')")
        try:
            if isinstance(values["layers"], Mapping):  # the form saved with a map
                return cls.from_dict(values)
            return cls.from_dict({"layers": values, "class_costs": values.get("class_costs")})
        except (ValueError, TypeError) as exc:  # LayerConfigError is a ValueError
            raise MapFormatError(path, f"invalid layer config: {exc}") from None

    def save_to(self, doc: MapDocument) -> None:
        """Keep these settings in ``doc.meta["settings"]`` (saved with the map)."""
        with doc.lock:
            settings = dict(doc.meta.get("settings") or {})
            settings.update(self.to_dict())
            doc.meta_update(settings=settings)


def _find_mesh_map(values: Mapping[str, Any], depth: int = 3) -> Mapping[str, Any] | None:
    """Return the ``mesh_map`` block of a ROS parameter file (``node: ros__parameters: ...``)."""
    found = values.get("mesh_map")
    if isinstance(found, Mapping):
        return found
    if depth > 0:
        for value in values.values():
            if isinstance(value, Mapping):
                found = _find_mesh_map(value, depth - 1)
                if found is not None:
                    return found
    return None


def label_inputs(
    doc: MapDocument, config: LayerConfig
) -> tuple[npt.NDArray[np.int32], dict[int, str], dict[str, npt.NDArray[np.float32]]]:
    """Return a consistent copy of what a computation reads from the document.

    Returns
    -------
    (face_labels int32 [F], instance id -> class name, stored layer name -> float32 [N])
    """
    with doc.lock:
        labels = np.array(doc.face_labels, dtype=np.int32)
        classes = {iid: inst.class_name for iid, inst in doc.instances.items()}
        stored = {
            name: np.array(doc.layers[name])
            for name in config.of_type(LayerType.STORED)
            if name in doc.layers
        }
    return labels, classes, stored


def compute_layers(
    doc: MapDocument, settings: LayerSettings, progress: Progress | None = None
) -> tuple[LayerStack, StackResult]:
    """Compute every layer of ``settings`` on ``doc`` and write them into it as one undo step.

    The settings are kept in ``doc.meta["settings"]`` too. Returns the stack (for cheap label
    updates later) and its result.

    Raises
    ------
    LayerSettingsError
        If the graph cannot be computed on this map (e.g. a stored layer the map lacks).
    """
    config = settings.effective_config()
    labels, classes, stored = label_inputs(doc, config)
    stack = LayerStack(config)
    try:
        result = stack.compute_all(
            doc.vertices,
            doc.faces,
            face_labels=labels,
            instance_classes=classes,
            stored=stored,
            progress=progress,
        )
    except NavigationError as exc:
        raise LayerSettingsError(str(exc)) from None
    with doc.gesture():
        for name, layer in result.layers.items():
            # a copy: the stack keeps its arrays, the document must own its own
            doc.set_layer(name, np.array(layer.cost, dtype=np.float32))
    settings.save_to(doc)
    return stack, result


def nan_report(result: StackResult) -> list[str]:
    """Return a line per layer holding NaN and per combination input whose NaN was replaced.

    Empty when no layer had NaN anywhere.
    """
    lines = [f"{name}: {n:,} NaN" for name, n in result.report.nan_counts.items() if n]
    for name, per_input in result.report.replaced_nan.items():
        for inp, n in per_input.items():
            if n:
                lines.append(f"{name}: {n:,} NaN of input {inp!r} replaced by its default")
    return lines
