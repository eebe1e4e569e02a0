"""The viewer's server answers only its own pages and the holder of its token.

viser accepts a WebSocket upgrade from any Origin and any Host, so a web page the user
visits could connect to `http://127.0.0.1:8080` (directly, or through DNS rebinding with
its own host name) and drive the viewer (issue 27). Every request must carry a Host
whose name is a loopback name, the address the server is bound to, or (bound to all
interfaces) an IP literal; a request with an Origin (browsers always send one for
WebSockets) must come from that same host. Clients without an Origin (scripts, tests)
are not web pages and may connect.

Host and Origin stop web pages, not people: another user of the machine reached root's
viewer on 127.0.0.1 and clicked Save (issue 42). So each run has a secret token, as
Jupyter's: the URL `armcli view` prints carries it (`/?token=...`), the page request that
presents it gets it back as a cookie (HttpOnly, SameSite=Strict, named after the port,
since cookies do not tell ports apart), and every request (the page, its scripts, the
WebSocket) must present it in the query or that cookie, or gets 403.
"""

from __future__ import annotations

import contextlib
import hmac
import http
import http.cookies
import ipaddress
import re
import secrets
from collections.abc import Callable, Iterator
from typing import Any
from urllib.parse import parse_qs, urlsplit

TOKEN_PARAM = "token"
COOKIE_PREFIX = "armcli-view-"  # + the port
LOOPBACK_NAMES = frozenset({"localhost", "127.0.0.1", "::1"})
WILDCARDS = frozenset({"0.0.0.0", "::", ""})
_HOST = re.compile(r"[A-Za-z0-9.\-]+(?::\d+)?|\[[0-9A-Fa-f:.]+\](?::\d+)?")


def _hostname(host_header: str) -> str | None:
    """The name part of a Host header (`[::1]:8080` -> `::1`), None when malformed."""
    if not _HOST.fullmatch(host_header):
        return None
    try:
        name = urlsplit(f"//{host_header}").hostname
    except ValueError:
        return None
    return name.lower() if name else None


def _is_ip(name: str) -> bool:
    try:
        ipaddress.ip_address(name)
    except ValueError:
        return False
    return True


def allowed(bind_host: str, host_header: str | None, origin: str | None) -> bool:
    """Whether a request with these headers may reach a server bound to `bind_host`."""
    name = _hostname(host_header or "")
    if name is None:
        return False
    ok = name in LOOPBACK_NAMES or name == bind_host.lower()
    if bind_host in WILDCARDS:
        ok = ok or _is_ip(name)
    if not ok:
        return False
    if origin is None:
        return True
    return origin in (f"http://{host_header}", f"https://{host_header}")


def new_token() -> str:
    """A run's secret: 256 random bits, URL-safe."""
    return secrets.token_urlsafe(32)


def _query_token(path: str) -> str | None:
    found = parse_qs(urlsplit(path).query).get(TOKEN_PARAM)
    return found[0] if found else None


def _cookie_token(header: str | None, port: int) -> str | None:
    jar: http.cookies.SimpleCookie = http.cookies.SimpleCookie()
    try:
        jar.load(header or "")
    except http.cookies.CookieError:
        return None
    morsel = jar.get(f"{COOKIE_PREFIX}{port}")
    return morsel.value if morsel is not None else None


def presents(token: str, path: str, cookie: str | None, port: int) -> bool:
    """Whether a request for `path` with this Cookie header carries `token` (in constant time)."""
    given = [t for t in (_query_token(path), _cookie_token(cookie, port)) if t is not None]
    return any(hmac.compare_digest(t.encode(), token.encode()) for t in given)


def _refused(why: str) -> Any:
    from websockets.datastructures import Headers
    from websockets.http11 import Response

    body = f"armcli view: request refused ({why})\n".encode()
    return Response(http.HTTPStatus.FORBIDDEN, "Forbidden", Headers(), body)


@contextlib.contextmanager
def checked_requests(bind_host: str, token: str) -> Iterator[None]:
    """While viser starts its server, wrap the server's request hook: Host, Origin, token.

    viser builds its websockets server inside `ViserServer(...)` (in a thread it waits
    for), so the wrapper is in place exactly while the constructor runs. viser's own hook
    serves the page and lets WebSocket upgrades through; the wrapper runs first.
    """
    import websockets.asyncio.server as ws_server

    real_serve = ws_server.serve

    def serve(*args: Any, **kwargs: Any) -> Any:
        inner: Callable[..., Any] | None = kwargs.get("process_request")

        def process_request(connection: Any, request: Any) -> Any:
            headers = request.headers
            if not allowed(bind_host, headers.get("Host"), headers.get("Origin")):
                return _refused("Host or Origin is not this viewer")
            port = int(connection.local_address[1])
            if not presents(token, request.path, headers.get("Cookie"), port):
                return _refused("no token: open the address `armcli view` printed")
            response = inner(connection, request) if inner is not None else None
            if response is not None and _query_token(request.path) is not None:
                response.headers["Set-Cookie"] = (
                    f"{COOKIE_PREFIX}{port}={token}; Path=/; HttpOnly; SameSite=Strict"
                )
            return response

        kwargs["process_request"] = process_request
        return real_serve(*args, **kwargs)

    setattr(ws_server, "serve", serve)  # noqa: B010 - viser looks it up at call time
    try:
        yield
    finally:
        setattr(ws_server, "serve", real_serve)  # noqa: B010
