"""Shared mesh topology for storage, selection and navigation: arrays in, arrays out."""

from geometry.normals import face_normals, lvr2_normals, vertex_normals
from geometry.origin import local_origin
from geometry.pose import (
    drag_point_on_plane,
    interpolated_normal,
    matrix_from_quaternion,
    quaternion_from_matrix,
    surface_pose,
    yaw_of,
)
from geometry.topology import (
    boundary_vertex_mask,
    edge_face_counts,
    face_adjacency,
    unique_edges,
    vertex_adjacency,
    vertex_face_incidence,
)

__all__ = [
    "boundary_vertex_mask",
    "drag_point_on_plane",
    "edge_face_counts",
    "face_adjacency",
    "face_normals",
    "interpolated_normal",
    "local_origin",
    "lvr2_normals",
    "matrix_from_quaternion",
    "quaternion_from_matrix",
    "surface_pose",
    "unique_edges",
    "vertex_adjacency",
    "vertex_face_incidence",
    "vertex_normals",
    "yaw_of",
]
