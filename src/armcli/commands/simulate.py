"""`armcli simulate`: run the arm along a JointTrajectory under PD control."""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import typer

from armcli.commands.flags import flag_errors, option_flags
from armcli.commands.options import choice, option
from armcli.commands.robot_input import robot_options, write_notes
from armcli.commands.values import Names, Numbers, names, numbers
from armcli.errors import InputError, ModelRefusedError, UnstableLoopError
from armcli.io import terminal
from armcli.io.outdir import existing, wrote
from armcli.io.together import write_files_together
from armcli.sim.options import INTEGRATORS, Integrator, SimOptions

if TYPE_CHECKING:  # the simulator is imported when the command runs: `--help` stays light
    from armcli.sim.armrun import ArmRun
    from armcli.sim.tipping import TipOptions
    from armcli.urdf.source import RobotFile, RobotInput

INTEGRATOR_HELP = "Semi-implicit Euler (default) or RK4."
GRAVITY_HELP = "Add g(q) to the PD torque (default: the spec's control.gravity_compensation)."
IGNORE_HELP = "Simulate the robot despite this `check` rule's error (repeatable)."
TRAJECTORY_HELP = "JointTrajectory YAML (a point without time_from_start: previous + 1 s)."
BASE_ACCEL_HELP = (
    "Base acceleration and braking [m/s²] for the zero-moment point (default: the base at rest)."
)
PAYLOAD_LINK_HELP = "Link carrying --payload at its origin (default: the tool point)."
CONTACT_LINKS_HELP = "Comma-separated links touching the ground (default: from the geometry)."
CMD_VEL_HELP = (
    "Drive the whole robot on its wheels in MuJoCo: /cmd_vel commands YAML (`commands:` "
    "Twist + time_from_start); --trajectory then optional."
)
WORLD_HELP = (
    "Objects in the world (a PlanningScene YAML as plan --scene reads): obstacles of a "
    "--cmd-vel drive; in an arm run, what its sensors see."
)
PROGRESS_AFTER_S = 1.0  # show a progress bar when the run is projected to take longer
# The library's names for what these flags set (errors name them; commands.flags maps back).
FLAGS = {
    **option_flags(SimOptions),
    "SimConfig.dt": "--dt",
    "joints": "--joints",
    "output": "--output",
    "cmd_vel": "--cmd-vel",
    "world": "--world",
    "ignore": "--ignore",
    "plot": "--plot",
}


def _flagged(line: str) -> str:
    """`SimOptions.message ...` as `--message ...`: a line names the flag the user typed."""
    source = line.split(" ", 1)[0]
    return FLAGS.get(source, source) + line[len(source) :]


@flag_errors(FLAGS)
@robot_options("spec")
def simulate_cmd(
    robot: RobotInput,
    trajectory: Path = option(None, "--trajectory", "-t", help=TRAJECTORY_HELP),
    message: str = option(None, "--message", "-m", help="JointTrajectory as YAML text."),
    urdf: Path = option(None, "--urdf", help="Simulate this URDF instead of the spec's arm."),
    joints: Names = option(
        None,
        "--joints",
        parser=names,
        metavar="JOINT,...",
        help="Comma-separated joints to move; others locked.",
    ),
    kp: Numbers = option(
        None,
        "--kp",
        parser=numbers("--kp"),
        metavar="KP,...",
        help="P gain(s): one value or one per joint [N·m/rad].",
    ),
    kd: Numbers = option(
        None,
        "--kd",
        parser=numbers("--kd"),
        metavar="KD,...",
        help="D gain(s): one value or one per joint [N·m·s/rad].",
    ),
    gravity_comp: bool = option(None, "--gravity-comp/--no-gravity-comp", help=GRAVITY_HELP),
    dt: float = option(None, "--dt", help="Time step [s] (default: the spec's control.dt)."),
    integrator: str = choice("euler", INTEGRATORS, "--integrator", help=INTEGRATOR_HELP),
    duration: float = option(None, "--duration", help="Simulated time [s] (default: end + 2 s)."),
    clamp: bool = option(False, "--clamp", help="Clamp positions outside the limits (warns)."),
    output: Path = option(
        None, "--output", "-o", help="Joint states at --rate: .csv, .json or .mcap (rosbag2)."
    ),
    plot: Path = option(None, "--plot", help="Write a tracking plot PNG."),
    rate: float = option(None, "--rate", help="Output rate [Hz] (default: the spec's publisher)."),
    ignore: list[str] = option([], "--ignore", help=IGNORE_HELP),
    base_accel: float = option(None, "--base-accel", help=BASE_ACCEL_HELP),
    payload: float = option(0.0, "--payload", help="Payload [kg] at the tool point (ZMP)."),
    payload_link: str = option(None, "--payload-link", help=PAYLOAD_LINK_HELP),
    contact_links: Names = option(
        None, "--contact-links", parser=names, metavar="LINK,...", help=CONTACT_LINKS_HELP
    ),
    cmd_vel: Path = option(None, "--cmd-vel", help=CMD_VEL_HELP),
    world: Path = option(None, "--world", help=WORLD_HELP),
) -> None:
    """Simulate the arm tracking a trajectory (Pinocchio ABA under PD control)."""
    from armcli.check.gate import require_known
    from armcli.sim.rosbag import check_outputs  # the writers: imported by runs that write
    from armcli.sim.tipping import TipOptions

    require_known(ignore)
    read = [*robot.paths] or ([robot.file()] if urdf is None else [])  # the spec: found first
    if trajectory is None and message is None and cmd_vel is None:
        raise InputError(
            "nothing to simulate: give the arm a trajectory (--trajectory FILE or "
            "--message YAML), or drive the robot's base (--cmd-vel FILE)",
            field="--trajectory",
        )
    read += [p for p in (urdf, trajectory, cmd_vel, world) if p is not None]
    check_outputs(output, plot, read)  # never over an input (issue 42)
    file, spec_path = _robot_file(robot, urdf)
    opts = SimOptions(
        trajectory=trajectory,
        message=message,
        joints=joints or None,
        kp=kp,
        kd=kd,
        gravity_comp=gravity_comp,
        dt=dt,
        integrator=cast(Integrator, integrator),
        duration=duration,
        clamp=clamp,
        rate=rate,
    )
    tip_opts = TipOptions(base_accel, payload, payload_link, contact_links)
    if cmd_vel is not None:
        _drive(file, opts, cmd_vel, world, tuple(ignore), output, plot, tip_opts != TipOptions())
        return
    asked = tip_opts != TipOptions()  # an arm on a fixed base is news only when asked about
    with _LazyProgress(terminal.console(sys.stderr)) as progress:
        run = _simulate(
            file, spec_path, opts, tip_opts, robot, tuple(ignore), progress, plot is not None, world
        )
    _report(run, output, plot, asked)


def _robot_file(robot: RobotInput, urdf: Path | None) -> tuple[RobotFile, Path | None]:
    """The robot file, read once, and the spec's path (None without a spec).

    The spec, or `--urdf`'s file run with the settings of a spec named beside it.
    """
    if urdf is None:
        return robot.read(), robot.file()
    file = robot.read(urdf)
    if robot.path is None:
        return file, None
    from armcli.spec.load import load_spec  # the spec layers: only for a spec

    return file.with_spec(load_spec(robot.path)), robot.path


def _simulate(
    file: RobotFile,
    spec_path: Path | None,
    opts: SimOptions,
    tip_opts: TipOptions,
    robot: RobotInput,
    ignore: tuple[str, ...],
    progress: _LazyProgress,
    plot: bool,
    world: Path | None,
) -> ArmRun:
    """The run, with library refusals told in the command's terms (options, spec fields).

    A model `check` reports as an error is not simulated (same rule ids), unless ignored.
    """
    from armcli.check.gate import bears_on_balance, refuse_check_errors
    from armcli.check.options import CheckOptions
    from armcli.sim.armrun import simulate_arm

    try:
        return simulate_arm(
            file,
            opts,
            tip_opts,
            robot.packages,
            gate=lambda doc: refuse_check_errors(doc, CheckOptions(robot_file=file), ignore=ignore),
            balance_gate=lambda doc: refuse_check_errors(
                doc, CheckOptions(robot_file=file), ignore=ignore, only=bears_on_balance
            ),
            progress=progress,
            plot=plot,
            world=world,
        )
    except ModelRefusedError as exc:
        flags = " ".join(f"--ignore {r}" for r in exc.rules())
        raise ModelRefusedError(
            exc.source, exc.violations, f"simulate it anyway with {flags}"
        ) from None
    except UnstableLoopError as exc:
        raise exc.located(**_sources(spec_path, opts)) from None


def _sources(spec_path: Path | None, opts: SimOptions) -> dict[str, Any]:
    """Where dt and the gains came from: options, or the spec's control fields."""
    fields = ["--dt" if opts.dt is not None else "control.dt"]
    fields += [flag for flag, value in (("--kp", opts.kp), ("--kd", opts.kd)) if value is not None]
    if opts.kp is None or opts.kd is None:
        fields.append("control.gains")
    if spec_path is None:  # no spec: the default dt and the given gains
        fields = [f for f in fields if not f.startswith("control.")]
    from_spec = any(f.startswith("control.") for f in fields)
    return {"file": spec_path if from_spec else None, "field": ", ".join(fields) or None}


def _drive(
    file: RobotFile,
    opts: SimOptions,
    cmd_vel: Path,
    world: Path | None,
    ignore: tuple[str, ...],
    output: Path | None,
    plot: Path | None,
    tip_asked: bool,
) -> None:
    """The whole robot on its wheels (commands.drive); the base-at-rest options do not apply."""
    from armcli.commands.drive import run_drive

    if tip_asked:
        raise InputError(
            "--base-accel, --payload, --payload-link and --contact-links are for the "
            "fixed-base run; a drive simulates the contacts",
            field="--cmd-vel",
        )
    with _LazyProgress(terminal.console(sys.stderr)) as progress:
        run_drive(file, opts, cmd_vel, ignore, output, plot, progress, world)


def _report(run: ArmRun, output: Path | None, plot: Path | None, asked: bool) -> None:
    """Write the files together, print the summary; a run that tips the robot exits 1.

    With a robot standing on a base, its zero-moment point is in the states file, the
    plot's fourth row and the summary. Why there is none is news only when `asked`.
    """
    from armcli.sim import job as simjob
    from armcli.sim import report as simreport

    err = terminal.console(sys.stderr)  # warnings whole in a log, wrapped at a terminal
    job, res, balance = run.job, run.result, run.balance
    write_notes([*run.notes, *(run.balance_notes if asked else ())])
    for w in run.warnings:
        terminal.line(err, f"warning: {_flagged(w)}")
    before = existing(output, plot)
    write_files_together(run.files(output, plot))  # never a new CSV beside an old plot
    metrics = simreport.joint_metrics(res, job.trajectory.duration)
    ee = simjob.tool_position(job, res.q[-1])
    out = terminal.console()
    out.print(simreport.summary_table(metrics, ee, job.tool_label, res), crop=False)
    if balance is not None:
        for note in balance.notes():  # too short to tip the robot: a wheel unloads, a warning
            terminal.line(err, f"warning: {note}")
        terminal.line(out, balance.line(), "red" if balance.tips else None)
    for path in (output, plot):
        if path is not None:
            terminal.line(out, wrote(path, path in before))
    if balance is not None and balance.tips:
        raise balance.error()


class _LazyProgress:
    """A rich progress bar that appears only when the run will take over ~1 s."""

    def __init__(self, console: Any) -> None:
        self.console = console
        self.bar: Any = None
        self.task: Any = None
        self.start: float | None = None  # the first call: the run starts (not its set-up)
        self.first = 0

    def __enter__(self) -> _LazyProgress:
        return self

    def __call__(self, done: int, total: int) -> None:
        if self.start is None:
            self.start, self.first = time.perf_counter(), done
            return
        elapsed = time.perf_counter() - self.start
        rate = elapsed / max(1, done - self.first)
        if self.bar is None and done < total and rate * (total - self.first) > PROGRESS_AFTER_S:
            from rich.progress import Progress

            self.bar = Progress(console=self.console, transient=True)
            self.bar.start()
            self.task = self.bar.add_task("simulating", total=total)
        if self.bar is not None:
            self.bar.update(self.task, completed=done)

    def __exit__(self, *exc: object) -> None:
        if self.bar is not None:
            self.bar.stop()


def register(app: typer.Typer) -> None:
    """Add the `simulate` command to the typer app."""
    app.command("simulate")(simulate_cmd)
