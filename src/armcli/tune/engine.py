"""One engine interface: score a batch of candidate gains, locally or on a Dask cluster.

`evaluate_candidate(problem, gains)` is the unit of work. It is a plain module-level
function of picklable arguments, so the thread pool and Dask run exactly the same code
and return bit-identical numbers for the same inputs (same compiled rollout, same
operation order). Backends only decide where it runs:

- `LocalEngine(jobs)`: a thread pool. The compiled rollout is called through ctypes,
  which releases the GIL, so threads run rollouts on separate cores;
- `DaskEngine(address)`: an existing `dask.distributed` scheduler (`dask scheduler` /
  `dask worker`, or dask-jobqueue / dask-kubernetes clusters, which expose the same
  address). The problem is broadcast once; each candidate is one task.

`rollout_cases` is the single place that runs the simulator; moving to a batch rollout
extension means changing that one function.
"""

from __future__ import annotations

from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from armcli.errors import InputError, SimulationError
from armcli.sim.simulate import Arm, SimConfig, SimResult, simulate
from armcli.tune.model_gains import loop_stable
from armcli.tune.objective import METRIC_FIELDS, Weights, run_cost, run_metrics
from armcli.tune.problem import Case, TuneProblem, scored_models

CONNECT_TIMEOUT_S = 3.0  # [s] to reach a Dask scheduler before giving up
DASK_HINT = "pip install 'armcli[dask]' (or: pip install 'dask[distributed]')"


@dataclass(frozen=True, eq=False)
class CandidateEval:
    """Scores of one candidate on every (model, trajectory) pair."""

    feasible: bool
    reason: str  # why infeasible ("" when feasible)
    costs: np.ndarray  # (models, cases) objective J per run; inf where not run
    metrics: np.ndarray  # (models, cases, joints, len(METRIC_FIELDS)); nan where not run


def rollout_cases(arm: Arm, cases: Sequence[Case], cfg: SimConfig) -> list[SimResult | None]:
    """Run every case under `cfg`; None for a run that diverged.

    Today: one `sim.simulate` per case (the compiled rollout when built, else the Python
    loop). The batch rollout extension replaces this body with one call for all cases.
    """
    out: list[SimResult | None] = []
    for case in cases:
        try:
            out.append(simulate(arm, case.reference, case.q0, case.duration, cfg))
        except SimulationError:
            out.append(None)
    return out


def evaluate_candidate(problem: TuneProblem, gains: np.ndarray, weights: Weights) -> CandidateEval:
    """Score gains [kp_1..kp_n, kd_1..kd_n] on every model and case of `problem`."""
    n = len(problem.joints)
    kp, kd = np.asarray(gains[:n], dtype=float), np.asarray(gains[n:], dtype=float)
    models = scored_models(problem)
    shape = (len(models), len(problem.cases))
    costs = np.full(shape, np.inf)
    metrics = np.full((*shape, n, len(METRIC_FIELDS)), np.nan)
    cfg = SimConfig(kp, kd, problem.dt, problem.integrator, problem.gravity_comp, "auto")
    # The nominal model needs the margin; perturbed models stand in for model error, so
    # each only has to be stable at dt itself.
    margin = 1.0 if problem.variants else problem.stability_margin
    h = margin * problem.dt
    for v, sm in enumerate(models):
        if not loop_stable(sm.arm, sm.Ms, kp, kd, problem.loop, h):
            why = f"{problem.loop} loop unstable at {margin:g} x dt"
            return CandidateEval(False, f"model {v}: {why}", costs, metrics)
        for c, res in enumerate(rollout_cases(sm.arm, problem.cases, cfg)):
            if res is None:
                return CandidateEval(False, f"model {v}: diverged on {problem.cases[c].label}",
                                     costs, metrics)  # fmt: skip
            metrics[v, c] = run_metrics(res, problem.cases[c].t_end)
            costs[v, c] = run_cost(metrics[v, c], weights)
    return CandidateEval(True, "", costs, metrics)


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
            raise InputError(f"must be >= 1, got {jobs}", field="--jobs")
        self.jobs = jobs
        self.name = f"local ({jobs} thread{'s' if jobs > 1 else ''})"
        self._pool = ThreadPoolExecutor(jobs) if jobs > 1 else None

    def evaluate(
        self, problem: TuneProblem, batch: Sequence[np.ndarray], weights: Weights
    ) -> list[CandidateEval]:
        """Score `batch` on the threads, results in batch order."""
        if self._pool is None:
            return [evaluate_candidate(problem, g, weights) for g in batch]
        return list(self._pool.map(lambda g: evaluate_candidate(problem, g, weights), batch))

    def close(self) -> None:
        """Stop the threads."""
        if self._pool is not None:
            self._pool.shutdown()


class DaskEngine:
    """Candidates as tasks on an existing dask.distributed scheduler."""

    def __init__(self, address: str, timeout: float = CONNECT_TIMEOUT_S) -> None:
        try:
            from distributed import Client
        except ImportError:
            raise InputError(f"needs dask.distributed: {DASK_HINT}", field="--scheduler") from None
        self.address = address
        try:
            _probe(address, timeout)
            self.client: Any = Client(  # type: ignore[no-untyped-call]
                address, timeout=f"{timeout}s", set_as_default=False
            )
        except ValueError as exc:
            raise InputError(f"not a Dask address: {exc}", field="--scheduler") from None
        except (OSError, TimeoutError) as exc:
            raise InputError(
                f"cannot reach the Dask scheduler at {address} within {timeout:g} s "
                f"({str(exc) or 'no answer'}); start one with `dask scheduler` and "
                "`dask worker ADDRESS`",
                field="--scheduler",
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


def keyed(problem: TuneProblem) -> TuneProblem:
    """`problem` with its content key set (required before shipping it to workers)."""
    return problem if problem.key else problem.with_key()
