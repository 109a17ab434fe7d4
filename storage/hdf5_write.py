"""Write a ``MapData`` as an HDF5 map in the current layout, atomically.

The layout is what lvr2 >= 25.1, mesh_navigation and the mesh_tools map display read (research
notes §1, names in ``storage.hdf5_layout``): float32 vertices and uint32 faces exactly, every
dataset 2-D, ``/mesh`` with its two string attributes, normals where mesh_map looks for them,
vertex colours twice, labels as uint32 [n, 1] face ids, no edge data. Vertices far from 0 are
stored relative to a float64 origin kept in ``/meshmark/origin``. Compression is gzip (with
the shuffle filter, both built into every HDF5 library) or none: lvr2's reader cannot decode
lzf or Blosc.
"""

from __future__ import annotations

import itertools
import json
import logging
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np
import numpy.typing as npt

from geometry import local_origin, lvr2_normals
from storage import hdf5_layout as L
from storage.atomic import atomic_path
from storage.errors import MapFormatError
from storage.model import MapData

logger = logging.getLogger(__name__)

#: gzip level: 1 compresses these arrays almost as well as 9 at a third of the time (measured
#: on the 1M-face bench terrain: level 1 ~27 MB in ~0.55 s, level 4 ~27 MB ~0.6 s, level 9
#: ~27 MB ~1.1 s; with shuffle), and saving is what the user waits for.
GZIP_LEVEL = 1
#: Rows per chunk: large enough for good ratios and few chunk lookups, small enough that
#: HDF5 never holds more than a few MB of one dataset in a filter buffer.
CHUNK_ROWS = 65_536
COMPRESSIONS = ("gzip", None)
_STR = h5py.string_dtype()


@dataclass(eq=False)
class _Plan:
    """Every array that goes into the file, prepared before the file is opened."""

    datasets: dict[str, np.ndarray] = field(default_factory=dict)
    strings: dict[str, np.ndarray] = field(default_factory=dict)  # object arrays [k, w]
    attrs: dict[str, dict[str, object]] = field(default_factory=dict)
    groups: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)  #: what the user should know about the file


def write_hdf5(data: MapData, path: str | Path, *, compression: str | None = "gzip") -> list[str]:
    """Write ``data`` to ``path`` in the current HDF5 layout, replacing any file atomically.

    Returns
    -------
    list of str
        Notes for the user about how other tools will see the file (a far-away origin, a
        texture only meshmark reads, label names the RViz display rejects); often empty.

    Raises
    ------
    MapFormatError
        When the data cannot be written as a map (names HDF5 cannot hold, arrays whose
        length does not fit the mesh) or the file cannot be written; an existing file at
        ``path`` is then left as it was.
    ValueError
        For a compression other than ``"gzip"`` or None.
    """
    if compression not in COMPRESSIONS:
        raise ValueError(
            f"compression must be 'gzip' or None, not {compression!r} "
            "(lvr2's HDF5 reader cannot decode lzf or Blosc)"
        )
    path = Path(path)
    plan = plan_file(data, path)
    if path.is_dir():
        raise MapFormatError(path, "is a folder; choose a file name ending in .h5")
    try:
        with atomic_path(path) as tmp, h5py.File(tmp, "w") as f:
            _write(f, plan, compression)
    except OSError as exc:
        raise MapFormatError(path, f"cannot be written: {exc.strerror or exc}") from exc
    except (ValueError, TypeError, UnicodeError) as exc:  # e.g. a name HDF5 cannot encode
        logger.debug("writing %s failed", path, exc_info=True)
        raise MapFormatError(path, f"cannot be written: {exc}") from exc
    for note in plan.notes:
        logger.info("%s: %s", path.name, note)
    return plan.notes


def plan_file(data: MapData, path: str | Path) -> _Plan:
    """Check ``data`` and turn it into the arrays of the file (normals, labels grouped...)."""
    n, f = data.n_vertices, data.n_faces
    if n == 0 or f == 0:
        raise MapFormatError(path, "an empty mesh cannot be saved as a map")
    plan = _Plan()
    origin = _origin(data)
    local = data.vertices - origin if origin.any() else data.vertices
    faces = data.faces
    face_n, vertex_n = lvr2_normals(local, faces, dtype=np.float32)

    plan.attrs[L.PART] = dict(L.PART_ATTRS)
    plan.datasets["version"] = np.int32(L.VERSION)  # type: ignore[assignment]
    plan.datasets[f"{L.GEOMETRY}/vertices"] = local.astype(np.float32)
    plan.datasets[f"{L.GEOMETRY}/face_indices"] = faces.astype(np.uint32)
    plan.datasets[f"{L.GEOMETRY}/vertex_normals"] = vertex_n
    plan.datasets[f"{L.FACE_ATTRIBUTES}/face_normals"] = face_n

    stored_names: dict[str, str] = {}
    for name, values in data.layers.items():
        stored = _layer_dataset_name(name, stored_names)
        values = np.asarray(values, dtype=np.float32).reshape(-1)
        if len(values) != n:
            raise MapFormatError(
                path, f"layer {name!r} has {len(values):,} values for {n:,} vertices"
            )
        stored_names[stored] = name
        plan.datasets[f"{L.VERTEX_ATTRIBUTES}/{stored}"] = values.reshape(n, 1)
    plan.datasets[f"{L.VERTEX_ATTRIBUTES}/vertex_normals"] = vertex_n
    if data.vertex_colors is not None:
        colors = np.ascontiguousarray(data.vertex_colors, dtype=np.uint8)
        if colors.shape != (n, 3):
            raise MapFormatError(path, f"vertex colours have shape {colors.shape}, not ({n}, 3)")
        plan.datasets[f"{L.GEOMETRY}/vertex_colors"] = colors
        plan.datasets[f"{L.VERTEX_ATTRIBUTES}/vertex_colors"] = colors
    if data.texture is not None:
        uv = np.ascontiguousarray(data.texture.uv, dtype=np.float32)
        if uv.shape != (n, 2):
            raise MapFormatError(path, f"texture coordinates have shape {uv.shape}, not ({n}, 2)")
        plan.datasets[f"{L.GEOMETRY}/texture_coordinates"] = uv
        plan.datasets[L.TEXTURE] = np.frombuffer(data.texture.image, np.uint8).reshape(-1, 1)
        plan.attrs[L.TEXTURE] = {
            "mime_type": data.texture.mime_type,
            "uv_origin": "bottom-left (OBJ and trimesh convention: v = 0 at the image bottom)",
        }
        plan.notes.append(
            "the texture is stored under /meshmark for meshmark; lvr2, mesh_navigation and "
            "the RViz map display ignore it"
        )
    renamed = [[s, o] for s, o in stored_names.items() if s != o]
    if renamed:
        plan.strings[L.LAYER_NAMES] = _str_table(renamed, 2)

    _plan_labels(plan, data, path)
    _plan_goals(plan, data)
    settings = data.meta.get("settings")
    if settings:
        try:
            text = json.dumps(settings, sort_keys=True, allow_nan=False)
        except (TypeError, ValueError) as exc:
            raise MapFormatError(path, f"meshmark settings cannot be saved: {exc}") from exc
        plan.strings[L.SETTINGS] = _str_table([text])
    plan.attrs[L.MESHMARK] = {"format_version": L.MESHMARK_FORMAT_VERSION, "writer": "meshmark"}
    if origin.any():
        plan.datasets[L.ORIGIN] = origin.reshape(1, 3)
        shown = ", ".join(f"{v:.0f}" for v in origin)
        plan.notes.append(
            f"vertices are stored relative to the origin ({shown}) kept in /meshmark/origin "
            "(float32 would lose precision); mesh_navigation and RViz see the map shifted by it"
        )
    plan.groups = [L.GEOMETRY, L.VERTEX_ATTRIBUTES, L.FACE_ATTRIBUTES, L.LABELS, L.MESHMARK]
    return plan


def _origin(data: MapData) -> npt.NDArray[np.float64]:
    """Use the document's origin when it has one, else choose one for far-away coordinates."""
    stored = data.meta.get("origin")
    if stored is not None:
        origin = np.asarray(stored, dtype=np.float64).ravel()
        if origin.shape == (3,) and np.isfinite(origin).all():
            return origin
    return local_origin(data.vertices)


def _layer_dataset_name(name: str, taken: Iterable[str]) -> str:
    """Return an HDF5 dataset name for layer ``name`` that no reader mistakes for geometry.

    '/' would make a subgroup, '.' and '..' are not names, the reserved per-vertex names are
    geometry, and ``*_idx`` marks a sparse index for lvr2: such names get a suffix, and the
    original name is kept in ``/meshmark/layer_names``.
    """
    stored = name.replace("/", "-").strip() or "layer"
    if stored in L.RESERVED_VERTEX_NAMES or stored in (".", "..") or stored.endswith("_idx"):
        stored = f"{stored}-layer"
    used = set(taken)
    candidate, k = stored, 2
    while candidate in used or candidate in L.RESERVED_VERTEX_NAMES:
        candidate, k = f"{stored}-{k}", k + 1
    return candidate


def _plan_labels(plan: _Plan, data: MapData, path: str | Path) -> None:
    """Group labelled faces by instance with one argsort (sorted uint32 [n, 1] per instance)."""
    names = [(cls.name, "label class") for cls in data.classes.values()]
    names += [(i.name, f"instance of {i.class_name!r}") for i in data.instances.values()]
    for name, what in names:
        _check_label_name(path, name, what)
    underscores = sorted({name for name, _ in names if "_" in name})
    if underscores:
        plan.notes.append(
            "the RViz map display rejects label names containing '_' (it splits "
            f"<class>_<instance>): {', '.join(underscores)}"
        )
    labels = data.face_labels
    assert labels is not None
    if len(labels) != data.n_faces:
        raise MapFormatError(path, f"{len(labels):,} face labels for {data.n_faces:,} faces")
    labelled = np.flatnonzero(labels >= 0)
    ids = labels[labelled]
    order = np.argsort(ids, kind="stable")
    faces_sorted = labelled[order].astype(np.uint32)
    ids_sorted = ids[order]
    starts = np.flatnonzero(np.r_[True, ids_sorted[1:] != ids_sorted[:-1]]) if len(ids) else []
    bounds = [*list(starts), len(ids_sorted)]
    by_path: dict[str, list[np.ndarray]] = {}
    for a, b in itertools.pairwise(bounds):
        iid = int(ids_sorted[a])
        inst = data.instances.get(iid)
        if inst is None:
            logger.warning("%d faces carry unknown instance id %d; not saved", b - a, iid)
            continue
        by_path.setdefault(f"{L.LABELS}/{inst.class_name}/{inst.name}", []).append(
            faces_sorted[a:b]
        )
    for key, chunks in by_path.items():
        merged = chunks[0] if len(chunks) == 1 else np.sort(np.concatenate(chunks))
        plan.datasets[key] = merged.reshape(-1, 1)

    names = list(data.classes)
    plan.strings[L.CLASS_NAMES] = _str_table(names)
    plan.datasets[L.CLASS_COLORS] = np.array(
        [data.classes[n].color for n in names], dtype=np.uint8
    ).reshape(-1, 3)
    iids = sorted(data.instances)
    plan.datasets[L.INSTANCE_IDS] = np.array(iids, dtype=np.int32).reshape(-1, 1)
    plan.strings[L.INSTANCE_CLASSES] = _str_table([data.instances[i].class_name for i in iids])
    plan.strings[L.INSTANCE_NAMES] = _str_table([data.instances[i].name for i in iids])


def _check_label_name(path: str | Path, name: str, what: str) -> None:
    if not name or "/" in name or name in (".", ".."):
        raise MapFormatError(
            path, f"the {what} {name!r} cannot be an HDF5 name (empty, '/', '.' or '..')"
        )


def _plan_goals(plan: _Plan, data: MapData) -> None:
    goals = data.goals
    plan.strings[L.GOAL_NAMES] = _str_table([g.name for g in goals])
    plan.strings[L.GOAL_FRAME_IDS] = _str_table([g.frame_id for g in goals])
    plan.datasets[L.GOAL_POSITIONS] = np.array(
        [g.position for g in goals], dtype=np.float64
    ).reshape(-1, 3)
    plan.datasets[L.GOAL_ORIENTATIONS] = np.array(
        [g.orientation_xyzw for g in goals], dtype=np.float64
    ).reshape(-1, 4)


def _str_table(values: list[str] | list[list[str]], width: int = 1) -> np.ndarray:
    """Return strings as an object array [k, width]: every meshmark dataset is 2-D too."""
    table = np.empty((len(values), width), dtype=object)
    for row, value in enumerate(values):
        table[row] = value
    return table


# ------------------------------------------------------------------------------ writing


def _write(f: h5py.File, plan: _Plan, compression: str | None) -> None:
    for group in plan.groups:
        # creation order: layers come back in the order the user had them
        f.create_group(group, track_order=group == L.VERTEX_ATTRIBUTES)
    for name, a in plan.datasets.items():
        _put(f, name, a, compression)
    for name, table in plan.strings.items():
        f.create_dataset(name, data=table, dtype=_STR)
    for name, attrs in plan.attrs.items():
        obj = f.require_group(name) if name not in f else f[name]
        for key, value in attrs.items():
            obj.attrs[key] = value


def _put(f: h5py.File, name: str, a: np.ndarray, compression: str | None) -> None:
    """Create one dataset: chunked and compressed when it has data, contiguous when empty."""
    if a.ndim == 0 or a.size == 0 or compression is None:
        f.create_dataset(name, data=a)
        return
    rows = min(len(a), CHUNK_ROWS)
    f.create_dataset(
        name,
        data=a,
        chunks=(rows, *a.shape[1:]),
        compression=compression,
        compression_opts=GZIP_LEVEL,
        shuffle=True,
    )
