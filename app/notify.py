"""Every viser callback goes through ``guarded``: errors reach the person as notifications.

viser runs plain callbacks on a thread pool whose failures only reach stderr; a person in the
browser would see nothing. A meshmark error shows its own message; anything else is logged
with its traceback and the notification points to the log.
"""

from __future__ import annotations

import functools
import logging
from collections.abc import Callable
from typing import Any, TypeVar

import viser

from storage import MeshmarkError

logger = logging.getLogger(__name__)

F = TypeVar("F", bound=Callable[..., Any])


def notify_error(client: viser.ClientHandle | None, title: str, body: str) -> None:
    """Show a red notification to ``client`` (or log it when there is no client)."""
    logger.warning("%s: %s", title, body)
    if client is None:
        return
    try:
        client.add_notification(title, body, color="red", auto_close_seconds=None)
    except Exception:  # the client may be gone; the log has it
        logger.debug("could not notify client", exc_info=True)


def notify_info(
    client: viser.ClientHandle | None, title: str, body: str, *, seconds: float = 5.0
) -> None:
    """Show a short-lived notification to ``client``."""
    logger.info("%s: %s", title, body)
    if client is not None:
        try:
            client.add_notification(title, body, auto_close_seconds=seconds)
        except Exception:
            logger.debug("could not notify client", exc_info=True)


def report_exception(client: viser.ClientHandle | None, exc: BaseException, what: str) -> None:
    """Turn an exception into the right notification: its message, or a pointer to the log."""
    if isinstance(exc, MeshmarkError):
        notify_error(client, f"Could not {what}", str(exc))
    else:
        logger.error("%s failed", what, exc_info=exc)
        notify_error(
            client,
            f"Could not {what}",
            f"Unexpected error ({type(exc).__name__}: {exc}); details are in the server log.",
        )


def guarded(what: str) -> Callable[[F], F]:
    """Wrap a viser callback so that any error becomes a notification to its client."""

    def decorate(fn: F) -> F:
        @functools.wraps(fn)
        def wrapper(event: Any) -> Any:
            try:
                return fn(event)
            except Exception as exc:
                report_exception(getattr(event, "client", None), exc, what)
                return None

        return wrapper  # type: ignore[return-value]

    return decorate
