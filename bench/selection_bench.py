"""Selection benchmarks: Embree picking, brush, rubber band, and UTM precision (issue 4).

Keys (1M faces in the reference run; each figure the median of ``args.repeats`` after one
warm-up, measured in the same run as its baseline):

- ``bvh_build_s``: ``MeshIndex(vertices, faces)``, BVH committed (what "indexing…" waits for);
- ``pick_us`` / ``pick_trimesh_us``: one float64 world ray per call, face id + distance,
  ``MeshIndex.pick`` vs trimesh's ``mesh.ray.intersects_first`` (embreex installed);
- ``brush_ms``: one drag step in connected mode: pick the new pointer position, fill the gap
  from the previous one (``stroke_points``, half-radius spacing, a step of one radius), brush
  every sample with a radius covering ~10k faces;
- ``rect_visible_ms`` / ``rect_through_ms`` / ``rect_naive_ms``: the central half in x and y
  of the overview view (1280x720); naive = project every centroid, then one batched trimesh
  ``intersects_first`` with a ray from the camera to each centroid in the rectangle;
- ``pick_agree_utm_pct``: share of 1,000 click rays (from the overview camera toward random
  points of the surface) on the UTM-shifted terrain whose face agrees
  with a float64 brute-force reference (either face when the ray is within 1e-6 m of a shared
  edge); ``pick_agree_trimesh_utm_pct`` is the same for trimesh;
- ``jit_s``: numba compile (or cache load) time of the selection kernels, paid once.
"""

from __future__ import annotations

import math
import sys
import time

import numba
import numpy as np
import trimesh

from bench.terrain import BenchCamera, Terrain, make_terrain, overview_camera
from bench.timing import median_seconds
from geometry import face_adjacency
from selection import (
    BrushIndex,
    CameraModel,
    MeshIndex,
    RectSelector,
    ScreenRect,
    brush_faces,
    flood_faces,
    stroke_points,
)

RECT = ScreenRect((0.25, 0.25), (0.75, 0.75))
BRUSH_FACES = 10_000
AGREE_RAYS = 1_000
EDGE_TOL = 1e-6


def run(terrain: Terrain, args) -> dict:
    repeats = max(int(args.repeats), 1)
    out: dict[str, object] = {"jit_s": _warm_up_kernels()}

    def median(fn, *, inner: int = 1) -> float:
        return median_seconds(fn, repeats=repeats) / inner

    # --- index build --------------------------------------------------------------------
    holder: dict[str, MeshIndex] = {}

    def build() -> None:
        holder["index"] = MeshIndex(terrain.vertices, terrain.faces)

    out["bvh_build_s"] = median(build)
    index = holder["index"]
    camera = _camera(overview_camera(terrain))
    _check_camera_fits(terrain, camera)

    # --- single-ray pick vs trimesh ------------------------------------------------------
    rng = np.random.default_rng(0)
    origins, directions = camera.rays(rng.uniform([0.3, 0.3], [0.7, 0.8], (200, 2)))
    rays = [(o.copy(), d.copy()) for o, d in zip(origins, directions, strict=True)]

    def pick_all() -> None:
        for o, d in rays:
            index.pick(o, d)

    out["pick_us"] = median(pick_all, inner=len(rays)) * 1e6
    mesh = trimesh.Trimesh(terrain.vertices, terrain.faces, process=False)
    mesh.ray.intersects_first(origins[:1], directions[:1])  # builds trimesh's own BVH
    trimesh_rays = [(o[None], d[None]) for o, d in rays]

    def trimesh_all() -> None:
        for o, d in trimesh_rays:
            mesh.ray.intersects_first(o, d)

    out["pick_trimesh_us"] = median(trimesh_all, inner=len(rays)) * 1e6

    # --- brush: one drag step --------------------------------------------------------------
    adjacency = face_adjacency(terrain.faces)
    brush = BrushIndex(terrain.vertices, terrain.faces, adjacency=adjacency)
    radius = math.sqrt(BRUSH_FACES * _mean_face_area(terrain) / math.pi)
    start, end = _drag(index, camera, radius)
    for _ in range(3):  # walls and slopes add area: size the brush to ~10k faces where it is
        dab = len(brush_faces(brush, start, radius, connected=True))
        radius *= math.sqrt(BRUSH_FACES / max(dab, 1))
        start, end = _drag(index, camera, radius)

    def drag_step() -> np.ndarray:
        hit = index.pick(end[0], end[1])
        point = index.hit_points(end[0], end[1], hit)[0]
        samples = stroke_points(start, point, radius / 2)
        seeds = brush.nearest_faces(samples, radius)
        seeds[-1] = hit.face_ids[0]
        return brush_faces(brush, samples, radius, seed_face=seeds, connected=True)

    out["brush_ms"] = median(drag_step) * 1e3
    out["brush_radius_m"] = radius
    out["brush_dab_faces"] = len(brush_faces(brush, start, radius, connected=True))
    out["brush_step_faces"] = len(drag_step())

    # --- rubber band ---------------------------------------------------------------------
    selector = RectSelector(terrain.vertices - index.origin, terrain.faces)
    local_camera = camera.shifted(index.origin)
    visible = selector.select(local_camera, RECT, mode="visible")
    through = selector.select(local_camera, RECT, mode="through")
    out["rect_visible_ms"] = (
        median(lambda: selector.select(local_camera, RECT, mode="visible")) * 1e3
    )
    out["rect_through_ms"] = (
        median(lambda: selector.select(local_camera, RECT, mode="through")) * 1e3
    )
    centroids = mesh.triangles_center  # cached per geometry, like RectSelector's

    def naive() -> np.ndarray:
        uv, depth = camera.project(centroids)
        inside = (depth > 0) & (uv >= RECT.min_xy).all(1) & (uv <= RECT.max_xy).all(1)
        ids = np.flatnonzero(inside)
        d = centroids[ids] - camera.position
        first = mesh.ray.intersects_first(np.broadcast_to(camera.position, d.shape), d)
        return ids[first == ids]

    out["rect_naive_ms"] = median(naive) * 1e3
    out["rect_visible_faces"] = len(visible)
    out["rect_through_faces"] = len(through)
    out["rect_naive_faces"] = len(naive())

    # --- precision at UTM coordinates ------------------------------------------------------
    out.update(_utm_agreement(terrain, rng))
    _report(out)
    return out


def _camera(bc: BenchCamera) -> CameraModel:
    return CameraModel(bc.position, bc.wxyz, bc.fov, bc.aspect, bc.width, bc.height)


def _check_camera_fits(terrain: Terrain, camera: CameraModel) -> None:
    """The overview camera must show the whole terrain (the rect figures assume it)."""
    uv, depth = camera.project(terrain.vertices)
    lo, hi = uv.min(axis=0), uv.max(axis=0)
    print(
        f"[bench] overview camera: terrain spans u {lo[0]:.3f}..{hi[0]:.3f}, "
        f"v {lo[1]:.3f}..{hi[1]:.3f}",
        file=sys.stderr,
    )
    if (depth <= 0).any() or (lo < 0).any() or (hi > 1).any():
        raise RuntimeError("bench.terrain.overview_camera does not show the whole terrain")


def _mean_face_area(terrain: Terrain) -> float:
    tri = terrain.vertices[terrain.faces]
    return (
        float(np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1).mean())
        / 2
    )


def _drag(index: MeshIndex, camera: CameraModel, radius: float):
    """A drag over open ground: the previous brush point and the next pointer ray."""
    o, d = camera.rays([0.45, 0.62])
    previous = index.hit_points(o[0], d[0])[0]
    # the next event: the pointer ray toward a point one radius further east
    target = previous + np.array([radius, 0.0, 0.0])
    direction = target - camera.position
    return previous, (camera.position.copy(), direction / np.linalg.norm(direction))


def _warm_up_kernels() -> float:
    """Compile (or load from numba's cache) every selection kernel on a tiny mesh."""
    t0 = time.perf_counter()
    small = make_terrain(200)
    index = MeshIndex(small.vertices, small.faces)
    camera = _camera(overview_camera(small, width=64, height=36))
    index.pick(*camera.rays([[0.5, 0.5], [0.4, 0.6]]))
    o, d = camera.rays([0.5, 0.5])
    index.pick(o[0], d[0])
    selector = RectSelector(small.vertices, small.faces)
    for mode in ("visible", "through"):
        selector.select(camera, RECT, mode=mode)
    brush = BrushIndex(small.vertices, small.faces)
    for connected in (True, False):
        brush_faces(brush, small.vertices[:2], 5.0, connected=connected)
    flood_faces(face_adjacency(small.faces), 0)
    return time.perf_counter() - t0


# --- the float64 reference for pick_agree_utm_pct ---------------------------------------------


def _utm_agreement(terrain: Terrain, rng: np.random.Generator) -> dict[str, float]:
    utm = make_terrain(terrain.n_faces, utm=True)
    camera = _camera(overview_camera(utm))
    # clicks on the map: rays from the camera toward random points of the surface
    tri = utm.vertices[utm.faces[rng.integers(0, utm.n_faces, AGREE_RAYS)]]
    targets = np.einsum("ij,ijk->ik", rng.dirichlet([1.0, 1.0, 1.0], AGREE_RAYS), tri)
    directions = targets - camera.position
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    origins = np.broadcast_to(camera.position, directions.shape).copy()
    ours = MeshIndex(utm.vertices, utm.faces).pick(origins, directions).face_ids
    mesh = trimesh.Trimesh(utm.vertices, utm.faces, process=False)
    theirs = mesh.ray.intersects_first(origins, directions)
    ref_ids, ref_t = _reference_pick(utm.vertices, utm.faces, origins, directions)
    return {
        "pick_agree_utm_pct": 100.0 * _agree(utm, origins, directions, ours, ref_ids, ref_t),
        "pick_agree_trimesh_utm_pct": 100.0
        * _agree(utm, origins, directions, theirs, ref_ids, ref_t),
        "pick_agree_rays_hit": int((ref_ids >= 0).sum()),
    }


def _agree(terrain, origins, directions, face_ids, ref_ids, ref_t) -> float:
    """Share of rays on the reference's face, or within 1e-6 m of it across a shared edge."""
    centre = terrain.vertices.mean(axis=0)
    local = terrain.vertices - centre
    ok = face_ids == ref_ids
    for i in np.flatnonzero(~ok):
        if face_ids[i] < 0 or ref_ids[i] < 0:
            continue
        hit = origins[i] - centre + ref_t[i] * directions[i]
        ok[i] = _point_triangle_distance(hit, local[terrain.faces[face_ids[i]]]) <= EDGE_TOL
    return float(ok.mean())


def _point_triangle_distance(p, tri) -> float:
    v0, v1, v2 = tri
    n = np.cross(v1 - v0, v2 - v0)
    n /= np.linalg.norm(n)
    off = float(np.dot(p - v0, n))
    q = p - off * n
    e1, e2, r = v1 - v0, v2 - v0, q - v0
    d11, d12, d22 = e1 @ e1, e1 @ e2, e2 @ e2
    det = d11 * d22 - d12 * d12
    b1 = (d22 * (r @ e1) - d12 * (r @ e2)) / det
    b2 = (d11 * (r @ e2) - d12 * (r @ e1)) / det
    if b1 >= 0 and b2 >= 0 and b1 + b2 <= 1:
        return abs(off)

    def seg(a, b):
        t = np.clip(np.dot(q - a, b - a) / np.dot(b - a, b - a), 0.0, 1.0)
        return float(np.linalg.norm(q - (a + t * (b - a))))

    return math.hypot(min(seg(v0, v1), seg(v1, v2), seg(v2, v0)), off)


def _reference_pick(vertices, faces, origins, directions):
    """Float64 first hit of every ray (Möller–Trumbore, watertight to 1e-12 barycentric).

    Faces are binned by their xy box into a 2-D grid, and each ray walks the cells it crosses
    in order (a DDA), stopping once its best hit lies before the next cell.
    """
    centre = vertices.mean(axis=0)
    local = np.ascontiguousarray(vertices - centre)
    tri = local[faces]
    lo = tri[:, :, :2].min(axis=(0, 1)) - 1e-9
    cell = max(float(np.sqrt(np.ptp(tri[:, :, :2], axis=1).prod(axis=1).mean()) * 4), 1e-6)
    dims = (np.ptp(tri[:, :, :2].reshape(-1, 2), axis=0) / cell).astype(np.int64) + 1
    start, members = _bin_faces(tri, lo, cell, dims)
    return _walk(
        np.ascontiguousarray(origins - centre), np.ascontiguousarray(directions), tri,
        lo, cell, dims, start, members,
    )  # fmt: skip


@numba.njit(cache=True)
def _bin_faces(tri, lo, cell, dims):
    n = tri.shape[0]
    counts = np.zeros(dims[0] * dims[1] + 1, np.int64)
    for f in range(n):
        x0 = int((min(tri[f, 0, 0], tri[f, 1, 0], tri[f, 2, 0]) - lo[0]) / cell)
        x1 = int((max(tri[f, 0, 0], tri[f, 1, 0], tri[f, 2, 0]) - lo[0]) / cell)
        y0 = int((min(tri[f, 0, 1], tri[f, 1, 1], tri[f, 2, 1]) - lo[1]) / cell)
        y1 = int((max(tri[f, 0, 1], tri[f, 1, 1], tri[f, 2, 1]) - lo[1]) / cell)
        for ix in range(x0, min(x1, dims[0] - 1) + 1):
            for iy in range(y0, min(y1, dims[1] - 1) + 1):
                counts[ix * dims[1] + iy + 1] += 1
    for k in range(dims[0] * dims[1]):
        counts[k + 1] += counts[k]
    members = np.empty(counts[-1], np.int32)
    fill = counts[:-1].copy()
    for f in range(n):
        x0 = int((min(tri[f, 0, 0], tri[f, 1, 0], tri[f, 2, 0]) - lo[0]) / cell)
        x1 = int((max(tri[f, 0, 0], tri[f, 1, 0], tri[f, 2, 0]) - lo[0]) / cell)
        y0 = int((min(tri[f, 0, 1], tri[f, 1, 1], tri[f, 2, 1]) - lo[1]) / cell)
        y1 = int((max(tri[f, 0, 1], tri[f, 1, 1], tri[f, 2, 1]) - lo[1]) / cell)
        for ix in range(x0, min(x1, dims[0] - 1) + 1):
            for iy in range(y0, min(y1, dims[1] - 1) + 1):
                k = ix * dims[1] + iy
                members[fill[k]] = f
                fill[k] += 1
    return counts, members


@numba.njit(cache=True)
def _walk(origins, directions, tri, lo, cell, dims, start, members):
    n = origins.shape[0]
    ids = np.full(n, -1, np.int32)
    dist = np.full(n, np.inf)
    eps = 1e-12
    for i in range(n):
        o = origins[i]
        d = directions[i]
        # clip the ray's xy path to the grid's box
        t_in, t_out = 0.0, np.inf
        for a in range(2):
            hi = lo[a] + dims[a] * cell
            if d[a] == 0.0:
                if o[a] < lo[a] or o[a] > hi:
                    t_in, t_out = 1.0, 0.0
            else:
                ta, tb = (lo[a] - o[a]) / d[a], (hi - o[a]) / d[a]
                t_in, t_out = max(t_in, min(ta, tb)), min(t_out, max(ta, tb))
        if t_in > t_out:
            continue
        if t_out == np.inf:  # a vertical ray: one cell
            t_out = t_in
        t = t_in
        p0 = o[0] + t * d[0]
        p1 = o[1] + t * d[1]
        ix = min(max(int((p0 - lo[0]) / cell), 0), dims[0] - 1)
        iy = min(max(int((p1 - lo[1]) / cell), 0), dims[1] - 1)
        step_x = 1 if d[0] > 0 else -1
        step_y = 1 if d[1] > 0 else -1
        next_x = (lo[0] + (ix + (step_x > 0)) * cell - o[0]) / d[0] if d[0] != 0 else np.inf
        next_y = (lo[1] + (iy + (step_y > 0)) * cell - o[1]) / d[1] if d[1] != 0 else np.inf
        dx = cell / abs(d[0]) if d[0] != 0 else np.inf
        dy = cell / abs(d[1]) if d[1] != 0 else np.inf
        best = np.inf
        best_f = -1
        while True:
            k = ix * dims[1] + iy
            for m in range(start[k], start[k + 1]):
                f = members[m]
                v0 = tri[f, 0]
                e1 = tri[f, 1] - v0
                e2 = tri[f, 2] - v0
                px = d[1] * e2[2] - d[2] * e2[1]
                py = d[2] * e2[0] - d[0] * e2[2]
                pz = d[0] * e2[1] - d[1] * e2[0]
                det = e1[0] * px + e1[1] * py + e1[2] * pz
                if det == 0.0:
                    continue
                s = o - v0
                b1 = (s[0] * px + s[1] * py + s[2] * pz) / det
                if b1 < -eps or b1 > 1 + eps:
                    continue
                qx = s[1] * e1[2] - s[2] * e1[1]
                qy = s[2] * e1[0] - s[0] * e1[2]
                qz = s[0] * e1[1] - s[1] * e1[0]
                b2 = (d[0] * qx + d[1] * qy + d[2] * qz) / det
                if b2 < -eps or b1 + b2 > 1 + eps:
                    continue
                tf = (e2[0] * qx + e2[1] * qy + e2[2] * qz) / det
                if tf >= 0.0 and (tf < best or (tf == best and f < best_f)):
                    best, best_f = tf, f
            t_next = min(next_x, next_y)
            if best <= t_next or t_next > t_out:
                break
            if next_x < next_y:
                ix += step_x
                next_x += dx
            else:
                iy += step_y
                next_y += dy
            if ix < 0 or iy < 0 or ix >= dims[0] or iy >= dims[1]:
                break
        ids[i] = best_f
        dist[i] = best
    return ids, dist


def _report(out: dict[str, object]) -> None:
    checks = [
        ("pick_us <= pick_trimesh_us / 2.5", out["pick_us"] <= out["pick_trimesh_us"] / 2.5),
        ("brush_ms <= 5", out["brush_ms"] <= 5),
        ("rect_visible_ms <= 100", out["rect_visible_ms"] <= 100),
        (
            "rect_visible_ms <= rect_naive_ms / 3",
            out["rect_visible_ms"] <= out["rect_naive_ms"] / 3,
        ),
        ("pick_agree_utm_pct >= 99.9", out["pick_agree_utm_pct"] >= 99.9),
    ]
    for name, ok in checks:
        print(f"[bench] selection: {'ok  ' if ok else 'MISS'} {name}", file=sys.stderr)
