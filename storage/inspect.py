"""What ``meshmark info`` prints: a map file's layout, sizes, layers, labels and warnings."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from storage.io import read_map_data


@dataclass(frozen=True)
class LayerStats:
    """One per-vertex layer: finite range and how many values are NaN, +inf, -inf."""

    name: str
    min: float | None  #: smallest finite value (None when there is none)
    max: float | None  #: largest finite value
    nan: int
    pos_inf: int
    neg_inf: int


@dataclass(frozen=True)
class ClassStats:
    """One label class: colour, instances with their face counts, and the total."""

    name: str
    color: tuple[int, int, int]
    instances: dict[str, int]
    faces: int


@dataclass(frozen=True)
class MapInfo:
    """Everything ``meshmark info`` reports about one file."""

    path: str
    format: str
    layout: str | None  #: HDF5 layout ("current", "flat", "legacy", "hdf5mapio") or None
    layout_description: str | None
    vertices: int
    faces: int
    layers: list[LayerStats]
    classes: list[ClassStats]
    labelled_faces: int
    goals: int
    texture: str | None  #: e.g. "image/png, 78,699 bytes" or None
    vertex_colors: bool
    origin: tuple[float, float, float] | None
    warnings: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    ignored: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """Return plain values (for JSON output)."""
        return asdict(self)

    def to_text(self) -> str:
        """Return the report as the command line prints it."""
        lines = [f"{Path(self.path).name}"]
        fmt = self.format.upper() + (f", layout {self.layout_description}" if self.layout else "")
        lines.append(f"  format      {fmt}")
        lines.append(f"  vertices    {self.vertices:,}")
        lines.append(f"  faces       {self.faces:,}")
        if self.origin is not None:
            o = ", ".join(f"{v:.3f}" for v in self.origin)
            lines.append(f"  origin      ({o}) — stored vertices are relative to it")
        lines.append(f"  texture     {self.texture or 'no'}")
        lines.append(f"  colours     {'yes (per vertex)' if self.vertex_colors else 'no'}")
        lines.append(f"  goals       {self.goals}")
        if self.layers:
            lines.append(f"  layers ({len(self.layers)})")
            width = max(len(layer.name) for layer in self.layers)
            for s in self.layers:
                span = "no finite values" if s.min is None else f"{s.min:.6g} .. {s.max:.6g}"
                extra = [
                    f"{count:,} {label}"
                    for count, label in ((s.nan, "NaN"), (s.pos_inf, "+inf"), (s.neg_inf, "-inf"))
                    if count
                ]
                tail = f"  ({', '.join(extra)})" if extra else ""
                lines.append(f"    {s.name:<{width}}  {span}{tail}")
        else:
            lines.append("  layers      none")
        if self.classes:
            lines.append(f"  labels ({self.labelled_faces:,} faces labelled)")
            for c in self.classes:
                inst = ", ".join(f"{k}: {v:,}" for k, v in c.instances.items()) or "no instances"
                lines.append(f"    {c.name}  rgb{c.color}  {c.faces:,} faces  [{inst}]")
        else:
            lines.append("  labels      none")
        for title, items in (("notes", self.notes), ("warnings", self.warnings)):
            if items:
                lines.append(f"  {title}")
                lines.extend(f"    - {item}" for item in items)
        if self.ignored:
            lines.append("  not read")
            lines.extend(f"    - {item}" for item in self.ignored)
        return "\n".join(lines)


def inspect_map(path: str | Path) -> MapInfo:
    """Read a map file and summarise it (see ``MapInfo``).

    Raises
    ------
    MapFormatError
        As ``load_map`` does.
    """
    data = read_map_data(path)
    layers = [_layer_stats(name, values) for name, values in data.layers.items()]
    labels = data.face_labels
    assert labels is not None
    labelled = labels[labels >= 0]
    counts = np.bincount(labelled) if len(labelled) else np.zeros(0, dtype=np.int64)
    classes = []
    for cls in data.classes.values():
        per = {
            inst.name: int(counts[iid]) if iid < len(counts) else 0
            for iid, inst in sorted(data.instances.items())
            if inst.class_name == cls.name
        }
        classes.append(ClassStats(cls.name, cls.color, per, sum(per.values())))
    origin = data.meta.get("origin")
    texture = None
    if data.texture is not None:
        texture = f"{data.texture.mime_type}, {len(data.texture.image):,} bytes"
    return MapInfo(
        path=str(path),
        format=str(data.meta.get("format", "?")),
        layout=data.meta.get("layout"),
        layout_description=data.meta.get("layout_description"),
        vertices=data.n_vertices,
        faces=data.n_faces,
        layers=layers,
        classes=classes,
        labelled_faces=len(labelled),
        goals=len(data.goals),
        texture=texture,
        vertex_colors=data.vertex_colors is not None,
        origin=tuple(float(v) for v in origin) if origin is not None else None,  # type: ignore[arg-type]
        warnings=list(data.warnings),
        notes=list(data.meta.get("notes", [])),
        ignored=list(data.meta.get("ignored", [])),
    )


def _layer_stats(name: str, values: np.ndarray) -> LayerStats:
    finite = values[np.isfinite(values)]
    return LayerStats(
        name=name,
        min=float(finite.min()) if len(finite) else None,
        max=float(finite.max()) if len(finite) else None,
        nan=int(np.isnan(values).sum()),
        pos_inf=int(np.isposinf(values).sum()),
        neg_inf=int(np.isneginf(values).sum()),
    )
