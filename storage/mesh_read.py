"""Read PLY, OBJ (+MTL, texture), GLB/glTF, STL and OFF through trimesh into ``MapData``.

Face ids are label ids, so face order and count follow the file: scenes are concatenated in
node order (node transforms applied), polygons are fan-triangulated where they stand, and
nothing is merged or removed (``process=False``). Vertices follow the file too, except that
textured OBJ files are split at UV seams (one vertex per position and UV pair) and STL
triangle soups are welded at identical positions; both are reported in ``meta["notes"]``.

What trimesh repairs silently is found first (``storage.obj_scan``, the PLY header) and
reported in ``MapData.warnings``; trimesh's own log lines during the load are captured too.
"""

from __future__ import annotations

import contextlib
import io
import json
import logging
import re
import struct
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import trimesh
from trimesh.visual.color import ColorVisuals
from trimesh.visual.texture import TextureVisuals

from storage import gltf_scan
from storage.colors import NAN_GREY, colors_to_uint8, nan_color_warning
from storage.errors import MapFormatError
from storage.mesh_checks import check_geometry
from storage.model import MapData, Texture
from storage.obj_scan import ObjScan, read_obj_plain, scan_obj
from storage.polygons import Triangulated, fan_triangulate, split_seams

logger = logging.getLogger(__name__)

#: PLY vertex properties that are geometry or appearance, not scalar layers.
_PLY_NOT_LAYERS = frozenset(
    {"x", "y", "z", "nx", "ny", "nz", "s", "t", "u", "v"}
    | {"red", "green", "blue", "alpha", "r", "g", "b", "a"}
    | {"diffuse_red", "diffuse_green", "diffuse_blue", "diffuse_alpha"}
    | {"texture_u", "texture_v", "texture_s", "texture_t"}
)
_PLY_COLOR_NAMES = (
    ("red", "green", "blue"),
    ("r", "g", "b"),
    ("diffuse_red", "diffuse_green", "diffuse_blue"),
)
_PLY_UV_NAMES = (("texture_u", "texture_v"), ("u", "v"), ("s", "t"), ("texture_s", "texture_t"))


def read_obj(path: Path) -> MapData:
    """Read a Wavefront OBJ (with its MTL and texture when they exist)."""
    scan = scan_obj(path)
    if scan.positions == 0 and scan.face_lines == 0:
        raise MapFormatError(path, "no vertices or faces found; not an OBJ mesh")
    warnings = _obj_warnings(scan)
    notes: list[str] = []
    if len(scan.materials) > 1:
        return _read_obj_in_order(path, scan, warnings)
    texture_file = scan.texture_file
    with _captured_trimesh_log() as log:
        scene = trimesh.load_scene(
            path,
            file_type="obj",
            process=False,
            maintain_order=texture_file is None,
            skip_materials=texture_file is None,
        )
    _add_log_warnings(log, warnings, known=_OBJ_LOG_KNOWN)
    mesh = _concatenate(path, scene, warnings, notes, textures=False)
    if mesh.colors is not None and scan.nan_color_ids and len(mesh.vertices) == scan.positions:
        mesh.colors[scan.nan_color_ids] = NAN_GREY
        warnings.append(nan_color_warning(len(scan.nan_color_ids)))
    if texture_file is not None and mesh.uv is not None:
        mesh.texture = _texture_from_file(texture_file, mesh.uv, warnings)
        if len(mesh.vertices) != scan.positions:
            notes.append(
                f"vertices split at texture seams: the file's {scan.positions:,} positions "
                f"became {len(mesh.vertices):,} vertices (face ids unchanged)"
            )
    elif scan.uvs:
        warnings.append("texture coordinates without a texture image are not kept")
    return mesh.to_map_data(path, "obj", warnings, notes)


def _obj_warnings(scan: ObjScan) -> list[str]:
    warnings = []
    if scan.short_faces:
        warnings.append(f"skipped {scan.short_faces:,} face line(s) with fewer than 3 vertices")
    if scan.polygons:
        warnings.append(
            f"{scan.polygons:,} polygon face(s) with more than 3 corners split into "
            f"{scan.polygon_triangles:,} triangles (fan, in place: face ids count triangles)"
        )
    for name in scan.missing_mtl:
        warnings.append(f"material library {name!r} not found; read without its materials")
    for mtl, image in scan.missing_textures:
        warnings.append(f"texture image {image!r} named in {mtl} not found; read untextured")
    return warnings


def _read_obj_in_order(path: Path, scan: ObjScan, warnings: list[str]) -> MapData:
    """Read an OBJ whose faces use several materials without trimesh, keeping face order."""
    vertices, colors, faces, _ = read_obj_plain(scan.text)
    warnings.append(
        f"faces use {len(scan.materials)} materials; read in file order without materials "
        "or textures (meshmark keeps one texture per map)"
    )
    mesh = _Mesh(vertices, faces)
    if colors is not None:
        mesh.colors = colors_to_uint8(colors, len(vertices), warnings, where="vertex colours")
    return mesh.to_map_data(path, "obj", warnings, [])


def read_ply(path: Path) -> MapData:
    """Read a PLY: faces from the file's own polygon list, scalar vertex properties as layers."""
    warnings: list[str] = []
    notes: list[str] = []
    texture_name = _ply_texture_name(path)
    with _captured_trimesh_log() as log:
        scene = trimesh.load_scene(path, file_type="ply", process=False, fix_texture=False)
    _add_log_warnings(log, warnings, known={})
    geometries = list(scene.geometry.values())
    raw = geometries[0].metadata.get("_ply_raw") if len(geometries) == 1 else None
    if raw is None or "vertex" not in raw:
        mesh = _concatenate(path, scene, warnings, notes)
        return mesh.to_map_data(path, "ply", warnings, notes)
    vertex = _columns(raw["vertex"]["data"])
    vertices = np.column_stack([vertex[c] for c in "xyz"]).astype(np.float64)
    face = _columns(raw["face"]["data"]) if "face" in raw and raw["face"]["length"] else {}
    polygons = next((face[k] for k in ("vertex_indices", "vertex_index") if k in face), None)
    if polygons is None:
        check_geometry(path, vertices, np.zeros((0, 3), np.int64), warnings)
    tri = fan_triangulate(polygons)  # type: ignore[arg-type]
    if tri.short:
        warnings.append(f"skipped {tri.short:,} face(s) with fewer than 3 vertices")
    if tri.polygons:
        warnings.append(
            f"{tri.polygons:,} polygon face(s) with more than 3 corners split into triangles "
            "(fan, in place: face ids count triangles)"
        )
    mesh = _Mesh(vertices, tri.faces)
    color_names = next((c for c in _PLY_COLOR_NAMES if all(k in vertex for k in c)), None)
    if color_names is not None:
        rgb = np.column_stack([vertex[c] for c in color_names])
        mesh.colors = colors_to_uint8(rgb, len(vertices), warnings, where="PLY vertex colours")
    for name, values in vertex.items():
        if name in _PLY_NOT_LAYERS:
            continue
        if values.dtype.kind in "fiub" and values.ndim == 1:
            mesh.layers[name] = values.astype(np.float32)
        else:
            warnings.append(f"PLY vertex property {name!r} is not a scalar; not read")
    per_face = [k for k in face if k not in ("vertex_indices", "vertex_index", "texcoord")]
    if per_face:
        warnings.append(
            f"per-face data not read (meshmark keeps per-vertex layers only): {', '.join(per_face)}"
        )
    _ply_texture(path, mesh, vertex, face, tri, texture_name, warnings, notes)
    return mesh.to_map_data(path, "ply", warnings, notes)


def _ply_texture(
    path: Path,
    mesh: _Mesh,
    vertex: dict[str, np.ndarray],
    face: dict[str, np.ndarray],
    tri: Triangulated,
    texture_name: str | None,
    warnings: list[str],
    notes: list[str],
) -> None:
    """Attach a ``comment TextureFile`` image with per-vertex or per-corner UVs."""
    uv_names = next((p for p in _PLY_UV_NAMES if all(k in vertex for k in p)), None)
    has_uv = uv_names is not None or "texcoord" in face
    image = (path.parent / texture_name) if texture_name else None
    if texture_name and not (image and image.is_file()):
        warnings.append(f"texture image {texture_name!r} not found; read untextured")
        return
    if image is None:
        if has_uv:
            warnings.append("texture coordinates without a texture image are not kept")
        return
    if uv_names is not None:
        uv = np.column_stack([vertex[uv_names[0]], vertex[uv_names[1]]]).astype(np.float32)
        mesh.texture = _texture_from_file(image, uv, warnings)
        return
    if "texcoord" not in face:
        warnings.append(f"texture image {texture_name!r} but no texture coordinates; untextured")
        return
    corner = _per_corner_uv(face["texcoord"], tri)
    if corner is None:
        warnings.append("per-face texture coordinates do not fit the faces; read untextured")
        return
    n_before = len(mesh.vertices)
    faces, source, uv = split_seams(mesh.faces, corner)
    mesh.faces, mesh.vertices = faces, mesh.vertices[source]
    mesh.layers = {k: v[source] for k, v in mesh.layers.items()}
    if mesh.colors is not None:
        mesh.colors = mesh.colors[source]
    mesh.texture = _texture_from_file(image, uv, warnings)
    if len(source) != n_before:
        notes.append(
            f"vertices split at texture seams: the file's {n_before:,} vertices became "
            f"{len(source):,} (face ids unchanged)"
        )


def _per_corner_uv(texcoord: np.ndarray, tri: Triangulated) -> np.ndarray | None:
    """Return per-corner UVs [T, 3, 2] for the triangulated faces, or None when they do not fit."""
    rows = [np.asarray(t, dtype=np.float32).reshape(-1, 2) for t in texcoord]
    if tri.polygons or any(len(r) != 3 for r in rows):
        return None
    return np.stack(rows)[tri.source]


def _ply_texture_name(path: Path) -> str | None:
    """Return the ``comment TextureFile <name>`` of a PLY header, if any."""
    with open(path, "rb") as fh:
        head = fh.read(65536)
    end = head.find(b"end_header")
    m = re.search(rb"^comment\s+TextureFile\s+(\S[^\r\n]*)", head[: max(end, 0)], re.M)
    return m.group(1).decode("utf-8", "replace").strip() if m else None


def _columns(data: Any) -> dict[str, np.ndarray]:
    """Return a PLY element's properties as name -> array (structured array or dict)."""
    if isinstance(data, dict):
        out = {}
        for k, v in data.items():
            a = np.asarray(v)
            out[k] = a.reshape(-1) if a.dtype != object and a.ndim == 2 and a.shape[1] == 1 else a
            if a.dtype == object:
                out[k] = a.reshape(-1)
        return out
    out = {}
    for name in data.dtype.names or ():
        column = data[name]
        if column.dtype.names and "f1" in column.dtype.names:  # binary list: (count, values)
            column = column["f1"]
        out[name] = column
    return out


def read_scene(path: Path, file_type: str) -> MapData:
    """Read GLB/glTF, STL or OFF: every mesh node of the scene, transformed and concatenated."""
    warnings: list[str] = []
    notes: list[str] = []
    if file_type == "gltf":
        try:
            json.loads(path.read_bytes())
        except (ValueError, UnicodeDecodeError) as exc:
            raise MapFormatError(path, "not a valid glTF file: not JSON text") from exc
    with _captured_trimesh_log() as log:
        scene = trimesh.load_scene(path, file_type=file_type, process=False, maintain_order=True)
    _add_log_warnings(log, warnings, known={})
    if not scene.geometry and path.stat().st_size > 0 and file_type != "gltf":
        raise MapFormatError(path, f"no triangles found; not a valid {file_type.upper()} mesh file")
    mesh = _concatenate(path, scene, warnings, notes)
    if file_type == "stl":
        _weld(mesh, notes)
    return mesh.to_map_data(path, file_type, warnings, notes)


# ------------------------------------------------------------------------ concatenation


class _Mesh:
    """The arrays a reader collects before they become ``MapData``."""

    def __init__(self, vertices: np.ndarray, faces: np.ndarray) -> None:
        self.vertices = vertices
        self.faces = faces
        self.colors: npt.NDArray[np.uint8] | None = None
        self.uv: npt.NDArray[np.float32] | None = None
        self.texture: Texture | None = None
        self.layers: dict[str, np.ndarray] = {}

    def to_map_data(self, path: Path, fmt: str, warnings: list[str], notes: list[str]) -> MapData:
        check_geometry(path, self.vertices, self.faces, warnings)
        return MapData(
            vertices=self.vertices,
            faces=self.faces,
            layers=self.layers,
            vertex_colors=self.colors,
            texture=self.texture,
            meta={"format": fmt, "source_name": path.name, "notes": notes, "ignored": []},
            warnings=warnings,
        )


def _concatenate(
    path: Path,
    scene: trimesh.Scene,
    warnings: list[str],
    notes: list[str],
    *,
    textures: bool = True,
) -> _Mesh:
    """Concatenate every mesh node of ``scene`` in node order, with its transform applied.

    With ``textures`` False only the UVs are collected (the caller knows the image file).
    """
    parts: list[tuple[trimesh.Trimesh, np.ndarray]] = []
    skipped: list[str] = []
    order = _file_order(path, scene)
    if order is None:
        order = list(scene.graph.nodes_geometry)
        if len(order) > 1 and path.suffix.lower() in (".glb", ".gltf"):
            notes.append("scene node order could not be matched to the file; trimesh's order used")
    for node in order:
        transform, name = scene.graph[node]
        geometry = scene.geometry[name]
        if isinstance(geometry, trimesh.Trimesh) and len(geometry.faces):
            parts.append((geometry, np.asarray(transform, dtype=np.float64)))
        else:
            skipped.append(f"{name} ({type(geometry).__name__})")
    if skipped:
        warnings.append(f"not a triangle mesh, skipped: {', '.join(skipped)}")
    if not parts:
        n = sum(len(getattr(g, "vertices", ())) for g in scene.geometry.values())
        check_geometry(path, np.zeros((n, 3)), np.zeros((0, 3), np.int64), warnings)
    vertices, faces, offset = [], [], 0
    for g, m in parts:
        v = np.asarray(g.vertices, dtype=np.float64) @ m[:3, :3].T + m[:3, 3]
        f = np.asarray(g.faces, dtype=np.int64)
        if np.linalg.det(m[:3, :3]) < 0:  # a mirroring transform flips the winding
            f = f[:, ::-1]
        vertices.append(v)
        faces.append(f + offset)
        offset += len(v)
    mesh = _Mesh(np.concatenate(vertices), np.concatenate(faces))
    if len(parts) > 1:
        notes.append(f"{len(parts)} scene meshes concatenated in the file's node order")
    geometries = [g for g, _ in parts]
    mesh.colors = _scene_colors(geometries, warnings)
    if textures:
        _scene_texture(path, geometries, mesh, warnings)
    else:
        uvs = [_uv(g) for g in geometries]
        if all(u is not None for u in uvs):
            mesh.uv = np.concatenate(uvs).astype(np.float32)  # type: ignore[arg-type]
    return mesh


def _file_order(path: Path, scene: trimesh.Scene) -> list[str] | None:
    """Return the scene's mesh nodes in the glTF file's order (trimesh visits them reversed).

    Each primitive of the file (depth-first through the scene's nodes, children and
    primitives in order) is matched to the trimesh node with the same vertex and face
    counts and the same world transform. None when the file is not glTF or a match fails.
    """
    if path.suffix.lower() not in (".glb", ".gltf") or len(scene.graph.nodes_geometry) < 2:
        return None
    try:
        wanted = gltf_scan.primitive_order(path)
    except (OSError, ValueError, KeyError, IndexError, TypeError, struct.error):
        logger.debug("could not read the node order of %s", path, exc_info=True)
        return None
    free = []
    for node in scene.graph.nodes_geometry:
        transform, name = scene.graph[node]
        g = scene.geometry[name]
        if isinstance(g, trimesh.Trimesh) and len(g.faces):
            free.append((node, len(g.vertices), len(g.faces), np.asarray(transform)))
    if len(free) != len(wanted):
        return None
    order = []
    for nv, nf, world in wanted:
        match = next(
            (
                item
                for item in free
                if item[1] == nv
                and item[2] == nf
                and np.allclose(item[3], world, rtol=1e-6, atol=1e-6)
            ),
            None,
        )
        if match is None:
            return None
        free.remove(match)
        order.append(match[0])
    return order


def _uv(g: trimesh.Trimesh) -> np.ndarray | None:
    uv = getattr(g.visual, "uv", None) if isinstance(g.visual, TextureVisuals) else None
    return None if uv is None or len(uv) != len(g.vertices) else np.asarray(uv)


def _scene_colors(parts: list[trimesh.Trimesh], warnings: list[str]) -> np.ndarray | None:
    """Return vertex colours when any part has vertex or face colours (others get theirs)."""
    kinds = [getattr(g.visual, "kind", None) for g in parts]
    if not any(k in ("vertex", "face") for k in kinds):
        return None
    if "face" in kinds:
        warnings.append("per-face colours converted to vertex colours (averaged)")
    out = []
    for g, kind in zip(parts, kinds, strict=True):
        if kind in ("vertex", "face") and isinstance(g.visual, ColorVisuals):
            out.append(np.asarray(g.visual.vertex_colors)[:, :3])
        else:
            main = getattr(g.visual, "main_color", None)
            if main is None and hasattr(g.visual, "material"):
                main = getattr(g.visual.material, "main_color", None)
            rgb = np.asarray(main if main is not None else (NAN_GREY,) * 3, dtype=np.uint8)[:3]
            out.append(np.broadcast_to(rgb, (len(g.vertices), 3)))
    return np.ascontiguousarray(np.concatenate(out), dtype=np.uint8)


def _scene_texture(
    path: Path, parts: list[trimesh.Trimesh], mesh: _Mesh, warnings: list[str]
) -> None:
    """Keep one texture: the file's own image bytes when every part uses that one image."""
    images = [_base_image(g.visual) for g in parts]
    uvs = [_uv(g) for g in parts]
    if all(i is None for i in images):
        if any(u is not None for u in uvs):
            warnings.append("texture coordinates without a texture image are not kept")
        return
    mesh.uv = None
    if all(i is not None for i in images) and all(u is not None for u in uvs):
        uv = np.concatenate([np.asarray(u, dtype=np.float32) for u in uvs])
        distinct = {id(i) for i in images}
        if len(distinct) == 1 or len({_image_key(i) for i in images}) == 1:
            mesh.uv = uv
            original = _original_image(path, images[0])
            if original is not None:
                mesh.texture = Texture(uv=uv, image=original[0], mime_type=original[1])
            else:
                mesh.texture = _encode_texture(images[0], uv)
            return
    # several images, or textured and untextured parts: let trimesh pack one atlas
    try:
        merged = trimesh.util.concatenate(parts)
        image = _base_image(merged.visual)
        uv = getattr(merged.visual, "uv", None)
    except Exception:  # packing is best effort: geometry matters, texture is optional
        logger.debug("packing textures of %s failed", path, exc_info=True)
        image, uv = None, None
    if image is None or uv is None or len(uv) != len(mesh.vertices):
        warnings.append("several textures could not be combined into one; read untextured")
        return
    mesh.texture = _encode_texture(image, np.asarray(uv, dtype=np.float32))
    warnings.append(
        f"{len(parts)} materials packed into one {image.size[0]}x{image.size[1]} texture "
        "atlas (re-encoded as PNG)"
    )


def _base_image(visual: Any) -> Any:
    """Return the base-colour PIL image of a textured visual, or None."""
    if not isinstance(visual, TextureVisuals) or visual.uv is None:
        return None
    # glTF materials only: OBJ's SimpleMaterial invents a 2x2 image when it has none, so
    # OBJ textures come from the MTL's map_Kd file (see read_obj)
    return getattr(visual.material, "baseColorTexture", None)


def _image_key(image: Any) -> tuple[Any, ...]:
    return (image.size, image.mode, hash(image.tobytes()))


def _weld(mesh: _Mesh, notes: list[str]) -> None:
    """Merge STL corners at identical positions (STL stores every triangle on its own)."""
    unique, first, inverse = np.unique(
        mesh.vertices, axis=0, return_index=True, return_inverse=True
    )
    if len(unique) == len(mesh.vertices):
        return
    order = np.argsort(first, kind="stable")
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    mesh.faces = rank[inverse.ravel()][mesh.faces]
    n = len(mesh.vertices)
    mesh.vertices = mesh.vertices[first[order]]
    if mesh.colors is not None:
        mesh.colors = mesh.colors[first[order]]
    notes.append(f"STL corners welded at identical positions: {n:,} became {len(unique):,}")


# ------------------------------------------------------------------------------ textures


def _texture_from_file(image: Path, uv: np.ndarray, warnings: list[str]) -> Texture | None:
    """Keep a PNG or JPEG file byte-exact; re-encode anything else as PNG."""
    data = image.read_bytes()
    mime = _mime(data)
    if mime is not None:
        return Texture(uv=np.asarray(uv, dtype=np.float32), image=data, mime_type=mime)
    try:
        from PIL import Image

        with Image.open(io.BytesIO(data)) as im:
            return _encode_texture(im, uv)
    except Exception as exc:  # an unreadable image must not cost the geometry
        warnings.append(f"texture image {image.name!r} cannot be read ({exc}); read untextured")
        return None


def _encode_texture(image: Any, uv: np.ndarray) -> Texture:
    buffer = io.BytesIO()
    if image.mode not in ("RGB", "RGBA", "L", "LA"):
        image = image.convert("RGBA" if "A" in image.getbands() else "RGB")
    image.save(buffer, format="PNG", compress_level=1)  # speed: atlases can be 8k x 4k
    return Texture(uv=np.asarray(uv, dtype=np.float32), image=buffer.getvalue())


def _mime(data: bytes) -> str | None:
    if data.startswith(b"\x89PNG\r\n\x1a\n"):
        return "image/png"
    if data.startswith(b"\xff\xd8\xff"):
        return "image/jpeg"
    return None


def _original_image(path: Path, image: Any) -> tuple[bytes, str] | None:
    """Return the encoded base-colour image of a glTF/GLB as stored, when there is one."""
    if path.suffix.lower() not in (".glb", ".gltf"):
        return None
    try:
        found = gltf_scan.base_color_images(path)
    except (OSError, ValueError, KeyError, IndexError, TypeError, struct.error):
        logger.debug("could not read image bytes of %s", path, exc_info=True)
        return None
    if len(found) != 1:
        return None
    data = found[0]
    mime = _mime(data)
    if mime is None:
        return None
    try:
        from PIL import Image

        with Image.open(io.BytesIO(data)) as im:
            if im.size != image.size:
                return None
    except Exception:
        return None
    return data, mime


# ----------------------------------------------------------------------- trimesh's log

#: trimesh log lines that the OBJ pre-scan already reports in better words.
_OBJ_LOG_KNOWN = {
    "unable to load materials": "",
    "face needs more values": "",
    "specified material": "",
    "failed to load image": "",
    "failed to convert color": "",
    "triangulating faces": "",
    "faces have mixed data": "",
}

_capture_lock = threading.Lock()
_capture_count = 0
_saved_level = logging.NOTSET


class _ThreadLog(logging.Filter):
    """Collect the calling thread's trimesh log records; drop those below the usual level."""

    def __init__(self, pass_level: int) -> None:
        super().__init__()
        self.thread = threading.get_ident()
        self.pass_level = pass_level
        self.records: list[logging.LogRecord] = []

    def filter(self, record: logging.LogRecord) -> bool:
        if record.thread == self.thread:
            self.records.append(record)
        return record.levelno >= self.pass_level


@contextlib.contextmanager
def _captured_trimesh_log() -> Iterator[list[logging.LogRecord]]:
    """Yield a list that fills with trimesh's log records (debug ones too) during the block.

    trimesh's loaders log through ``trimesh.util`` and report skipped faces and missing files
    at debug level. That logger is lowered to DEBUG while a load runs, and the filter drops
    what would not have been shown otherwise, so nothing extra reaches the application's log.
    """
    global _capture_count, _saved_level
    log = logging.getLogger("trimesh.util")
    with _capture_lock:
        if _capture_count == 0:
            _saved_level = log.level
            log.setLevel(logging.DEBUG)
        _capture_count += 1
        parent = log.parent.getEffectiveLevel() if log.parent else logging.WARNING
        pass_level = _saved_level or parent
    catcher = _ThreadLog(pass_level)
    log.addFilter(catcher)
    try:
        yield catcher.records
    finally:
        log.removeFilter(catcher)
        with _capture_lock:
            _capture_count -= 1
            if _capture_count == 0:
                log.setLevel(_saved_level)


def _add_log_warnings(
    records: list[logging.LogRecord], warnings: list[str], *, known: dict[str, str]
) -> None:
    """Turn trimesh warnings into user warnings; debug lines only go to our debug log."""
    for record in records:
        message = record.getMessage()
        logger.debug("trimesh: %s", message)
        if any(message.startswith(k) for k in known):
            continue
        if record.levelno >= logging.WARNING:
            text = f"trimesh: {message}"
            if text not in warnings:
                warnings.append(text)


#: suffix -> reader, merged into ``storage.io``'s registry.
READERS: dict[str, Callable[[Path], MapData]] = {
    ".obj": read_obj,
    ".ply": read_ply,
    ".glb": lambda p: read_scene(p, "glb"),
    ".gltf": lambda p: read_scene(p, "gltf"),
    ".stl": lambda p: read_scene(p, "stl"),
    ".off": lambda p: read_scene(p, "off"),
}
