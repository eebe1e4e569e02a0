"""`armcli tune` as one library call: the outputs checked, the job, the search, the files.

`tune` refuses an output it could not write before any rollout runs (a search takes
minutes), prepares the job (tune.job: the model-based start gains), runs the seeded
search on the engine asked for (local threads or Dask) and returns the outcome with
the files it makes as bytes by path, for the caller to write together (all new or all
as before). `started` hears the job and the engine's name once the start gains are
known and before the search: the command prints why it starts where it does.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from armcli.errors import InputError
from armcli.io.outdir import check_output_file, check_png_file
from armcli.spec.load import load_spec
from armcli.tune import gains as gain_vector
from armcli.tune import job as tjob
from armcli.tune import report, session
from armcli.tune.engine import make_engine
from armcli.tune.problem import nominal_robot
from armcli.tune.search import SearchOptions, validate
from armcli.tune.write import check_writable, edited_spec
from armcli.urdf.source import RobotFile

Started = Callable[[tjob.TuneJob, str], None]  # the job and the engine's name
Progress = Callable[[int, int], None]  # trials done, trials in all


@dataclass(frozen=True)
class TuneRequest:
    """One tuning: the spec, its trajectories, the settings, where it runs, what it writes."""

    spec: Path
    settings: tjob.TuneSettings
    search: SearchOptions
    trajectories: tuple[Path, ...] = ()  # default: the spec's trajectories/, else its poses
    jobs: int | None = None  # local threads (None: every core)
    scheduler: str | None = None  # a Dask scheduler address instead of local threads
    trust_scheduler: bool = False  # a plain tcp:// scheduler on another host (docs/security.md)
    output: Path | None = None  # the results as JSON
    plot: Path | None = None  # the history and the before/after tracking, PNG
    write: bool = False  # the tuned gains into the spec's control.gains, in place


@dataclass(frozen=True)
class Tuned:
    """A finished tuning: its job, the rows compared, and the files it makes."""

    job: tjob.TuneJob
    outcome: session.Outcome
    engine: str  # the engine's name, as the JSON records it
    damping: np.ndarray  # [N·m·s/rad] the nominal arm's joint damping (the tables' column)
    files: dict[Path, bytes] = field(default_factory=dict)  # written together by the caller


def tune(
    req: TuneRequest, *, started: Started | None = None, progress: Progress | None = None
) -> Tuned:
    """Tune the spec's PD gains as `req` asks; nothing is written here."""
    validate(req.search)
    check_outputs(req)
    file = RobotFile.of_spec(load_spec(req.spec), req.spec)  # compiled once
    job = tjob.prepare(file, list(req.trajectories), req.settings)
    jobs = req.jobs if req.jobs is not None else (os.cpu_count() or 1)
    engine = make_engine(jobs, req.scheduler, trust_scheduler=req.trust_scheduler)
    try:
        if started is not None:
            started(job, engine.name)
        outcome = session.run(job, engine, req.search, progress or (lambda done, total: None))
    finally:
        engine.close()
    damping = nominal_robot(job.problem).damping
    return Tuned(
        job, outcome, engine.name, damping, _files(req, job, outcome, engine.name, damping)
    )


def check_outputs(req: TuneRequest) -> None:
    """Refuse an output that could not be written, before the search (no partial outputs)."""
    if req.output is not None and req.output.suffix.lower() != ".json":
        raise InputError("the output file must end in .json", field="output")
    read = [req.spec, *req.trajectories]  # never written over (issue 42)
    if req.output is not None:
        check_output_file(req.output, "output", read)
    if req.plot is not None:
        check_png_file(req.plot, "plot", read)
    if req.write:
        check_writable(req.spec)


def _files(
    req: TuneRequest, job: tjob.TuneJob, outcome: session.Outcome, engine: str, damping: np.ndarray
) -> dict[Path, bytes]:
    files: dict[Path, bytes] = {}
    if req.output is not None:
        text = report.to_json(
            job.problem, job.start, outcome.rows, outcome.result, req.search, engine, damping
        )
        files[req.output] = text.encode("utf-8")
    if req.plot is not None:
        from armcli.tune.plot import tune_png  # matplotlib: only for a plot

        case = session.showcase_case(job, outcome)
        runs = session.tracking_runs(job, outcome, case)
        files[req.plot] = tune_png(outcome.result.history, runs, job.problem.cases[case].label)
    if req.write:
        best = gain_vector.by_joint(outcome.result.best, job.problem.joints)
        files[req.spec] = edited_spec(req.spec, best)
    return files
