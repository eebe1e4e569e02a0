"""One engine interface: score a batch of candidate gains, locally or on a Dask cluster.

The work is `evaluate.evaluate_candidates` on chunks of the batch; backends only decide
where the chunks run, and results come back in batch order:

- `LocalEngine(jobs)`: a thread pool, one candidate per task. The compiled rollout
  (the armcli.sim._rollout extension) releases the GIL, so threads run rollouts on separate cores;
- `DaskEngine(address)`: an existing `dask.distributed` scheduler (`dask scheduler` /
  `dask worker`, or dask-jobqueue / dask-kubernetes clusters, which expose the same
  address). The problem is broadcast once; each candidate is one task.
"""

from __future__ import annotations

from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Protocol

import numpy as np

from armcli.errors import InputError
from armcli.tune.evaluate import CandidateEval, evaluate_candidate, evaluate_candidates
from armcli.tune.objective import Weights
from armcli.tune.problem import TuneProblem

CONNECT_TIMEOUT_S = 3.0  # [s] to reach a Dask scheduler before giving up
TASK_CANDIDATES = 1  # candidates per thread-pool task
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

    def __init__(self, address: str, timeout: float = CONNECT_TIMEOUT_S) -> None:
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
        """Score `batch` as one task per candidate, results in batch order."""
        if problem.key not in self._shipped:
            self._shipped[problem.key] = self.client.scatter(problem, broadcast=True, hash=False)
        shipped = self._shipped[problem.key]
        futures = [
            self.client.submit(evaluate_candidate, shipped, g, weights, pure=False) for g in batch
        ]
        return list(self.client.gather(futures))

    def close(self) -> None:
        """Disconnect from the scheduler (the cluster keeps running)."""
        self.client.close()


def _probe(address: str, timeout: float) -> None:
    """Connect and handshake with a hard deadline.

    `Client` alone can wait forever on a port that accepts TCP but never speaks Dask.
    """
    import asyncio

    from distributed.comm.core import connect

    async def once() -> None:
        comm = await asyncio.wait_for(connect(address, timeout=timeout), timeout)  # type: ignore[no-untyped-call]
        await comm.close()

    asyncio.run(once())


def make_engine(jobs: int, scheduler: str | None) -> Engine:
    """The local thread pool, or Dask when a scheduler address is given."""
    if scheduler:
        return DaskEngine(scheduler)
    return LocalEngine(jobs)
