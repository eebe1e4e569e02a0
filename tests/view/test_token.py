"""`armcli view` obeys only the holder of its per-run token (issue 42).

Before: the viewer bound 127.0.0.1 but had no secret, so another (unprivileged) user of
the machine connected to root's viewer and clicked Save (a new file in root's save
directory; root's `roots-notes.yaml` overwritten). Now the printed URL carries a token;
the page and its WebSocket are refused without it. Real clients: websockets' own client
and http.client (a browser is driven in test_browser.py through the same URL).
"""

from __future__ import annotations

import http.client
import re
from collections.abc import Iterator
from pathlib import Path

import pytest
import viser

from armcli.view.browser import Viewer
from armcli.view.origin import COOKIE_PREFIX, presents
from armcli.view.scene import load_robot
from tests.view.viewer_process import view_then_ctrl_c

PROTOCOL = f"viser-v{viser.__version__}"  # the subprotocol viser's page asks for
TIMEOUT_S = 10.0


@pytest.fixture(scope="module")
def viewer(default_spec_path: Path) -> Iterator[Viewer]:
    robot = load_robot(default_spec_path)
    v = Viewer(robot.xml, name=robot.name, port=0)
    try:
        yield v
    finally:
        v.close()


def _connect(v: Viewer, path: str, headers: dict[str, str] | None = None) -> object:
    from websockets.sync.client import connect

    return connect(f"ws://127.0.0.1:{v.port}{path}", subprotocols=[PROTOCOL],  # type: ignore[list-item]
                   additional_headers=headers, open_timeout=TIMEOUT_S)  # fmt: skip


def test_a_websocket_without_the_token_is_refused(viewer: Viewer) -> None:
    from websockets.exceptions import InvalidStatus

    for path, headers in [
        ("/", None),
        ("/?token=wrong", None),
        ("/", {"Cookie": f"{COOKIE_PREFIX}{viewer.port}=wrong"}),
        ("/", {"Cookie": f"{COOKIE_PREFIX}1={viewer.token}"}),  # another port's viewer
    ]:
        with pytest.raises(InvalidStatus) as info:
            _connect(viewer, path, headers)
        assert info.value.response.status_code == 403
    assert not viewer.server.get_clients()


def test_a_websocket_with_the_token_is_served(viewer: Viewer) -> None:
    from websockets.sync.client import ClientConnection

    for path, headers in [
        (f"/?token={viewer.token}", None),
        ("/", {"Cookie": f"{COOKIE_PREFIX}{viewer.port}={viewer.token}"}),
    ]:
        ws = _connect(viewer, path, headers)
        assert isinstance(ws, ClientConnection)
        try:
            first = ws.recv(timeout=TIMEOUT_S)  # viser sends the scene at once
            assert len(first) > 0
        finally:
            ws.close()


def _get(v: Viewer, path: str, cookie: str | None = None) -> http.client.HTTPResponse:
    conn = http.client.HTTPConnection("127.0.0.1", v.port, timeout=TIMEOUT_S)
    headers = {"Cookie": cookie} if cookie else {}
    conn.request("GET", path, headers=headers)
    response = conn.getresponse()
    response.read()
    conn.close()
    return response


def test_the_page_needs_the_token_and_gives_it_as_a_cookie(viewer: Viewer) -> None:
    assert _get(viewer, "/").status == 403
    assert _get(viewer, "/index.html").status == 403
    page = _get(viewer, f"/?token={viewer.token}")
    assert page.status == 200
    cookie = page.getheader("Set-Cookie") or ""
    assert cookie.startswith(f"{COOKIE_PREFIX}{viewer.port}={viewer.token};")
    assert "HttpOnly" in cookie and "SameSite=Strict" in cookie
    # the page's scripts ask without the query: the cookie lets them through
    assert _get(viewer, "/index.html", cookie.split(";")[0]).status == 200


def test_tokens_compare_whole() -> None:
    assert presents("abc", "/?token=abc", None, 8080)
    assert not presents("abc", "/?token=ab", None, 8080)
    assert not presents("abc", "/?token=abcd", None, 8080)
    assert presents("abc", "/", f"x=1; {COOKIE_PREFIX}8080=abc", 8080)
    assert not presents("abc", "/", 'bad"cookie', 8080)


def test_the_printed_url_carries_a_fresh_token(tmp_path: Path, default_spec_path: Path) -> None:
    tokens = []
    for _ in range(2):
        first, code, _, err = view_then_ctrl_c([str(default_spec_path), "--port", "0"], tmp_path)
        assert code == 0, err
        found = re.search(r"at http://127\.0\.0\.1:\d+/\?token=([A-Za-z0-9_-]{43}) ", first)
        assert found, first
        tokens.append(found.group(1))
    assert tokens[0] != tokens[1]


def test_another_user_of_the_machine_is_refused(viewer: Viewer) -> None:
    """The audit's case: an ordinary user connecting to the viewer the test user (root) runs."""
    import subprocess
    import sys

    from tests.helpers import ROOT
    from tests.urdf.ordinary_user import ordinary_user

    user = ordinary_user()
    if isinstance(user, str):
        pytest.skip(f"cannot run as an ordinary user here: {user}")
    code = (
        "import sys\nfrom websockets.sync.client import connect\n"
        "from websockets.exceptions import InvalidStatus\n"
        "try:\n    connect(sys.argv[1], subprotocols=[sys.argv[2]], open_timeout=10).close()\n"
        "    print('connected')\n"
        "except InvalidStatus as exc:\n    print(exc.response.status_code)\n"
    )
    for path, answer in [("/", "403"), (f"/?token={viewer.token}", "connected")]:
        proc = subprocess.run(
            [*user.prefix, sys.executable, "-c", code, f"ws://127.0.0.1:{viewer.port}{path}",
             PROTOCOL],
            capture_output=True, text=True, timeout=60, check=False,
            env={"PATH": "/usr/bin:/bin", "PYTHONPATH": str(ROOT / "src")},
        )  # fmt: skip
        assert proc.stdout.strip() == answer, proc.stderr[-500:]
