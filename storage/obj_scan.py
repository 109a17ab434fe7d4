"""What an OBJ file holds that trimesh repairs silently: read it first so warnings are honest.

trimesh skips face lines with fewer than 3 corners, fan-triangulates n-gons, turns NaN vertex
colours into black and loads without a missing ``.mtl`` or texture, logging at most a debug
line. A few regular-expression passes over the text (no per-line Python loop) find each of
these, plus what decides how the file must be loaded: whether it is textured (trimesh then
splits vertices at UV seams) and whether its faces use several materials (trimesh then
regroups faces by material, so meshmark reads such files itself to keep face order).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import numpy.typing as npt

from storage.polygons import fan_triangulate

_CONT = re.compile(rb"\\[ \t]*\r?\n")
_V = re.compile(rb"^[ \t]*v[ \t]", re.M)
_VT = re.compile(rb"^[ \t]*vt[ \t]", re.M)
_F = re.compile(rb"^[ \t]*f[ \t]", re.M)
_F_BODY = re.compile(rb"^[ \t]*f[ \t]([^\r\n#]*)", re.M)
_V_LINE = re.compile(rb"^[ \t]*v[ \t]+([^\r\n#]*)", re.M)
_VF_LINE = re.compile(rb"^[ \t]*(v|f)[ \t]+([^\r\n#]*)", re.M)
_MTLLIB = re.compile(rb"^[ \t]*mtllib[ \t]+([^\r\n#]+)", re.M)
_USEMTL = re.compile(rb"^[ \t]*usemtl[ \t]*([^\r\n#]*)", re.M)
_NEWMTL = re.compile(r"^[ \t]*newmtl[ \t]+([^\r\n#]+)", re.M)
_MAP_KD = re.compile(r"^[ \t]*map_Kd[ \t]+([^\r\n#]+)", re.M)


@dataclass
class ObjScan:
    """Facts about one OBJ file, before any mesh is built."""

    text: bytes = b""  #: the file's bytes, backslash continuations joined
    positions: int = 0  #: ``v`` lines
    uvs: int = 0  #: ``vt`` lines
    face_lines: int = 0
    short_faces: int = 0  #: face lines with fewer than 3 corners (skipped by every loader)
    polygons: int = 0  #: face lines with more than 3 corners
    polygon_triangles: int = 0  #: triangles the polygons become
    continued_lines: int = 0  #: lines joined by a trailing backslash
    nan_color_ids: list[int] = field(default_factory=list)  #: vertices whose colour is NaN
    materials: list[str] = field(default_factory=list)  #: materials that faces use, in order
    missing_mtl: list[str] = field(default_factory=list)
    textures: dict[str, Path] = field(default_factory=dict)  #: material -> existing map_Kd
    missing_textures: list[tuple[str, str]] = field(default_factory=list)  #: (mtl, image)

    @property
    def triangles(self) -> int:
        """Return how many triangles the faces become."""
        return self.face_lines - self.short_faces - self.polygons + self.polygon_triangles

    @property
    def texture_file(self) -> Path | None:
        """Return the one texture image used by the faces, if the file is textured that way."""
        if self.uvs == 0 or len(self.materials) > 1:
            return None
        used = self.materials[0] if self.materials else None
        if used is not None and used in self.textures:
            return self.textures[used]
        return None


def scan_obj(path: Path) -> ObjScan:
    """Read an OBJ file's text and find what loaders hide (see the module docstring)."""
    raw = path.read_bytes()
    data = _CONT.sub(b" ", raw)
    scan = ObjScan(text=data, continued_lines=len(_CONT.findall(raw)))
    scan.positions = _count_lines(data, b"v", _V)
    scan.uvs = _count_lines(data, b"vt", _VT)
    bodies = _F_BODY.findall(data)
    counts = np.fromiter(map(len, map(bytes.split, bodies)), dtype=np.int64, count=len(bodies))
    scan.face_lines = len(counts)
    scan.short_faces = int((counts < 3).sum())
    big = counts[counts > 3]
    scan.polygons, scan.polygon_triangles = len(big), int((big - 2).sum())
    if any(word in data for word in (b"nan", b"NaN", b"NAN", b"Nan")):
        scan.nan_color_ids = _nan_color_ids(data)
    scan.materials = _materials_used(data) if b"usemtl" in data else []
    for m in _MTLLIB.finditer(data) if b"mtllib" in data else ():
        _read_mtl(path.parent, m.group(1).decode("utf-8", "replace").strip(), scan)
    return scan


def _count_lines(data: bytes, keyword: bytes, pattern: re.Pattern[bytes]) -> int:
    """Count lines starting with ``keyword``: ``bytes.count`` unless lines are indented."""
    if b"\n " in data or b"\n\t" in data or b"\t" in data[:1] or data[:1] == b" ":
        return len(pattern.findall(data))
    n = data.count(b"\n" + keyword + b" ") + data.count(b"\n" + keyword + b"\t")
    return n + int(data.startswith((keyword + b" ", keyword + b"\t")))


def _nan_color_ids(data: bytes) -> list[int]:
    ids = []
    for i, m in enumerate(_V_LINE.finditer(data)):
        values = m.group(1).split()
        if len(values) >= 6 and any(v.lower() == b"nan" for v in values[3:6]):
            ids.append(i)
    return ids


def _materials_used(data: bytes) -> list[str]:
    """Return the distinct materials that have faces after their ``usemtl``, in order."""
    marks = [
        (m.start(), m.group(1).decode("utf-8", "replace").strip()) for m in _USEMTL.finditer(data)
    ]
    runs = [(0, ""), *marks]
    used: list[str] = []
    for (start, name), (end, _) in zip(runs, [*runs[1:], (len(data), "")], strict=True):
        if _F.search(data, start, end) and name not in used:
            used.append(name)
    if used == [""]:
        return []
    return used


def _read_mtl(folder: Path, name: str, scan: ObjScan) -> None:
    mtl = folder / name
    if not mtl.is_file():
        scan.missing_mtl.append(name)
        return
    text = mtl.read_text(errors="replace")
    material = ""
    for line in text.splitlines():
        m = _NEWMTL.match(line)
        if m:
            material = m.group(1).strip()
            continue
        m = _MAP_KD.match(line)
        if m:
            image = _map_file(m.group(1))
            candidate = mtl.parent / image
            if candidate.is_file():
                scan.textures[material] = candidate
            else:
                scan.missing_textures.append((name, image))


def _map_file(args: str) -> str:
    """Return the file name of a ``map_Kd [-options values] file`` statement."""
    tokens = args.split()
    # options take 1-3 values; the file name is what is left at the end
    i = 0
    while i < len(tokens) - 1 and tokens[i].startswith("-"):
        i += 1
        while i < len(tokens) - 1 and _is_number(tokens[i]):
            i += 1
    return " ".join(tokens[i:]).replace("\\", "/")


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return token in ("on", "off")
    return True


# ------------------------------------------------------------------- file-order reading


def read_obj_plain(
    data: bytes,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64] | None, npt.NDArray[np.int64], int]:
    """Read positions, ``v`` colours and faces in file order, ignoring materials and UVs.

    Used for files whose faces use several materials, where trimesh would regroup faces.

    Returns
    -------
    (vertices float64 [N, 3], colours float64 [N, 3] or None, faces int64 [F, 3],
    face lines skipped for having fewer than 3 corners)
    """
    rows: list[list[bytes]] = []
    polygons = []
    for m in _VF_LINE.finditer(data):
        tokens = m.group(2).split()
        if m.group(1) == b"v":
            rows.append(tokens)
            continue
        ids = [int(t.split(b"/", 1)[0]) for t in tokens]
        # OBJ ids are 1-based; negative ids count back from the last vertex read so far
        polygons.append([i - 1 if i > 0 else len(rows) + i for i in ids])
    vertices = np.array([[float(v) for v in r[:3]] for r in rows], dtype=np.float64)
    colors = None
    if rows and all(len(r) >= 6 for r in rows):
        colors = np.array([[float(v) for v in r[3:6]] for r in rows], dtype=np.float64)
    tri = fan_triangulate(polygons)
    return vertices.reshape(-1, 3), colors, tri.faces, tri.short
