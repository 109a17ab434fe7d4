import math

import numpy as np
import pytest

from selection import CameraModel, MeshIndex, RectSelector, ScreenRect, select_rect
from tests.conftest import grid_mesh
from tests.selection.oracles import faces_seen_by_rays

OCCLUDED = 1e-2  # a centroid is occluded when something is > 1 % of its distance in front


def combine(*meshes):
    """Concatenate (vertices, faces) pairs; return vertices, faces and each part's face ids."""
    vertices, faces, parts, offset, first = [], [], [], 0, 0
    for v, f in meshes:
        vertices.append(v)
        faces.append(f + offset)
        parts.append(np.arange(first, first + len(f)))
        offset += len(v)
        first += len(f)
    return np.concatenate(vertices), np.concatenate(faces).astype(np.int32), parts


def wall(x0, x1, y, z0, z1, n=(12, 6), flip=False):
    """A vertical grid in the plane y = const; ``flip`` reverses the winding (a back face)."""
    xs, zs = np.linspace(x0, x1, n[0] + 1), np.linspace(z0, z1, n[1] + 1)
    gx, gz = np.meshgrid(xs, zs)
    v = np.stack([gx.ravel(), np.full(gx.size, y), gz.ravel()], axis=1)
    idx = np.arange(gx.size).reshape(gx.shape)
    a, b, c, d = idx[:-1, :-1], idx[:-1, 1:], idx[1:, :-1], idx[1:, 1:]
    f = np.concatenate(
        [np.stack([a, b, d], -1).reshape(-1, 3), np.stack([a, d, c], -1).reshape(-1, 3)]
    )
    return v, (f[:, ::-1] if flip else f).astype(np.int32)


def floor(n=20, size=10.0, z=0.0):
    v, f = grid_mesh(n, size)
    v[:, 2] = z
    return v, f


def check_visible(vertices, faces, camera, rect, selected):
    """The oracle's rules: all it sees is selected; nothing else with a hidden centroid."""
    index = MeshIndex(vertices, faces)
    centroids = vertices[faces].mean(axis=1)
    seen, ratio = faces_seen_by_rays(index, camera, rect, centroids)
    chosen = set(selected.tolist())
    missed = seen - chosen
    assert not missed, (
        f"{len(missed)} faces the camera sees were not selected: {sorted(missed)[:10]}"
    )
    extra = np.array(sorted(chosen - seen), dtype=int)
    hidden = extra[~(ratio[extra] >= 1.0 - OCCLUDED)] if len(extra) else extra
    assert len(hidden) == 0, f"{len(hidden)} hidden faces were selected: {hidden[:10]}"
    return seen


def check_through(vertices, faces, camera, rect, selected):
    """Faces with a sampled point in the rect are selected; none whose box misses it."""
    chosen = np.zeros(len(faces), bool)
    chosen[selected] = True
    w = np.array([(i, j) for i in range(21) for j in range(21 - i)], float) / 20
    bary = np.stack([1 - w.sum(1), w[:, 0], w[:, 1]], axis=1)
    pts = np.einsum("sk,fkd->fsd", bary, vertices[faces])
    uv, depth = camera.project(pts.reshape(-1, 3))
    uv, depth = uv.reshape(len(faces), -1, 2), depth.reshape(len(faces), -1)
    lo, hi = np.array(rect.min_xy), np.array(rect.max_xy)
    eps = 1e-9  # points on the rect's edge may round either way
    inside = ((uv >= lo + eps) & (uv <= hi - eps)).all(-1) & (depth > camera.near * 1.001)
    must = inside.any(axis=1)
    assert chosen[must].all(), (
        f"faces in the rect not selected: {np.flatnonzero(must & ~chosen)[:10]}"
    )
    vuv, vdepth = camera.project(vertices[faces].reshape(-1, 3))
    vuv = vuv.reshape(len(faces), 3, 2)
    in_front = (vdepth.reshape(len(faces), 3) > camera.near).all(axis=1)
    box_misses = in_front & ((vuv.max(1) < lo - eps) | (vuv.min(1) > hi + eps)).any(axis=1)
    assert not (chosen & box_misses).any()
    behind = (vdepth.reshape(len(faces), 3) <= 0).all(axis=1)
    assert not (chosen & behind).any()


@pytest.fixture
def wall_before_floor():
    """A 6 m x 3 m wall at y = 3 in front of a 10 m floor, seen from the south."""
    vertices, faces, (floor_ids, wall_ids) = combine(floor(), wall(2.0, 8.0, 3.0, 0.0, 3.0))
    camera = CameraModel.look_at(
        [5.0, -8.0, 4.0], [5.0, 5.0, 0.0], fov=math.radians(60), width=320, height=240
    )
    return vertices, faces, floor_ids, wall_ids, camera


@pytest.mark.parametrize(
    "corners",
    [((0.25, 0.25), (0.75, 0.75)), ((0.0, 0.0), (1.0, 1.0)), ((0.4, 0.1), (0.62, 0.9))],
    ids=["centre", "whole", "strip"],
)
def test_visible_agrees_with_ray_oracle(wall_before_floor, corners):
    vertices, faces, floor_ids, wall_ids, camera = wall_before_floor
    rect = ScreenRect(*corners)
    selected = RectSelector(vertices, faces).select(camera, rect, mode="visible")
    seen = check_visible(vertices, faces, camera, rect, selected)
    # the wall hides part of the floor: through takes it, visible does not
    hidden_floor = set(floor_ids.tolist()) - seen
    through = RectSelector(vertices, faces).select(camera, rect, mode="through")
    assert hidden_floor & set(through.tolist())
    assert np.isin(wall_ids, selected).any()


def test_visible_front_wall_only_through_both():
    vertices, faces, (front, back) = combine(
        wall(2.0, 8.0, 3.0, 0.0, 3.0), wall(2.0, 8.0, 6.0, 0.0, 3.0, flip=True)
    )
    camera = CameraModel.look_at(
        [5.0, -6.0, 1.5], [5.0, 3.0, 1.5], fov=math.radians(50), width=320, height=240
    )
    # a rect well inside the front wall's silhouette: the back wall is entirely hidden there
    rect = ScreenRect((0.3, 0.3), (0.7, 0.7))
    selector = RectSelector(vertices, faces)
    visible = selector.select(camera, rect, mode="visible")
    through = selector.select(camera, rect, mode="through")
    assert len(visible) and np.isin(visible, front).all()
    assert np.isin(through, front).any() and np.isin(through, back).any()
    check_visible(vertices, faces, camera, rect, visible)
    check_through(vertices, faces, camera, rect, through)
    # seen from behind, the back wall shows its back faces: no culling, it is what is seen
    camera_behind = CameraModel.look_at(
        [5.0, 15.0, 1.5], [5.0, 3.0, 1.5], fov=math.radians(50), width=320, height=240
    )
    from_behind = selector.select(camera_behind, rect, mode="visible")
    assert len(from_behind) and np.isin(from_behind, back).all()


def test_sub_pixel_faces_and_a_thin_wall():
    """A floor of faces smaller than a pixel, behind a wall thinner than a pixel."""
    floor_v, floor_f = floor(n=120, size=12.0)
    rng = np.random.default_rng(4)
    floor_v[:, 2] += rng.normal(0, 0.01, len(floor_v))
    # a 2 cm thick, 1.5 m high double-sided slab across the view
    front = wall(1.0, 11.0, 5.0, 0.0, 1.5, n=(40, 6))
    back = wall(1.0, 11.0, 5.02, 0.0, 1.5, n=(40, 6), flip=True)
    vertices, faces, (floor_ids, _, back_ids) = combine((floor_v, floor_f), front, back)
    # (an unround camera position: no centroid ray runs exactly through a wall's edge)
    camera = CameraModel.look_at(
        [6.013, -6.021, 3.007], [6.0, 6.0, 0.0], fov=math.radians(55), width=160, height=120
    )
    for corners in [((0.2, 0.2), (0.8, 0.8)), ((0.0, 0.3), (1.0, 0.7))]:
        rect = ScreenRect(*corners)
        selector = RectSelector(vertices, faces)
        visible = selector.select(camera, rect, mode="visible")
        check_visible(vertices, faces, camera, rect, visible)
        assert not np.isin(visible, back_ids).any()
        assert np.isin(visible, floor_ids).any()


def test_faces_crossing_the_near_plane():
    """Standing on the floor: faces under and behind the camera are clipped, not projected."""
    vertices, faces = floor(n=4, size=10.0)  # 2.5 m cells: the one underfoot is in view
    camera = CameraModel.look_at(
        [5.1, 4.0, 0.5], [5.1, 9.0, 0.0], fov=math.radians(70), width=200, height=150, near=0.05
    )
    _, depth = camera.project(vertices[faces].reshape(-1, 3))
    depth = depth.reshape(-1, 3)
    crossing = np.flatnonzero((depth.min(1) < camera.near) & (depth.max(1) > camera.near))
    rect = ScreenRect((0.1, 0.5), (0.9, 1.0))
    selector = RectSelector(vertices, faces)
    through = selector.select(camera, rect, mode="through")
    check_through(vertices, faces, camera, rect, through)
    assert np.isin(crossing, through).any()
    visible = selector.select(camera, rect, mode="visible")
    check_visible(vertices, faces, camera, rect, visible)
    assert np.isin(crossing, visible).any()


def test_rect_edges_and_pixels():
    rect = ScreenRect.from_corners((0.75, 0.2), (0.25, 0.8))
    assert rect.min_xy == (0.25, 0.2) and rect.max_xy == (0.75, 0.8)
    # pointer positions are pixel centres: (x + 0.5) / width
    r = ScreenRect(((10 + 0.5) / 100, (3 + 0.5) / 50), ((20 + 0.5) / 100, (7 + 0.5) / 50))
    assert r.pixel_range(100, 50) == (10, 3, 20, 7)
    with pytest.raises(ValueError, match="beyond"):
        ScreenRect((0.5, 0.5), (0.4, 0.6))


def test_select_rect_one_off_and_empty_cases(wall_before_floor):
    vertices, faces, _, _, camera = wall_before_floor
    rect = ScreenRect((0.45, 0.45), (0.55, 0.55))
    one_off = select_rect(vertices, faces, camera, rect, mode="visible")
    np.testing.assert_array_equal(
        one_off, RectSelector(vertices, faces).select(camera, rect, mode="visible")
    )
    assert one_off.dtype == np.int32 and (np.diff(one_off) > 0).all()
    # looking away: nothing
    away = CameraModel.look_at([5, -8, 4], [5, -20, 4], fov=1.0, width=100, height=100)
    for mode in ("visible", "through"):
        assert len(select_rect(vertices, faces, away, rect, mode=mode)) == 0
    # a rect between pixel centres holds no pixel; visible still judges centroids
    tiny = ScreenRect((0.5001, 0.5001), (0.5002, 0.5002))
    assert len(select_rect(vertices, faces, camera, tiny, mode="visible")) <= 2
    with pytest.raises(ValueError, match="sideways"):
        select_rect(vertices, faces, camera, rect, mode="sideways")


def test_utm_world_camera_through_local_frame(wall_before_floor):
    vertices, faces, _, _, camera = wall_before_floor
    origin = np.array([500_000.0, 5_700_000.0, 100.0])
    world_camera = camera.shifted(-origin)  # the same view, in UTM coordinates
    rect = ScreenRect((0.2, 0.2), (0.8, 0.8))
    expected = select_rect(vertices, faces, camera, rect, mode="visible")
    got = select_rect(vertices, faces, world_camera.shifted(origin), rect, mode="visible")
    np.testing.assert_array_equal(got, expected)
