"""Face and vertex normals exactly as lvr2 computes them (what stored maps and layers expect).

Computed column-wise in float64 (x, y, z as separate arrays): about 7x faster than row-wise
cross products at 1M faces, which keeps saving a map close to a raw h5py write.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt


def lvr2_normals(
    vertices: npt.NDArray[np.floating],
    faces: npt.NDArray[np.integer],
    *,
    dtype: npt.DTypeLike = np.float64,
) -> tuple[npt.NDArray[np.floating], npt.NDArray[np.floating]]:
    """Return lvr2's face and vertex normals in one pass.

    Face normal = unit ``(v1 - v0) x (v2 - v0)`` (lvr2 writes ``(v0 - v1) x (v0 - v2)``, the
    same vector); degenerate faces get +z. Vertex normal = the normalised, *unweighted* sum of
    its faces' normals; vertices without faces (or whose sum vanishes) get +z.

    Returns
    -------
    (face normals [F, 3], vertex normals [N, 3]) of ``dtype``
    """
    n = len(vertices)
    cols = np.ascontiguousarray(np.asarray(vertices, dtype=np.float64).reshape(-1, 3).T)
    corners = np.ascontiguousarray(np.asarray(faces).reshape(-1, 3).T)
    x, y, z = cols
    i, j, k = corners
    ax, ay, az = x[j] - x[i], y[j] - y[i], z[j] - z[i]
    bx, by, bz = x[k] - x[i], y[k] - y[i], z[k] - z[i]
    fn = _unit(ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx)
    flat = corners.ravel()
    vn = _unit(*(np.bincount(flat, weights=np.tile(c, 3), minlength=n) for c in fn))
    return _stack(fn, dtype), _stack(vn, dtype)


def face_normals(
    vertices: npt.NDArray[np.floating], faces: npt.NDArray[np.integer]
) -> npt.NDArray[np.float64]:
    """Return unit face normals (float64 [F, 3]); degenerate faces get +z (see ``lvr2_normals``)."""
    return lvr2_normals(vertices, faces)[0]


def vertex_normals(
    vertices: npt.NDArray[np.floating], faces: npt.NDArray[np.integer]
) -> npt.NDArray[np.float64]:
    """Return lvr2's unweighted vertex normals (float64 [N, 3]; see ``lvr2_normals``)."""
    return lvr2_normals(vertices, faces)[1]


def _unit(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Normalise column vectors in place; zero (or NaN) length becomes +z like lvr2."""
    length = np.sqrt(x * x + y * y + z * z)
    bad = ~(length > 0)
    length[bad] = 1.0
    x /= length
    y /= length
    z /= length
    if bad.any():
        x[bad], y[bad], z[bad] = 0.0, 0.0, 1.0
    return x, y, z


def _stack(cols: tuple[np.ndarray, np.ndarray, np.ndarray], dtype: npt.DTypeLike) -> np.ndarray:
    out = np.empty((len(cols[0]), 3), dtype=dtype)
    for axis, c in enumerate(cols):
        out[:, axis] = c
    return out
