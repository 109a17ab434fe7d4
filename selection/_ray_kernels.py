"""Compiled float64 ray–triangle kernels behind ``MeshIndex`` (private to selection)."""

from __future__ import annotations

import numba
import numpy as np
import numpy.typing as npt

# Barycentric slack of the float64 re-test: a ray through an edge must not slip between the
# two faces by rounding (1e-11 of a 1 m face is 0.01 nm).
_BARY_EPS = 1e-11

#: ``face_ids`` value for a ray that float32 Embree stopped at a face it misses in float64
#: (grazing a ridge): the caller casts it again from just beyond that distance.
GRAZED = -2

# A float32 Embree hit this close to an edge of its face (relative to the scene scale) may
# belong to the neighbour in exact arithmetic; float32 rounding is ~6e-8 of the scale, so this
# leaves a wide safety factor while re-testing well under 1 % of the rays.
_NEAR_EDGE_REL = 4e-6


@numba.njit(nogil=True, cache=True)
def shift_rays(
    origins: npt.NDArray[np.float64],
    directions: npt.NDArray[np.float64],
    origin: npt.NDArray[np.float64],
    origins32: npt.NDArray[np.float32],
    directions32: npt.NDArray[np.float32],
) -> None:
    """Write ``origins - origin`` (subtracted in float64) and ``directions`` as float32 rows."""
    for i in range(origins.shape[0]):
        for k in range(3):
            origins32[i, k] = origins[i, k] - origin[k]
    for j in range(directions.shape[0]):  # [n, 3], or one row shared by all rays
        for k in range(3):
            directions32[j, k] = directions[j, k]


@numba.njit(nogil=True, cache=True, inline="always")
def _hit_triangle(
    ox: float,
    oy: float,
    oz: float,
    dx: float,
    dy: float,
    dz: float,
    vertices: npt.NDArray[np.float64],
    faces: npt.NDArray[np.int32],
    f: int,
) -> tuple[float, float, float, float, float]:
    """Return (t, b0, b1, b2, scale) of the ray and face ``f``'s plane (Möller–Trumbore).

    ``t`` is NaN when the ray runs parallel to the plane; the barycentric weights are not
    clamped, so a negative one means the ray passes outside that edge.
    """
    a = faces[f, 0]
    b = faces[f, 1]
    c = faces[f, 2]
    ax, ay, az = vertices[a, 0], vertices[a, 1], vertices[a, 2]
    e1x, e1y, e1z = vertices[b, 0] - ax, vertices[b, 1] - ay, vertices[b, 2] - az
    e2x, e2y, e2z = vertices[c, 0] - ax, vertices[c, 1] - ay, vertices[c, 2] - az
    px = dy * e2z - dz * e2y
    py = dz * e2x - dx * e2z
    pz = dx * e2y - dy * e2x
    det = e1x * px + e1y * py + e1z * pz
    if det == 0.0:
        return np.nan, -1.0, -1.0, -1.0, 0.0
    inv = 1.0 / det
    sx, sy, sz = ox - ax, oy - ay, oz - az
    b1 = (sx * px + sy * py + sz * pz) * inv
    qx = sy * e1z - sz * e1y
    qy = sz * e1x - sx * e1z
    qz = sx * e1y - sy * e1x
    b2 = (dx * qx + dy * qy + dz * qz) * inv
    t = (e2x * qx + e2y * qy + e2z * qz) * inv
    # Scale of the rounding Embree saw: the largest local coordinate involved.
    scale = max(abs(ox), abs(oy), abs(oz), abs(ax), abs(ay), abs(az))
    return t, 1.0 - b1 - b2, b1, b2, scale


@numba.njit(nogil=True, cache=True, inline="always")
def _edge_clearance(
    vertices: npt.NDArray[np.float64],
    faces: npt.NDArray[np.int32],
    f: int,
    b0: float,
    b1: float,
    b2: float,
) -> float:
    """Return the hit point's distance to the nearest edge of face ``f`` (metres)."""
    a = faces[f, 0]
    b = faces[f, 1]
    c = faces[f, 2]
    ab = np.sqrt(
        (vertices[b, 0] - vertices[a, 0]) ** 2
        + (vertices[b, 1] - vertices[a, 1]) ** 2
        + (vertices[b, 2] - vertices[a, 2]) ** 2
    )
    bc = np.sqrt(
        (vertices[c, 0] - vertices[b, 0]) ** 2
        + (vertices[c, 1] - vertices[b, 1]) ** 2
        + (vertices[c, 2] - vertices[b, 2]) ** 2
    )
    ca = np.sqrt(
        (vertices[a, 0] - vertices[c, 0]) ** 2
        + (vertices[a, 1] - vertices[c, 1]) ** 2
        + (vertices[a, 2] - vertices[c, 2]) ** 2
    )
    e1x = vertices[b, 0] - vertices[a, 0]
    e1y = vertices[b, 1] - vertices[a, 1]
    e1z = vertices[b, 2] - vertices[a, 2]
    e2x = vertices[c, 0] - vertices[a, 0]
    e2y = vertices[c, 1] - vertices[a, 1]
    e2z = vertices[c, 2] - vertices[a, 2]
    nx = e1y * e2z - e1z * e2y
    ny = e1z * e2x - e1x * e2z
    nz = e1x * e2y - e1y * e2x
    twice_area = np.sqrt(nx * nx + ny * ny + nz * nz)
    # distance to the edge opposite corner k = b_k * height_k = b_k * 2A / |edge_k|
    d0 = b0 * twice_area / bc if bc > 0.0 else 0.0
    d1 = b1 * twice_area / ca if ca > 0.0 else 0.0
    d2 = b2 * twice_area / ab if ab > 0.0 else 0.0
    return min(d0, d1, d2)


@numba.njit(nogil=True, cache=True, inline="always")
def _refine(
    f: int,
    ox: float,
    oy: float,
    oz: float,
    dx: float,
    dy: float,
    dz: float,
    vertices: npt.NDArray[np.float64],
    faces: npt.NDArray[np.int32],
    incidence_ptr: npt.NDArray[np.int64],
    incidence_ids: npt.NDArray[np.int32],
) -> tuple[int, float]:
    """Return the float64 (face, t) for Embree's hit ``f`` of the local-frame ray ``o + t d``.

    A hit well inside its face is kept and only gets its float64 distance. A hit near an edge
    (or outside the face in float64) is re-tested against every face sharing a vertex with it,
    and the nearest float64 hit among them wins; when none is hit, the ray grazes a ridge and
    the answer is (``GRAZED``, t). Misses stay misses (t = +inf).
    """
    if f < 0:
        return f, np.inf
    t, b0, b1, b2, scale = _hit_triangle(ox, oy, oz, dx, dy, dz, vertices, faces, f)
    if t == t and b0 >= 0.0 and b1 >= 0.0 and b2 >= 0.0:
        dnorm = np.sqrt(dx * dx + dy * dy + dz * dz)
        tol = _NEAR_EDGE_REL * max(scale, abs(t) * dnorm)
        if _edge_clearance(vertices, faces, f, b0, b1, b2) > tol:
            return f, t
    best_f = -1
    best_t = np.inf
    for corner in range(3):
        vtx = faces[f, corner]
        for k in range(incidence_ptr[vtx], incidence_ptr[vtx + 1]):
            g = incidence_ids[k]
            tg, c0, c1, c2, _ = _hit_triangle(ox, oy, oz, dx, dy, dz, vertices, faces, g)
            # inclusive by a rounding hair, so a ray exactly through an edge finds a face
            inside = tg == tg and tg >= 0.0 and min(c0, c1, c2) >= -_BARY_EPS
            if inside and (tg < best_t or (tg == best_t and g < best_f)):
                best_t = tg
                best_f = g
    if best_f >= 0:
        return best_f, best_t
    # Float32 caught a ridge or rim that the float64 ray passes by: what it hits lies beyond.
    return GRAZED, (t if t == t else 0.0)


@numba.njit(nogil=True, cache=True)
def refine_hits(
    face_ids: npt.NDArray[np.int32],
    origins: npt.NDArray[np.float64],
    directions: npt.NDArray[np.float64],
    origin: npt.NDArray[np.float64],
    vertices: npt.NDArray[np.float64],
    faces: npt.NDArray[np.int32],
    incidence_ptr: npt.NDArray[np.int64],
    incidence_ids: npt.NDArray[np.int32],
    distances: npt.NDArray[np.float64],
) -> None:
    """Check float32 Embree hits of [n, 3] rays in float64 (``_refine``), in place."""
    n = face_ids.shape[0]
    step = 1 if directions.shape[0] == n else 0
    for i in range(n):
        j = i * step
        f, t = _refine(
            face_ids[i],
            origins[i, 0] - origin[0],
            origins[i, 1] - origin[1],
            origins[i, 2] - origin[2],
            directions[j, 0],
            directions[j, 1],
            directions[j, 2],
            vertices,
            faces,
            incidence_ptr,
            incidence_ids,
        )
        face_ids[i] = f
        distances[i] = t


@numba.njit(nogil=True, cache=True)
def shift_ray(
    origin_world: npt.NDArray[np.float64],
    direction: npt.NDArray[np.float64],
    origin: npt.NDArray[np.float64],
    origins32: npt.NDArray[np.float32],
    directions32: npt.NDArray[np.float32],
) -> None:
    """Write one [3] ray, shifted in float64, into row 0 of the float32 buffers."""
    for k in range(3):
        origins32[0, k] = origin_world[k] - origin[k]
        directions32[0, k] = direction[k]


@numba.njit(nogil=True, cache=True)
def refine_hit(
    face_ids: npt.NDArray[np.int32],
    origin_world: npt.NDArray[np.float64],
    direction: npt.NDArray[np.float64],
    origin: npt.NDArray[np.float64],
    vertices: npt.NDArray[np.float64],
    faces: npt.NDArray[np.int32],
    incidence_ptr: npt.NDArray[np.int64],
    incidence_ids: npt.NDArray[np.int32],
    distances: npt.NDArray[np.float64],
) -> None:
    """Check one [3] ray's Embree hit in float64 (``_refine``), in place."""
    f, t = _refine(
        face_ids[0],
        origin_world[0] - origin[0],
        origin_world[1] - origin[1],
        origin_world[2] - origin[2],
        direction[0],
        direction[1],
        direction[2],
        vertices,
        faces,
        incidence_ptr,
        incidence_ids,
    )
    face_ids[0] = f
    distances[0] = t
