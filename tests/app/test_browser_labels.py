"""Labelling in a real browser: click, rubber band (visible vs through), brush, undo, save."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from app.tools import ToolMode
from storage import MapData, MapDocument, load_map
from tests.app.conftest import (
    VIEWPORT,
    screenshot_rgb,
    sync_browser,
    text_input,
    wait_until,
)

pytestmark = pytest.mark.browser

RED = (230, 30, 30)


def wall(x0, x1, y, z0, z1, n=40):
    xs = np.linspace(x0, x1, n + 1)
    zs = np.linspace(z0, z1, n + 1)
    gx, gz = np.meshgrid(xs, zs)
    v = np.stack([gx.ravel(), np.full(gx.size, y), gz.ravel()], axis=1)
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    a, b, c, d = idx[:-1, :-1], idx[:-1, 1:], idx[1:, :-1], idx[1:, 1:]
    f = np.concatenate(
        [np.stack([a, b, d], -1).reshape(-1, 3), np.stack([a, d, c], -1).reshape(-1, 3)]
    )
    return v, f


def two_walls() -> tuple[MapDocument, int]:
    """A front wall (y=0) and a larger back wall (y=2) behind it, as a document.

    Seen from (0, -3, 0.5) with viser's default 75° fov, the left half of the canvas shows the
    front wall with the back wall hidden behind it.
    """
    vf, ff = wall(-2.0, 2.0, 0.0, -0.5, 1.5)
    vb, fb = wall(-5.0, 5.0, 2.0, -2.0, 3.0)
    v = np.concatenate([vf, vb])
    f = np.concatenate([ff, fb + len(vf)]).astype(np.int32)
    doc = MapDocument(MapData(v, f, meta={"source_name": "walls.h5"}))
    return doc, len(ff)


def prepare(make_app, open_page, tool: ToolMode, tmp_path):
    doc, n_front = two_walls()
    running = make_app(doc, data_dir=tmp_path)
    app = running.app
    wait_until(lambda: app.picking is not None, msg="picking index never became ready")
    with doc.gesture():
        doc.add_class("wall", RED)
        iid = doc.add_instance("wall", "1")
    doc.history.clear()
    app.label_panel.refresh()
    app.label_panel.active.value = "wall / 1"
    app.tool_panel.set_mode(tool)
    page = open_page(running)
    client = running.client()
    target = np.array([0.0, -3.0, 0.5])
    echoed = threading.Event()
    client.camera.on_update(
        lambda cam: echoed.set() if np.allclose(cam.position, target, atol=1e-3) else None
    )
    client.camera.position = tuple(target)
    client.camera.look_at = (0.0, 1.0, 0.5)
    client.camera.up_direction = (0.0, 0.0, 1.0)
    assert echoed.wait(60), "the browser did not take the camera pose"
    sync_browser(running.server, page)
    return running, page, doc, iid, n_front


def test_click_labels_the_face_under_the_cursor(make_app, open_page, tmp_path):
    running, page, doc, iid, n_front = prepare(make_app, open_page, ToolMode.PICK, tmp_path)
    x, y = VIEWPORT["width"] * 0.3, VIEWPORT["height"] * 0.55
    page.mouse.click(x, y)
    wait_until(lambda: (doc.face_labels == iid).any(), msg="the click labelled nothing")
    labelled = np.flatnonzero(doc.face_labels == iid)
    assert len(labelled) == 1
    assert labelled[0] < n_front, "the click labelled a face of the hidden back wall"
    # The face is the one the click's ray hits (server-side ray from the client's camera).
    from app.adapters import camera_model

    cam = camera_model(running.client())
    o, d = cam.rays(np.array([[(x + 0.5) / VIEWPORT["width"], (y + 0.5) / VIEWPORT["height"]]]))
    hit = running.app.index.pick(o[0] + doc.origin, d[0])
    assert hit.face_ids[0] == labelled[0]

    # Its colour appears on screen around the cursor.
    def red_at_cursor():
        img = screenshot_rgb(page)
        patch = img[int(y) - 2 : int(y) + 3, int(x) - 2 : int(x) + 3].reshape(-1, 3)
        r, g, b = patch.mean(axis=0)
        return r > g + 60 and r > b + 60

    wait_until(red_at_cursor, msg="the label colour never appeared under the cursor")
    # A second click on it toggles the label off.
    page.mouse.click(x, y)
    wait_until(lambda: not (doc.face_labels == iid).any(), msg="the second click did not toggle")


def rubber_band(page, x0, y0, x1, y1):
    w, h = VIEWPORT["width"], VIEWPORT["height"]
    page.keyboard.down("Shift")
    page.mouse.move(x0 * w, y0 * h)
    page.mouse.down()
    page.mouse.move(x1 * w, y1 * h, steps=8)
    page.mouse.up()
    page.keyboard.up("Shift")


@pytest.mark.parametrize("mode", ["visible only", "through"])
def test_rubber_band_visible_or_through(make_app, open_page, tmp_path, mode):
    running, page, doc, iid, n_front = prepare(make_app, open_page, ToolMode.RECT, tmp_path)
    running.app.tool_panel.rect_mode.value = mode
    sync_browser(running.server, page)
    rubber_band(page, 0.25, 0.45, 0.45, 0.65)  # inside the front wall's image
    wait_until(lambda: (doc.face_labels == iid).any(), msg="the rubber band labelled nothing")
    labelled = np.flatnonzero(doc.face_labels == iid)
    front = labelled[labelled < n_front]
    back = labelled[labelled >= n_front]
    assert len(front) > 10
    if mode == "visible only":
        assert len(back) == 0, f"{len(back)} hidden back-wall faces selected"
    else:
        assert len(back) > 10, "through mode did not reach the wall behind"


def test_brush_stroke_undo_and_save_reload(make_app, open_page, tmp_path):
    from playwright.sync_api import expect

    running, page, doc, iid, n_front = prepare(make_app, open_page, ToolMode.BRUSH, tmp_path)
    running.app.tool_panel.radius.value = 0.15
    wait_until(lambda: running.app.tool_panel._drag_nodes, msg="no drag binding")
    sync_browser(running.server, page)
    w, h = VIEWPORT["width"], VIEWPORT["height"]
    page.mouse.move(0.26 * w, 0.55 * h)  # the front wall spans about 0.22 to 0.78 of the width
    page.mouse.down()
    for k in range(1, 9):
        page.mouse.move((0.26 + 0.03 * k) * w, 0.55 * h)
    page.mouse.up()
    wait_until(lambda: not doc.history.is_open and doc.history.can_undo, msg="stroke not done")
    labelled = np.flatnonzero(doc.face_labels == iid)
    assert len(labelled) > 20
    assert (labelled < n_front).all()
    # the stroke is continuous along x: labelled faces span most of the dragged width
    centroids = doc.vertices[doc.faces[labelled]].mean(axis=1)
    assert np.ptp(centroids[:, 0]) > 0.3

    page.get_by_role("button", name="Undo").click()
    wait_until(lambda: not (doc.face_labels == iid).any(), msg="undo did not remove the stroke")
    page.get_by_role("button", name="Redo").click()
    wait_until(lambda: (doc.face_labels == iid).sum() == len(labelled), msg="redo failed")

    box = text_input(page, "Save as")
    box.fill("walls_labelled.h5")
    box.press("Enter")
    wait_until(lambda: running.app.file_panel.save_as_path.value == "walls_labelled.h5")
    page.get_by_role("button", name="Save as…").click()
    saved = tmp_path / "walls_labelled.h5"
    wait_until(lambda: saved.exists() and not doc.dirty, msg="save as did not write the map")
    reloaded = load_map(saved)
    assert np.array_equal(reloaded.face_labels >= 0, doc.face_labels >= 0)
    assert {i.full_name for i in reloaded.instances.values()} == {"wall_1"}
    # Opening it again in the app shows the labels (overlay nodes exist).
    running.app.open_path(saved, None)
    wait_until(lambda: running.app.doc is not doc and running.app.overlay.node_count > 0)
    expect(page.get_by_text("walls_labelled.h5").first).to_be_visible()


def test_erase_drag_starting_on_a_labelled_face(make_app, open_page, tmp_path):
    running, page, doc, iid, n_front = prepare(make_app, open_page, ToolMode.ERASE, tmp_path)
    doc.label_faces(np.arange(n_front), iid)  # the whole front wall is labelled: overlay nodes
    wait_until(lambda: running.app.overlay.node_count > 0, msg="no overlay nodes")
    running.app.tool_panel.radius.value = 0.15
    running.app.tool_panel.refresh_drag_bindings()
    sync_browser(running.server, page)
    w, h = VIEWPORT["width"], VIEWPORT["height"]
    page.mouse.move(0.3 * w, 0.5 * h)  # on the overlay, not on the base mesh
    page.mouse.down()
    for k in range(1, 7):
        page.mouse.move((0.3 + 0.03 * k) * w, 0.5 * h)
    page.mouse.up()
    wait_until(lambda: (doc.face_labels[:n_front] == -1).sum() > 20, msg="erase did nothing")
    assert (doc.face_labels[:n_front] == iid).sum() > n_front // 2  # only the stroke is erased
    wait_until(lambda: not doc.history.is_open, msg="the erase gesture never closed")
    doc.undo()
    assert (doc.face_labels[:n_front] == iid).all()
