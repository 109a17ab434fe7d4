"""Real-browser fixtures: an in-process meshmark app on a free port and Debian's Chromium.

Waiting follows ../shared/recipes/browser-testing.md: the client counts as connected after its
first camera message; scene changes are awaited through viser's own E2E hooks; a fresh dummy
node proves that earlier messages have been applied.
"""

from __future__ import annotations

import io
import os
import shutil
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

TIMEOUT_S = float(os.environ.get("MESHMARK_E2E_TIMEOUT", "60"))
TIMEOUT_MS = int(TIMEOUT_S * 1000)
VIEWPORT = {"width": 1000, "height": 640}
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--ignore-gpu-blocklist",
    "--disable-background-networking",
    "--disable-component-update",
]


def chromium_path() -> str | None:
    """Return Debian's Chromium, or None."""
    found = os.environ.get("CHROMIUM_PATH") or shutil.which("chromium")
    if found:
        return found
    return "/usr/bin/chromium" if Path("/usr/bin/chromium").exists() else None


def wait_until(pred: Callable[[], Any], timeout: float = TIMEOUT_S, msg: str = "") -> Any:
    """Poll ``pred`` until it returns something truthy (any array counts) or time runs out."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = pred()
        if value is not None if isinstance(value, np.ndarray) else bool(value):
            return value
        time.sleep(0.05)
    raise AssertionError(f"timed out after {timeout:.0f}s: {msg}")


def sync_browser(server: Any, page: Any) -> None:
    """Return once the browser applied every message queued so far (and drew a frame)."""
    name = f"/_sync_{time.monotonic_ns()}"
    handle = server.scene.add_frame(name, show_axes=False)
    page.wait_for_function(
        "n => !!(window.__viserMutable && window.__viserMutable.nodeRefFromName[n])",
        arg=name,
        timeout=TIMEOUT_MS,
    )
    handle.remove()


def screenshot_rgb(page: Any) -> np.ndarray:
    """Return the page as an RGB array."""
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(page.screenshot())).convert("RGB")).astype(np.int16)


def text_input(page: Any, label: str) -> Any:
    """Return the text box of a viser ``add_text`` control (its <label> is not linked to it)."""
    return page.locator(
        f"xpath=//label[normalize-space()='{label}']/ancestor::div[.//input][1]"
        "//input[not(@type) or @type='text']"
    ).first


def canvas_region(img: np.ndarray) -> np.ndarray:
    """Return the part of the screenshot not covered by the control panel or the toasts."""
    h, w, _ = img.shape
    return img[int(h * 0.3) :, : int(w * 0.6)]


@pytest.fixture(scope="session")
def chromium() -> Iterator[Any]:
    """A headless Debian Chromium driven by Playwright (fails under CI when missing)."""
    path = chromium_path()
    if path is None:
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail("CI=true but Debian's chromium is not installed (apt-get install chromium)")
        pytest.skip("chromium not installed (apt-get install chromium) - browser tests skipped")
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail("CI=true but playwright is not installed (pip install -e '.[test]')")
        pytest.skip("playwright not installed (pip install -e '.[test]')")
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=path, args=CHROMIUM_ARGS, headless=True)
        yield browser
        browser.close()


class Running:
    """A meshmark app served on a free local port, with helpers for tests."""

    def __init__(self, app: Any, server: Any) -> None:
        self.app = app
        self.server = server
        self.url = f"http://127.0.0.1:{server.get_port()}/"
        self.connected = threading.Event()
        server.on_client_connect(lambda _client: self.connected.set())

    def client(self) -> Any:
        return next(iter(self.server.get_clients().values()))


@pytest.fixture
def make_app(tmp_path: Path) -> Iterator[Callable[..., Running]]:
    """Start ``MeshmarkApp`` on a document (default: the demo map) with ``tmp_path`` as data dir."""
    import viser

    from app.server import MeshmarkApp
    from static import demo_map_path
    from storage import load_map

    started: list[Running] = []

    def start(doc: Any = None, data_dir: Path | None = None) -> Running:
        server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
        app = MeshmarkApp(server, doc or load_map(demo_map_path()), data_dir=data_dir or tmp_path)
        running = Running(app, server)
        started.append(running)
        return running

    yield start
    for running in started:
        running.app.close()
        running.server.stop()


@pytest.fixture
def open_page(chromium: Any) -> Iterator[Callable[[Running], Any]]:
    """Open a page on a running app and wait until the map is mounted and drawn."""
    from playwright.sync_api import expect

    expect.set_options(timeout=TIMEOUT_MS)
    contexts: list[Any] = []
    errors: list[str] = []

    def open_(running: Running) -> Any:
        context = chromium.new_context(viewport=VIEWPORT)
        context.set_default_timeout(TIMEOUT_MS)
        contexts.append(context)
        page = context.new_page()
        page.on("pageerror", lambda exc: errors.append(str(exc)))
        page.goto(running.url)
        assert running.connected.wait(TIMEOUT_S), "the browser never connected"
        page.wait_for_function(
            """() => { const m = window.__viserMutable, t = window.__viserTestpoints;
                       return !!(m && t && m.nodeRefFromName['/map/base']
                                 && t.rendererInfo.render.frame > 0); }""",
            timeout=TIMEOUT_MS,
        )
        toast = page.locator(".mantine-Notification-root", has_text="Software WebGL")
        if toast.count():
            toast.locator("button").dispatch_event("click")
        return page

    yield open_
    for context in contexts:
        context.close()
    assert not errors, f"uncaught errors in the page: {errors}"
