"""Compiled kernels behind flood fill and the brush (private to selection)."""

from __future__ import annotations

import numba
import numpy as np
import numpy.typing as npt


@numba.njit(nogil=True, cache=True)
def flood(
    indptr: npt.NDArray[np.int64],
    indices: npt.NDArray[np.int32],
    seed: int,
    within: npt.NDArray[np.bool_],
) -> npt.NDArray[np.int32]:
    """Return the faces reachable from ``seed`` over the CSR graph, staying inside ``within``.

    ``within`` is a bool [F] mask, or an empty array for "no restriction". Breadth-first order.
    """
    n = len(indptr) - 1
    restrict = len(within) > 0
    if restrict and not within[seed]:
        return np.zeros(0, np.int32)
    visited = np.zeros(n, np.bool_)
    queue = np.empty(n, np.int32)
    queue[0] = seed
    visited[seed] = True
    head = 0
    tail = 1
    while head < tail:
        f = queue[head]
        head += 1
        for k in range(indptr[f], indptr[f + 1]):
            g = indices[k]
            if not visited[g] and (not restrict or within[g]):
                visited[g] = True
                queue[tail] = g
                tail += 1
    return queue[:tail].copy()


@numba.njit(nogil=True, cache=True)
def brush_flood(
    indptr: npt.NDArray[np.int64],
    indices: npt.NDArray[np.int32],
    centroids: npt.NDArray[np.float64],
    centers: npt.NDArray[np.float64],
    radius: float,
    seeds: npt.NDArray[np.int32],
) -> npt.NDArray[np.int32]:
    """Return the union over brush samples of the faces connected to the sample's seed face.

    For sample s, flood from ``seeds[s]`` (always taken) over face adjacency through faces
    whose centroid lies within ``radius`` of ``centers[s]``. Seeds < 0 are skipped.
    """
    n = len(indptr) - 1
    r2 = radius * radius
    stamp = np.zeros(n, np.int32)  # s + 1: visited while flooding sample s
    taken = np.zeros(n, np.bool_)
    queue = np.empty(n, np.int32)
    out = np.empty(n, np.int32)
    n_out = 0
    for s in range(len(seeds)):
        seed = seeds[s]
        if seed < 0:
            continue
        cx, cy, cz = centers[s, 0], centers[s, 1], centers[s, 2]
        queue[0] = seed
        stamp[seed] = s + 1
        head = 0
        tail = 1
        while head < tail:
            f = queue[head]
            head += 1
            if not taken[f]:
                taken[f] = True
                out[n_out] = f
                n_out += 1
            for k in range(indptr[f], indptr[f + 1]):
                g = indices[k]
                if stamp[g] == s + 1:
                    continue
                stamp[g] = s + 1
                dx = centroids[g, 0] - cx
                dy = centroids[g, 1] - cy
                dz = centroids[g, 2] - cz
                if dx * dx + dy * dy + dz * dz <= r2:
                    queue[tail] = g
                    tail += 1
    return out[:n_out].copy()


@numba.njit(nogil=True, cache=True)
def build_grid(
    centroids: npt.NDArray[np.float64],
    lo: npt.NDArray[np.float64],
    cell: float,
    dims: npt.NDArray[np.int64],
) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int32]]:
    """Bucket face centroids into a dense uniform grid (counting sort).

    Returns
    -------
    cell_start : int64 [cells + 1]
        Faces of cell k are ``cell_faces[cell_start[k]:cell_start[k + 1]]``, with
        k = (ix * dims[1] + iy) * dims[2] + iz.
    cell_faces : int32 [F]
    """
    n = centroids.shape[0]
    n_cells = dims[0] * dims[1] * dims[2]
    cell_of = np.empty(n, np.int64)
    cell_start = np.zeros(n_cells + 1, np.int64)
    for f in range(n):
        ix = min(max(int((centroids[f, 0] - lo[0]) / cell), 0), dims[0] - 1)
        iy = min(max(int((centroids[f, 1] - lo[1]) / cell), 0), dims[1] - 1)
        iz = min(max(int((centroids[f, 2] - lo[2]) / cell), 0), dims[2] - 1)
        k = (ix * dims[1] + iy) * dims[2] + iz
        cell_of[f] = k
        cell_start[k + 1] += 1
    for k in range(n_cells):
        cell_start[k + 1] += cell_start[k]
    fill = cell_start[:-1].copy()
    cell_faces = np.empty(n, np.int32)
    for f in range(n):
        k = cell_of[f]
        cell_faces[fill[k]] = f
        fill[k] += 1
    return cell_start, cell_faces


@numba.njit(nogil=True, cache=True, inline="always")
def _cell_range(
    centers: npt.NDArray[np.float64],
    s: int,
    radius: float,
    lo: npt.NDArray[np.float64],
    cell: float,
    dims: npt.NDArray[np.int64],
    lo_i: npt.NDArray[np.int64],
    hi_i: npt.NDArray[np.int64],
) -> bool:
    """Write the grid cells a ball of ``radius`` around centre ``s`` overlaps; False if none."""
    for a in range(3):
        c = centers[s, a]
        first = min(max(np.floor((c - radius - lo[a]) / cell), -1.0), float(dims[a]))
        last = min(max(np.floor((c + radius - lo[a]) / cell), -1.0), float(dims[a]))
        lo_i[a] = max(int(first), 0)
        hi_i[a] = min(int(last), dims[a] - 1)
        if lo_i[a] > hi_i[a]:
            return False
    return True


@numba.njit(nogil=True, cache=True)
def ball_faces(
    cell_start: npt.NDArray[np.int64],
    cell_faces: npt.NDArray[np.int32],
    lo: npt.NDArray[np.float64],
    cell: float,
    dims: npt.NDArray[np.int64],
    centroids: npt.NDArray[np.float64],
    centers: npt.NDArray[np.float64],
    radius: float,
    seeds: npt.NDArray[np.int32],
) -> npt.NDArray[np.int32]:
    """Return the union over samples of the faces whose centroid lies within ``radius``.

    Seeds >= 0 are always included (the face under the cursor, even for a tiny brush).
    """
    n = centroids.shape[0]
    r2 = radius * radius
    taken = np.zeros(n, np.bool_)
    out = np.empty(n, np.int32)
    n_out = 0
    lo_i = np.empty(3, np.int64)
    hi_i = np.empty(3, np.int64)
    for s in range(centers.shape[0]):
        seed = seeds[s]
        if seed >= 0 and not taken[seed]:
            taken[seed] = True
            out[n_out] = seed
            n_out += 1
        cx, cy, cz = centers[s, 0], centers[s, 1], centers[s, 2]
        if not _cell_range(centers, s, radius, lo, cell, dims, lo_i, hi_i):
            continue
        for ix in range(lo_i[0], hi_i[0] + 1):
            for iy in range(lo_i[1], hi_i[1] + 1):
                base = (ix * dims[1] + iy) * dims[2]
                for k in range(cell_start[base + lo_i[2]], cell_start[base + hi_i[2] + 1]):
                    f = cell_faces[k]
                    if taken[f]:
                        continue
                    dx = centroids[f, 0] - cx
                    dy = centroids[f, 1] - cy
                    dz = centroids[f, 2] - cz
                    if dx * dx + dy * dy + dz * dz <= r2:
                        taken[f] = True
                        out[n_out] = f
                        n_out += 1
    return out[:n_out].copy()


@numba.njit(nogil=True, cache=True)
def nearest_in_ball(
    cell_start: npt.NDArray[np.int64],
    cell_faces: npt.NDArray[np.int32],
    lo: npt.NDArray[np.float64],
    cell: float,
    dims: npt.NDArray[np.int64],
    centroids: npt.NDArray[np.float64],
    centers: npt.NDArray[np.float64],
    radius: float,
) -> npt.NDArray[np.int32]:
    """Return, per centre, the face whose centroid is nearest within ``radius`` (-1 if none)."""
    m = centers.shape[0]
    out = np.full(m, -1, np.int32)
    lo_i = np.empty(3, np.int64)
    hi_i = np.empty(3, np.int64)
    for s in range(m):
        best = radius * radius
        if not _cell_range(centers, s, radius, lo, cell, dims, lo_i, hi_i):
            continue
        for ix in range(lo_i[0], hi_i[0] + 1):
            for iy in range(lo_i[1], hi_i[1] + 1):
                base = (ix * dims[1] + iy) * dims[2]
                for k in range(cell_start[base + lo_i[2]], cell_start[base + hi_i[2] + 1]):
                    f = cell_faces[k]
                    dx = centroids[f, 0] - centers[s, 0]
                    dy = centroids[f, 1] - centers[s, 1]
                    dz = centroids[f, 2] - centers[s, 2]
                    d2 = dx * dx + dy * dy + dz * dz
                    if d2 <= best:
                        best = d2
                        out[s] = f
    return out
