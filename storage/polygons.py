"""Polygons to indexed triangles in file order: face ids must follow the file they came from.

trimesh triangulates mixed polygon lists with all triangles first and the quads after, which
renumbers faces; these functions keep every polygon's triangles where the polygon was.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt


@dataclass(frozen=True, eq=False)
class Triangulated:
    """Triangles of a polygon list, in file order."""

    faces: npt.NDArray[np.int64]  #: [T, 3] vertex ids
    source: npt.NDArray[np.int64]  #: [T] index of the polygon each triangle came from
    short: int  #: polygons with fewer than 3 corners, skipped
    polygons: int  #: polygons with more than 3 corners, fan-triangulated


def fan_triangulate(polygons: Sequence[npt.ArrayLike] | npt.NDArray[np.integer]) -> Triangulated:
    """Split every polygon ``(p0, p1, ..., pk)`` into ``(p0, pi, pi+1)`` in place of the polygon.

    Parameters
    ----------
    polygons : [P, k] integer array, or a sequence of 1-D index arrays of any lengths

    Returns
    -------
    Triangulated
        Polygons with fewer than 3 corners produce nothing and are counted in ``short``.
    """
    if isinstance(polygons, np.ndarray) and polygons.dtype != object and polygons.ndim == 2:
        counts = np.full(len(polygons), polygons.shape[1], dtype=np.int64)
        flat = polygons.astype(np.int64).ravel()
        if polygons.shape[1] == 3:
            return Triangulated(flat.reshape(-1, 3), np.arange(len(polygons)), 0, 0)
    else:
        parts = [np.asarray(p, dtype=np.int64).ravel() for p in polygons]
        counts = np.array([len(p) for p in parts], dtype=np.int64)
        flat = np.concatenate(parts) if parts else np.zeros(0, dtype=np.int64)
    starts = np.cumsum(counts) - counts
    per = np.maximum(counts - 2, 0)
    source = np.repeat(np.arange(len(counts)), per)
    first = np.repeat(starts, per)
    step = np.arange(len(source)) - np.repeat(np.cumsum(per) - per, per) + 1
    faces = np.stack([flat[first], flat[first + step], flat[first + step + 1]], axis=1)
    return Triangulated(faces, source, int((counts < 3).sum()), int((counts > 3).sum()))


def split_seams(
    faces: npt.NDArray[np.integer], corner_uv: npt.NDArray[np.floating]
) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64], npt.NDArray[np.float32]]:
    """Give each (vertex, uv) pair its own vertex so per-corner UVs become per-vertex UVs.

    Faces keep their order; a vertex used with one UV everywhere keeps one copy.

    Parameters
    ----------
    faces : [F, 3] vertex ids
    corner_uv : [F, 3, 2] (or [F, 6]) texture coordinates per face corner

    Returns
    -------
    (faces [F, 3] new vertex ids, source [M] old vertex id of each new vertex, uv float32 [M, 2])
    """
    corners = np.asarray(faces, dtype=np.int64).ravel()
    uv = np.asarray(corner_uv, dtype=np.float32).reshape(-1, 2)
    key = np.empty(len(corners), dtype=[("v", np.int64), ("u", np.float32), ("w", np.float32)])
    key["v"], key["u"], key["w"] = corners, uv[:, 0], uv[:, 1]
    _, first, inverse = np.unique(key, return_index=True, return_inverse=True)
    # number new vertices in order of first use, so the result does not depend on sorting
    order = np.argsort(first, kind="stable")
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    new_faces = rank[inverse.ravel()].reshape(-1, 3)
    chosen = first[order]
    return new_faces, corners[chosen], uv[chosen]
