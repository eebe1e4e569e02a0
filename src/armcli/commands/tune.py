"""`armcli tune`: PD gains from the model, refined over rollouts, locally or on Dask."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from armcli.commands.flags import flag_errors, option_flags
from armcli.commands.options import choice, option, seed_option
from armcli.commands.robot_input import robot_options
from armcli.commands.values import Names, Numbers, names, numbers
from armcli.defaults import PD_LOOPS, ROBUST_MODES
from armcli.io import terminal

if TYPE_CHECKING:  # the tuner is imported when the command runs: `--help` stays light
    from armcli.tune import session
    from armcli.tune.api import Tuned
    from armcli.tune.job import TuneJob
    from armcli.urdf.source import RobotInput


TRAJECTORY_HELP = (
    "JointTrajectory YAML (repeatable; default: trajectories/*.yaml next to the spec, "
    "else the named poses as steps)."
)
LOOP_HELP = (
    "Stability bound: implicit (default: armcli's simulator) or explicit (a torque loop "
    "stepped explicitly, e.g. Gazebo's effort controller)."
)
ROBUST_MODE_HELP = "Aggregate over the perturbed models: worst (default) or quantile."
SCHEDULER_HELP = "Dask scheduler address, e.g. tcp://HOST:8786 (needs dask[distributed])."
TRUST_SCHEDULER_HELP = (
    "Allow a plain tcp:// scheduler on another host: the Dask client unpickles what the "
    "cluster sends, so it runs code in armcli (docs/security.md)."
)


def flags() -> dict[str, str]:
    """The library's names for what these flags set (errors name them; commands.flags maps back)."""
    from armcli.tune import job as tjob
    from armcli.tune.search import SearchOptions

    return {
        **option_flags(SearchOptions, robust="--robust-mode"),
        **option_flags(tjob.TuneSettings),
        "jobs": "--jobs",
        "scheduler": "--scheduler",
        "joints": "--joints",
        "trajectories": "--trajectory",
        "output": "--output",
        "plot": "--plot",
    }


@robot_options("spec", xacro=False, packages=False)
def tune_cmd(
    robot: RobotInput,
    trajectory: list[Path] = option(None, "--trajectory", "-t", help=TRAJECTORY_HELP),
    joints: Names = option(
        None,
        "--joints",
        parser=names,
        metavar="JOINT,...",
        help="Comma-separated joints; others locked.",
    ),
    loop: str = choice("implicit", PD_LOOPS, "--loop", help=LOOP_HELP),
    zeta: float = option(1.0, "--zeta", help="Damping ratio of the start gains"),
    wn: float = option(
        None, "--wn", help="Target natural frequency [rad/s] (default: 2π·rate/10)."
    ),
    trials: int = option(60, "--trials", help="Candidates to evaluate (Optuna trials)"),
    batch: int = option(8, "--batch", help="Candidates per batch (the result depends on it)"),
    seed: int = seed_option("Seed of the sampler and of the perturbed models"),
    span: float = option(4.0, "--span", help="Search kp, kd in [start/span, start*span]"),
    settle: float = option(2.0, "--settle", help="Simulated time after the last point [s]"),
    robust: int = option(0, "--robust", help="Score every candidate on N perturbed models"),
    mass_scale: Numbers = option(
        "0.8,1.2",
        "--mass-scale",
        parser=numbers("--mass-scale", 2),
        metavar="LO,HI",
        help="Mass/inertia scale range",
    ),
    friction_scale: Numbers = option(
        "0.5,2",
        "--friction-scale",
        parser=numbers("--friction-scale", 2),
        metavar="LO,HI",
        help="Friction scale range",
    ),
    robust_mode: str = choice("worst", ROBUST_MODES, "--robust-mode", help=ROBUST_MODE_HELP),
    quantile: float = option(0.9, "--quantile", help="Quantile for --robust-mode quantile"),
    jobs: int = option(None, "--jobs", "-j", help="Local threads (default: every core)."),
    scheduler: str = option(None, "--scheduler", help=SCHEDULER_HELP),
    trust_scheduler: bool = option(False, "--trust-scheduler", help=TRUST_SCHEDULER_HELP),
    output: Path = option(None, "--output", "-o", help="Write the results as JSON."),
    plot: Path = option(None, "--plot", help="Write history + before/after tracking PNG."),
    write: bool = option(False, "--write", help="Update control.gains in the spec in place."),
) -> None:
    """Tune PD gains: model-based start, then a seeded search over simulated rollouts."""
    from armcli.tune.api import TuneRequest, tune  # on use: `--help` stays light
    from armcli.tune.job import TuneSettings
    from armcli.tune.search import SearchOptions

    scales = (mass_scale[0], mass_scale[1]), (friction_scale[0], friction_scale[1])
    settings = TuneSettings(joints or None, loop, zeta, wn, settle, robust, *scales, seed)
    search = SearchOptions(trials, batch, seed, span, robust_mode, quantile)
    bar = _Bar(terminal.console(), trials)
    with flag_errors(flags()), bar:
        req = TuneRequest(
            robot.file(),
            settings,
            search,
            tuple(trajectory or ()),
            jobs,
            scheduler,
            trust_scheduler,
            output,
            plot,
            write,
        )
        tuned = tune(req, started=bar.start, progress=bar)
    _report(bar.out, tuned)


class _Bar:
    """The start gains printed, then a progress bar on stderr while the search runs."""

    def __init__(self, out: Any, trials: int) -> None:
        self.out, self.trials = out, trials
        self.bar: Any = None
        self.task: Any = None

    def start(self, job: TuneJob, engine: str) -> None:
        from rich.console import Console
        from rich.progress import Progress

        from armcli.tune import report

        self.out.print(report.reasoning_table(job.start), crop=False)
        self.bar = Progress(console=Console(stderr=True), transient=True)
        self.bar.start()
        self.task = self.bar.add_task(f"tuning on {engine}", total=self.trials)

    def __call__(self, done: int, total: int) -> None:
        if self.bar is not None:
            self.bar.update(self.task, completed=done)

    def __enter__(self) -> _Bar:
        return self

    def __exit__(self, *exc: object) -> None:
        if self.bar is not None:
            self.bar.stop()


def _report(out: Any, tuned: Tuned) -> None:
    """The comparison and the summary; the files written together (all new or as before)."""
    from armcli.io.outdir import existing, wrote
    from armcli.io.together import write_files_together
    from armcli.tune import report

    rows = tuned.outcome.rows
    table = report.comparison_table(tuned.job.problem, tuned.job.start, rows, tuned.damping)
    out.print(table, crop=False)
    _summary(out, tuned.outcome)
    before = existing(*tuned.files)
    write_files_together(tuned.files)
    for path in tuned.files:
        terminal.line(out, wrote(path, path in before))


def _summary(out: Any, outcome: session.Outcome) -> None:
    from armcli.tune import session

    tuned = outcome.row("tuned")
    parts = []
    for row in outcome.rows:
        if row.label != "tuned" and row.nominal.feasible and tuned.nominal.feasible:
            a, b = session.mean_rms(row), session.mean_rms(tuned)
            parts.append(f"{row.label} {a:.4g} -> tuned {b:.4g} rad ({100 * (b - a) / a:+.1f} %)")
    if parts:
        terminal.line(out, "mean RMS error: " + "; ".join(parts))
    if tuned.robust_cost is not None:
        costs = ", ".join(f"{r.label} {r.robust_cost:.4g}" for r in outcome.rows)
        terminal.line(out, f"robust cost over the perturbed models: {costs}")


def register(app: typer.Typer) -> None:
    """Add `tune` to the app."""
    app.command("tune")(tune_cmd)
