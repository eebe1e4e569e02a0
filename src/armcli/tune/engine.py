"""One engine interface: score a batch of candidate gains, locally or on a Dask cluster.

The work is `evaluate.evaluate_candidates` on chunks of the batch; backends only decide
where the chunks run, and results come back in batch order:

- `LocalEngine(jobs)`: a thread pool, one candidate per task. The compiled rollout
  (the armcli.sim._rollout extension) releases the GIL, so threads run rollouts on separate cores;
- `DaskEngine(address)`: an existing `dask.distributed` scheduler (`dask scheduler` /
  `dask worker`, or dask-jobqueue / dask-kubernetes clusters, which expose the same
  address). The problem is broadcast once; a batch is cut into a few chunks per worker,
  one task each (a candidate is ~20 ms of rollouts on the seed arm; a task per candidate
  spent a large share of that on Dask's per-task messaging).

Trust: the Dask client unpickles what the scheduler and workers send, so whoever runs
the cluster, or can speak in its place on the network, runs code inside armcli. The
trust boundary is the cluster: a plain `tcp://` address on another host is refused
unless the user says it is trusted (`--trust-scheduler`); `tls://` (with Dask's TLS
configuration) or a loopback address is accepted. Before Dask's own handshake, a
raw probe checks that the address answers like a Dask comm (a non-Dask server gave
`MemoryError` for a 3 EiB frame length).
"""

from __future__ import annotations

import ipaddress
import socket
import struct
import time
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Protocol
from urllib.parse import urlsplit

import numpy as np

from armcli.errors import InputError
from armcli.tune.evaluate import CandidateEval, evaluate_candidates
from armcli.tune.objective import Weights
from armcli.tune.problem import TuneProblem

CONNECT_TIMEOUT_S = 3.0  # [s] to reach a Dask scheduler before giving up
MAX_HANDSHAKE_BYTES = 1 << 20  # a Dask handshake is a few hundred bytes
PLAIN_SCHEMES = ("tcp", "ws", "ucx")  # unencrypted, unauthenticated transports
TRUST_HINT = (
    "the Dask client unpickles what the cluster sends, so a scheduler reached over plain "
    "tcp:// on another host can run code in armcli: use tls:// (Dask's TLS settings), an SSH "
    "tunnel to a loopback address, or pass --trust-scheduler if you trust the network and "
    "the cluster"
)
TASK_CANDIDATES = 1  # candidates per thread-pool task
DASK_TASKS_PER_WORKER = 2  # a batch becomes this many tasks per worker (balance vs overhead)
DASK_HINT = "pip install 'dask[distributed]' (what armcli's `dask` extra installs)"


class Engine(Protocol):
    """Scores batches of candidates; results are in the order of `batch`."""

    name: str

    def evaluate(
        self, problem: TuneProblem, batch: Sequence[np.ndarray], weights: Weights
    ) -> list[CandidateEval]:
        """Score every candidate of `batch` on `problem`, in order."""
        ...

    def close(self) -> None:
        """Release threads or the cluster connection."""
        ...


class LocalEngine:
    """A thread pool of `jobs` workers in this process."""

    def __init__(self, jobs: int) -> None:
        if jobs < 1:
            raise InputError(f"must be >= 1, got {jobs}", field="jobs")
        self.jobs = jobs
        self.name = f"local ({jobs} thread{'s' if jobs > 1 else ''})"
        self._pool = ThreadPoolExecutor(jobs) if jobs > 1 else None

    def evaluate(
        self, problem: TuneProblem, batch: Sequence[np.ndarray], weights: Weights
    ) -> list[CandidateEval]:
        """Score `batch` on the threads, results in batch order."""
        if self._pool is None:
            return evaluate_candidates(problem, batch, weights)
        # One candidate per task: while one thread runs a rollout in C++ (GIL released),
        # another does a candidate's Python set-up and scoring, instead of every thread
        # contending for the GIL at the same moments of one big chunk each.
        tasks = [batch[k : k + TASK_CANDIDATES] for k in range(0, len(batch), TASK_CANDIDATES)]
        done = self._pool.map(lambda c: evaluate_candidates(problem, c, weights), tasks)
        return [ev for chunk in done for ev in chunk]

    def close(self) -> None:
        """Stop the threads."""
        if self._pool is not None:
            self._pool.shutdown(cancel_futures=True)  # Ctrl-C: queued candidates never start


class DaskEngine:
    """Candidates as tasks on an existing dask.distributed scheduler."""

    def __init__(
        self, address: str, timeout: float = CONNECT_TIMEOUT_S, *, trusted: bool = False
    ) -> None:
        check_scheduler_address(address, trusted)
        try:
            from distributed import Client
        except ImportError:
            raise InputError(f"needs dask.distributed: {DASK_HINT}", field="scheduler") from None
        self.address = address
        try:
            _probe(address, timeout)
            self.client: Any = Client(  # type: ignore[no-untyped-call]
                address, timeout=f"{timeout}s", set_as_default=False
            )
        except ValueError as exc:
            raise InputError(f"not a Dask address: {exc}", field="scheduler") from None
        except (OSError, TimeoutError) as exc:
            raise InputError(
                f"cannot reach the Dask scheduler at {address} within {timeout:g} s "
                f"({str(exc) or 'no answer'}); start one with `dask scheduler` and "
                "`dask worker ADDRESS`",
                field="scheduler",
            ) from None
        workers = self.client.scheduler_info().get("workers", {})
        self.name = f"dask {address} ({len(workers)} worker{'s' if len(workers) != 1 else ''})"
        self._shipped: dict[str, Any] = {}

    def evaluate(
        self, problem: TuneProblem, batch: Sequence[np.ndarray], weights: Weights
    ) -> list[CandidateEval]:
        """Score `batch` in DASK_TASKS_PER_WORKER chunks per worker, results in batch order."""
        if problem.key not in self._shipped:
            self._shipped[problem.key] = self.client.scatter(problem, broadcast=True, hash=False)
        shipped = self._shipped[problem.key]
        workers = max(1, len(self.client.scheduler_info().get("workers", {})))
        size = max(1, -(-len(batch) // (DASK_TASKS_PER_WORKER * workers)))
        chunks = [list(batch[k : k + size]) for k in range(0, len(batch), size)]
        futures = [
            self.client.submit(evaluate_candidates, shipped, c, weights, pure=False) for c in chunks
        ]
        return [ev for chunk in self.client.gather(futures) for ev in chunk]

    def close(self) -> None:
        """Disconnect from the scheduler (the cluster keeps running)."""
        self.client.close()


def _split(address: str) -> tuple[str, str, int | None]:
    """(scheme, host, port) of a Dask address; `HOST:PORT` alone means tcp://."""
    scheme, sep, rest = address.partition("://")
    if not sep:
        scheme, rest = "tcp", address
    parsed = urlsplit(f"//{rest}")
    try:
        port = parsed.port
    except ValueError:
        raise InputError(f"bad port in {address!r}", field="scheduler") from None
    return scheme.lower(), (parsed.hostname or "").lower(), port


def is_loopback(host: str) -> bool:
    """Whether `host` names this machine without asking DNS (localhost or a loopback IP)."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def check_scheduler_address(address: str, trusted: bool) -> None:
    """Refuse a plain-text scheduler on another host unless `trusted` (see the docstring)."""
    scheme, host, _ = _split(address)
    if scheme in PLAIN_SCHEMES and not is_loopback(host) and not trusted:
        raise InputError(
            f"{address} is not encrypted and not on this machine: {TRUST_HINT}", field="scheduler"
        )


def _raw_probe(host: str, port: int, timeout: float) -> None:
    """Read the first 8 bytes the peer sends: a Dask comm's handshake length, sent unasked.

    A server that stays silent is unreachable (TimeoutError); one that announces a message
    of gigabytes is not a Dask scheduler.
    """
    with socket.create_connection((host, port), timeout=timeout) as sock:
        head = b""
        deadline = time.monotonic() + timeout
        while len(head) < 8:
            sock.settimeout(max(deadline - time.monotonic(), 0.001))
            try:
                chunk = sock.recv(8 - len(head))
            except TimeoutError:
                raise TimeoutError("no answer") from None  # reported as unreachable
            if not chunk:
                raise ConnectionResetError("the connection was closed before the handshake")
            head += chunk
    (size,) = struct.unpack("<Q", head)
    if size > MAX_HANDSHAKE_BYTES:
        raise _NotDaskError(f"its first message claims {size} bytes")


class _NotDaskError(Exception):
    """The address answers, but not as a Dask scheduler."""


def _probe(address: str, timeout: float) -> None:
    """Check the peer, then connect and handshake with a hard deadline.

    `Client` alone can wait forever on a port that accepts TCP but never speaks Dask, and
    Dask's reader allocates whatever length a stranger's first 8 bytes claim.
    """
    import asyncio

    from distributed.comm.core import connect

    scheme, host, port = _split(address)
    try:
        if scheme == "tcp" and port is not None:
            _raw_probe(host, port, timeout)

        async def once() -> None:
            comm = await asyncio.wait_for(connect(address, timeout=timeout), timeout)  # type: ignore[no-untyped-call]
            await comm.close()

        asyncio.run(once())
    except (_NotDaskError, MemoryError, OverflowError, struct.error) as exc:
        why = str(exc) or type(exc).__name__
        raise InputError(
            f"{address} does not answer as a Dask scheduler ({why})", field="scheduler"
        ) from None


def make_engine(jobs: int, scheduler: str | None, *, trust_scheduler: bool = False) -> Engine:
    """The local thread pool, or Dask when a scheduler address is given."""
    if scheduler:
        return DaskEngine(scheduler, trusted=trust_scheduler)
    return LocalEngine(jobs)
