"""Build the GLB the browser draws for vertex-colour, cost-layer and texture display modes.

viser has no per-vertex colour prop on ``add_mesh_simple``; a glTF primitive with ``COLOR_0``
(or a base-colour texture) is the way. Normals are left out: the glTF rule makes the client
shade flat, which reads terrain well and keeps the message small.
"""

from __future__ import annotations

import io

import numpy as np
import numpy.typing as npt
import trimesh
from PIL import Image
from trimesh.visual import TextureVisuals
from trimesh.visual.material import PBRMaterial

#: glTF vertex colours are linear while colormaps and file colours are sRGB: convert, or every
#: colour renders washed out (dark purple becomes magenta).
_SRGB_TO_LINEAR = np.round(
    255
    * np.where((c := np.arange(256) / 255.0) <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
).astype(np.uint8)


def _material(opacity: float, image: Image.Image | None = None) -> PBRMaterial:
    alpha = round(255 * min(max(opacity, 0.0), 1.0))
    return PBRMaterial(
        baseColorFactor=[255, 255, 255, alpha],
        baseColorTexture=image,
        alphaMode="BLEND" if alpha < 255 else "OPAQUE",
        doubleSided=True,
        metallicFactor=0.0,
        roughnessFactor=1.0,
    )


def colored_glb(
    vertices_local: npt.NDArray[np.float32],
    faces: npt.NDArray[np.integer],
    colors: npt.NDArray[np.uint8],
    *,
    opacity: float = 1.0,
) -> bytes:
    """Return GLB bytes of the mesh with per-vertex sRGB colours ([N, 3] uint8)."""
    mesh = trimesh.Trimesh(vertices_local, faces, process=False, validate=False)
    mesh.visual = TextureVisuals(material=_material(opacity))
    rgba = np.empty((len(colors), 4), dtype=np.uint8)
    rgba[:, :3] = _SRGB_TO_LINEAR[colors[:, :3]]
    rgba[:, 3] = 255
    mesh.visual.vertex_attributes["color"] = rgba
    return mesh.export(file_type="glb", include_normals=False)


def textured_glb(
    vertices_local: npt.NDArray[np.float32],
    faces: npt.NDArray[np.integer],
    uv: npt.NDArray[np.float32],
    image_bytes: bytes,
    *,
    opacity: float = 1.0,
    max_texture_px: int = 4096,
) -> bytes:
    """Return GLB bytes of the mesh with its texture image (shrunk beyond ``max_texture_px``)."""
    image = Image.open(io.BytesIO(image_bytes))
    image.load()
    if max(image.size) > max_texture_px:
        image.thumbnail((max_texture_px, max_texture_px))
    if image.mode not in ("RGB", "RGBA"):
        image = image.convert("RGBA" if "A" in image.getbands() else "RGB")
    mesh = trimesh.Trimesh(vertices_local, faces, process=False, validate=False)
    mesh.visual = TextureVisuals(uv=uv, material=_material(opacity, image))
    return mesh.export(file_type="glb", include_normals=False)
