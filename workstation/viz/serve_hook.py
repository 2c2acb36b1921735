"""One way to hook the HTTP side of viser's server (pinned viser 1.1 serves with
``websockets.asyncio.server.serve`` and reads it at call time): wrap its ``process_request``.
Used by :mod:`.origin_guard` (refuse other sites' websockets) and :mod:`.page_keys` (keyboard
shortcuts in the page)."""

from __future__ import annotations


def hook(flag: str, wrap) -> None:
    """Make every later ``serve(handler, process_request=p)`` use ``wrap(p)`` instead (``p`` may
    be None); once per ``flag``."""
    import websockets.asyncio.server as wss

    if getattr(wss.serve, flag, False):
        return
    original = wss.serve

    class hooked(original):  # type: ignore[misc, valid-type]
        def __init__(self, handler, *args, process_request=None, **kwargs):
            super().__init__(handler, *args, process_request=wrap(process_request), **kwargs)

    setattr(hooked, flag, True)
    setattr(wss, "serve", hooked)  # noqa: B010 - a patch of the module's attribute
