"""The page shows the map, display modes change the picture, bad files give a notification."""

from __future__ import annotations

import numpy as np
import pytest

from app.view import DisplayMode
from tests.app.conftest import (
    canvas_region,
    screenshot_rgb,
    sync_browser,
    text_input,
    wait_until,
)

pytestmark = pytest.mark.browser


def mean_diff(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(canvas_region(a) - canvas_region(b)).mean())


def test_demo_map_is_drawn(make_app, open_page):
    running = make_app()
    page = open_page(running)
    sync_browser(running.server, page)
    with_map = screenshot_rgb(page)
    # The same page with the map hidden is the empty scene to compare with.
    running.app.view._base.visible = False
    sync_browser(running.server, page)
    empty = wait_until(
        lambda: (lambda s: s if mean_diff(s, with_map) > 5 else None)(screenshot_rgb(page)),
        msg="hiding the map did not change the picture: the map was never drawn",
    )
    region = canvas_region(with_map)
    assert region.std() > 10, "the map area is a flat colour"
    assert mean_diff(with_map, empty) > 5


def test_switching_to_a_cost_layer_changes_the_picture(make_app, open_page):
    from playwright.sync_api import expect

    running = make_app()
    page = open_page(running)
    sync_browser(running.server, page)
    before = screenshot_rgb(page)
    page.get_by_label("Mode", exact=True).click()
    page.get_by_role("option", name="Cost layer").click()
    wait_until(
        lambda: running.app.view.settings.mode is DisplayMode.COST_LAYER,
        msg="the server never switched to the cost-layer mode",
    )
    expect(page.get_by_label("Layer", exact=True)).to_be_visible()
    sync_browser(running.server, page)
    after = wait_until(
        lambda: (lambda s: s if mean_diff(s, before) > 3 else None)(screenshot_rgb(page)),
        msg="the picture did not change after switching to a cost layer",
    )
    # Cost colours (viridis) are saturated; the fixed grey is not.
    sat = lambda img: float(np.ptp(canvas_region(img), axis=2).mean())  # noqa: E731
    assert sat(after) > sat(before) + 5


def test_opening_a_broken_file_notifies_and_keeps_the_map(make_app, open_page, tmp_path):
    from playwright.sync_api import expect

    broken = tmp_path / "broken.h5"
    broken.write_bytes(b"\x89HDF\r\n\x1a\n" + b"\0" * 100)  # an HDF5 signature, then nothing
    running = make_app(data_dir=tmp_path)
    doc = running.app.doc
    page = open_page(running)
    box = text_input(page, "Open path")
    box.fill("broken.h5")
    box.press("Enter")
    wait_until(lambda: running.app.file_panel.open_path.value == "broken.h5", msg="no path typed")
    page.get_by_role("button", name="Open", exact=True).click()
    expect(page.get_by_text("broken.h5", exact=False).last).to_be_visible()
    note = page.locator(".mantine-Notification-root", has_text="Could not")
    expect(note.first).to_be_visible()
    expect(note.first).to_contain_text("broken.h5")
    assert running.app.doc is doc, "the open map was replaced by a broken one"
    assert running.server.scene.get_handle_by_name("/map/base") is not None
