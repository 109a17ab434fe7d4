"""The goal tool in a real browser: drag sets position and heading, click uses the default heading.

Runs on the demo map (floor_is_lava): its flat strip at z ≈ -0.12 m (x -1.5..7.5, y -0.9..0.9) is
seen from a yawed camera, so "drag to the right on screen" is a world direction that is neither
+x nor +y and the test has to get it from the camera model.
"""

from __future__ import annotations

import math
import re
import threading
import time

import numpy as np
import pytest

from app.adapters import camera_model
from app.goals_panel import PREVIEW_NODE
from app.tools import ToolMode
from geometry.pose import matrix_from_quaternion, yaw_of
from storage import load_map
from tests.app.conftest import TIMEOUT_MS, VIEWPORT, sync_browser, text_input, wait_until

pytestmark = pytest.mark.browser

# The camera looks down at the flat strip at about 45°, turned so that screen-right is about
# 35° clockwise from world +x.
CAMERA_POSITION = (2.2, -1.4, 1.6)
CAMERA_LOOK_AT = (3.2, 0.0, -0.2)
DRAG_START = (380, 400)  # pixels, left of the control panel
DRAG_PX = 100
CLICK_AT = (330, 470)


def prepare(make_app, open_page):
    running = make_app()  # the demo map
    app = running.app
    wait_until(lambda: app.picking is not None, msg="picking index never became ready")
    app.tool_panel.set_mode(ToolMode.GOAL)
    wait_until(lambda: app.tool_panel._drag_nodes, msg="the goal tool bound no drag callback")
    page = open_page(running)
    client = running.client()
    target = np.array(CAMERA_POSITION)
    echoed = threading.Event()
    client.camera.on_update(
        lambda cam: echoed.set() if np.allclose(cam.position, target, atol=1e-3) else None
    )
    client.camera.position = CAMERA_POSITION
    client.camera.look_at = CAMERA_LOOK_AT
    client.camera.up_direction = (0.0, 0.0, 1.0)
    assert echoed.wait(60), "the browser did not take the camera pose"
    sync_browser(running.server, page)  # camera, tool mode and drag binding have landed
    return running, page, app.doc


def surface_under(running, px: float, py: float):
    """Return (world point, face id) under a pixel of the page, by the client's camera model."""
    doc = running.app.doc
    cam = camera_model(running.client())
    uv = np.array([[(px + 0.5) / VIEWPORT["width"], (py + 0.5) / VIEWPORT["height"]]])
    o, d = cam.rays(uv)
    hit = running.app.index.pick(o[0] + doc.origin, d[0])
    face = int(hit.face_ids[0])
    assert face >= 0, f"nothing under pixel {(px, py)}"
    return o[0] + doc.origin + d[0] * float(hit.distances[0]), face


def face_normal(doc, face: int, toward: np.ndarray, at: np.ndarray) -> np.ndarray:
    a, b, c = doc.vertices[doc.faces[face]].astype(np.float64)
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n)
    return n if np.dot(toward - at, n) >= 0 else -n


def yaw_error_deg(a: float, b: float) -> float:
    return abs(math.degrees((a - b + math.pi) % (2 * math.pi) - math.pi))


def test_drag_sets_position_and_heading_then_list_save_and_undo(make_app, open_page, tmp_path):
    from playwright.sync_api import expect

    running, page, doc = prepare(make_app, open_page)
    x0, y0 = DRAG_START
    x1 = x0 + DRAG_PX
    start, start_face = surface_under(running, x0, y0)
    end, end_face = surface_under(running, x1, y0)
    eye = np.asarray(running.client().camera.position, dtype=np.float64) + doc.origin
    normal = face_normal(doc, start_face, eye, start)
    assert normal[2] > 0.999, "the drag must start on the level floor (camera set up wrongly?)"
    assert face_normal(doc, end_face, eye, end)[2] > 0.999, "the drag must end on the floor"
    along = end - start
    along -= np.dot(along, normal) * normal
    expected_yaw = math.atan2(along[1], along[0])
    assert 20 < abs(math.degrees(expected_yaw)) < 70, "screen-right should not be a world axis"

    page.mouse.move(x0, y0)
    page.mouse.down()
    for k in range(1, 9):
        page.mouse.move(x0 + DRAG_PX * k / 8, y0)
    # While the button is held, the live heading arrow is drawn (and no goal exists yet).
    page.wait_for_function(
        "n => !!window.__viserMutable.nodeRefFromName[n]", arg=PREVIEW_NODE, timeout=TIMEOUT_MS
    )
    assert doc.goals == ()
    page.mouse.up()
    wait_until(lambda: len(doc.goals) == 1, msg="the drag created no goal")
    sync_browser(running.server, page)
    time.sleep(0.5)  # a stray click handler would add a second goal by now
    assert len(doc.goals) == 1, f"one drag made {len(doc.goals)} goals"

    goal = doc.goals[0]
    assert goal.name == "goal1"
    assert goal.frame_id == "map"
    position = np.asarray(goal.position)
    assert np.linalg.norm(position - start) < 0.01, (position, start)
    axes = matrix_from_quaternion(goal.orientation_xyzw)
    assert np.allclose(axes.T @ axes, np.eye(3), atol=1e-9)
    assert np.linalg.det(axes) == pytest.approx(1.0, abs=1e-9)
    assert np.dot(axes[:, 2], normal) > math.cos(math.radians(1)), "z is not the face normal"
    assert axes[2, 2] > 0.999, "z must point up on the floor (toward the camera)"
    # x lies in the face plane (1° slack: the browser's hit may be a neighbouring floor face)
    assert abs(np.dot(axes[:, 0], normal)) < math.sin(math.radians(1)), "x leaves the plane"
    yaw = yaw_of(goal.orientation_xyzw)
    assert yaw_error_deg(yaw, expected_yaw) < 5, (math.degrees(yaw), math.degrees(expected_yaw))
    # The live preview arrow is gone once the goal exists.
    assert running.server.scene.get_handle_by_name(PREVIEW_NODE) is None

    # The list shows it: server side and in the (collapsed) Goals folder of the page.
    wait_until(lambda: "goal1" in running.app.goals_panel.listing.content, msg="not listed")
    assert f"yaw {math.degrees(yaw):.0f}°" in running.app.goals_panel.listing.content
    page.get_by_text("Goals", exact=True).click()
    row = page.get_by_text(re.compile(r"goal1.*yaw -?\d+°"))
    expect(row.first).to_be_visible()
    assert running.app.goals_panel.selected.value == "goal1"

    # Save as in the page, load the file: the same goals, bit for bit.
    box = text_input(page, "Save as")
    box.fill("demo_goals.h5")
    box.press("Enter")
    wait_until(lambda: running.app.file_panel.save_as_path.value == "demo_goals.h5")
    page.get_by_role("button", name="Save as…").click()
    saved = tmp_path / "demo_goals.h5"
    wait_until(lambda: saved.exists() and not doc.dirty, msg="save as did not write the map")
    assert load_map(saved).goals == doc.goals

    # Undo (the Labels folder's button) removes the goal, from the document and the list.
    page.get_by_role("button", name="Undo").click()
    wait_until(lambda: len(doc.goals) == 0, msg="undo did not remove the goal")
    wait_until(
        lambda: "goal1" not in running.app.goals_panel.listing.content,
        msg="the list still shows the undone goal",
    )
    expect(page.get_by_text(re.compile(r"goal1.*yaw"))).to_have_count(0)


def test_click_without_drag_uses_the_default_heading(make_app, open_page):
    running, page, doc = prepare(make_app, open_page)
    x, y = CLICK_AT
    point, face = surface_under(running, x, y)
    eye = np.asarray(running.client().camera.position, dtype=np.float64) + doc.origin
    normal = face_normal(doc, face, eye, point)
    assert normal[2] > 0.999, "the click must land on the level floor"

    page.mouse.click(x, y)
    wait_until(lambda: len(doc.goals) == 1, msg="a click in goal mode created no goal")
    sync_browser(running.server, page)
    time.sleep(0.5)
    assert len(doc.goals) == 1, f"one click made {len(doc.goals)} goals"
    goal = doc.goals[0]
    assert np.linalg.norm(np.asarray(goal.position) - point) < 0.01
    axes = matrix_from_quaternion(goal.orientation_xyzw)
    assert np.dot(axes[:, 2], normal) > math.cos(math.radians(1))
    # Default heading: world +x projected into the (level) floor, i.e. yaw 0.
    assert abs(math.degrees(yaw_of(goal.orientation_xyzw))) < 1.0
    doc.undo()
    assert doc.goals == ()
