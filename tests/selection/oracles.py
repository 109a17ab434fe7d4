"""Slow, obviously-correct references for the selection tests (float64 numpy, no Embree)."""

from __future__ import annotations

import numpy as np

EDGE_TOL = 1e-6  # metres: a ray this close to a shared edge may hit either face


def bumpy_terrain(n=40, size=20.0, *, seed=0, utm=False, wall=True):
    """Seeded grid terrain: sines + 5 cm noise + a thin wall; optionally at UTM coordinates."""
    rng = np.random.default_rng(seed)
    xs = np.linspace(-size / 2, size / 2, n + 1)
    gx, gy = np.meshgrid(xs, xs)
    z = 0.8 * np.sin(gx / 3.0) + 0.5 * np.cos(gy / 2.0) + rng.normal(0.0, 0.05, gx.shape)
    if wall:
        z += np.where(np.abs(gx - 2.0) < 0.6 * size / n, 3.0, 0.0) * (np.abs(gy) < 6.0)
    vertices = np.stack([gx.ravel(), gy.ravel(), z.ravel()], axis=1)
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    a, b, c, d = idx[:-1, :-1], idx[:-1, 1:], idx[1:, :-1], idx[1:, 1:]
    faces = np.concatenate(
        [np.stack([a, b, d], -1).reshape(-1, 3), np.stack([a, d, c], -1).reshape(-1, 3)]
    ).astype(np.int32)
    if utm:
        vertices = vertices + np.array([500_000.0, 5_700_000.0, 100.0])
    return vertices, faces


def ray_triangle(origin, direction, tri):
    """Möller–Trumbore for one ray against [F, 3, 3] triangles: (t, b1, b2), t NaN if parallel."""
    v0, v1, v2 = tri[:, 0], tri[:, 1], tri[:, 2]
    e1, e2 = v1 - v0, v2 - v0
    p = np.cross(direction, e2)
    det = np.einsum("ij,ij->i", e1, p)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        s = origin - v0
        b1 = np.einsum("ij,ij->i", s, p) * inv
        q = np.cross(s, e1)
        b2 = (q @ direction) * inv
        t = np.einsum("ij,ij->i", e2, q) * inv
    t[det == 0] = np.nan
    return t, b1, b2


def brute_force_pick(vertices, faces, origins, directions):
    """Return (face_ids, t) of the first float64 hit per ray over all faces; -1 / inf on a miss.

    Work in a frame centred on the mesh so the float64 arithmetic is as good as it gets, and
    widen every triangle by 1e-12 in barycentric terms so that a ray exactly through an edge or
    vertex cannot slip through a rounding crack.
    """
    centre = vertices.mean(axis=0)
    tri = (vertices - centre)[faces]
    ids = np.full(len(origins), -1, np.int32)
    dist = np.full(len(origins), np.inf)
    for i, (o, d) in enumerate(zip(origins - centre, directions, strict=True)):
        t, b1, b2 = ray_triangle(o, d, tri)
        eps = 1e-12
        hit = (t >= 0) & (b1 >= -eps) & (b2 >= -eps) & (b1 + b2 <= 1 + eps)
        if hit.any():
            k = np.flatnonzero(hit)[np.argmin(t[hit])]
            ids[i], dist[i] = k, t[k]
    return ids, dist


def _point_segment_distance(p, a, b):
    ab = b - a
    t = np.clip(np.dot(p - a, ab) / np.dot(ab, ab), 0.0, 1.0)
    return float(np.linalg.norm(p - (a + t * ab)))


def distance_to_face(point, tri):
    """Return the distance from a point to a triangle [3, 3] (float64)."""
    v0, v1, v2 = tri
    n = np.cross(v1 - v0, v2 - v0)
    n /= np.linalg.norm(n)
    foot = point - np.dot(point - v0, n) * n
    # barycentric inside test of the foot point
    e1, e2, r = v1 - v0, v2 - v0, foot - v0
    d11, d12, d22 = e1 @ e1, e1 @ e2, e2 @ e2
    det = d11 * d22 - d12 * d12
    b1 = (d22 * (r @ e1) - d12 * (r @ e2)) / det
    b2 = (d11 * (r @ e2) - d12 * (r @ e1)) / det
    off_plane = abs(float(np.dot(point - v0, n)))
    if b1 >= 0 and b2 >= 0 and b1 + b2 <= 1:
        return off_plane
    edge = min(
        _point_segment_distance(foot, v0, v1),
        _point_segment_distance(foot, v1, v2),
        _point_segment_distance(foot, v2, v0),
    )
    return float(np.hypot(edge, off_plane))


def _distance_to_boundary(point, tri):
    v0, v1, v2 = tri
    return min(
        _point_segment_distance(point, v0, v1),
        _point_segment_distance(point, v1, v2),
        _point_segment_distance(point, v2, v0),
    )


def agreement(vertices, faces, origins, directions, face_ids, ref_ids, ref_t):
    """Compare picks with the float64 reference; return (agree, grazing) bool arrays per ray.

    agree: the same face (or both miss), or our face passes within 1e-6 m of the reference hit
    point, i.e. the ray hits a shared edge and either face is right.
    grazing: not agree, but the ray passes within 1e-6 m of a ridge or of the mesh's outer edge,
    where it hits or misses depending on a hair: the reference hit lies within 1e-6 m of its
    face's boundary and ours is what the ray gives a hair away (a miss past the outer edge, or
    a face behind the ridge), or our hit lies on the rim of our face, in front of the
    reference's. Either answer is right at 1e-6.
    """
    centre = vertices.mean(axis=0)
    local = vertices - centre
    agree = face_ids == ref_ids
    grazing = np.zeros_like(agree)
    for i in np.flatnonzero(~agree):
        o, d = origins[i] - centre, directions[i]
        ref_hit = o + ref_t[i] * d if ref_ids[i] >= 0 else None
        if face_ids[i] >= 0:
            ours_tri = local[faces[face_ids[i]]]
            t = ray_triangle(o, d, ours_tri[None])[0][0]
            ours_hit = o + t * d
        if ref_hit is not None and face_ids[i] >= 0:
            if distance_to_face(ref_hit, ours_tri) <= EDGE_TOL:
                agree[i] = True  # a shared edge: either face
            else:
                # a ridge the ray grazes: ours passes it (reference hit on its rim, ours beyond)
                # or stops at it (our hit on the rim of our face, in front of the reference's)
                grazing[i] = (
                    _distance_to_boundary(ref_hit, local[faces[ref_ids[i]]]) <= EDGE_TOL
                    and distance_to_face(ours_hit, ours_tri) <= EDGE_TOL
                    and t >= ref_t[i]
                ) or (_distance_to_boundary(ours_hit, ours_tri) <= EDGE_TOL and t <= ref_t[i])
        elif ref_hit is not None:  # we miss where the reference hits
            grazing[i] = _distance_to_boundary(ref_hit, local[faces[ref_ids[i]]]) <= EDGE_TOL
        else:  # we hit where the reference misses
            grazing[i] = _distance_to_boundary(ours_hit, ours_tri) <= EDGE_TOL
    return agree, grazing


def faces_seen_by_rays(index, camera, rect, centroids_world):
    """The visible-mode oracle: faces hit first by a ray through a pixel centre in the rect or by
    the ray to their own centroid; also the first-hit distance ratio of every centroid ray.

    Returns
    -------
    seen : set of face ids
    centroid_hit_ratio : float [F]
        (distance to the first hit) / (distance to the centroid) along the centroid ray; 1 when
        the face itself is hit first, < 1 when something else is in front. NaN off-rect.
    """
    i0, j0, i1, j1 = rect.pixel_range(camera.width, camera.height)
    ii, jj = np.meshgrid(np.arange(i0, i1 + 1), np.arange(j0, j1 + 1))
    uv = np.stack([(ii.ravel() + 0.5) / camera.width, (jj.ravel() + 0.5) / camera.height], 1)
    origins, directions = camera.rays(uv)
    pixel_hits = index.pick(origins, directions).face_ids
    seen = set(pixel_hits[pixel_hits >= 0].tolist())

    uv_c, depth = camera.project(centroids_world)
    in_rect = (
        (depth > camera.near)
        & (uv_c[:, 0] >= rect.min_xy[0])
        & (uv_c[:, 0] <= rect.max_xy[0])
        & (uv_c[:, 1] >= rect.min_xy[1])
        & (uv_c[:, 1] <= rect.max_xy[1])
    )
    ratio = np.full(len(centroids_world), np.nan)
    ids = np.flatnonzero(in_rect)
    d = centroids_world[ids] - camera.position
    hits = index.pick(np.broadcast_to(camera.position, d.shape), d)
    ratio[ids] = np.where(hits.face_ids == ids, 1.0, np.minimum(hits.distances, 1.0))
    seen |= set(ids[hits.face_ids == ids].tolist())
    return seen, ratio
