"""`armcli view` answers only its own page: a web page elsewhere cannot drive it (issue 27).

Before: the viewer's server accepted WebSocket upgrades from any Origin and any Host, so a
page the user visited (or a DNS-rebinding host name pointing at 127.0.0.1) could connect.
"""

from __future__ import annotations

import http.client
from collections.abc import Iterator
from pathlib import Path

import pytest
import viser

from armcli.view.browser import Viewer
from armcli.view.origin import allowed
from armcli.view.scene import load_robot


@pytest.fixture(scope="module")
def viewer(default_spec_path: Path) -> Iterator[Viewer]:
    robot = load_robot(default_spec_path)
    v = Viewer(robot.xml, name=robot.name, port=0)
    try:
        yield v
    finally:
        v.close()


def _upgrade(v: Viewer, host: str, origin: str | None) -> int:
    """The HTTP status of a WebSocket upgrade request with these Host and Origin headers."""
    conn = http.client.HTTPConnection("127.0.0.1", v.port, timeout=10)
    headers = {
        "Host": host,
        "Upgrade": "websocket",
        "Connection": "Upgrade",
        "Sec-WebSocket-Key": "dGhlIHNhbXBsZSBub25jZQ==",
        "Sec-WebSocket-Version": "13",
        "Sec-WebSocket-Protocol": f"viser-v{viser.__version__}",  # else viser prints a warning
        **({"Origin": origin} if origin is not None else {}),
    }
    conn.request("GET", f"/?token={v.token}", headers=headers)  # the token: test_token.py
    status = conn.getresponse().status
    conn.close()
    return status


def test_foreign_origin_is_refused(viewer: Viewer) -> None:
    own = f"127.0.0.1:{viewer.port}"
    assert _upgrade(viewer, own, "http://evil.example") == 403
    assert _upgrade(viewer, own, "null") == 403


def test_foreign_host_is_refused(viewer: Viewer) -> None:
    """DNS rebinding: the page's own host name resolved to 127.0.0.1."""
    evil = f"evil.example:{viewer.port}"
    assert _upgrade(viewer, evil, f"http://{evil}") == 403
    conn = http.client.HTTPConnection("127.0.0.1", viewer.port, timeout=10)
    conn.request("GET", f"/?token={viewer.token}", headers={"Host": evil})
    assert conn.getresponse().status == 403  # the page itself is not served either
    conn.close()


def test_own_page_and_scripts_connect(viewer: Viewer) -> None:
    for host in (f"127.0.0.1:{viewer.port}", f"localhost:{viewer.port}"):
        assert _upgrade(viewer, host, f"http://{host}") == 101
    assert _upgrade(viewer, f"127.0.0.1:{viewer.port}", None) == 101  # no Origin: not a page


@pytest.mark.parametrize(
    ("bind", "host", "origin", "ok"),
    [
        ("127.0.0.1", "127.0.0.1:8080", "http://127.0.0.1:8080", True),
        ("127.0.0.1", "[::1]:8080", "http://[::1]:8080", True),
        ("127.0.0.1", "127.0.0.1:8080", "http://localhost:8080", False),  # another origin
        ("127.0.0.1", "192.168.1.5:8080", None, False),
        ("0.0.0.0", "192.168.1.5:8080", "http://192.168.1.5:8080", True),  # exposed on purpose
        ("0.0.0.0", "evil.example:8080", None, False),  # names are never trusted
        ("127.0.0.1", None, None, False),
        ("127.0.0.1", "127.0.0.1:8080\r\nX: y", None, False),
    ],
)
def test_allowed(bind: str, host: str | None, origin: str | None, ok: bool) -> None:
    assert allowed(bind, host, origin) is ok
