"""Face labels for other tools: class ids as .npy with a classes JSON, and a face-coloured PLY.

Files written
-------------
``<stem>.npy``
    int32 [F] class id per face: an index into the JSON's ``classes`` list (display order),
    ``-1`` = unlabelled. Face ``i`` is row ``i`` of the map's faces.
``<stem>.json``
    ``{"format": "meshmark-face-labels", "version": 1, "vertices": N, "faces": F,
    "unlabelled": -1, "labelled_faces": n, "arrays": {...}, "classes": [{"id", "name",
    "color": [r, g, b], "faces", "instances": [{"instance_id", "name", "faces"}]}]}``.
``<stem>_instances.npy`` (optional)
    int32 [F] instance id per face, ``-1`` = unlabelled. The ids are the map's own (saved in its
    meshmark table, so they survive a save and reload) and each one appears in the JSON as an
    ``instance_id``. Optional because most tools want classes only.
``<stem>.ply``
    binary little-endian PLY: the vertices as stored (world frame, ``double``, so UTM
    coordinates keep their precision) and the faces in face-id order, each with
    ``red green blue alpha`` = its class colour, ``UNLABELLED_COLOR`` when unlabelled.

A face whose instance id is unknown, or whose instance's class is missing, counts as unlabelled
in every file (the HDF5 writer skips such faces too).
"""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from storage.atomic import atomic_path
from storage.errors import MapFormatError
from storage.model import UNLABELLED, MapData

FORMAT = "meshmark-face-labels"
VERSION = 1
#: Colour of unlabelled faces in the PLY: mid grey, opaque.
UNLABELLED_COLOR: tuple[int, int, int] = (128, 128, 128)
_ARRAYS = {
    "class_ids": "int32 [faces] per face, in the .npy: index into 'classes', -1 = unlabelled",
    "instance_ids": (
        "int32 [faces] per face, in the optional _instances.npy: an 'instance_id' of "
        "'instances', -1 = unlabelled"
    ),
}


def _known_instance_ids(data: MapData) -> npt.NDArray[np.int32]:
    """Return the face labels with unknown instances (or instances of no class) set to -1."""
    labels = data.face_labels
    assert labels is not None
    top = max(int(labels.max(initial=-1)), max(data.instances, default=-1))
    known = np.zeros(top + 1, dtype=bool)
    for iid, inst in data.instances.items():
        if iid >= 0:
            known[iid] = inst.class_name in data.classes
    out = np.full(len(labels), UNLABELLED, dtype=np.int32)
    labelled = np.flatnonzero(labels >= 0)
    keep = labelled[known[labels[labelled]]]
    out[keep] = labels[keep]
    return out


def label_instance_ids(data: MapData) -> npt.NDArray[np.int32]:
    """Return the per-face instance ids to export, so they agree with ``label_arrays``' JSON.

    Returns
    -------
    int32 [F]
        The map's instance id per face, -1 = unlabelled (also for an unknown instance).
    """
    return _known_instance_ids(data)


def label_arrays(data: MapData) -> tuple[npt.NDArray[np.int32], dict[str, Any]]:
    """Turn instance labels into per-face class ids and a JSON-able description of the classes.

    Returns
    -------
    class_ids : int32 [F]
        Index into ``info["classes"]`` (the map's class display order), -1 = unlabelled.
    info : dict
        The classes JSON (see the module docstring): per class its id, name, RGB colour,
        face count and instances (by instance id) with their face counts.
    """
    instance_ids = _known_instance_ids(data)
    class_index = {name: k for k, name in enumerate(data.classes)}
    iids = sorted(i for i in data.instances if i >= 0)
    # instance id -> class id, with the last slot catching -1 (unlabelled)
    lookup = np.full(max(iids, default=-1) + 2, UNLABELLED, dtype=np.int32)
    for iid in iids:
        lookup[iid] = class_index.get(data.instances[iid].class_name, UNLABELLED)
    class_ids = lookup[instance_ids]
    instance_counts = np.bincount(instance_ids[instance_ids >= 0], minlength=len(lookup))
    class_counts = np.bincount(class_ids[class_ids >= 0], minlength=len(class_index))

    classes = []
    for name, cls in data.classes.items():
        k = class_index[name]
        members = [i for i in iids if data.instances[i].class_name == name]
        classes.append(
            {
                "id": k,
                "name": name,
                "color": [int(c) for c in cls.color],
                "faces": int(class_counts[k]),
                "instances": [
                    {
                        "instance_id": int(i),
                        "name": data.instances[i].name,
                        "faces": int(instance_counts[i]),
                    }
                    for i in members
                ],
            }
        )
    info: dict[str, Any] = {
        "format": FORMAT,
        "version": VERSION,
        "vertices": data.n_vertices,
        "faces": data.n_faces,
        "unlabelled": UNLABELLED,
        "labelled_faces": int(np.count_nonzero(class_ids >= 0)),
        "arrays": dict(_ARRAYS),
        "classes": classes,
    }
    return class_ids, info


def _npy_bytes(array: npt.NDArray[Any]) -> bytes:
    buffer = io.BytesIO()
    np.save(buffer, array, allow_pickle=False)
    return buffer.getvalue()


def _json_text(info: dict[str, Any]) -> str:
    return json.dumps(info, indent=2, ensure_ascii=False) + "\n"


def label_files_bytes(data: MapData) -> tuple[bytes, str]:
    """Return the .npy file (bytes) and the JSON text, for a browser download.

    Returns
    -------
    npy : bytes
        ``np.save`` of the int32 [F] class ids (``np.load(io.BytesIO(npy))`` reads it back).
    json_text : str
        The classes JSON, UTF-8 safe, ending in a newline.
    """
    class_ids, info = label_arrays(data)
    return _npy_bytes(class_ids), _json_text(info)


def write_label_files(
    data: MapData,
    npy_path: str | Path,
    json_path: str | Path,
    *,
    instances_path: str | Path | None = None,
) -> dict[str, Any]:
    """Write the class ids (.npy), the classes JSON and optionally the instance ids, atomically.

    Every file is written to a temporary name first and renamed only once all of them were
    written, so a failure leaves any earlier files untouched.

    Returns
    -------
    dict
        The classes JSON that was written (for a summary).

    Raises
    ------
    MapFormatError
        Naming the file that could not be written.
    """
    class_ids, info = label_arrays(data)
    contents: list[tuple[Path, bytes]] = [
        (Path(npy_path), _npy_bytes(class_ids)),
        (Path(json_path), _json_text(info).encode("utf-8")),
    ]
    if instances_path is not None:
        contents.append((Path(instances_path), _npy_bytes(label_instance_ids(data))))
    targets = [p.resolve() for p, _ in contents]
    if len(set(targets)) != len(targets):
        raise MapFormatError(contents[0][0], "the label files need distinct names")
    _write_all(contents)
    return info


def _write_all(contents: list[tuple[Path, bytes]]) -> None:
    """Write each (path, bytes) through ``atomic_path``; the renames happen after every write."""
    if not contents:
        return
    (path, payload), rest = contents[0], contents[1:]
    try:
        with atomic_path(path) as tmp:
            tmp.write_bytes(payload)
            _write_all(rest)
    except OSError as exc:
        raise MapFormatError(path, f"cannot be written: {exc.strerror or exc}") from exc


def ply_with_face_colors(
    data: MapData, *, unlabelled_color: tuple[int, int, int] = UNLABELLED_COLOR
) -> bytes:
    """Return a binary PLY of the mesh whose face colours are the class colours, for viewers.

    Vertices are written as stored (world frame) in ``double`` so large (UTM) coordinates
    survive; trimesh's own PLY exporter writes ``float`` and would round them to ~0.5 m.
    Faces keep their order (face id = PLY face index), each with ``uchar red green blue
    alpha`` (alpha 255). Unlabelled faces get ``unlabelled_color``; the header lists the
    classes in comments.
    """
    class_ids, info = label_arrays(data)
    palette = np.array(
        [c["color"] for c in info["classes"]] + [list(unlabelled_color)], dtype=np.uint8
    ).reshape(-1, 3)
    rgb = palette[class_ids]  # -1 picks the last row: the unlabelled colour

    vertex = np.empty(data.n_vertices, dtype=[("xyz", "<f8", (3,))])
    vertex["xyz"] = data.vertices
    face = np.empty(data.n_faces, dtype=[("n", "u1"), ("ids", "<i4", (3,)), ("rgba", "u1", (4,))])
    face["n"] = 3
    face["ids"] = data.faces
    face["rgba"][:, :3] = rgb
    face["rgba"][:, 3] = 255

    comments = [
        f"meshmark face labels: face colour = class colour, unlabelled = "
        f"{' '.join(str(int(c)) for c in unlabelled_color)}",
        *(
            f"class {c['id']} {json.dumps(c['name'], ensure_ascii=True)} "
            f"{' '.join(str(x) for x in c['color'])}"
            for c in info["classes"]
        ),
    ]
    header = "\n".join(
        [
            "ply",
            "format binary_little_endian 1.0",
            *(f"comment {line}" for line in comments),
            f"element vertex {data.n_vertices}",
            "property double x",
            "property double y",
            "property double z",
            f"element face {data.n_faces}",
            "property list uchar int vertex_indices",
            "property uchar red",
            "property uchar green",
            "property uchar blue",
            "property uchar alpha",
            "end_header",
        ]
    )
    return (header + "\n").encode("ascii") + vertex.tobytes() + face.tobytes()


def write_ply_with_face_colors(data: MapData, path: str | Path) -> None:
    """Write ``ply_with_face_colors(data)`` to ``path`` atomically.

    Raises
    ------
    MapFormatError
        Naming the file when it cannot be written.
    """
    _write_all([(Path(path), ply_with_face_colors(data))])
