"""`tune --scheduler`: what armcli connects to (issue 20).

An address that answered but was not Dask (an SSH server) gave `internal error:
MemoryError ... 3.07 EiB`, since Dask's reader allocates whatever length the first 8
bytes claim. And the Dask client unpickles what the scheduler and workers send, so a
plain tcp:// scheduler on another host is refused unless the user trusts it.
"""

from __future__ import annotations

import socket
import struct
import threading
import time
from collections.abc import Iterator

import pytest

from armcli.errors import InputError
from armcli.tune.engine import CONNECT_TIMEOUT_S, check_scheduler_address, make_engine

pytest.importorskip("distributed")
REFUSE_FAST_S = 1.0  # the address policy decides before any connection


def _server(first_bytes: bytes | None) -> Iterator[str]:
    """A loopback TCP server that sends `first_bytes` (None: nothing) to each client."""
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(4)
    stop = threading.Event()

    def serve() -> None:
        srv.settimeout(0.2)
        while not stop.is_set():
            try:
                conn, _ = srv.accept()
            except TimeoutError:
                continue
            if first_bytes is not None:
                conn.sendall(first_bytes)
            time.sleep(0.5)
            conn.close()

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    try:
        yield f"tcp://127.0.0.1:{srv.getsockname()[1]}"
    finally:
        stop.set()
        thread.join()
        srv.close()


@pytest.fixture(params=["ssh-banner", "huge-length", "silent"])
def not_dask(request: pytest.FixtureRequest) -> Iterator[tuple[str, str]]:
    first, said = {
        "ssh-banner": (b"SSH-2.0-OpenSSH_9.2p1 Debian-2\r\n", "does not answer as a Dask"),
        "huge-length": (struct.pack("<Q", 3 << 60), "does not answer as a Dask"),
        "silent": (None, "cannot reach the Dask scheduler .* within 3 s"),
    }[request.param]
    for address in _server(first):
        yield address, said


def test_a_server_that_is_not_dask_is_a_clean_error(not_dask: tuple[str, str]) -> None:
    address, said = not_dask
    start = time.monotonic()
    with pytest.raises(InputError, match=said):
        make_engine(1, address)  # before: internal error: MemoryError
    assert time.monotonic() - start < CONNECT_TIMEOUT_S + 2.0


@pytest.mark.parametrize(
    "address",
    ["tcp://192.0.2.1:8786", "192.0.2.1:8786", "ws://head-node:8786", "tcp://[2001:db8::1]:8786"],
)
def test_plain_remote_scheduler_needs_trust(address: str) -> None:
    start = time.monotonic()
    with pytest.raises(
        InputError, match=r"not encrypted and not on this machine.*--trust-scheduler"
    ):
        make_engine(1, address)
    assert time.monotonic() - start < REFUSE_FAST_S  # refused before connecting


@pytest.mark.parametrize(
    "address",
    ["tcp://127.0.0.1:8786", "localhost:8786", "tcp://[::1]:8786", "tls://head-node:8786"],
)
def test_loopback_and_tls_need_no_trust(address: str) -> None:
    check_scheduler_address(address, trusted=False)


def test_trusted_remote_scheduler_is_tried() -> None:
    with pytest.raises(InputError, match=r"cannot reach the Dask scheduler at tcp://192\.0\.2\.1"):
        make_engine(1, "tcp://192.0.2.1:8786", trust_scheduler=True)  # TEST-NET-1: unroutable
