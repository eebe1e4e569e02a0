"""The viewer's server answers only pages it served itself: Host and Origin are checked.

viser accepts a WebSocket upgrade from any Origin and any Host, so a web page the user
visits could connect to `http://127.0.0.1:8080` (directly, or through DNS rebinding with
its own host name) and drive the viewer (issue 27). Every request must carry a Host
whose name is a loopback name, the address the server is bound to, or (bound to all
interfaces) an IP literal; a request with an Origin (browsers always send one for
WebSockets) must come from that same host. Clients without an Origin (scripts, tests)
are not web pages and may connect.
"""

from __future__ import annotations

import contextlib
import http
import ipaddress
import re
from collections.abc import Callable, Iterator
from typing import Any
from urllib.parse import urlsplit

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


@contextlib.contextmanager
def checked_requests(bind_host: str) -> Iterator[None]:
    """While viser starts its server, wrap the server's request hook with `allowed`.

    viser builds its websockets server inside `ViserServer(...)` (in a thread it waits
    for), so the wrapper is in place exactly while the constructor runs.
    """
    import websockets.asyncio.server as ws_server
    from websockets.datastructures import Headers
    from websockets.http11 import Response

    real_serve = ws_server.serve

    def serve(*args: Any, **kwargs: Any) -> Any:
        inner: Callable[..., Any] | None = kwargs.get("process_request")

        def process_request(connection: Any, request: Any) -> Any:
            headers = request.headers
            if not allowed(bind_host, headers.get("Host"), headers.get("Origin")):
                body = b"armcli view: request refused (Host or Origin is not this viewer)\n"
                return Response(http.HTTPStatus.FORBIDDEN, "Forbidden", Headers(), body)
            return inner(connection, request) if inner is not None else None

        kwargs["process_request"] = process_request
        return real_serve(*args, **kwargs)

    setattr(ws_server, "serve", serve)  # noqa: B010 - viser looks it up at call time
    try:
        yield
    finally:
        setattr(ws_server, "serve", real_serve)  # noqa: B010
