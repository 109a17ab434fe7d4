"""Compiled kernels behind the cost layers: CSR topology, radius-bounded floods, wavefronts.

Every kernel is ``nogil`` and cached; the per-vertex ones run in parallel over interleaved blocks
of vertices, each worker with its own visit stamps and queue (so no resets between vertices).
Positions and normals are float32 and the arithmetic stays float32 where lvr2 uses ``float``, so
radius tests and ranges round the way the C++ does.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

_JIT = {"nogil": True, "cache": True, "error_model": "numpy"}
#: Vertices per block handed round-robin to the workers (balances walls vs. flat ground).
BLOCK = 256

BALL = 0  # 3-D ball around the start vertex
DISC_XY = 1  # plane with n = (0, 0, 1): the xy-disc (2024 height difference)
PLANE = 2  # plane perpendicular to the start vertex's normal


# --------------------------------------------------------------------------------------------
# topology
# --------------------------------------------------------------------------------------------


@nb.njit(**_JIT)
def _sort_small(a: np.ndarray) -> None:
    """Sort a short slice in place (insertion sort; 1-rings hold about a dozen entries)."""
    n = len(a)
    if n > 48:
        a[:] = np.sort(a)
        return
    for i in range(1, n):
        x = a[i]
        j = i - 1
        while j >= 0 and a[j] > x:
            a[j + 1] = a[j]
            j -= 1
        a[j + 1] = x


@nb.njit(parallel=True, **_JIT)
def build_vertex_csr(faces: np.ndarray, n_vertices: int):
    """Return the 1-ring CSR (indptr, indices) and, per entry, how many faces use that edge.

    Faces that repeat a vertex id are skipped (lvr2's half-edge mesh cannot hold them); their
    count is returned last.
    """
    n_faces = faces.shape[0]
    counts = np.zeros(n_vertices + 1, np.int64)
    n_skipped = 0
    for f in range(n_faces):
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        if a in (b, c) or b == c:
            n_skipped += 1
            continue
        counts[a + 1] += 2
        counts[b + 1] += 2
        counts[c + 1] += 2
    start = np.cumsum(counts)
    fill = start[:-1].copy()
    raw = np.empty(start[-1], np.int32)
    for f in range(n_faces):
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        if a in (b, c) or b == c:
            continue
        raw[fill[a]] = b
        raw[fill[a] + 1] = c
        fill[a] += 2
        raw[fill[b]] = c
        raw[fill[b] + 1] = a
        fill[b] += 2
        raw[fill[c]] = a
        raw[fill[c] + 1] = b
        fill[c] += 2
    # sort each row, then count distinct neighbours (a neighbour repeats once per shared face)
    unique_counts = np.zeros(n_vertices + 1, np.int64)
    for v in nb.prange(n_vertices):
        lo, hi = start[v], start[v + 1]
        if hi == lo:
            continue
        _sort_small(raw[lo:hi])
        k = 1
        for i in range(lo + 1, hi):
            if raw[i] != raw[i - 1]:
                k += 1
        unique_counts[v + 1] = k
    indptr = np.cumsum(unique_counts)
    indices = np.empty(indptr[-1], np.int32)
    edge_faces = np.zeros(indptr[-1], np.int32)
    for v in nb.prange(n_vertices):
        lo, hi = start[v], start[v + 1]
        out = indptr[v] - 1
        for i in range(lo, hi):
            if i == lo or raw[i] != raw[i - 1]:
                out += 1
                indices[out] = raw[i]
            edge_faces[out] += 1
    return indptr, indices, edge_faces, n_skipped


@nb.njit(**_JIT)
def build_vertex_faces(faces: np.ndarray, n_vertices: int):
    """Return the vertex -> incident faces CSR (indptr int64 [N+1], face ids int32)."""
    counts = np.zeros(n_vertices + 1, np.int64)
    for f in range(faces.shape[0]):
        for k in range(3):
            counts[faces[f, k] + 1] += 1
    indptr = np.cumsum(counts)
    fill = indptr[:-1].copy()
    out = np.empty(indptr[-1], np.int32)
    for f in range(faces.shape[0]):
        for k in range(3):
            v = faces[f, k]
            out[fill[v]] = f
            fill[v] += 1
    return indptr, out


@nb.njit(**_JIT)
def _local_index(indices: np.ndarray, lo: int, hi: int, u: int) -> int:
    """Return the position of ``u`` in the sorted row ``indices[lo:hi]`` relative to lo, or -1."""
    a, b = lo, hi
    while a < b:
        m = (a + b) // 2
        if indices[m] < u:
            a = m + 1
        else:
            b = m
    if a < hi and indices[a] == u:
        return a - lo
    return -1


@nb.njit(**_JIT)
def _find(parent: np.ndarray, i: int) -> int:
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i


@nb.njit(parallel=True, **_JIT)
def non_manifold_vertices(
    indptr: np.ndarray,
    indices: np.ndarray,
    edge_faces: np.ndarray,
    vf_indptr: np.ndarray,
    vf_faces: np.ndarray,
    faces: np.ndarray,
) -> np.ndarray:
    """Flag vertices a half-edge mesh cannot circulate: an edge with > 2 faces, or > 1 face fan."""
    n = len(indptr) - 1
    flag = np.zeros(n, np.bool_)
    for v in nb.prange(n):
        lo, hi = indptr[v], indptr[v + 1]
        deg = hi - lo
        if deg == 0:
            continue
        bad = False
        for i in range(lo, hi):
            if edge_faces[i] > 2:
                bad = True
        if not bad:
            # fans = connected components of the link (faces join their two other corners)
            parent = np.arange(deg)
            comps = deg
            for j in range(vf_indptr[v], vf_indptr[v + 1]):
                f = vf_faces[j]
                a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
                if a in (b, c) or b == c:
                    continue
                if a == v:
                    x, y = b, c
                elif b == v:
                    x, y = c, a
                else:
                    x, y = a, b
                rx = _find(parent, _local_index(indices, lo, hi, x))
                ry = _find(parent, _local_index(indices, lo, hi, y))
                if rx != ry:
                    parent[rx] = ry
                    comps -= 1
            bad = comps > 1
        flag[v] = bad
    return flag


# --------------------------------------------------------------------------------------------
# edge angles
# --------------------------------------------------------------------------------------------


@nb.njit(parallel=True, **_JIT)
def average_angles(
    indptr: np.ndarray, indices: np.ndarray, normals: np.ndarray, non_manifold: np.ndarray
) -> np.ndarray:
    """Return lvr2's avgAngle: mean acos(n_v . n_u) over the 1-ring (NaN -> 0), pi if flagged."""
    n = len(indptr) - 1
    out = np.zeros(n, np.float32)
    one = np.float32(1.0)
    for v in nb.prange(n):
        if non_manifold[v]:
            out[v] = np.float32(math.pi)
            continue
        lo, hi = indptr[v], indptr[v + 1]
        if hi == lo:
            continue  # no edges: no angle (lvr2 would divide 0 by 0)
        s = np.float32(0.0)
        for i in range(lo, hi):
            u = indices[i]
            d = normals[v, 0] * normals[u, 0] + normals[v, 1] * normals[u, 1]
            d = d + normals[v, 2] * normals[u, 2]
            if d != d:
                continue  # NaN normal: lvr2 sets the edge angle to 0
            d = min(one, max(-one, d))
            s += np.float32(math.acos(d))
        out[v] = np.float32(s / np.float32(hi - lo))
    return out


# --------------------------------------------------------------------------------------------
# radius-bounded floods (lvr2 visitLocalVertexNeighborhood / ...Plane)
# --------------------------------------------------------------------------------------------


@nb.njit(**_JIT)
def _flood(v, indptr, indices, pos, mode, nx, ny, nz, r2, stamp, queue) -> int:
    """Collect the flood from ``v`` into ``queue[:k]`` (v excluded) and return k.

    A neighbour u of an accepted vertex is accepted when unvisited and its squared distance to
    v, measured per ``mode``, is ``< r2``. Which vertices are accepted does not depend on the
    visiting order, so a queue replaces lvr2's stack.
    """
    tag = v + 1
    stamp[v] = tag
    if mode == PLANE:
        s = pos[v, 0] * nx + pos[v, 1] * ny + pos[v, 2] * nz
        qx, qy, qz = pos[v, 0] - nx * s, pos[v, 1] - ny * s, pos[v, 2] - nz * s
    else:
        qx, qy, qz = pos[v, 0], pos[v, 1], pos[v, 2]
    k = 0
    head = -1
    cur = v
    while True:
        for i in range(indptr[cur], indptr[cur + 1]):
            u = indices[i]
            if stamp[u] == tag:
                continue
            if mode == BALL:
                dx, dy, dz = pos[u, 0] - qx, pos[u, 1] - qy, pos[u, 2] - qz
                d2 = dx * dx + dy * dy + dz * dz
            elif mode == DISC_XY:
                dx, dy = pos[u, 0] - qx, pos[u, 1] - qy
                d2 = dx * dx + dy * dy
            else:
                s = pos[u, 0] * nx + pos[u, 1] * ny + pos[u, 2] * nz
                dx = (pos[u, 0] - nx * s) - qx
                dy = (pos[u, 1] - ny * s) - qy
                dz = (pos[u, 2] - nz * s) - qz
                d2 = dx * dx + dy * dy + dz * dz
            if d2 < r2:
                stamp[u] = tag
                queue[k] = u
                k += 1
        head += 1
        if head >= k:
            return k
        cur = queue[head]


@nb.njit(**_JIT)
def _blocks(n: int, n_workers: int, w: int):
    """Return the block starts worker ``w`` owns (round-robin blocks of BLOCK vertices)."""
    return np.arange(w * BLOCK, n, n_workers * BLOCK)


@nb.njit(**_JIT)
def neighborhood(indptr, indices, pos, v, mode, normal, r2):
    """Return the flood of one vertex (for tests and inspection), sorted by id."""
    n = len(indptr) - 1
    stamp = np.zeros(n, np.int32)
    queue = np.empty(n, np.int32)
    k = _flood(v, indptr, indices, pos, mode, normal[0], normal[1], normal[2], r2, stamp, queue)
    return np.sort(queue[:k])


@nb.njit(parallel=True, **_JIT)
def height_diff(indptr, indices, pos, normals, mode, r2, n_workers):
    """Return max - min of n.p over {v} and its flood (DISC_XY: n = +z; PLANE: n = n_v)."""
    n = len(indptr) - 1
    out = np.zeros(n, np.float32)
    for w in nb.prange(n_workers):
        stamp = np.zeros(n, np.int32)
        queue = np.empty(n, np.int32)
        for b in _blocks(n, n_workers, w):
            for v in range(b, min(b + BLOCK, n)):
                if mode == PLANE:
                    nx, ny, nz = normals[v, 0], normals[v, 1], normals[v, 2]
                else:
                    nx, ny, nz = np.float32(0.0), np.float32(0.0), np.float32(1.0)
                k = _flood(v, indptr, indices, pos, mode, nx, ny, nz, r2, stamp, queue)
                h = pos[v, 0] * nx + pos[v, 1] * ny + pos[v, 2] * nz
                lo, hi = h, h
                for j in range(k):
                    u = queue[j]
                    h = pos[u, 0] * nx + pos[u, 1] * ny + pos[u, 2] * nz
                    lo = min(lo, h)
                    hi = max(hi, h)
                out[v] = hi - lo
    return out


@nb.njit(parallel=True, **_JIT)
def ball_mean(indptr, indices, pos, values, r2, n_workers):
    """Return the mean of ``values`` over {v} and its 3-D ball flood (lvr2 roughness)."""
    n = len(indptr) - 1
    out = np.zeros(n, np.float32)
    zero = np.float32(0.0)
    for w in nb.prange(n_workers):
        stamp = np.zeros(n, np.int32)
        queue = np.empty(n, np.int32)
        for b in _blocks(n, n_workers, w):
            for v in range(b, min(b + BLOCK, n)):
                k = _flood(v, indptr, indices, pos, BALL, zero, zero, zero, r2, stamp, queue)
                s = values[v]
                for j in range(k):
                    s += values[queue[j]]
                out[v] = s / np.float32(k + 1)
    return out


@nb.njit(parallel=True, **_JIT)
def ridge(indptr, indices, pos, normals, r2, empty_value, n_workers):
    """Return the mean |(p_u + n_u) - (p_v + n_v)| over the 3-D ball flood (v excluded)."""
    n = len(indptr) - 1
    out = np.zeros(n, np.float32)
    zero = np.float32(0.0)
    for w in nb.prange(n_workers):
        stamp = np.zeros(n, np.int32)
        queue = np.empty(n, np.int32)
        for b in _blocks(n, n_workers, w):
            for v in range(b, min(b + BLOCK, n)):
                k = _flood(v, indptr, indices, pos, BALL, zero, zero, zero, r2, stamp, queue)
                if k == 0:
                    out[v] = empty_value
                    continue
                rx = pos[v, 0] + normals[v, 0]
                ry = pos[v, 1] + normals[v, 1]
                rz = pos[v, 2] + normals[v, 2]
                s = np.float32(0.0)
                for j in range(k):
                    u = queue[j]
                    dx = pos[u, 0] + normals[u, 0] - rx
                    dy = pos[u, 1] + normals[u, 1] - ry
                    dz = pos[u, 2] + normals[u, 2] - rz
                    s += np.float32(math.sqrt(dx * dx + dy * dy + dz * dz))
                out[v] = s / np.float32(k)
    return out


# --------------------------------------------------------------------------------------------
# labels
# --------------------------------------------------------------------------------------------


@nb.njit(**_JIT)
def vertex_max_of_faces(faces: np.ndarray, face_values: np.ndarray, n_vertices: int):
    """Return per vertex the max of its faces' values (0 where no face is larger)."""
    out = np.zeros(n_vertices, np.float32)
    for f in range(faces.shape[0]):
        c = face_values[f]
        if c > 0:
            for k in range(3):
                v = faces[f, k]
                if c > out[v]:
                    out[v] = c
    return out


# --------------------------------------------------------------------------------------------
# distance propagation (inflation)
# --------------------------------------------------------------------------------------------


@nb.njit(**_JIT)
def _heap_push(keys, vals, size, key, val) -> int:
    i = size
    keys[i] = key
    vals[i] = val
    while i > 0:
        p = (i - 1) >> 1
        if keys[p] <= keys[i]:
            break
        keys[p], keys[i] = keys[i], keys[p]
        vals[p], vals[i] = vals[i], vals[p]
        i = p
    return size + 1


@nb.njit(**_JIT)
def _heap_pop(keys, vals, size) -> int:
    """Move the minimum to ``[size - 1]`` and restore the heap on ``[:size - 1]``; return size-1."""
    last = size - 1
    keys[0], keys[last] = keys[last], keys[0]
    vals[0], vals[last] = vals[last], vals[0]
    i = 0
    while True:
        left = 2 * i + 1
        if left >= last:
            break
        c = left
        if left + 1 < last and keys[left + 1] < keys[left]:
            c = left + 1
        if keys[i] <= keys[c]:
            break
        keys[c], keys[i] = keys[i], keys[c]
        vals[c], vals[i] = vals[i], vals[c]
        i = c
    return last


@nb.njit(**_JIT)
def _edge_length(pos, a, b) -> float:
    dx, dy, dz = pos[a, 0] - pos[b, 0], pos[a, 1] - pos[b, 1], pos[a, 2] - pos[b, 2]
    return np.float32(math.sqrt(dx * dx + dy * dy + dz * dz))


@nb.njit(**_JIT)
def _sethian_verbatim(d1, d2, a, b, dot):
    """Return InflationLayer::computeUpdateSethianMethod (F = 1) reproduced term for term.

    a = |BC|, b = |AC|, ``dot`` = cos of the angle at C, d1 = T(A), d2 = T(B). Kept as written,
    with its ``a^2 sin`` where Kimmel & Sethian have ``a^2 sin^2`` and an ``else`` bound to the
    wrong ``if`` (it swaps a valid root for ``-f0/f1``); both overestimate distances.
    """
    inf = np.inf
    t = inf
    r_cos = dot
    r_sin = math.sqrt(1.0 - dot * dot) if dot * dot <= 1.0 else np.nan
    u = d2 - d1
    f2 = a * a + b * b - 2.0 * a * b * r_cos
    f1 = b * u * (a * r_cos - b)
    f0 = b * b * (u * u - a * a * r_sin)
    delta = f1 * f1 - f0 * f2
    if delta >= 0.0:
        if abs(f2) > 1e-9:
            t = (-f1 - math.sqrt(delta)) / f2
            if t < u or b * (t - u) / t < a * r_cos or a / r_cos < b * (t - u) / 2.0:
                t = (-f1 + math.sqrt(delta)) / f2
            elif f1 != 0.0:
                t = -f0 / f1
            else:
                t = -inf
    else:
        t = -inf
    if u < t and a * r_cos < b * (t - u) / t and b * (t - u) / t < a / r_cos:
        return t + d1
    return min(b + d1, a + d2)


@nb.njit(**_JIT)
def _planar(d1, d2, a, b, c):
    """Return T(C) from T(A) = d1, T(B) = d2 for a plane front crossing AB (unit speed).

    a = |BC|, b = |AC|, c = |AB|. The front's direction n has n.(B - A) = d2 - d1; T(C) =
    d1 + n.(C - A) when the ray from C back along n crosses AB, else the cheaper edge path.
    This is Kimmel & Sethian's update, computed from coordinates rather than cos(C), so right
    and obtuse angles need no special case.
    """
    fallback = min(d1 + b, d2 + a)
    if c <= 0.0:
        return fallback
    cx = (b * b + c * c - a * a) / (2.0 * c)
    cy2 = b * b - cx * cx
    nx = (d2 - d1) / c
    if cy2 <= 0.0 or nx * nx >= 1.0:
        return fallback
    cy = math.sqrt(cy2)
    ny = math.sqrt(1.0 - nx * nx)
    x0 = cx - nx * cy / ny
    if x0 < 0.0 or x0 > c:
        return fallback
    return min(fallback, d1 + nx * cx + ny * cy)


@nb.njit(**_JIT)
def fmm_distances(pos, faces, indptr, indices, vf_indptr, vf_faces, seeds, max_distance, verbatim):
    """Return geodesic distances from ``seeds`` by mesh_navigation's triangle wavefront.

    As InflationLayer::waveCostInflation: all seeds start fixed at 0; a popped vertex updates
    the free corner of each incident face whose other two corners are fixed, and that corner
    re-enters the queue only while both fixed corners lie within ``max_distance``. ``verbatim``
    uses mesh_navigation's update as written; otherwise the update is Kimmel & Sethian's
    plane-front one (exact for plane fronts, first order near point-like seeds) and a popped
    vertex within max_distance also offers ``d + |edge|`` to its neighbours, so a lone seed
    vertex spreads too (mesh_navigation leaves it alone); only vertices within max_distance
    are queued. Untouched vertices stay +inf.
    """
    n = pos.shape[0]
    dist = np.full(n, np.inf)
    fixed = np.zeros(n, np.bool_)
    cap = len(vf_faces) + len(indices) + 1
    keys = np.empty(cap, np.float64)
    vals = np.empty(cap, np.int32)
    for s in seeds:
        dist[s] = 0.0
        fixed[s] = True
    # the seeds leave the queue first (all at 0), so settle them without queueing them
    size = 0
    for s in seeds:
        size = _settle(
            s,
            pos,
            faces,
            indptr,
            indices,
            vf_indptr,
            vf_faces,
            dist,
            fixed,
            keys,
            vals,
            size,
            max_distance,
            verbatim,
        )
    while size > 0:
        size = _heap_pop(keys, vals, size)
        cur = vals[size]
        if fixed[cur]:
            continue
        fixed[cur] = True
        size = _settle(
            cur,
            pos,
            faces,
            indptr,
            indices,
            vf_indptr,
            vf_faces,
            dist,
            fixed,
            keys,
            vals,
            size,
            max_distance,
            verbatim,
        )
    return dist


@nb.njit(**_JIT)
def _settle(
    cur,
    pos,
    faces,
    indptr,
    indices,
    vf_indptr,
    vf_faces,
    dist,
    fixed,
    keys,
    vals,
    size,
    max_distance,
    verbatim,
) -> int:
    """Update the free corner of cur's faces that have two fixed corners; return queue size."""
    for j in range(vf_indptr[cur], vf_indptr[cur + 1]):
        f = vf_faces[j]
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        if a in (b, c) or b == c:
            continue
        fa, fb, fc = fixed[a], fixed[b], fixed[c]
        if fa and fb and not fc:
            v1, v2, v3 = a, b, c
        elif fa and fc and not fb:
            v1, v2, v3 = c, a, b
        elif fb and fc and not fa:
            v1, v2, v3 = b, c, a
        else:
            continue
        u1, u2, u3 = dist[v1], dist[v2], dist[v3]
        if u3 == 0.0:
            continue
        ec = _edge_length(pos, v1, v2)
        eb = _edge_length(pos, v1, v3)
        ea = _edge_length(pos, v2, v3)
        if verbatim:
            dot = (ea * ea + eb * eb - ec * ec) / (2.0 * ea * eb)
            u3new = _sethian_verbatim(u1, u2, ea, eb, dot)
        else:
            u3new = _planar(u1, u2, ea, eb, ec)
        if not math.isfinite(u3new) or not u3new < u3:
            continue
        dist[v3] = u3new
        if u1 <= max_distance and u2 <= max_distance and (verbatim or u3new <= max_distance):
            size = _heap_push(keys, vals, size, u3new, v3)
    if verbatim or dist[cur] > max_distance:
        return size
    for i in range(indptr[cur], indptr[cur + 1]):
        u = indices[i]
        if fixed[u]:
            continue
        nd = dist[cur] + _edge_length(pos, cur, u)
        if nd < dist[u]:
            dist[u] = nd
            if nd <= max_distance:
                size = _heap_push(keys, vals, size, nd, u)
    return size


@nb.njit(**_JIT)
def edge_distances(pos, indptr, indices, seeds, max_distance):
    """Return shortest edge-path distances from ``seeds``, not expanding beyond max_distance."""
    n = pos.shape[0]
    dist = np.full(n, np.inf)
    cap = len(seeds) + len(indices) + 1
    keys = np.empty(cap, np.float64)
    vals = np.empty(cap, np.int32)
    size = 0
    for s in seeds:
        if dist[s] != 0.0:
            dist[s] = 0.0
            size = _heap_push(keys, vals, size, 0.0, s)
    done = np.zeros(n, np.bool_)
    while size > 0:
        size = _heap_pop(keys, vals, size)
        cur = vals[size]
        if done[cur]:
            continue
        done[cur] = True
        d = dist[cur]
        if d > max_distance:
            continue
        for i in range(indptr[cur], indptr[cur + 1]):
            u = indices[i]
            nd = d + _edge_length(pos, cur, u)
            if nd < dist[u]:
                dist[u] = nd
                size = _heap_push(keys, vals, size, nd, u)
    return dist
