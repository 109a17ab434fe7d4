"""What a glTF/GLB file says that trimesh's scene loses: node order and original image bytes.

trimesh walks glTF nodes with a stack (siblings come out reversed) and decodes images into
PIL objects; meshmark wants faces in file order and PNG/JPEG textures byte-exact, so it
reads the JSON itself for those two facts.
"""

from __future__ import annotations

import base64
import json
import struct
from pathlib import Path
from typing import Any
from urllib.parse import unquote

import numpy as np
import numpy.typing as npt

_TRIANGLES, _STRIP, _FAN = 4, 5, 6


def read_gltf(path: Path) -> tuple[dict[str, Any], bytes]:
    """Return the glTF JSON document and the GLB binary chunk (empty for .gltf)."""
    blob = path.read_bytes()
    if blob[:4] != b"glTF":
        return json.loads(blob), b""
    doc, binary, offset = None, b"", 12
    while offset + 8 <= len(blob):
        length, kind = struct.unpack_from("<I4s", blob, offset)
        chunk = blob[offset + 8 : offset + 8 + length]
        if kind == b"JSON":
            doc = json.loads(chunk)
        elif kind == b"BIN\x00":
            binary = chunk
        offset += 8 + length
    if doc is None:
        raise ValueError("GLB without a JSON chunk")
    return doc, binary


def primitive_order(path: Path) -> list[tuple[int, int, npt.NDArray[np.float64]]]:
    """Return (vertex count, triangle count, world matrix) of every triangle primitive.

    In file order: depth-first through the default scene's root nodes, each node's
    primitives before its children, children in the order listed.
    """
    doc, _ = read_gltf(path)
    nodes, meshes, accessors = doc.get("nodes", []), doc.get("meshes", []), doc["accessors"]
    scenes = doc.get("scenes", [])
    roots = scenes[doc.get("scene", 0)].get("nodes", []) if scenes else range(len(nodes))
    out: list[tuple[int, int, npt.NDArray[np.float64]]] = []
    stack = [(i, np.eye(4)) for i in reversed(list(roots))]
    seen = set()
    while stack:
        index, parent = stack.pop()
        if index in seen:  # a malformed file may loop
            continue
        seen.add(index)
        node = nodes[index]
        world = parent @ _local_matrix(node)
        if "mesh" in node:
            for p in meshes[node["mesh"]]["primitives"]:
                mode = p.get("mode", _TRIANGLES)
                if mode not in (_TRIANGLES, _STRIP, _FAN):
                    continue
                nv = accessors[p["attributes"]["POSITION"]]["count"]
                count = accessors[p["indices"]]["count"] if "indices" in p else nv
                nf = count // 3 if mode == _TRIANGLES else max(count - 2, 0)
                out.append((nv, nf, world))
        stack.extend((c, world) for c in reversed(node.get("children", [])))
    return out


def _local_matrix(node: dict[str, Any]) -> npt.NDArray[np.float64]:
    if "matrix" in node:
        return np.array(node["matrix"], dtype=np.float64).reshape(4, 4).T
    m = np.eye(4)
    if "scale" in node:
        m = np.diag([*node["scale"], 1.0]) @ m
    if "rotation" in node:
        x, y, z, w = node["rotation"]
        r = np.array(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
            ]
        )
        rot = np.eye(4)
        rot[:3, :3] = r
        m = rot @ m
    if "translation" in node:
        t = np.eye(4)
        t[:3, 3] = node["translation"]
        m = t @ m
    return m


def base_color_images(path: Path) -> list[bytes]:
    """Return the encoded images the materials use as base colour, each once."""
    doc, binary = read_gltf(path)
    sources = set()
    for material in doc.get("materials", []):
        ref = material.get("pbrMetallicRoughness", {}).get("baseColorTexture")
        if ref is None:
            continue
        texture = doc["textures"][ref["index"]]
        source = texture.get("source")
        for ext in texture.get("extensions", {}).values():
            source = ext.get("source", source)
        if source is not None:
            sources.add(int(source))
    return [_image_bytes(path, doc, binary, doc["images"][s]) for s in sorted(sources)]


def _image_bytes(path: Path, doc: dict[str, Any], binary: bytes, image: dict[str, Any]) -> bytes:
    if "bufferView" in image:
        view = doc["bufferViews"][image["bufferView"]]
        buffer = doc["buffers"][view.get("buffer", 0)]
        data = binary if "uri" not in buffer else _uri_bytes(path, buffer["uri"])
        start = view.get("byteOffset", 0)
        return data[start : start + view["byteLength"]]
    return _uri_bytes(path, image["uri"])


def _uri_bytes(path: Path, uri: str) -> bytes:
    if uri.startswith("data:"):
        return base64.b64decode(uri.split(",", 1)[1])
    return (path.parent / unquote(uri)).read_bytes()
