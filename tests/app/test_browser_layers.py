"""Computing cost layers from the page: the button, the notification, the Layer dropdown."""

from __future__ import annotations

import pytest

from tests.app.conftest import wait_until

pytestmark = pytest.mark.browser


def open_folder(page, title: str, inside) -> None:
    """Expand a GUI folder unless it is open already (``inside`` is one of its controls)."""
    if not inside.is_visible():
        page.get_by_text(title, exact=True).click()


def test_compute_layers_from_the_page(make_app, open_page):
    from playwright.sync_api import expect

    running = make_app()
    assert "steepness" not in running.app.doc.layers
    page = open_page(running)
    compute = page.get_by_role("button", name="Compute layers")
    open_folder(page, "Cost layers", compute)
    compute.click()
    note = page.locator(".mantine-Notification-root", has_text="Cost layers computed")
    expect(note.first).to_be_visible()
    expect(note.first).to_contain_text("NaN: none")
    wait_until(
        lambda: "steepness" in running.app.display_panel.layer.options,
        msg="the computed layers never reached the Layer dropdown",
    )

    mode = page.get_by_label("Mode", exact=True)
    open_folder(page, "Display", mode)
    mode.click()
    page.get_by_role("option", name="Cost layer").click()
    page.get_by_label("Layer", exact=True).click()
    for name in ("steepness", "static_inflation", "final"):
        expect(page.get_by_role("option", name=name, exact=True)).to_be_visible()
