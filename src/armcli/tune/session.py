"""One tuning end to end, as a library call: search, then the before/after evaluation.

The command module only parses options, calls `run` and prints; tests call `run` too.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from armcli.sim.simulate import SimConfig, SimResult, simulate
from armcli.tune import gains as gain_vector
from armcli.tune.engine import Engine
from armcli.tune.job import TuneJob
from armcli.tune.problem import nominal_robot
from armcli.tune.report import Row
from armcli.tune.search import SearchOptions, SearchResult, cost_of, nominal, search


@dataclass(frozen=True, eq=False)
class Outcome:
    """The search result and the labelled gain sets evaluated on the nominal model."""

    result: SearchResult
    rows: tuple[Row, ...]  # "spec" (when the spec has gains for every joint), "start", "tuned"

    def row(self, label: str) -> Row:
        """The row labelled `label`."""
        return next(r for r in self.rows if r.label == label)


def run(
    job: TuneJob,
    engine: Engine,
    opts: SearchOptions,
    progress: Callable[[int, int], None] | None = None,
) -> Outcome:
    """Search from the model-based start, then score spec/start/tuned for the report."""
    start = gain_vector.stack(job.start.kp, job.start.kd)
    extra = [job.spec_gains] if job.spec_gains is not None else []
    result = search(job.problem, start, engine, opts, also_try=extra, progress=progress)
    labelled = ([("spec", job.spec_gains)] if job.spec_gains is not None else []) + [
        ("start", start),
        ("tuned", result.best),
    ]
    gains = [g for _, g in labelled]
    nominal_evals = engine.evaluate(nominal(job.problem), gains, opts.weights)
    robust: list[float | None] = [None] * len(gains)
    if job.problem.variants:
        robust = [cost_of(ev, opts) for ev in engine.evaluate(job.problem, gains, opts.weights)]
    rows = tuple(
        Row(label, g, ev, rc)
        for (label, g), ev, rc in zip(labelled, nominal_evals, robust, strict=True)
    )
    return Outcome(result, rows)


def mean_rms(row: Row) -> float:
    """Mean RMS tracking error over joints and trajectories on the nominal model [rad]."""
    return float(np.mean(row.nominal.metrics[0, :, :, 0]))


def showcase_case(job: TuneJob, outcome: Outcome) -> int:
    """The trajectory to plot: where the start gains track worst (the most telling)."""
    costs = outcome.row("start").nominal.costs[0]
    return int(np.argmax(np.where(np.isfinite(costs), costs, -np.inf)))


def tracking_runs(job: TuneJob, outcome: Outcome, case: int) -> list[tuple[str, SimResult]]:
    """Full time series of each gain set on one trajectory (nominal model), for the plot."""
    p = job.problem
    robot = nominal_robot(p)
    c = p.cases[case]
    out = []
    for row in outcome.rows:
        if not row.nominal.feasible:
            continue
        kp, kd = gain_vector.split(row.gains)
        cfg = SimConfig(kp, kd, p.dt, p.integrator, p.gravity_comp)
        out.append((row.label, simulate(robot, c.reference, c.q0, c.duration, cfg)))
    return out
