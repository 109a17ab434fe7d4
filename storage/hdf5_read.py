"""Read HDF5 mesh maps in every layout found in real files into one ``MapData``.

Layouts (see ../shared/data/README.md and the research notes §1):

- current (lvr2 >= 25.1): ``/<part>/geometry/{vertices,face_indices,...}``,
  ``/<part>/vertex_attributes/<layer>``, ``/<part>/face_attributes``, ``/<part>/labels``;
- flat (lvr2 <= 24.12, the 2024 tutorial maps): everything in ``/<part>/channels``;
- legacy (lvr2 2019, pluto maps): ``/meshes/<name>/{vertices,indices,vertex_attributes,...}``;
- HDF5MapIO (old mesh_tools): ``/geometry/{vertices,faces}`` as flat 1-D arrays,
  ``/attributes/...``, ``/labels/<class>/<instance>``, ``/textures/...``.

The part is found by content, not by name: any group that holds a ``vertices`` dataset and a
face dataset. Vertices are kept exactly (unreferenced ones too: layers index them), faces
keep their order (face ids are label ids), NaN and infinities in layers are data. The file
is closed before this returns: everything is read into memory.
"""

from __future__ import annotations

import io
import json
import logging
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import h5py
import numpy as np
import numpy.typing as npt

from storage import hdf5_layout as L
from storage.colors import class_color, colors_to_uint8
from storage.errors import MapFormatError
from storage.mesh_checks import check_geometry
from storage.model import UNLABELLED, Goal, Instance, LabelClass, MapData, Texture

logger = logging.getLogger(__name__)

LAYOUTS = {
    "current": "current (/{part}/geometry + vertex_attributes, lvr2 >= 25.1)",
    "flat": "flat 2024 (/{part}/channels, lvr2 <= 24.12; lvr2 >= 25.1 cannot load it)",
    "legacy": "legacy lvr2 2019 ({part}/vertices + indices)",
    "hdf5mapio": "mesh_tools HDF5MapIO (/geometry/vertices + faces, 1-D)",
}

_FACE_NAMES = ("face_indices", "indices", "faces")
#: Per-vertex datasets read as something other than a layer (or deliberately dropped).
_NOT_LAYERS = L.RESERVED_VERTEX_NAMES | {"face_indices", "indices", "faces"}
#: Per-face datasets that are geometry, not attributes anyone would miss.
_FACE_GEOMETRY = {"face_normals", "face_colors", "face_indices", "indices", "faces"}


@dataclass
class _Part:
    """Where one mesh lives in the file, and which groups hold its attributes."""

    layout: str
    part: h5py.Group
    geometry: h5py.Group
    faces_name: str
    vertex_groups: list[h5py.Group] = field(default_factory=list)
    face_groups: list[h5py.Group] = field(default_factory=list)


def read_hdf5(path: str | Path) -> MapData:
    """Read an HDF5 mesh map of any known layout.

    Raises
    ------
    MapFormatError
        When the file is not HDF5, is truncated or damaged, holds no mesh, or its mesh is
        unusable (see ``storage.mesh_checks``).
    """
    path = Path(path)
    if not h5py.is_hdf5(path):
        raise MapFormatError(path, "not an HDF5 file (the HDF5 signature is missing)")
    try:
        with h5py.File(path, "r") as f:
            return _read(path, f)
    except MapFormatError:
        raise
    except (OSError, KeyError, ValueError, RuntimeError, TypeError) as exc:
        logger.debug("reading %s failed", path, exc_info=True)
        raise MapFormatError(
            path, f"the HDF5 file is truncated or damaged and cannot be read ({_short(exc)})"
        ) from exc


def find_parts(f: h5py.File) -> list[_Part]:
    """Return every mesh part in the file, ``/mesh`` first, then in file order."""
    containers: list[h5py.Group] = []
    if _is_container(f):
        containers.append(f)

    def visit(_: str, obj: Any) -> None:
        if isinstance(obj, h5py.Group) and _is_container(obj):
            containers.append(obj)

    f.visititems(visit)
    parts = [_classify(c) for c in containers]
    parts.sort(key=lambda p: p.part.name != "/" + L.PART)
    return parts


def _is_container(g: h5py.Group) -> bool:
    names = set(g.keys())
    return "vertices" in names and any(n in names for n in _FACE_NAMES)


def _classify(c: h5py.Group) -> _Part:
    """Tell the layout from where ``vertices`` sits and what the faces are called."""
    base = c.name.rsplit("/", 1)[-1]
    faces_name = next(n for n in _FACE_NAMES if n in c)
    parent = c.parent
    if base == "geometry" and faces_name == "faces":
        attrs = _group(parent, "attributes")
        return _Part("hdf5mapio", parent, c, faces_name, vertex_groups=attrs)
    if base == "geometry":
        return _Part(
            "current",
            parent,
            c,
            faces_name,
            vertex_groups=_group(parent, "vertex_attributes"),
            face_groups=_group(parent, "face_attributes"),
        )
    if base == "channels":
        return _Part("flat", parent, c, faces_name, vertex_groups=[c])
    return _Part(
        "legacy",
        c,
        c,
        faces_name,
        vertex_groups=_group(c, "vertex_attributes"),
        face_groups=_group(c, "face_attributes"),
    )


def _group(parent: h5py.Group, name: str) -> list[h5py.Group]:
    obj = parent.get(name)
    return [obj] if isinstance(obj, h5py.Group) else []


# ------------------------------------------------------------------------------ reading


def _read(path: Path, f: h5py.File) -> MapData:
    warnings: list[str] = []
    notes: list[str] = []
    ignored: list[str] = []
    parts = find_parts(f)
    with_faces = [p for p in parts if p.geometry[p.faces_name].size > 0]
    if not parts:
        raise MapFormatError(
            path,
            "the HDF5 file holds no mesh (no group with 'vertices' and 'face_indices', "
            "'indices' or 'faces'); it is not a mesh map",
        )
    chosen = with_faces[0] if with_faces else parts[0]
    if len(parts) > 1:
        warnings.append(
            f"the file holds {len(parts)} meshes ({', '.join(p.part.name for p in parts)}); "
            f"read {chosen.part.name}, ignored the others"
        )
    part = chosen
    mm = f.get(L.MESHMARK)
    mm = mm if isinstance(mm, h5py.Group) else None

    vertices = _vertices(path, part.geometry["vertices"])
    faces = _faces(path, part.geometry[part.faces_name])
    check_geometry(path, vertices, faces, warnings)
    n, n_faces = len(vertices), len(faces)

    origin = _origin(mm, warnings)
    if origin is not None:
        vertices = vertices.astype(np.float64) + origin

    renamed = _layer_names(mm)
    layers = _layers(part, n, n_faces, renamed, warnings, ignored)
    colors = _colors(part, n, warnings)
    texture = _texture(f, part, mm, n, warnings)

    classes, instances, face_labels = _labels(f, part, mm, n_faces, warnings)
    goals = _goals(mm, warnings)

    for name in ("edge_attributes", "cluster_attributes", "clustersets"):
        obj = part.part.get(name)
        if isinstance(obj, h5py.Group) and len(obj):
            ignored.append(f"{obj.name}: {', '.join(obj)} (not used by meshmark)")
    layout_text = LAYOUTS[part.layout].format(part=part.part.name.strip("/") or "")
    if part.layout == "flat":
        notes.append(
            "the 2024 /mesh/channels layout cannot be loaded by lvr2 >= 25.1 or current "
            "mesh_navigation; saving (or `meshmark convert`) writes the current layout"
        )
    elif part.layout in ("legacy", "hdf5mapio"):
        notes.append(
            "this old layout cannot be loaded by current mesh_navigation; saving writes the "
            "current layout"
        )
    if mm is not None:
        version = int(mm.attrs.get("format_version", L.MESHMARK_FORMAT_VERSION))
        if version > L.MESHMARK_FORMAT_VERSION:
            warnings.append(
                f"written by a newer meshmark (format {version}); some meshmark data may be lost"
            )
    meta: dict[str, Any] = {
        "format": "hdf5",
        "layout": part.layout,
        "layout_description": layout_text,
        "part": part.part.name,
        "source_name": path.name,
        "written_by_meshmark": mm is not None,
        "notes": notes,
        "ignored": ignored,
    }
    if origin is not None:
        meta["origin"] = origin
    settings = _settings(mm, warnings)
    if settings:
        meta["settings"] = settings
    return MapData(
        vertices=vertices,
        faces=faces,
        layers=layers,
        vertex_colors=colors,
        texture=texture,
        face_labels=face_labels,
        classes=classes,
        instances=instances,
        goals=goals,
        meta=meta,
        warnings=warnings,
    )


def _vertices(path: Path, ds: h5py.Dataset) -> npt.NDArray[np.floating]:
    """Read vertices as stored ([N, 3] or flat [3N], any float dtype)."""
    a = _array(ds)
    if a.dtype.kind not in "fiu":
        raise MapFormatError(path, f"{ds.name} holds {a.dtype} values, not coordinates")
    if a.ndim == 2 and a.shape[1] == 3:
        return a
    if a.size % 3 == 0 and (a.ndim == 1 or a.shape[-1] == 1):
        return a.reshape(-1, 3)
    raise MapFormatError(path, f"{ds.name} has shape {a.shape}; expected [N, 3] coordinates")


def _faces(path: Path, ds: h5py.Dataset) -> npt.NDArray[np.integer]:
    """Read faces as stored ([F, 3] or flat [3F], any integer dtype)."""
    a = _array(ds)
    if a.dtype.kind not in "iu":
        raise MapFormatError(path, f"{ds.name} holds {a.dtype} values, not vertex ids")
    if a.ndim == 2 and a.shape[1] == 3:
        return a
    if a.size % 3 == 0 and (a.ndim == 1 or a.shape[-1] == 1):
        return a.reshape(-1, 3)
    raise MapFormatError(
        path, f"{ds.name} has shape {a.shape}; expected triangles [F, 3] (maps hold triangles)"
    )


def _array(ds: h5py.Dataset) -> np.ndarray:
    return np.asarray(ds[()])


def _origin(mm: h5py.Group | None, warnings: list[str]) -> npt.NDArray[np.float64] | None:
    ds = mm.get("origin") if mm is not None else None
    if not isinstance(ds, h5py.Dataset):
        return None
    origin = np.asarray(ds[()], dtype=np.float64).ravel()
    if origin.shape != (3,) or not np.isfinite(origin).all():
        warnings.append(f"/meshmark/origin {origin.tolist()} is not 3 finite numbers; ignored")
        return None
    return origin if origin.any() else None


def _layer_names(mm: h5py.Group | None) -> dict[str, str]:
    """Return stored dataset name -> original layer name for names the writer had to change."""
    ds = mm.get("layer_names") if mm is not None else None
    if not isinstance(ds, h5py.Dataset):
        return {}
    pairs = np.asarray(ds.asstr()[()]).reshape(-1, 2)
    return {str(stored): str(original) for stored, original in pairs}


def _layers(
    part: _Part,
    n: int,
    n_faces: int,
    renamed: dict[str, str],
    warnings: list[str],
    ignored: list[str],
) -> dict[str, npt.NDArray[np.float32]]:
    """Collect per-vertex scalar datasets ([N] or [N, 1], any number type) as layers."""
    layers: dict[str, npt.NDArray[np.float32]] = {}
    per_face: list[str] = []
    for group in part.vertex_groups:
        for name, obj in group.items():
            if not isinstance(obj, h5py.Dataset):
                ignored.append(f"{obj.name}: a group, not a per-vertex layer")
                continue
            if name in _NOT_LAYERS or name in _FACE_GEOMETRY:
                continue
            shape, kind = obj.shape, obj.dtype.kind
            edge = part.layout == "flat" and name.startswith("edge_")  # mixed in channels
            if edge or name.endswith("_idx") or f"{name}_idx" in group:
                ignored.append(
                    f"{obj.name} {shape} {obj.dtype}: edge or sparse data (mesh_navigation "
                    "recomputes it)"
                )
                continue
            width = int(np.prod(shape[1:])) if len(shape) > 1 else 1
            if kind not in "fiub" or width != 1 or len(shape) == 0:
                ignored.append(f"{obj.name} {shape} {obj.dtype}: not a per-vertex scalar")
                continue
            if shape[0] == n:
                values = np.asarray(obj[()])
                if kind != "f":
                    warnings.append(f"layer {name!r} holds {obj.dtype} values; read as float32")
                layers[renamed.get(name, name)] = values.reshape(-1).astype(np.float32, copy=False)
            elif shape[0] == n_faces:
                per_face.append(name)
            else:
                ignored.append(
                    f"{obj.name} {shape}: length fits neither the {n:,} vertices nor the "
                    f"{n_faces:,} faces"
                )
    for group in part.face_groups:
        for name in group:
            if name not in _FACE_GEOMETRY and not name.endswith("_idx"):
                per_face.append(name)
    if per_face:
        warnings.append(
            f"per-face data not read (meshmark keeps per-vertex layers only): "
            f"{', '.join(sorted(set(per_face)))}"
        )
    return layers


def _colors(part: _Part, n: int, warnings: list[str]) -> npt.NDArray[np.uint8] | None:
    """Find vertex colours where each layout keeps them; return uint8 [N, 3] or None."""
    for group, name in [
        (part.geometry, "vertex_colors"),
        *[(g, "vertex_colors") for g in part.vertex_groups],
        *[(g, "rgb_colors") for g in part.vertex_groups],
    ]:
        ds = group.get(name)
        if isinstance(ds, h5py.Dataset):
            colors = colors_to_uint8(np.asarray(ds[()]), n, warnings, where=ds.name)
            if colors is not None:
                return colors
    return None


def _texture(
    f: h5py.File, part: _Part, mm: h5py.Group | None, n: int, warnings: list[str]
) -> Texture | None:
    """Read meshmark's texture (image bytes + UVs), or a single HDF5MapIO texture image."""
    image_ds = mm.get("texture") if mm is not None else None
    uv_ds = part.geometry.get("texture_coordinates")
    if isinstance(image_ds, h5py.Dataset):
        if not isinstance(uv_ds, h5py.Dataset):
            warnings.append("texture image without texture_coordinates; texture not read")
            return None
        uv = np.asarray(uv_ds[()], dtype=np.float32).reshape(-1, 2)
        if len(uv) != n:
            warnings.append(f"{len(uv):,} texture coordinates for {n:,} vertices; texture not read")
            return None
        image = np.asarray(image_ds[()], dtype=np.uint8).tobytes()
        mime = image_ds.attrs.get("mime_type", "image/png")
        return Texture(uv=uv, image=image, mime_type=str(mime))
    for textures in (part.part.get("textures"), f.get("textures")):
        if isinstance(textures, h5py.Group) and "images" in textures:
            return _mapio_texture(textures, n, warnings)
    if isinstance(uv_ds, h5py.Dataset):
        warnings.append("texture coordinates without a texture image are not kept")
    return None


def _mapio_texture(textures: h5py.Group, n: int, warnings: list[str]) -> Texture | None:
    """Read HDF5MapIO's ``textures/images/<i>`` (raw H5IM pixels) when there is one image."""
    images = [v for v in textures["images"].values() if isinstance(v, h5py.Dataset)]
    coords = textures.get("coords")
    if not images:
        return None
    if len(images) > 1 or not isinstance(coords, h5py.Dataset):
        warnings.append(
            f"{len(images)} texture images with per-face materials: not read (meshmark keeps "
            "one texture per map)"
        )
        return None
    uv_all = np.asarray(coords[()], dtype=np.float32).ravel()
    if uv_all.size not in (2 * n, 3 * n):
        warnings.append(f"{uv_all.size} texture coordinates for {n:,} vertices; texture not read")
        return None
    from PIL import Image

    pixels = np.asarray(images[0][()], dtype=np.uint8)
    buffer = io.BytesIO()
    Image.fromarray(pixels).save(buffer, format="PNG")
    uv = np.ascontiguousarray(uv_all.reshape(n, -1)[:, :2])
    return Texture(uv=uv, image=buffer.getvalue(), mime_type="image/png")


# ------------------------------------------------------------------------------ labels


def _labels(
    f: h5py.File, part: _Part, mm: h5py.Group | None, n_faces: int, warnings: list[str]
) -> tuple[dict[str, LabelClass], dict[int, Instance], npt.NDArray[np.int32]]:
    """Read ``labels/<class>/<instance>`` face-id lists and meshmark's class/instance tables."""
    class_order, colors = _class_table(mm)
    table = _instance_table(mm)
    found: list[tuple[str, str, np.ndarray]] = []
    roots = [part.part.get("labels"), f.get("labels")]
    seen: set[str] = set()
    for root in roots:
        if not isinstance(root, h5py.Group) or root.name in seen:
            continue
        seen.add(root.name)
        for class_name, group in root.items():
            if not isinstance(group, h5py.Group):
                warnings.append(f"{group.name} is not a class group of face-id lists; ignored")
                continue
            if class_name not in class_order:
                class_order.append(class_name)
            for inst_name, ds in group.items():
                if not isinstance(ds, h5py.Dataset) or ds.dtype.kind not in "iu":
                    warnings.append(f"{ds.name} is not a list of face ids; ignored")
                    continue
                found.append((class_name, inst_name, np.asarray(ds[()]).ravel()))

    instances: dict[int, Instance] = {}
    key_to_id: dict[tuple[str, str], int] = {}
    for iid, (cls, name) in table.items():
        if cls not in class_order:
            class_order.append(cls)
        instances[iid] = Instance(cls, name)
        key_to_id[(cls, name)] = iid
    next_id = max(instances, default=-1) + 1

    face_labels = np.full(n_faces, UNLABELLED, dtype=np.int32)
    overlaps = dropped = 0
    for cls, name, ids in found:
        iid = key_to_id.get((cls, name))
        if iid is None:
            iid, next_id = next_id, next_id + 1
            instances[iid] = Instance(cls, name)
            key_to_id[(cls, name)] = iid
        ok = (ids >= 0) & (ids < n_faces)
        if not ok.all():
            dropped += int((~ok).sum())
            ids = ids[ok]
        overlaps += int(np.count_nonzero(face_labels[ids] != UNLABELLED))
        face_labels[ids] = iid
    if dropped:
        warnings.append(
            f"{dropped:,} label face ids are outside 0..{n_faces - 1} (the map has "
            f"{n_faces:,} faces); dropped"
        )
    if overlaps:
        warnings.append(
            f"{overlaps:,} faces belong to more than one label instance; each keeps the last one "
            "read (a face has one label in meshmark)"
        )
    classes = {}
    for i, name in enumerate(class_order):
        color = colors.get(name, class_color(i))
        classes[name] = LabelClass(name, color)
    bad = [n for n in class_order if "_" in n] + [
        i.name for i in instances.values() if "_" in i.name
    ]
    if bad:
        warnings.append(
            "label names containing '_' are rejected by the RViz map display "
            f"(<class>_<instance>); rename: {', '.join(sorted(set(bad)))}"
        )
    return classes, instances, face_labels


def _class_table(mm: h5py.Group | None) -> tuple[list[str], dict[str, tuple[int, int, int]]]:
    if mm is None or "classes/names" not in mm:
        return [], {}
    names = [str(s) for s in np.asarray(mm["classes/names"].asstr()[()]).ravel()]
    colors_ds = mm.get("classes/colors")
    colors: dict[str, tuple[int, int, int]] = {}
    if isinstance(colors_ds, h5py.Dataset):
        rgb = np.asarray(colors_ds[()]).reshape(-1, 3)
        for name, c in zip(names, rgb, strict=False):
            colors[name] = (int(c[0]), int(c[1]), int(c[2]))
    return names, colors


def _instance_table(mm: h5py.Group | None) -> dict[int, tuple[str, str]]:
    if mm is None or "instances/ids" not in mm:
        return {}
    ids = np.asarray(mm["instances/ids"][()]).ravel()
    classes = np.asarray(mm["instances/classes"].asstr()[()]).ravel()
    names = np.asarray(mm["instances/names"].asstr()[()]).ravel()
    return {int(i): (str(c), str(n)) for i, c, n in zip(ids, classes, names, strict=True)}


def _goals(mm: h5py.Group | None, warnings: list[str]) -> list[Goal]:
    if mm is None or "goals/names" not in mm:
        return []
    try:
        names = np.asarray(mm["goals/names"].asstr()[()]).ravel()
        frames = np.asarray(mm["goals/frame_ids"].asstr()[()]).ravel()
        positions = np.asarray(mm["goals/positions"][()], dtype=np.float64).reshape(-1, 3)
        quats = np.asarray(mm["goals/orientations_xyzw"][()], dtype=np.float64).reshape(-1, 4)
    except KeyError as exc:
        warnings.append(f"goals in /meshmark/goals are incomplete ({exc}); not read")
        return []
    if not len(names) == len(frames) == len(positions) == len(quats):
        warnings.append("goal tables in /meshmark/goals differ in length; goals not read")
        return []
    return [
        Goal(str(name), tuple(map(float, p)), tuple(map(float, q)), str(frame))  # type: ignore[arg-type]
        for name, frame, p, q in zip(names, frames, positions, quats, strict=True)
    ]


def _settings(mm: h5py.Group | None, warnings: list[str]) -> dict[str, Any]:
    """Return meshmark's saved settings (layer parameters, class costs), or {}."""
    if mm is None or "settings" not in mm:
        return {}
    try:
        raw = mm["settings"][()].reshape(-1)[0]
        value = json.loads(raw.decode() if isinstance(raw, bytes) else str(raw))
    except (ValueError, IndexError, TypeError, KeyError, AttributeError) as exc:
        warnings.append(f"meshmark settings could not be read and were reset ({exc})")
        return {}
    if not isinstance(value, dict):
        warnings.append("meshmark settings were not a mapping and were reset")
        return {}
    return value


def _short(exc: BaseException) -> str:
    text = str(exc) or type(exc).__name__
    return text if len(text) <= 200 else text[:197] + "..."


#: suffix -> reader, merged into ``storage.io``'s registry.
READERS = {".h5": read_hdf5, ".hdf5": read_hdf5}
