"""Face and vertex normals exactly as lvr2 computes them (what stored maps and layers expect)."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

_UP = np.array([0.0, 0.0, 1.0])


def face_normals(
    vertices: npt.NDArray[np.floating], faces: npt.NDArray[np.integer]
) -> npt.NDArray[np.float64]:
    """Return unit face normals ``normalize((v1 - v0) x (v2 - v0))``; degenerate faces get +z.

    lvr2 (NormalAlgorithms.tcc) writes ``(v0 - v1) x (v0 - v2)``, which is the same vector.

    Returns
    -------
    float64 [F, 3]
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces)
    if len(f) == 0:
        return np.zeros((0, 3))
    v0 = v[f[:, 0]]
    n = np.cross(v[f[:, 1]] - v0, v[f[:, 2]] - v0)
    length = np.linalg.norm(n, axis=1)
    ok = length > 0
    n[ok] /= length[ok, None]
    n[~ok] = _UP
    return n


def vertex_normals(
    vertices: npt.NDArray[np.floating],
    faces: npt.NDArray[np.integer],
    face_normals_: npt.NDArray[np.floating] | None = None,
) -> npt.NDArray[np.float64]:
    """Return lvr2's vertex normals: the normalised, *unweighted* sum of adjacent face normals.

    Vertices without faces (or whose sum vanishes) get +z, as lvr2 does.

    Returns
    -------
    float64 [N, 3]
    """
    n_vertices = len(vertices)
    fn = face_normals(vertices, faces) if face_normals_ is None else np.asarray(face_normals_)
    f = np.asarray(faces)
    acc = np.zeros((n_vertices, 3))
    for corner in range(3):
        for axis in range(3):
            acc[:, axis] += np.bincount(f[:, corner], weights=fn[:, axis], minlength=n_vertices)
    length = np.linalg.norm(acc, axis=1)
    ok = length > 0
    acc[ok] /= length[ok, None]
    acc[~ok] = _UP
    return acc
