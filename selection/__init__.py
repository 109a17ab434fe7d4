"""Picking and selection on an Embree index: numpy arrays in, face ids out."""

from selection.brush import BrushIndex, brush_faces, stroke_points
from selection.camera import CameraModel
from selection.grow import flood_faces
from selection.mesh_index import MeshIndex, PickResult
from selection.rect import RectMode, RectSelector, ScreenRect, select_rect

__all__ = [
    "BrushIndex",
    "CameraModel",
    "MeshIndex",
    "PickResult",
    "RectMode",
    "RectSelector",
    "ScreenRect",
    "brush_faces",
    "flood_faces",
    "select_rect",
    "stroke_points",
]
