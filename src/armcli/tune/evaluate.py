"""The unit of work: score a chunk of candidate gains on every model and case.

`evaluate_candidates(problem, chunk, weights)` is a module-level function of picklable
arguments, so the thread pool and Dask run exactly the same code and get bit-identical
numbers for the same inputs (same compiled rollout, same operation order); how a batch
is cut into chunks does not change any result, since every rollout is independent.

`rollout_batch` is the single place that runs the simulator: all rollouts of a chunk
(candidates x models x cases) in one `sim.simulate.simulate_batch` call, which hands them
to the compiled engine together.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from armcli.robot.model import Robot
from armcli.sim.simulate import Run, SimConfig, SimResult, simulate_batch, steps_of
from armcli.tune import gains as gain_vector
from armcli.tune.model_gains import loop_stable
from armcli.tune.objective import METRIC_FIELDS, Weights, run_cost, run_metrics
from armcli.tune.problem import Case, TuneProblem, scored_models


@dataclass(frozen=True, eq=False)
class CandidateEval:
    """Scores of one candidate on every (model, trajectory) pair."""

    feasible: bool
    reason: str  # why infeasible ("" when feasible)
    costs: np.ndarray  # (models, cases) objective J per run; inf where not run or diverged
    metrics: np.ndarray  # (models, cases, joints, len(METRIC_FIELDS)); nan likewise


@dataclass(frozen=True, eq=False)
class RolloutJob:
    """One closed-loop run: a robot, a case and the controller settings."""

    robot: Robot
    case: Case
    cfg: SimConfig


def rollout_batch(jobs: Sequence[RolloutJob]) -> list[SimResult | None]:
    """Run every job through the simulator's batch entry point; None for a diverged run.

    Each run keeps the states from its last trajectory point on (what `run_metrics` reads
    beyond the engine's statistics), not every step: the copy out of the engine holds
    the GIL, which the threads of `--jobs` share.
    """
    runs = [
        Run(j.robot, j.case.reference, j.case.q0, j.case.duration, j.cfg, _tail(j.case, j.cfg.dt))
        for j in jobs
    ]
    return [r if isinstance(r, SimResult) else None for r in simulate_batch(runs)]


def _tail(case: Case, dt: float) -> np.ndarray:
    """The steps from the case's last trajectory point to its end."""
    steps = steps_of(case.duration, dt)
    return np.arange(min(round(case.t_end / dt), steps), steps + 1, dtype=np.int64)


def _unstable_reason(problem: TuneProblem, kp: np.ndarray, kd: np.ndarray) -> str:
    """Why the loop is unstable on some model ("" when stable on all).

    The nominal model needs the margin; perturbed models stand in for model error, so
    each only has to be stable at dt itself.
    """
    margin = 1.0 if problem.variants else problem.stability_margin
    for v, sm in enumerate(scored_models(problem)):
        if not loop_stable(sm.robot, sm.lin, kp, kd, problem.loop, margin * problem.dt):
            return f"model {v}: {problem.loop} loop unstable at {margin:g} x dt"
    return ""


def evaluate_candidates(
    problem: TuneProblem, chunk: Sequence[np.ndarray], weights: Weights
) -> list[CandidateEval]:
    """Score gains [kp_1..kp_n, kd_1..kd_n] of each candidate on every model and case."""
    n = len(problem.joints)
    models = scored_models(problem)
    shape = (len(models), len(problem.cases))
    cfgs, reasons, jobs = [], [], []
    for gains in chunk:
        kp, kd = gain_vector.split(gains)
        cfg = SimConfig(kp, kd, problem.dt, problem.integrator, problem.gravity_comp)
        cfgs.append(cfg)
        reasons.append(_unstable_reason(problem, kp, kd))
        if not reasons[-1]:
            jobs += [RolloutJob(sm.robot, case, cfg) for sm in models for case in problem.cases]
    results = iter(rollout_batch(jobs))
    out = []
    for reason in reasons:
        costs = np.full(shape, np.inf)
        metrics = np.full((*shape, n, len(METRIC_FIELDS)), np.nan)
        if not reason:
            for v in range(shape[0]):
                for c, case in enumerate(problem.cases):
                    res = next(results)
                    if res is None:
                        reason = reason or f"model {v}: diverged on {case.label}"
                        continue
                    metrics[v, c] = run_metrics(res, case.t_end)
                    costs[v, c] = run_cost(metrics[v, c], weights)
        out.append(CandidateEval(not reason, reason, costs, metrics))
    return out
