"""Compiled screen-space kernels behind the rubber band (private to selection).

Pixel coordinates: ``X = u * width``, ``Y = v * height`` (u, v normalised OpenCV screen
coordinates), so the centre of pixel (i, j) is at (i + 0.5, j + 0.5). Depth is camera-frame z;
the z-buffers store its inverse, which is affine in (X, Y) over a planar face.

``view`` is the tuple (fx, fy, cx, cy, near, x0, y0, x1, y1): focal lengths and principal point
in pixels (``X = cx + fx x_c / z_c``), the near plane, and the rect in pixel coordinates.
``pixels`` is (i0, j0, i1, j1): the inclusive columns and rows whose centres lie in the rect.
"""

from __future__ import annotations

import numba
import numpy as np
import numpy.typing as npt

View = tuple[float, float, float, float, float, float, float, float, float]
Pixels = tuple[int, int, int, int]


@numba.njit(nogil=True, cache=True)
def project_vertices(
    vertices: npt.NDArray[np.float64],
    position: npt.NDArray[np.float64],
    rotation: npt.NDArray[np.float64],
    view: View,
) -> npt.NDArray[np.float64]:
    """Return [N, 5] rows (x_c, y_c, z_c, X, Y): camera-frame point and pixel position.

    X and Y are NaN for vertices not beyond the near plane.
    """
    fx, fy, cx, cy, near = view[0], view[1], view[2], view[3], view[4]
    n = vertices.shape[0]
    out = np.empty((n, 5))
    for i in range(n):
        px = vertices[i, 0] - position[0]
        py = vertices[i, 1] - position[1]
        pz = vertices[i, 2] - position[2]
        xc = px * rotation[0, 0] + py * rotation[1, 0] + pz * rotation[2, 0]
        yc = px * rotation[0, 1] + py * rotation[1, 1] + pz * rotation[2, 1]
        zc = px * rotation[0, 2] + py * rotation[1, 2] + pz * rotation[2, 2]
        out[i, 0] = xc
        out[i, 1] = yc
        out[i, 2] = zc
        if zc >= near:
            out[i, 3] = cx + fx * xc / zc
            out[i, 4] = cy + fy * yc / zc
        else:
            out[i, 3] = np.nan
            out[i, 4] = np.nan
    return out


@numba.njit(nogil=True, cache=True, inline="always")
def _clip_polygon(
    f: int,
    faces: npt.NDArray[np.int32],
    proj: npt.NDArray[np.float64],
    view: View,
    xs: npt.NDArray[np.float64],
    ys: npt.NDArray[np.float64],
) -> int:
    """Write the screen polygon of the part of face ``f`` beyond the near plane; return its size.

    Sutherland–Hodgman against z = near: 0 (nothing beyond it), 3 or 4 vertices.
    """
    fx, fy, cx, cy, near = view[0], view[1], view[2], view[3], view[4]
    count = 0
    for k in range(3):
        p = faces[f, k]
        q = faces[f, (k + 1) % 3]
        zp = proj[p, 2]
        zq = proj[q, 2]
        if zp >= near:
            xs[count] = proj[p, 3]
            ys[count] = proj[p, 4]
            count += 1
        if (zp >= near) != (zq >= near):
            s = (near - zp) / (zq - zp)
            x = proj[p, 0] + s * (proj[q, 0] - proj[p, 0])
            y = proj[p, 1] + s * (proj[q, 1] - proj[p, 1])
            xs[count] = cx + fx * x / near
            ys[count] = cy + fy * y / near
            count += 1
    return count


@numba.njit(nogil=True, cache=True, inline="always")
def _edge_separates(
    ax: float,
    ay: float,
    bx: float,
    by: float,
    mx: float,
    my: float,
    view: View,
) -> bool:
    """Say whether the line a-b has the rect strictly on the other side from point m."""
    x0, y0, x1, y1 = view[5], view[6], view[7], view[8]
    ex = bx - ax
    ey = by - ay
    if ex == 0.0 and ey == 0.0:
        return False
    inner = ex * (my - ay) - ey * (mx - ax)
    e00 = ex * (y0 - ay) - ey * (x0 - ax)
    e01 = ex * (y1 - ay) - ey * (x0 - ax)
    e10 = ex * (y0 - ay) - ey * (x1 - ax)
    e11 = ex * (y1 - ay) - ey * (x1 - ax)
    if inner >= 0.0 and e00 < 0.0 and e01 < 0.0 and e10 < 0.0 and e11 < 0.0:
        return True
    return inner <= 0.0 and e00 > 0.0 and e01 > 0.0 and e10 > 0.0 and e11 > 0.0


@numba.njit(nogil=True, cache=True, inline="always")
def _triangle_on_screen(
    ax: float,
    ay: float,
    bx: float,
    by: float,
    qx: float,
    qy: float,
    view: View,
) -> tuple[bool, float, float, float, float]:
    """Say whether a screen triangle meets the rect; also return its box (lo_x, hi_x, lo_y, hi_y).

    Separating-axis test: the rect's axes (boxes), then the triangle's edges. Touching counts;
    a zero-area triangle is tested as a segment.
    """
    x0, y0, x1, y1 = view[5], view[6], view[7], view[8]
    lo_x = min(ax, bx, qx)
    hi_x = max(ax, bx, qx)
    lo_y = min(ay, by, qy)
    hi_y = max(ay, by, qy)
    if hi_x < x0 or lo_x > x1 or hi_y < y0 or lo_y > y1:
        return False, lo_x, hi_x, lo_y, hi_y
    if not (lo_x >= x0 and hi_x <= x1 and lo_y >= y0 and hi_y <= y1):
        mx = (ax + bx + qx) / 3.0
        my = (ay + by + qy) / 3.0
        if (
            _edge_separates(ax, ay, bx, by, mx, my, view)
            or _edge_separates(bx, by, qx, qy, mx, my, view)
            or _edge_separates(qx, qy, ax, ay, mx, my, view)
        ):
            return False, lo_x, hi_x, lo_y, hi_y
    return True, lo_x, hi_x, lo_y, hi_y


@numba.njit(nogil=True, cache=True, inline="always")
def _placement(
    f: int,
    faces: npt.NDArray[np.int32],
    proj: npt.NDArray[np.float64],
    near: float,
) -> int:
    """Return 1 if face ``f`` lies wholly beyond the near plane, -1 if it crosses it, else 0."""
    za = proj[faces[f, 0], 2]
    zb = proj[faces[f, 1], 2]
    zc = proj[faces[f, 2], 2]
    if za >= near and zb >= near and zc >= near:
        return 1
    if za >= near or zb >= near or zc >= near:
        return -1
    return 0


@numba.njit(nogil=True, cache=True, inline="always")
def _corners(
    f: int,
    faces: npt.NDArray[np.int32],
    proj: npt.NDArray[np.float64],
) -> tuple[float, float, float, float, float, float]:
    """Return the screen corners (ax, ay, bx, by, qx, qy) of a face beyond the near plane."""
    a = faces[f, 0]
    b = faces[f, 1]
    c = faces[f, 2]
    return proj[a, 3], proj[a, 4], proj[b, 3], proj[b, 4], proj[c, 3], proj[c, 4]


@numba.njit(nogil=True, cache=True)
def faces_meeting_rect(
    faces: npt.NDArray[np.int32],
    proj: npt.NDArray[np.float64],
    view: View,
) -> npt.NDArray[np.bool_]:
    """Return bool [F]: some part of the face beyond the near plane projects into the rect.

    Faces crossing the near plane are clipped to it (their screen polygon is 3 or 4 corners,
    tested as a fan of triangles).
    """
    near = view[4]
    n = faces.shape[0]
    meets = np.zeros(n, np.bool_)
    crossing = []
    for f in range(n):
        placement = _placement(f, faces, proj, near)
        if placement == 1:
            ax, ay, bx, by, qx, qy = _corners(f, faces, proj)
            meets[f] = _triangle_on_screen(ax, ay, bx, by, qx, qy, view)[0]
        elif placement == -1:
            crossing.append(f)
    xs = np.empty(4)
    ys = np.empty(4)
    for f in crossing:
        count = _clip_polygon(f, faces, proj, view, xs, ys)
        for t in range(1, count - 1):
            if _triangle_on_screen(xs[0], ys[0], xs[t], ys[t], xs[t + 1], ys[t + 1], view)[0]:
                meets[f] = True
    return meets


@numba.njit(nogil=True, cache=True, inline="always")
def _inverse_depth_plane(
    f: int,
    faces: npt.NDArray[np.int32],
    proj: npt.NDArray[np.float64],
    view: View,
) -> tuple[float, float, float]:
    """Return (A, B, C) with 1 / z = A X + B Y + C on face ``f``'s plane; zeros if edge-on.

    The plane n . p = h (camera frame) meets the pixel ray p = z ((X - cx)/fx, (Y - cy)/fy, 1)
    at 1 / z = (n . ((X - cx)/fx, (Y - cy)/fy, 1)) / h.
    """
    fx, fy, cx, cy = view[0], view[1], view[2], view[3]
    a = faces[f, 0]
    b = faces[f, 1]
    c = faces[f, 2]
    e1x = proj[b, 0] - proj[a, 0]
    e1y = proj[b, 1] - proj[a, 1]
    e1z = proj[b, 2] - proj[a, 2]
    e2x = proj[c, 0] - proj[a, 0]
    e2y = proj[c, 1] - proj[a, 1]
    e2z = proj[c, 2] - proj[a, 2]
    nx = e1y * e2z - e1z * e2y
    ny = e1z * e2x - e1x * e2z
    nz = e1x * e2y - e1y * e2x
    h = nx * proj[a, 0] + ny * proj[a, 1] + nz * proj[a, 2]
    if h == 0.0:
        return 0.0, 0.0, 0.0
    qa = nx / (fx * h)
    qb = ny / (fy * h)
    return qa, qb, nz / h - qa * cx - qb * cy


@numba.njit(nogil=True, cache=True, inline="always")
def _inside(
    ax: float,
    ay: float,
    bx: float,
    by: float,
    qx: float,
    qy: float,
    sign: float,
    x: float,
    y: float,
) -> bool:
    """Say whether (x, y) lies in the triangle a, b, q of orientation ``sign`` (edges included)."""
    return (
        sign * ((bx - ax) * (y - ay) - (by - ay) * (x - ax)) >= 0.0
        and sign * ((qx - bx) * (y - by) - (qy - by) * (x - bx)) >= 0.0
        and sign * ((ax - qx) * (y - qy) - (ay - qy) * (x - qx)) >= 0.0
    )


@numba.njit(nogil=True, cache=True, inline="always")
def _raster_triangle(
    f: int,
    ax: float,
    ay: float,
    bx: float,
    by: float,
    qx: float,
    qy: float,
    lo_x: float,
    hi_x: float,
    lo_y: float,
    hi_y: float,
    faces: npt.NDArray[np.int32],
    proj: npt.NDArray[np.float64],
    view: View,
    pixels: Pixels,
    ids: npt.NDArray[np.int32],
    inv_depth: npt.NDArray[np.float64],
) -> None:
    """Depth-test a screen triangle of face ``f`` at the pixel centres in the rect it covers."""
    i0, j0, i1, j1 = pixels
    # pixel centres i + 0.5 inside the box, within the rect's pixels
    pi0 = max(int(np.ceil(lo_x - 0.5)), i0)
    pi1 = min(int(np.floor(hi_x - 0.5)), i1)
    pj0 = max(int(np.ceil(lo_y - 0.5)), j0)
    pj1 = min(int(np.floor(hi_y - 0.5)), j1)
    if pi0 > pi1 or pj0 > pj1:
        return
    area = (bx - ax) * (qy - ay) - (by - ay) * (qx - ax)
    if area == 0.0:
        return
    sign = 1.0 if area > 0.0 else -1.0  # either winding: no back-face culling
    have_plane = False
    qa = qb = qc = 0.0
    for j in range(pj0, pj1 + 1):
        py = j + 0.5
        for i in range(pi0, pi1 + 1):
            px = i + 0.5
            if _inside(ax, ay, bx, by, qx, qy, sign, px, py):
                if not have_plane:
                    qa, qb, qc = _inverse_depth_plane(f, faces, proj, view)
                    have_plane = True
                inv = qa * px + qb * py + qc
                if inv > inv_depth[j - j0, i - i0]:
                    inv_depth[j - j0, i - i0] = inv
                    ids[j - j0, i - i0] = f


@numba.njit(nogil=True, cache=True)
def _zbuffer_pass(
    faces: npt.NDArray[np.int32],
    proj: npt.NDArray[np.float64],
    view: View,
    pixels: Pixels,
) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.int32], npt.NDArray[np.float64]]:
    """Z-buffer the faces meeting the rect at the pixel centres in the rect.

    Returns
    -------
    meets : bool [F]
        Faces some part of which (beyond the near plane) projects into the rect.
    ids : int32 [j1 - j0 + 1, i1 - i0 + 1]
        The face nearest to the camera at each pixel centre, -1 for background.
    inv_depth : float64 [j1 - j0 + 1, i1 - i0 + 1]
        1 / z of that face at the pixel centre; 0 for background (infinitely far).
    """
    i0, j0, i1, j1 = pixels
    near = view[4]
    n = faces.shape[0]
    meets = np.zeros(n, np.bool_)
    ids = np.full((j1 - j0 + 1, i1 - i0 + 1), -1, np.int32)
    inv_depth = np.zeros((j1 - j0 + 1, i1 - i0 + 1))
    crossing = []
    # The hot loop is written out: most faces are smaller than a pixel and cover no centre.
    for f in range(n):
        a = faces[f, 0]
        b = faces[f, 1]
        c = faces[f, 2]
        if not (proj[a, 2] >= near and proj[b, 2] >= near and proj[c, 2] >= near):
            if proj[a, 2] >= near or proj[b, 2] >= near or proj[c, 2] >= near:
                crossing.append(f)
            continue
        ax = proj[a, 3]
        ay = proj[a, 4]
        bx = proj[b, 3]
        by = proj[b, 4]
        qx = proj[c, 3]
        qy = proj[c, 4]
        ok, lo_x, hi_x, lo_y, hi_y = _triangle_on_screen(ax, ay, bx, by, qx, qy, view)
        if not ok:
            continue
        meets[f] = True
        # pixel centres i + 0.5 inside the box, within the rect's pixels
        pi0 = max(int(np.ceil(lo_x - 0.5)), i0)
        pi1 = min(int(np.floor(hi_x - 0.5)), i1)
        pj0 = max(int(np.ceil(lo_y - 0.5)), j0)
        pj1 = min(int(np.floor(hi_y - 0.5)), j1)
        if pi0 > pi1 or pj0 > pj1:
            continue
        area = (bx - ax) * (qy - ay) - (by - ay) * (qx - ax)
        if area == 0.0:
            continue
        sign = 1.0 if area > 0.0 else -1.0  # either winding: no back-face culling
        have_plane = False
        qa = qb = qc = 0.0
        for j in range(pj0, pj1 + 1):
            py = j + 0.5
            for i in range(pi0, pi1 + 1):
                px = i + 0.5
                if _inside(ax, ay, bx, by, qx, qy, sign, px, py):
                    if not have_plane:
                        qa, qb, qc = _inverse_depth_plane(f, faces, proj, view)
                        have_plane = True
                    inv = qa * px + qb * py + qc
                    if inv > inv_depth[j - j0, i - i0]:
                        inv_depth[j - j0, i - i0] = inv
                        ids[j - j0, i - i0] = f
    xs = np.empty(4)
    ys = np.empty(4)
    for f in crossing:
        count = _clip_polygon(f, faces, proj, view, xs, ys)
        for t in range(1, count - 1):
            ax, ay, bx, by, qx, qy = xs[0], ys[0], xs[t], ys[t], xs[t + 1], ys[t + 1]
            ok, lo_x, hi_x, lo_y, hi_y = _triangle_on_screen(ax, ay, bx, by, qx, qy, view)
            if ok:
                meets[f] = True
                _raster_triangle(
                    f, ax, ay, bx, by, qx, qy, lo_x, hi_x, lo_y, hi_y,
                    faces, proj, view, pixels, ids, inv_depth,
                )  # fmt: skip
    return meets, ids, inv_depth


@numba.njit(nogil=True, cache=True)
def _face_box(
    f: int,
    faces: npt.NDArray[np.int32],
    proj: npt.NDArray[np.float64],
    view: View,
) -> tuple[float, float, float, float]:
    """Return the screen box (lo_x, hi_x, lo_y, hi_y) of face ``f``'s part beyond the near plane.

    An empty box (lo > hi) when nothing of it lies beyond the near plane.
    """
    placement = _placement(f, faces, proj, view[4])
    if placement == 1:
        ax, ay, bx, by, qx, qy = _corners(f, faces, proj)
        return min(ax, bx, qx), max(ax, bx, qx), min(ay, by, qy), max(ay, by, qy)
    if placement == 0:
        return 1.0, 0.0, 1.0, 0.0
    xs = np.empty(4)
    ys = np.empty(4)
    count = _clip_polygon(f, faces, proj, view, xs, ys)
    return xs[:count].min(), xs[:count].max(), ys[:count].min(), ys[:count].max()


@numba.njit(nogil=True, cache=True, inline="always")
def _mark_box(
    suspicious: npt.NDArray[np.bool_],
    lo_x: float,
    hi_x: float,
    lo_y: float,
    hi_y: float,
    i0: int,
    j0: int,
) -> None:
    """Flag the pixel cells (clipped to the z-buffer) that a screen box touches."""
    rows, cols = suspicious.shape
    c0 = max(int(np.floor(lo_x)) - i0, 0)
    c1 = min(int(np.floor(hi_x)) - i0, cols - 1)
    r0 = max(int(np.floor(lo_y)) - j0, 0)
    r1 = min(int(np.floor(hi_y)) - j0, rows - 1)
    for r in range(r0, r1 + 1):
        for c in range(c0, c1 + 1):
            suspicious[r, c] = True


@numba.njit(nogil=True, cache=True, inline="always")
def _project_centroid(
    f: int,
    centroids: npt.NDArray[np.float64],
    position: npt.NDArray[np.float64],
    rotation: npt.NDArray[np.float64],
    view: View,
) -> tuple[bool, float, float, float]:
    """Return (in_rect, X, Y, 1 / z) of face ``f``'s centroid."""
    fx, fy, cx, cy, near = view[0], view[1], view[2], view[3], view[4]
    x0, y0, x1, y1 = view[5], view[6], view[7], view[8]
    px = centroids[f, 0] - position[0]
    py = centroids[f, 1] - position[1]
    pz = centroids[f, 2] - position[2]
    zc = px * rotation[0, 2] + py * rotation[1, 2] + pz * rotation[2, 2]
    if zc < near:
        return False, 0.0, 0.0, 0.0
    inv_c = 1.0 / zc
    x = cx + fx * (px * rotation[0, 0] + py * rotation[1, 0] + pz * rotation[2, 0]) * inv_c
    y = cy + fy * (px * rotation[0, 1] + py * rotation[1, 1] + pz * rotation[2, 1]) * inv_c
    return x0 <= x <= x1 and y0 <= y <= y1, x, y, inv_c


#: ``_surface_class`` answers
_ON_SURFACE = 0
_BEHIND = 1
_UNSURE = 2


@numba.njit(nogil=True, cache=True, inline="always")
def _surface_class(
    x: float,
    y: float,
    inv_c: float,
    inv_depth: npt.NDArray[np.float64],
    i0: int,
    j0: int,
    consistency: float,
) -> int:
    """Compare the point (x, y, 1/z) with the z-buffer's four pixel samples around it.

    ``_ON_SURFACE``: within the relative ``consistency`` of their bilinear interpolation.
    ``_BEHIND``: farther than every one of them by more than that: the four pixel centres
    around it all see something nearer, so it is hidden (unless it shows through a hole
    smaller than a pixel). ``_UNSURE``: anything else, e.g. a depth edge, background, or a
    point in front of the surface seen there.
    """
    rows, cols = inv_depth.shape
    gx = x - 0.5 - i0
    gy = y - 0.5 - j0
    ca = int(np.floor(gx))
    ra = int(np.floor(gy))
    tx = gx - ca
    ty = gy - ra
    c0 = min(max(ca, 0), cols - 1)
    c1 = min(max(ca + 1, 0), cols - 1)
    r0 = min(max(ra, 0), rows - 1)
    r1 = min(max(ra + 1, 0), rows - 1)
    s00 = inv_depth[r0, c0]
    s01 = inv_depth[r0, c1]
    s10 = inv_depth[r1, c0]
    s11 = inv_depth[r1, c1]
    if s00 == 0.0 or s01 == 0.0 or s10 == 0.0 or s11 == 0.0:
        return _UNSURE
    est = (1.0 - ty) * ((1.0 - tx) * s00 + tx * s01) + ty * ((1.0 - tx) * s10 + tx * s11)
    if abs(inv_c - est) <= consistency * est:
        return _ON_SURFACE
    if inv_c * (1.0 + consistency) < min(s00, s01, s10, s11):
        return _BEHIND
    return _UNSURE


@numba.njit(nogil=True, cache=True)
def _classify_centroids(
    faces: npt.NDArray[np.int32],
    centroids: npt.NDArray[np.float64],
    proj: npt.NDArray[np.float64],
    position: npt.NDArray[np.float64],
    rotation: npt.NDArray[np.float64],
    view: View,
    pixels: Pixels,
    meets: npt.NDArray[np.bool_],
    ids: npt.NDArray[np.int32],
    inv_depth: npt.NDArray[np.float64],
    consistency: float,
) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.float64], npt.NDArray[np.int32]]:
    """Sort faces that win no pixel centre into surely seen and uncertain, by their centroid.

    A centroid in the rect whose inverse depth matches the bilinear interpolation of the four
    surrounding pixel samples (within the relative ``consistency``) lies on the surface the
    z-buffer saw: the face is seen; a centroid behind all four samples is hidden; either only
    when the centroid's cell is not suspicious. Any other centroid is uncertain, and its face's box
    becomes suspicious (it may hide something the pixel centres missed, e.g. a wall thinner
    than a pixel), as do the boxes of faces seen at pixels where the z-buffer jumps in depth
    (silhouettes). Uncertain centroids go to the exact test (``_occlude_samples``).

    Returns
    -------
    seen : bool [F]
        Faces seen at a pixel centre, or surely seen by their centroid.
    samples : float64 [m, 3]
        (X, Y, 1 / z) of the uncertain centroids.
    sample_faces : int32 [m]
    """
    i0, j0 = pixels[0], pixels[1]
    n = faces.shape[0]
    rows, cols = ids.shape
    seen = np.zeros(n, np.bool_)
    marked = np.zeros(n, np.bool_)
    suspicious = np.zeros((rows, cols), np.bool_)
    bend = 2.0 * consistency
    for r in range(rows):
        for c in range(cols):
            f = ids[r, c]
            if f < 0:
                continue
            seen[f] = True
            if marked[f]:
                continue
            v = inv_depth[r, c]
            # a jump in depth to either neighbour, beyond what a straight line explains
            jump = False
            if 0 < c < cols - 1:
                jump |= abs(inv_depth[r, c - 1] + inv_depth[r, c + 1] - 2.0 * v) > bend * v
            if 0 < r < rows - 1:
                jump |= abs(inv_depth[r - 1, c] + inv_depth[r + 1, c] - 2.0 * v) > bend * v
            if jump:
                marked[f] = True
                lo_x, hi_x, lo_y, hi_y = _face_box(f, faces, proj, view)
                _mark_box(suspicious, lo_x, hi_x, lo_y, hi_y, i0, j0)
    # faces that won no pixel: on the surface (maybe), or uncertain and suspicious themselves
    # the pixel cell of a centroid on the surface (k >= 0) or behind it (-2 - k)
    cell_of = np.full(n, -1, np.int32)
    for f in range(n):
        if not meets[f] or seen[f]:
            continue
        in_rect, x, y, inv_c = _project_centroid(f, centroids, position, rotation, view)
        if not in_rect:
            continue
        kind = _surface_class(x, y, inv_c, inv_depth, i0, j0, consistency)
        if kind == _UNSURE:
            marked[f] = True  # marks an uncertain centroid
            lo_x, hi_x, lo_y, hi_y = _face_box(f, faces, proj, view)
            _mark_box(suspicious, lo_x, hi_x, lo_y, hi_y, i0, j0)
        else:
            c = min(max(int(np.floor(x)) - i0, 0), cols - 1)
            r = min(max(int(np.floor(y)) - j0, 0), rows - 1)
            cell_of[f] = r * cols + c if kind == _ON_SURFACE else -2 - (r * cols + c)
    # near a depth edge or an uncertain face, neither answer is sure: the exact test decides
    flat = suspicious.ravel()
    m = 0
    for f in range(n):
        k = cell_of[f]
        if k >= 0:
            if flat[k]:
                marked[f] = True
            else:
                seen[f] = True
        elif k < -1 and flat[-2 - k]:
            marked[f] = True
        if marked[f] and not seen[f]:
            m += 1
    samples = np.empty((m, 3))
    sample_faces = np.empty(m, np.int32)
    k = 0
    for f in range(n):
        if marked[f] and not seen[f]:
            _, x, y, inv_c = _project_centroid(f, centroids, position, rotation, view)
            samples[k, 0] = x
            samples[k, 1] = y
            samples[k, 2] = inv_c
            sample_faces[k] = f
            k += 1
    return seen, samples, sample_faces


@numba.njit(nogil=True, cache=True, inline="always")
def _occlude_by_triangle(
    f: int,
    ax: float,
    ay: float,
    bx: float,
    by: float,
    qx: float,
    qy: float,
    qa: float,
    qb: float,
    qc: float,
    pixels: Pixels,
    cell_start: npt.NDArray[np.int64],
    packed: npt.NDArray[np.float64],
    hidden: npt.NDArray[np.bool_],
) -> None:
    """Mark the samples that a screen triangle of face ``f`` covers while nearer than them.

    ``packed`` rows are (X, Y, 1/z times (1 + tolerance), face id) in cell order.
    """
    i0, j0, i1, j1 = pixels
    cols = i1 - i0 + 1
    lo_x = min(ax, bx, qx)
    hi_x = max(ax, bx, qx)
    lo_y = min(ay, by, qy)
    hi_y = max(ay, by, qy)
    c0 = max(int(np.floor(lo_x)) - i0, 0)
    c1 = min(int(np.floor(hi_x)) - i0, cols - 1)
    r0 = max(int(np.floor(lo_y)) - j0, 0)
    r1 = min(int(np.floor(hi_y)) - j0, j1 - j0)
    area = (bx - ax) * (qy - ay) - (by - ay) * (qx - ax)
    if area == 0.0:
        return
    sign = 1.0 if area > 0.0 else -1.0
    for r in range(r0, r1 + 1):
        for k in range(cell_start[r * cols + c0], cell_start[r * cols + c1 + 1]):
            x = packed[k, 0]
            y = packed[k, 1]
            if (
                lo_x <= x <= hi_x
                and lo_y <= y <= hi_y
                and qa * x + qb * y + qc > packed[k, 2]
                and packed[k, 3] != f
                and _inside(ax, ay, bx, by, qx, qy, sign, x, y)
            ):
                hidden[k] = True


@numba.njit(nogil=True, cache=True)
def _occlude_samples(
    faces: npt.NDArray[np.int32],
    proj: npt.NDArray[np.float64],
    view: View,
    pixels: Pixels,
    meets: npt.NDArray[np.bool_],
    samples: npt.NDArray[np.float64],
    sample_faces: npt.NDArray[np.int32],
    tolerance: float,
) -> npt.NDArray[np.bool_]:
    """Return bool [m]: the samples another face covers on screen while nearer by > tolerance.

    Exact (an irregular z-buffer): samples are bucketed by pixel cell, and every face meeting
    the rect tests the samples in the cells of its bounding box (most boxes hold none).
    """
    i0, j0, i1, j1 = pixels
    near = view[4]
    rows = j1 - j0 + 1
    cols = i1 - i0 + 1
    m = len(sample_faces)
    occluded = np.zeros(m, np.bool_)
    if m == 0:
        return occluded
    cell_start = np.zeros(rows * cols + 1, np.int64)
    cell_of = np.empty(m, np.int64)
    for s in range(m):
        c = min(max(int(np.floor(samples[s, 0])) - i0, 0), cols - 1)
        r = min(max(int(np.floor(samples[s, 1])) - j0, 0), rows - 1)
        cell_of[s] = r * cols + c
        cell_start[r * cols + c + 1] += 1
    # 4 x 4-pixel tiles holding samples: a small table that stays in cache
    tiles = np.zeros(((rows + 3) // 4, (cols + 3) // 4), np.bool_)
    for k in range(rows * cols):
        if cell_start[k + 1] > 0:
            tiles[(k // cols) // 4, (k % cols) // 4] = True
        cell_start[k + 1] += cell_start[k]
    order = np.empty(m, np.int64)
    fill = cell_start[:-1].copy()
    for s in range(m):
        order[fill[cell_of[s]]] = s
        fill[cell_of[s]] += 1
    packed = np.empty((m, 4))
    for k in range(m):
        s = order[k]
        packed[k, 0] = samples[s, 0]
        packed[k, 1] = samples[s, 1]
        packed[k, 2] = samples[s, 2] * (1.0 + tolerance)
        packed[k, 3] = sample_faces[s]
    hidden = np.zeros(m, np.bool_)
    crossing = []
    # The hot loop is written out (not via helpers) so that the ~1M faces without samples
    # in their box cost only a box and a lookup or two.
    for f in range(faces.shape[0]):
        if not meets[f]:
            continue
        a = faces[f, 0]
        b = faces[f, 1]
        c = faces[f, 2]
        if not (proj[a, 2] >= near and proj[b, 2] >= near and proj[c, 2] >= near):
            crossing.append(f)
            continue
        ax = proj[a, 3]
        ay = proj[a, 4]
        bx = proj[b, 3]
        by = proj[b, 4]
        qx = proj[c, 3]
        qy = proj[c, 4]
        c0 = max(int(np.floor(min(ax, bx, qx))) - i0, 0)
        c1 = min(int(np.floor(max(ax, bx, qx))) - i0, cols - 1)
        r0 = max(int(np.floor(min(ay, by, qy))) - j0, 0)
        r1 = min(int(np.floor(max(ay, by, qy))) - j0, rows - 1)
        if c0 > c1 or r0 > r1:
            continue
        if not (
            tiles[r0 >> 2, c0 >> 2]
            or tiles[r0 >> 2, c1 >> 2]
            or tiles[r1 >> 2, c0 >> 2]
            or tiles[r1 >> 2, c1 >> 2]
            or (r1 >> 2) - (r0 >> 2) > 1
            or (c1 >> 2) - (c0 >> 2) > 1
        ):
            continue  # a box over at most 2 x 2 tiles, none holding samples
        n_samples = 0
        for r in range(r0, r1 + 1):
            n_samples += cell_start[r * cols + c1 + 1] - cell_start[r * cols + c0]
        if n_samples == 0:
            continue
        qa, qb, qc = _inverse_depth_plane(f, faces, proj, view)
        _occlude_by_triangle(
            f, ax, ay, bx, by, qx, qy, qa, qb, qc, pixels, cell_start, packed, hidden
        )
    xs = np.empty(4)
    ys = np.empty(4)
    for f in crossing:
        qa, qb, qc = _inverse_depth_plane(f, faces, proj, view)
        count = _clip_polygon(f, faces, proj, view, xs, ys)
        for t in range(1, count - 1):
            _occlude_by_triangle(
                f, xs[0], ys[0], xs[t], ys[t], xs[t + 1], ys[t + 1], qa, qb, qc,
                pixels, cell_start, packed, hidden,
            )  # fmt: skip
    for k in range(m):
        occluded[order[k]] = hidden[k]
    return occluded


@numba.njit(nogil=True, cache=True)
def visible_faces(
    faces: npt.NDArray[np.int32],
    centroids: npt.NDArray[np.float64],
    proj: npt.NDArray[np.float64],
    position: npt.NDArray[np.float64],
    rotation: npt.NDArray[np.float64],
    view: View,
    pixels: Pixels,
    tolerance: float,
    consistency: float,
) -> npt.NDArray[np.bool_]:
    """Return bool [F]: the faces the camera sees inside the rect (see ``selection.rect``).

    1. z-buffer of face ids at the pixel centres in the rect: the winners are seen;
    2. the centroid of every other face meeting the rect is checked against the z-buffer:
       on the surface seen there (bilinear, ``consistency``) and away from depth edges: seen;
    3. the remaining centroids get the exact test: seen unless another face covers the
       centroid on screen and is nearer there by more than the relative ``tolerance``.
    """
    i0, j0, i1, j1 = pixels
    if i0 > i1 or j0 > j1:
        return np.zeros(faces.shape[0], np.bool_)
    meets, ids, inv_depth = _zbuffer_pass(faces, proj, view, pixels)
    seen, samples, sample_faces = _classify_centroids(
        faces, centroids, proj, position, rotation, view, pixels, meets, ids, inv_depth,
        consistency,
    )  # fmt: skip
    occluded = _occlude_samples(faces, proj, view, pixels, meets, samples, sample_faces, tolerance)
    for s in range(len(sample_faces)):
        if not occluded[s]:
            seen[sample_faces[s]] = True
    return seen
