"""Refinement over rollouts: seeded Optuna (TPE) in log space around the start gains.

Candidates are asked in fixed-size batches, scored through an `Engine`, and told back in
batch order, so for a given seed and batch size the sampler sees the same history
whichever backend scored them: the result is identical on threads or on Dask.

The search box is [start / span, start * span] per gain, widened to hold the spec's
current gains. The first trial is the model-based start and the second the spec's gains
(when all are > 0), so the result is never worse (by the objective) than either.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from armcli.defaults import ROBUST_MODES
from armcli.errors import InputError
from armcli.tune import gains as gain_vector
from armcli.tune.engine import Engine
from armcli.tune.evaluate import CandidateEval
from armcli.tune.objective import Weights, aggregate
from armcli.tune.problem import TuneProblem

ROUND_DIGITS = 4  # significant digits of the reported (and written) gains


@dataclass(frozen=True)
class SearchOptions:
    """How the search runs; `robust` is "worst" or "quantile" over the perturbed models."""

    trials: int = 60
    batch: int = 8
    seed: int = 0
    span: float = 4.0
    robust: str = "worst"
    quantile: float = 0.9
    weights: Weights = field(default_factory=Weights)


@dataclass(frozen=True, eq=False)
class TrialRecord:
    """One scored candidate, in the order Optuna asked for it."""

    number: int
    gains: np.ndarray  # [kp..., kd...]
    cost: float
    feasible: bool
    reason: str


@dataclass(frozen=True, eq=False)
class SearchResult:
    """The best candidate (rounded to ROUND_DIGITS) and the whole history."""

    best: np.ndarray  # [kp..., kd...]
    best_cost: float  # cost of the rounded best
    history: tuple[TrialRecord, ...]


def validate(opts: SearchOptions) -> None:
    """InputError for options no search can run with."""
    if opts.trials < 1:
        raise InputError(f"must be >= 1, got {opts.trials}", field="SearchOptions.trials")
    if opts.batch < 1:
        raise InputError(f"must be >= 1, got {opts.batch}", field="SearchOptions.batch")
    if not (math.isfinite(opts.span) and opts.span > 1.0):
        raise InputError(f"must be > 1, got {opts.span:g}", field="SearchOptions.span")
    if opts.robust not in ROBUST_MODES:
        raise InputError(
            f"unknown {opts.robust!r}; valid: worst, quantile", field="SearchOptions.robust"
        )
    if not 0.0 <= opts.quantile <= 1.0:
        raise InputError(
            f"must be in [0, 1], got {opts.quantile:g}", field="SearchOptions.quantile"
        )


def round_sig(x: np.ndarray, digits: int = ROUND_DIGITS) -> np.ndarray:
    """Round to `digits` significant digits (the precision gains are written with)."""
    return np.array([float(f"{v:.{digits}g}") for v in np.asarray(x, dtype=float)])


def cost_of(ev: CandidateEval, opts: SearchOptions) -> float:
    """The scalar the sampler minimises for one evaluation."""
    return aggregate(ev.costs, ev.feasible, opts.robust, opts.quantile)


def search(
    problem: TuneProblem,
    start: np.ndarray,
    engine: Engine,
    opts: SearchOptions,
    *,
    also_try: Sequence[np.ndarray] = (),
    progress: Callable[[int, int], None] | None = None,
) -> SearchResult:
    """Minimise the objective over gains [kp..., kd...] starting from `start`."""
    import optuna

    validate(opts)
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    names = gain_vector.param_names(problem.joints)
    lo, hi = start / opts.span, start * opts.span
    for g in also_try:  # widen the box to hold the user's gains (when all are > 0)
        if np.all(g > 0):
            lo, hi = np.minimum(lo, g), np.maximum(hi, g)
    dists: dict[str, optuna.distributions.BaseDistribution] = {
        nm: optuna.distributions.FloatDistribution(float(a), float(b), log=True)
        for nm, a, b in zip(names, lo, hi, strict=True)
    }
    study = optuna.create_study(sampler=optuna.samplers.TPESampler(seed=opts.seed))
    for g in (start, *also_try):
        if np.all(g >= lo) and np.all(g <= hi):
            study.enqueue_trial(dict(zip(names, map(float, g), strict=True)))
    history: list[TrialRecord] = []
    while len(history) < opts.trials:
        k = min(opts.batch, opts.trials - len(history))
        trials = [study.ask(dists) for _ in range(k)]
        batch = [np.array([t.params[nm] for nm in names]) for t in trials]
        for t, g, ev in zip(
            trials, batch, engine.evaluate(problem, batch, opts.weights), strict=True
        ):
            cost = cost_of(ev, opts)
            study.tell(t, cost)
            history.append(TrialRecord(t.number, g, cost, ev.feasible, ev.reason))
        if progress is not None:
            progress(len(history), opts.trials)
    best = min(history, key=lambda r: (r.cost, r.number))
    rounded = round_sig(best.gains)
    ev = engine.evaluate(problem, [rounded], opts.weights)[0]
    return SearchResult(rounded, cost_of(ev, opts), tuple(history))


def nominal(problem: TuneProblem) -> TuneProblem:
    """The same problem on the unperturbed model only (for the before/after report)."""
    return replace(problem, variants=(), key="").with_key()
