"""Edges, adjacency and boundary of a triangle mesh as plain functions over arrays.

Everything here treats faces as given (no welding): two faces are adjacent when they share
both vertex ids of an edge, exactly like lvr2's half-edge mesh on the stored indices.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import scipy.sparse as sp


def _face_edges(faces: npt.NDArray[np.integer]) -> npt.NDArray[np.int64]:
    """Return the 3F directed edges (v_a, v_b) in face order: edge k of face f is row 3f + k."""
    f = np.asarray(faces, dtype=np.int64)
    return np.stack([f, np.roll(f, -1, axis=1)], axis=2).reshape(-1, 2)


def unique_edges(
    faces: npt.NDArray[np.integer],
) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
    """Return the undirected edges and, for every face corner edge, its edge id.

    Returns
    -------
    edges : int64 [E, 2], each row sorted (low id first)
    face_edge_ids : int64 [F, 3], edge id of (v0,v1), (v1,v2), (v2,v0) of each face
    """
    directed = np.sort(_face_edges(faces), axis=1)
    if len(directed) == 0:
        return np.zeros((0, 2), np.int64), np.zeros((0, 3), np.int64)
    edges, inverse = np.unique(directed, axis=0, return_inverse=True)
    return edges, inverse.reshape(-1, 3)


def edge_face_counts(faces: npt.NDArray[np.integer]) -> tuple[npt.NDArray, npt.NDArray]:
    """Return the undirected edges and how many faces use each (1 = boundary, >2 = non-manifold).

    Returns
    -------
    edges : int64 [E, 2]
    counts : int64 [E]
    """
    edges, face_edge_ids = unique_edges(faces)
    return edges, np.bincount(face_edge_ids.ravel(), minlength=len(edges))


def boundary_vertex_mask(faces: npt.NDArray[np.integer], n_vertices: int) -> npt.NDArray[np.bool_]:
    """Return True for every vertex that touches an edge used by exactly one face."""
    edges, counts = edge_face_counts(faces)
    mask = np.zeros(n_vertices, dtype=bool)
    mask[edges[counts == 1].ravel()] = True
    return mask


def vertex_adjacency(faces: npt.NDArray[np.integer], n_vertices: int) -> sp.csr_matrix:
    """Return the symmetric vertex–vertex adjacency over mesh edges as CSR (data = 1).

    ``adj.indptr``/``adj.indices`` give each vertex's 1-ring, sorted by neighbour id.
    """
    edges, _ = unique_edges(faces)
    rows = np.concatenate([edges[:, 0], edges[:, 1]])
    cols = np.concatenate([edges[:, 1], edges[:, 0]])
    data = np.ones(len(rows), dtype=np.int8)
    adj = sp.csr_matrix((data, (rows, cols)), shape=(n_vertices, n_vertices))
    adj.sort_indices()
    return adj


def face_adjacency(faces: npt.NDArray[np.integer]) -> sp.csr_matrix:
    """Return the symmetric face–face adjacency (faces sharing an edge) as CSR (data = 1).

    Non-manifold edges connect every pair of faces that use them.
    """
    n_faces = len(faces)
    _, face_edge_ids = unique_edges(faces)
    face_of = np.repeat(np.arange(n_faces), 3)
    # incidence faces x edges, then F = I I^T minus the diagonal
    inc = sp.csr_matrix(
        (np.ones(3 * n_faces, dtype=np.int32), (face_of, face_edge_ids.ravel())),
        shape=(n_faces, int(face_edge_ids.max(initial=-1)) + 1),
    )
    adj = (inc @ inc.T).tocsr()
    adj.setdiag(0)
    adj.eliminate_zeros()
    adj.data[:] = 1
    adj.sort_indices()
    return adj.astype(np.int8)


def vertex_face_incidence(faces: npt.NDArray[np.integer], n_vertices: int) -> sp.csr_matrix:
    """Return the vertex × face incidence as CSR: row v lists the faces that use vertex v."""
    n_faces = len(faces)
    f = np.asarray(faces, dtype=np.int64)
    return sp.csr_matrix(
        (np.ones(3 * n_faces, dtype=np.int8), (f.ravel(), np.repeat(np.arange(n_faces), 3))),
        shape=(n_vertices, n_faces),
    )
