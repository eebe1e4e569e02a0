"""`armcli simulate`: run the arm along a JointTrajectory under PD control."""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Any, cast

import typer

from armcli.check.gate import refuse_check_errors
from armcli.commands.options import choice, option, spec_argument
from armcli.commands.xacro_inputs import (
    args_argument,
    env_option,
    package_dir_option,
    split_robot,
    write_notes,
    xacro_inputs,
)
from armcli.errors import InputError
from armcli.io import terminal
from armcli.io.outdir import check_output_file
from armcli.io.together import write_files_together
from armcli.sim import job as simjob
from armcli.sim import report as simreport
from armcli.sim import rosbag, states
from armcli.sim.options import ENGINES, INTEGRATORS, Engine, Integrator, SimOptions
from armcli.sim.plot import tracking_png
from armcli.spec.discover import find_spec
from armcli.spec.load import load_spec
from armcli.urdf.source import TRUST_XACRO_HELP, UNSANDBOXED_HELP, trust_mode

ENGINE_HELP = "auto (default: compiled when available), native (compiled) or python."
INTEGRATOR_HELP = "Semi-implicit Euler (default) or RK4."
GRAVITY_HELP = "Add g(q) to the PD torque (default: the spec's control.gravity_compensation)."
TRAJECTORY_HELP = "JointTrajectory YAML (a point without time_from_start: previous + 1 s)."
PROGRESS_AFTER_S = 1.0  # show a progress bar when the run is projected to take longer


def _floats(text: str | None, option: str) -> list[float] | None:
    if text is None:
        return None
    try:
        return [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise InputError(f"expected comma-separated numbers, got {text!r}", field=option) from None


def simulate_cmd(
    spec: Path | None = spec_argument(),
    args: list[str] = args_argument(),
    trajectory: Path = option(None, "--trajectory", "-t", help=TRAJECTORY_HELP),
    message: str = option(None, "--message", "-m", help="JointTrajectory as YAML text."),
    urdf: Path = option(None, "--urdf", help="Simulate this URDF instead of the spec's arm."),
    joints: str = option(None, "--joints", help="Comma-separated joints to move; others locked."),
    kp: str = option(None, "--kp", help="P gain(s): one value or one per joint [N·m/rad]."),
    kd: str = option(None, "--kd", help="D gain(s): one value or one per joint [N·m·s/rad]."),
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
    engine: str = choice("auto", ENGINES, "--engine", help=ENGINE_HELP),
    package_dir: list[str] = package_dir_option(),
    env: list[str] = env_option(),
    trust_xacro: bool = option(False, "--trust-xacro", help=TRUST_XACRO_HELP),
    unsandboxed: bool = option(False, "--trust-xacro-unsandboxed", help=UNSANDBOXED_HELP),
) -> None:
    """Simulate the arm tracking a trajectory (Pinocchio ABA under PD control)."""
    spec, tokens = split_robot(spec, args)
    inputs = xacro_inputs(tokens, env, package_dir)
    if output is not None:
        if not rosbag.is_mcap(output):
            states.output_format(output)
        check_output_file(output, "--output")
    if plot is not None:
        check_output_file(plot, "--plot")
    spec_obj = load_spec(find_spec(spec)) if (spec is not None or urdf is None) else None
    kp_values, kd_values = _floats(kp, "--kp"), _floats(kd, "--kd")
    opts = SimOptions(
        trajectory=trajectory,
        message=message,
        urdf=urdf,
        joints=tuple(j.strip() for j in joints.split(",") if j.strip()) if joints else None,
        kp=tuple(kp_values) if kp_values is not None else None,
        kd=tuple(kd_values) if kd_values is not None else None,
        gravity_comp=gravity_comp,
        dt=dt,
        integrator=cast(Integrator, integrator),
        duration=duration,
        clamp=clamp,
        rate=rate,
        engine=cast(Engine, engine),
        trust_xacro=trust_mode(trust_xacro, unsandboxed),
        xacro=inputs,
    )
    # a model `check` reports as an error is not simulated (same rule ids)
    _run(simjob.prepare(spec_obj, opts, gate=refuse_check_errors), output, plot)


def _run(job: simjob.SimJob, output: Path | None, plot: Path | None) -> None:
    """Run the prepared job with a progress bar, write the files, print the summary."""
    err = terminal.console(sys.stderr)  # warnings whole in a log, wrapped at a terminal
    write_notes(job.notes)
    for w in job.trajectory.warnings:
        err.print(f"warning: {w}", markup=False, highlight=False)
    with _LazyProgress(err) as progress:
        res = simjob.run(job, progress)
    if res.notice:
        err.print(f"note: {res.notice}", markup=False, highlight=False, soft_wrap=True)
    metrics = simreport.joint_metrics(res, job.trajectory.duration)
    ee = simjob.tool_position(job, res.q[-1])
    files: dict[Path, bytes] = {}  # written together: never a new CSV beside an old plot
    if output is not None and rosbag.is_mcap(output):
        files[output] = rosbag.run_mcap_bytes(res, job.rate, job.urdf)
    elif output is not None:
        files[output] = states.states_bytes(
            states.sample_states(res, job.rate), states.output_format(output)
        )
    if plot is not None:
        files[plot] = tracking_png(res, job.arm.effort)
    write_files_together(files)
    out = terminal.console()
    out.print(simreport.summary_table(metrics, ee, job.tool_label, res), crop=False)
    for path in (output, plot):
        if path is not None:
            out.print(f"wrote {path}", markup=False, highlight=False)


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
