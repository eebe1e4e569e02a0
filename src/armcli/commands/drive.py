"""`armcli simulate SPEC --cmd-vel drive.yaml`: the whole robot on its wheels (drive.job).

Called by the simulate command; here only what the command prints and writes: the
files together (never a new CSV beside an old plot), the summary, the warnings, and
exit 1 when the robot tips over.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from armcli.errors import ModelRefusedError
from armcli.io import terminal
from armcli.io.outdir import existing, wrote
from armcli.io.together import write_files_together
from armcli.sim.options import SimOptions

if TYPE_CHECKING:
    from armcli.urdf.source import RobotFile


def run_drive(
    file: RobotFile,
    opts: SimOptions,
    cmd_vel: Path,
    ignore: tuple[str, ...],
    output: Path | None,
    plot: Path | None,
    progress: Callable[[int, int], None] | None = None,
    world: Path | None = None,
) -> None:
    """Drive, write and report; raises TipOverError when the robot tips over."""
    from armcli.check.gate import refuse_check_errors
    from armcli.check.options import CheckOptions
    from armcli.drive.api import drive_robot
    from armcli.sim import job as simjob
    from armcli.sim import report as simreport

    try:
        driven = drive_robot(
            file,
            opts,
            cmd_vel,
            progress=progress,
            world=world,
            gate=lambda u: refuse_check_errors(u, CheckOptions(robot_file=file), ignore=ignore),
        )
    except ModelRefusedError as exc:
        flags = " ".join(f"--ignore {r}" for r in exc.rules())
        raise ModelRefusedError(
            exc.source, exc.violations, f"drive it anyway with {flags}"
        ) from None
    err = terminal.console(sys.stderr)
    for w in driven.warnings:
        terminal.line(err, f"warning: {w}")
    before = existing(output, plot)
    write_files_together(driven.files(output, plot))  # never a new CSV beside an old plot
    job, res, res_run, verdict = driven.job, driven.arm, driven.run, driven.verdict
    for note in verdict.notes():
        terminal.line(err, f"warning: {note}")
    out = terminal.console()
    metrics = simreport.joint_metrics(res, job.arm.trajectory.duration)
    ee = simjob.tool_position(job.arm, res.q[-1])
    engine = f"MuJoCo implicitfast ({res.wall_time * 1e6 / max(1, res.steps):.2f} µs/step)"
    out.print(simreport.summary_table(metrics, ee, job.arm.tool_label, res, engine), crop=False)
    o = res_run.odometry
    L = job.model.layout
    end = res_run.sensors[-1, L.base_pos]
    terminal.line(
        out,
        f"base: odometry ({o.x[-1]:.3f}, {o.y[-1]:.3f}) m, yaw {o.yaw[-1]:.3f} "
        f"rad; ground truth ({end[0]:.3f}, {end[1]:.3f}) m",
    )
    terminal.line(out, verdict.line(), "red" if verdict.tips else None)
    for path in (output, plot):
        if path is not None:
            terminal.line(out, wrote(path, path in before))
    if verdict.tips:
        raise verdict.error()
