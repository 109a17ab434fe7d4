"""The one executor for long work (loading, saving, index builds, layers) and its progress.

Callbacks hand work here so the viser thread pool stays free; the person who started a job
sees a loading notification that turns into the result or the error.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any, TypeVar

import viser

from app.notify import report_exception

logger = logging.getLogger(__name__)

T = TypeVar("T")


class Jobs:
    """Run long jobs one after another on a background thread, with progress for the client."""

    def __init__(self) -> None:
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="meshmark-job")

    def submit(
        self,
        what: str,
        fn: Callable[[], T],
        *,
        client: viser.ClientHandle | None = None,
        on_done: Callable[[T], Any] | None = None,
        done_message: Callable[[T], str] | None = None,
    ) -> Future[T | None]:
        """Run ``fn`` in the background; ``what`` reads as "Loading map.h5" in the notification."""
        note = None
        if client is not None:
            try:
                note = client.add_notification(
                    what + "…", "working", loading=True, with_close_button=False
                )
            except Exception:
                note = None

        def run() -> T | None:
            try:
                result = fn()
                if on_done is not None:
                    on_done(result)
            except Exception as exc:
                _close(note)
                report_exception(client, exc, what[:1].lower() + what[1:])
                return None
            if note is not None:
                try:
                    note.title = what + " — done"
                    note.body = done_message(result) if done_message else "done"
                    note.loading = False
                    note.with_close_button = True
                    note.auto_close_seconds = 4.0
                except Exception:
                    logger.debug("could not update notification", exc_info=True)
            return result

        return self._pool.submit(run)

    def shutdown(self) -> None:
        """Stop taking jobs and wait for the running one."""
        self._pool.shutdown(wait=True, cancel_futures=True)


def _close(note: Any) -> None:
    if note is not None:
        try:
            note.remove()
        except Exception:
            logger.debug("could not remove notification", exc_info=True)
