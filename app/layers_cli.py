"""``meshmark layers MAP``: compute the cost layers headless and save them into the map.

For scripts and many maps at once: the same layer graph and class costs as the app (saved
with the map, or from ``--config``), a plain-text progress bar on stderr, a summary on stdout.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path
from typing import Any, TextIO

import numpy as np

from app.cost_layers import LayerSettings, LayerSettingsError, compute_layers, nan_report
from navigation import NavigationError, StackResult, export_mesh_navigation_config
from storage import MapDocument, MapFormatError, load_map, save_map

BAR_WIDTH = 30


def add_parser(subparsers: Any) -> None:
    """Register ``meshmark layers`` on the command's subparsers."""
    p = subparsers.add_parser(
        "layers",
        help="compute the cost layers of a map and save them into it",
        description=(
            "Compute the cost layers (height difference, roughness, steepness, border, "
            "inflation, labels, combinations) and save them as /mesh/vertex_attributes/<name>. "
            "Without --config the settings saved with the map are used (else the defaults)."
        ),
    )
    p.add_argument("path", type=Path, help="the map (.h5, or a mesh file)")
    p.add_argument(
        "--out",
        type=Path,
        help="where to write the map (default: MAP itself if it is .h5, else MAP with .h5)",
    )
    p.add_argument(
        "--config",
        type=Path,
        help="layer graph YAML: meshmark's form or mesh_navigation's (mesh_map: ...)",
    )
    p.add_argument(
        "--label-layer",
        metavar="NAME",
        help="save the label cost layer under NAME (the layer name mesh_navigation reads)",
    )
    p.add_argument(
        "--export-yaml",
        type=Path,
        metavar="PATH",
        help="also write the mesh_navigation mesh_map config for the label layer to PATH",
    )
    p.set_defaults(run=run)


def default_out(path: Path) -> Path:
    """Return where the map is written without --out: in place for .h5, else beside it."""
    return path if path.suffix.lower() == ".h5" else path.with_suffix(".h5")


class ProgressBar:
    """Draw ``[#####     ]  50% computing roughness`` on one line of a stream."""

    def __init__(self, stream: TextIO, width: int = BAR_WIDTH) -> None:
        self.stream = stream
        self.width = width
        self._last_len = 0

    def __call__(self, fraction: float, message: str) -> None:
        """Redraw the bar at ``fraction`` (0..1) with ``message``."""
        fraction = min(max(fraction, 0.0), 1.0)
        filled = round(fraction * self.width)
        text = f"[{'#' * filled}{' ' * (self.width - filled)}] {fraction * 100:3.0f}% {message}"
        pad = " " * max(0, self._last_len - len(text))
        self.stream.write("\r" + text + pad)
        self.stream.flush()
        self._last_len = len(text)

    def close(self) -> None:
        """End the bar's line."""
        if self._last_len:
            self.stream.write("\n")
            self.stream.flush()
            self._last_len = 0


def _settings(args: argparse.Namespace, doc: MapDocument) -> tuple[LayerSettings, str]:
    if args.config is not None:
        settings, source = LayerSettings.from_yaml_file(args.config), str(args.config)
    else:
        settings, problem = LayerSettings.from_meta(doc.meta)
        if problem:
            print(f"meshmark: {args.path.name}: {problem}", file=sys.stderr)
        saved = isinstance(doc.meta.get("settings"), dict) and problem is None
        source = "the settings saved with the map" if saved else "the default layer graph"
    if args.label_layer:
        settings = settings.renamed(args.label_layer)
    return settings, source


def _range(values: np.ndarray) -> str:
    finite = values[np.isfinite(values)]
    if not len(finite):
        return "no finite values"
    return f"{float(finite.min()):.4g} .. {float(finite.max()):.4g}"


def summary(doc: MapDocument, result: StackResult, seconds: float) -> str:
    """Return what was computed, in a few lines for the terminal."""
    report = result.report
    width = max(len(n) for n in result.layers)
    lines = [
        f"computed {len(result.layers)} layers on {doc.n_vertices:,} vertices, "
        f"{doc.n_faces:,} faces in {seconds:.2f} s",
        f"  {'layer':<{width}}  {'lethal':>9}  {'+inf':>9}  range (finite)",
    ]
    for name, layer in result.layers.items():
        n_inf = int(np.count_nonzero(layer.cost == math.inf))
        lines.append(
            f"  {name:<{width}}  {report.lethal_counts[name]:>9,}  {n_inf:>9,}  "
            f"{_range(layer.cost)}"
        )
    nan = nan_report(result)
    lines.append("NaN: none" if not nan else "NaN:\n" + "\n".join(f"  {x}" for x in nan))
    lines += [f"note: {w}" for w in report.warnings if "NaN" not in w]
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    """Compute and save the layers of ``args.path``; return the exit code."""
    doc = load_map(args.path)
    for warning in doc.warnings:
        print(f"meshmark: {args.path.name}: {warning}", file=sys.stderr)
    settings, source = _settings(args, doc)
    print(f"meshmark: {args.path.name}: layer graph from {source}", file=sys.stderr)
    bar = ProgressBar(sys.stderr)
    t0 = time.perf_counter()
    try:
        _, result = compute_layers(doc, settings, bar)
    finally:
        bar.close()
    seconds = time.perf_counter() - t0
    out = args.out if args.out is not None else default_out(args.path)
    save_map(doc, out)
    print(summary(doc, result, seconds))
    label_layer = settings.label_layer
    if label_layer is not None:
        print(f"label costs saved as /mesh/vertex_attributes/{label_layer} (+inf = lethal)")
    if args.export_yaml is not None:
        if label_layer is None:
            raise LayerSettingsError("--export-yaml needs a label layer in the layer graph")
        try:
            text = export_mesh_navigation_config(settings.effective_config(), label_layer)
        except NavigationError as exc:
            raise LayerSettingsError(str(exc)) from None
        try:
            args.export_yaml.write_text(text, encoding="utf-8")
        except OSError as exc:
            raise MapFormatError(args.export_yaml, f"cannot write ({exc.strerror})") from None
        print(f"mesh_navigation config written to {args.export_yaml}")
    print(f"wrote {out}")
    return 0
