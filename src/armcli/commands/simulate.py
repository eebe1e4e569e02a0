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
from armcli.io.oneline import one_line
from armcli.io.outdir import check_output_file, check_png_file
from armcli.io.together import write_files_together
from armcli.sim.options import INTEGRATORS, Integrator, SimOptions

if TYPE_CHECKING:  # the simulator is imported when the command runs: `--help` stays light
    from armcli.sim import job as simjob
    from armcli.sim import tipping
    from armcli.urdf.source import RobotInput

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
PROGRESS_AFTER_S = 1.0  # show a progress bar when the run is projected to take longer
# The library's names for what these flags set (errors name them; commands.flags maps back).
FLAGS = {
    **option_flags(SimOptions),
    "SimConfig.dt": "--dt",
    "joints": "--joints",
    "output": "--output",
}


def _flagged(line: str) -> str:
    """`SimOptions.message ...` as `--message ...`: a line names the flag the user typed."""
    source = line.split(" ", 1)[0]
    return FLAGS.get(source, source) + line[len(source) :]


def _diagnose(job: Any) -> None:
    """Refuse a reference faster than a velocity limit; warn of efforts below gravity."""
    from armcli.sim.precheck import holding_problems, speed_problems

    fast = speed_problems(job)
    if fast:
        more = f" (and {len(fast) - 1} more joint(s))" if len(fast) > 1 else ""
        raise InputError(_flagged(fast[0]) + more)
    for line in holding_problems(job):
        sys.stderr.write(one_line(f"warning: {_flagged(line)}") + "\n")


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
) -> None:
    """Simulate the arm tracking a trajectory (Pinocchio ABA under PD control)."""
    from armcli.check.rules import unknown_rules
    from armcli.sim import states, tipping
    from armcli.sim.tipping import TipOptions

    unknown = unknown_rules(ignore)
    if unknown:
        raise InputError(f"unknown rule(s) {', '.join(unknown)}", field="--ignore")
    if output is not None:
        from armcli.sim import rosbag  # the MCAP writer: imported by runs that write a file

        if not rosbag.is_mcap(output):
            states.output_format(output)
        check_output_file(output, "--output")
    if plot is not None:
        check_png_file(plot, "--plot")
    spec_path, spec_obj = None, None
    if robot.path is not None or urdf is None:  # the spec layers are imported only for a spec
        from armcli.spec.load import load_spec

        spec_path = robot.file()
        spec_obj = load_spec(spec_path)
    opts = SimOptions(
        trajectory=trajectory,
        message=message,
        urdf=urdf,
        joints=joints or None,
        kp=kp,
        kd=kd,
        gravity_comp=gravity_comp,
        dt=dt,
        integrator=cast(Integrator, integrator),
        duration=duration,
        clamp=clamp,
        rate=rate,
        trust_xacro=robot.trust,
        xacro=robot.xacro,
    )
    tip_opts = TipOptions(base_accel, payload, payload_link, contact_links)
    if cmd_vel is not None:
        _drive(spec_obj, opts, cmd_vel, tuple(ignore), output, plot, tip_opts != TipOptions())
        return
    job = _prepare(spec_obj, spec_path, opts, tuple(ignore))
    _diagnose(job)  # the trajectory's own impossibilities before any simulated verdict
    notes: list[str] = []
    tip = tipping.prepare(spec_obj, job, tip_opts, robot.packages, notes)
    asked = tip_opts != TipOptions()  # an arm on a fixed base is news only when asked about
    _run(job, output, plot, tip, notes if asked else [])


def _prepare(
    spec: Any, spec_path: Path | None, opts: SimOptions, ignore: tuple[str, ...]
) -> simjob.SimJob:
    """The job, with library refusals told in the command's terms (options, spec fields).

    A model `check` reports as an error is not simulated (same rule ids), unless ignored.
    """
    from armcli.check.gate import bears_on_balance, refuse_check_errors
    from armcli.sim import job as simjob

    def gate(doc: Any) -> None:
        refuse_check_errors(doc, ignore=ignore)

    try:
        job = simjob.prepare(spec, opts, gate=gate)
        if spec is not None and opts.urdf is None:  # a spec's whole robot, as `check` sees it
            from armcli.sim.tipping import robot_urdf

            whole = robot_urdf(spec, job)
            if whole is not None and whole is not job.urdf:  # the base: only for the balance
                refuse_check_errors(whole, ignore=ignore, only=bears_on_balance)
            elif whole is not None:
                gate(whole)
        return job
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
    spec: Any, opts: SimOptions, cmd_vel: Path, ignore: tuple[str, ...], output: Path | None,
    plot: Path | None, tip_asked: bool,
) -> None:  # fmt: skip
    """The whole robot on its wheels (commands.drive); the base-at-rest options do not apply."""
    from armcli.commands.drive import run_drive

    if tip_asked:
        raise InputError(
            "--base-accel, --payload, --payload-link and --contact-links are for the "
            "fixed-base run; a drive simulates the contacts",
            field="--cmd-vel",
        )
    with _LazyProgress(terminal.console(sys.stderr)) as progress:
        run_drive(spec, opts, cmd_vel, ignore, output, plot, progress)


def _run(
    job: simjob.SimJob,
    output: Path | None,
    plot: Path | None,
    tip: tipping.Tipping | None = None,
    notes: list[str] | None = None,
) -> None:
    """Run the prepared job with a progress bar, write the files, print the summary.

    With a robot standing on a base (`tip`), also its zero-moment point: in the states
    file, the plot's fourth row and the summary; a run that tips it over exits 1.
    """
    from armcli.sim import job as simjob
    from armcli.sim import report as simreport
    from armcli.sim import states, tipping
    from armcli.sim.plot import tracking_png

    err = terminal.console(sys.stderr)  # warnings whole in a log, wrapped at a terminal
    write_notes([*job.notes, *(notes or [])])
    for w in job.trajectory.warnings:
        err.print(one_line(f"warning: {_flagged(w)}"), markup=False, highlight=False)
    extra = None if tip is None else (lambda steps: tip.steps(job, steps))
    with _LazyProgress(err) as progress:
        res = simjob.run(job, progress, plot=plot is not None, extra=extra)
    series = tip.series(job, res) if tip is not None else None
    metrics = simreport.joint_metrics(res, job.trajectory.duration)
    ee = simjob.tool_position(job, res.q[-1])
    files: dict[Path, bytes] = {}  # written together: never a new CSV beside an old plot
    if output is not None:
        from armcli.sim import rosbag

        if rosbag.is_mcap(output):
            files[output] = rosbag.run_mcap_bytes(res, job.rate, job.urdf)
        else:
            cols = states.sample_states(res, job.rate)
            if series is not None:
                cols = {**cols, **tipping.columns(series, res, job.rate)}
            files[output] = states.states_bytes(cols, states.output_format(output))
    if plot is not None:
        row = tipping.plot_row(series) if series is not None else None
        files[plot] = tracking_png(res, job.arm.effort, row)
    write_files_together(files)
    out = terminal.console()
    out.print(simreport.summary_table(metrics, ee, job.tool_label, res), crop=False)
    balance = tipping.report(tip, series) if tip is not None and series is not None else None
    if balance is not None:
        for lift in balance.lifts:  # too short to tip the robot: a wheel unloads, a warning
            err.print(one_line(f"warning: {lift.line()}"), markup=False, highlight=False)
        line = tipping.summary_line(balance)
        out.print(line, style="red" if balance.tips else None, markup=False, highlight=False)
    for path in (output, plot):
        if path is not None:
            out.print(one_line(f"wrote {path}"), markup=False, highlight=False)
    if balance is not None and balance.tips:
        raise tipping.tip_error(balance)


class _LazyProgress:
    """A rich progress bar that appears only when the run will take over ~1 s."""

    def __init__(self, console: Any) -> None:
        self.console = console
        self.bar: Any = None
        self.task: Any = None
        self.start = time.perf_counter()

    def __enter__(self) -> _LazyProgress:
        return self

    def __call__(self, done: int, total: int) -> None:
        elapsed = time.perf_counter() - self.start
        if self.bar is None and done < total and elapsed / done * total > PROGRESS_AFTER_S:
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
