"""Redraw a panel on a background thread when asked: requests arrive under the document lock."""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable

logger = logging.getLogger(__name__)


class Refresher:
    """Run ``refresh`` on a daemon thread after ``request()``; bursts collapse into one run."""

    def __init__(self, refresh: Callable[[], None], name: str) -> None:
        self._refresh = refresh
        self._wanted = threading.Event()
        threading.Thread(target=self._loop, name=name, daemon=True).start()

    def request(self) -> None:
        """Ask for a refresh (cheap, never blocks)."""
        self._wanted.set()

    def _loop(self) -> None:
        while True:
            self._wanted.wait()
            self._wanted.clear()
            try:
                self._refresh()
            except Exception:  # a panel must keep refreshing after one bad moment
                logger.exception("%s refresh failed", threading.current_thread().name)
