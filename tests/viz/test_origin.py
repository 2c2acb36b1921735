"""The panel refuses websocket connections from other sites (issue #18)."""

import asyncio

import pytest

from tests.conftest import REPO
from workstation.editor import SurveyEditor
from workstation.graph import LandmarkGraph
from workstation.session import load_session
from workstation.viz.origin_guard import handshake_allowed

WALK = REPO / "sample_sessions" / "office2f" / "normal"


@pytest.mark.parametrize(
    "host,origin,ok",
    [
        ("127.0.0.1:8080", "http://127.0.0.1:8080", True),
        ("localhost:8080", "http://localhost:8080", True),
        ("127.0.0.1:8080", None, True),  # not a browser
        ("127.0.0.1:8080", "http://evil.example", False),
        ("127.0.0.1:8080", "http://127.0.0.1:9999", False),  # another local page
        ("127.0.0.1:8080", "null", False),  # sandboxed iframe, file://
        ("evil.example:8080", "http://evil.example:8080", False),  # DNS rebinding
    ],
)
def test_handshake_rules(host, origin, ok):
    h = {"Host": host} | ({"Origin": origin} if origin else {})
    assert handshake_allowed(h) is ok


def test_a_page_from_another_site_cannot_connect(tmp_path):
    import websockets.asyncio.client as wsc
    from websockets.exceptions import InvalidStatus

    from workstation.viz.panel import SurveyPanel

    ed = SurveyEditor(load_session(WALK), LandmarkGraph.load(WALK / "graph.yaml"), out_dir=tmp_path)
    pan = SurveyPanel(ed, None, port=0)
    url = f"ws://127.0.0.1:{pan.port}"

    async def connect(origin):
        async with wsc.connect(url, origin=origin, subprotocols=["viser-v1.1.1"]) as ws:
            return ws.response.status_code

    try:
        with pytest.raises(InvalidStatus) as e:
            asyncio.run(connect("http://evil.example"))
        assert e.value.response.status_code == 403
        assert asyncio.run(connect(f"http://127.0.0.1:{pan.port}")) == 101
    finally:
        pan.stop()


def test_a_request_with_a_header_twice_is_refused_not_an_error(tmp_path):
    """Issue #67 item 6: two Origin (or Host, or Upgrade) headers got HTTP 500 — which one
    counts is ambiguous: refused with 400, the panel serving on."""
    import socket

    from workstation.viz.panel import SurveyPanel

    ed = SurveyEditor(load_session(WALK), LandmarkGraph.load(WALK / "graph.yaml"), out_dir=tmp_path)
    pan = SurveyPanel(ed, None, port=0)

    def status(extra: str) -> int:
        with socket.create_connection(("127.0.0.1", pan.port), timeout=10) as s:
            s.sendall((f"GET / HTTP/1.1\r\nHost: 127.0.0.1:{pan.port}\r\nUpgrade: websocket\r\n"
                       "Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
                       f"Sec-WebSocket-Version: 13\r\n{extra}\r\n").encode())  # fmt: skip
            return int(s.recv(4096).split(b" ")[1])

    try:
        ok = f"Origin: http://127.0.0.1:{pan.port}\r\n"
        assert status(ok + "Origin: http://evil.example\r\n") == 400
        assert status(ok + f"Host: 127.0.0.1:{pan.port}\r\n") == 400
        assert status("Upgrade: websocket\r\n" + ok) == 400
        assert status(ok) == 101  # and it still serves
    finally:
        pan.stop()
