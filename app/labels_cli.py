"""``meshmark export-labels MAP OUT_STEM``: the face labels as files other tools read.

Writes ``OUT_STEM.npy`` (int32 class id per face, -1 = unlabelled) and ``OUT_STEM.json`` (the
classes: ids, names, colours, counts, instances); ``--ply`` adds ``OUT_STEM.ply`` with face
colours, ``--instances`` adds ``OUT_STEM_instances.npy``. The formats are described in
``storage.label_export``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from storage import (
    UNLABELLED_COLOR,
    load_map,
    write_label_files,
    write_ply_with_face_colors,
)

#: Suffixes dropped from OUT_STEM, so ``labels.npy`` does not become ``labels.npy.npy``.
_OWN_SUFFIXES = (".npy", ".json", ".ply")


def add_parser(subparsers: Any) -> None:
    """Register ``meshmark export-labels`` on the command's subparsers."""
    p = subparsers.add_parser(
        "export-labels",
        help="write the face labels as .npy class ids + classes JSON (and a coloured PLY)",
        description=(
            "Write OUT_STEM.npy (int32 class id per face in face order, -1 = unlabelled) and "
            "OUT_STEM.json (format meshmark-face-labels: classes in display order with their "
            "id, name, colour, face count and instances)."
        ),
    )
    p.add_argument("path", type=Path, metavar="MAP", help="the map (.h5, or a mesh file)")
    p.add_argument(
        "out_stem",
        type=Path,
        metavar="OUT_STEM",
        help="output path without suffix, e.g. out/site_labels",
    )
    p.add_argument(
        "--ply",
        action="store_true",
        help=(
            "also write OUT_STEM.ply: the mesh (double vertices, world frame) with face colours "
            f"= class colours, unlabelled = grey {UNLABELLED_COLOR}"
        ),
    )
    p.add_argument(
        "--instances",
        action="store_true",
        help="also write OUT_STEM_instances.npy: int32 instance id per face (-1 = unlabelled)",
    )
    p.set_defaults(run=run)


def output_paths(out_stem: Path) -> dict[str, Path]:
    """Return the file written for each kind (``npy``, ``json``, ``ply``, ``instances``)."""
    if out_stem.suffix.lower() in _OWN_SUFFIXES:
        out_stem = out_stem.with_suffix("")
    base = str(out_stem)
    return {
        "npy": Path(base + ".npy"),
        "json": Path(base + ".json"),
        "ply": Path(base + ".ply"),
        "instances": Path(base + "_instances.npy"),
    }


def summary(info: dict[str, Any]) -> str:
    """Return the classes and counts of an export, in a few lines for the terminal."""
    faces = max(int(info["faces"]), 1)
    labelled = int(info["labelled_faces"])
    lines = [
        f"{labelled:,} of {info['faces']:,} faces labelled ({100.0 * labelled / faces:.1f} %), "
        f"{len(info['classes'])} classes"
    ]
    for c in info["classes"]:
        lines.append(
            f"  {c['id']:>3}  {c['name']}  {c['faces']:,} faces, "
            f"{len(c['instances'])} instance(s), colour {tuple(c['color'])}"
        )
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    """Export the labels of ``args.path`` next to ``args.out_stem``; return the exit code."""
    doc = load_map(args.path)
    for warning in doc.warnings:
        print(f"meshmark: {args.path.name}: {warning}", file=sys.stderr)
    data = doc.snapshot()
    paths = output_paths(args.out_stem)
    info = write_label_files(
        data,
        paths["npy"],
        paths["json"],
        instances_path=paths["instances"] if args.instances else None,
    )
    written = [paths["npy"], paths["json"]]
    if args.instances:
        written.append(paths["instances"])
    if args.ply:
        write_ply_with_face_colors(data, paths["ply"])
        written.append(paths["ply"])
    print(summary(info))
    for path in written:
        print(f"wrote {path}")
    return 0
