"""Shared mesh topology for storage, selection and navigation: arrays in, arrays out."""

from geometry.normals import face_normals, vertex_normals
from geometry.origin import local_origin
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
    "edge_face_counts",
    "face_adjacency",
    "face_normals",
    "local_origin",
    "unique_edges",
    "vertex_adjacency",
    "vertex_face_incidence",
    "vertex_normals",
]
