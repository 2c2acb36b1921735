"""The panel answers only its own pages: a web page from another site that the surveyor happens to
open must not be able to connect to the panel's websocket on 127.0.0.1 and click "Delete" and
"Save" (issue #18).

viser 1.1 (pinned) serves its websocket with ``websockets.asyncio.server.serve`` and checks no
``Origin``. :func:`install` wraps that ``serve`` so that every websocket handshake is refused
(HTTP 403) unless

- the ``Host`` header names this machine (127.0.0.1, localhost, [::1]) or the address the panel
  was bound to on purpose — which stops DNS rebinding (evil.example resolving to 127.0.0.1), and
- the ``Origin`` header, when the client sends one (browsers always do), is that same host and
  port — which stops every other site.

Plain HTTP requests (the panel's page and scripts) are served as before; they carry no state.
A request with two ``Host``, ``Origin`` or ``Upgrade`` headers is refused (HTTP 400): which one
counts is ambiguous (issue #67 item 6: it got HTTP 500).
"""

from __future__ import annotations

import http
from urllib.parse import urlsplit

from workstation.viz.serve_hook import hook

LOOPBACK = {"127.0.0.1", "localhost", "::1", "[::1]"}
SINGLE = ("Host", "Origin", "Upgrade")  # a request may carry each at most once
_extra_hosts: set[str] = set()


def allow_host(host: str) -> None:
    """Also accept ``host`` (the address given with ``--host``)."""
    if host and host not in ("0.0.0.0", "::"):
        _extra_hosts.add(host.lower())


def repeated(headers) -> list[str]:
    """The headers of ``SINGLE`` that ``headers`` (websockets' ``Headers``) carries twice."""
    return [h for h in SINGLE if len(headers.get_all(h)) > 1]


def handshake_allowed(headers) -> bool:
    host = (headers.get("Host") or "").lower()
    hostname = urlsplit(f"//{host}").hostname or ""
    if hostname not in LOOPBACK and hostname not in _extra_hosts:
        return False
    origin = headers.get("Origin")
    if origin is None:
        return True  # not a browser: a local program, which could read the files anyway
    o = urlsplit(origin.lower())
    return o.scheme in ("http", "https") and o.netloc == host


def install() -> None:
    """Refuse foreign websocket handshakes from now on (idempotent)."""
    from websockets.datastructures import Headers
    from websockets.http11 import Response

    def wrap(process_request):
        def check(connection, request):
            twice = repeated(request.headers)
            if twice:
                return Response(
                    http.HTTPStatus.BAD_REQUEST, "Bad Request", Headers(),
                    f"one {', '.join(twice)} header at most\n".encode(),
                )  # fmt: skip
            if request.headers.get("Upgrade", "").lower() == "websocket" and not (
                handshake_allowed(request.headers)
            ):
                return Response(
                    http.HTTPStatus.FORBIDDEN, "Forbidden", Headers(),
                    b"cross-site connections to the survey panel are refused\n",
                )  # fmt: skip
            return None if process_request is None else process_request(connection, request)

        return check

    hook("_workstation_guard", wrap)
