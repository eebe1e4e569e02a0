"""A drive of the whole robot as one library call: what `simulate --cmd-vel` runs.

`drive_robot` prepares (drive.job: the exported MuJoCo model, the check gate a caller
passes), runs, and turns the run into the arm's `SimResult` and the tip-over verdict;
`Driven.files` gives the states file (.csv, .json, .mcap) and the plot as bytes, for the
caller to write together.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from armcli.analysis.liftoff import TiltVerdict
from armcli.drive import job as drive
from armcli.drive import output as driveout
from armcli.drive.job import DriveJob, DriveRun
from armcli.io.scene import Scene
from armcli.sim.options import SimOptions
from armcli.sim.simulate import SimResult
from armcli.urdf.doc import Urdf
from armcli.urdf.source import RobotFile


@dataclass(frozen=True)
class Driven:
    """A finished drive: the run, the arm's part of it, whether it tipped, what to say."""

    job: DriveJob
    run: DriveRun
    arm: SimResult  # at the output rate and the plot's steps
    verdict: TiltVerdict
    warnings: tuple[str, ...]  # the trajectory's, the commands', the model's

    def files(self, output: Path | None, plot: Path | None) -> dict[Path, bytes]:
        """The states file and the plot, as bytes by path."""
        from armcli.drive import bag as drivebag
        from armcli.sim import rosbag, states

        files: dict[Path, bytes] = {}
        rate = self.job.arm.rate
        if output is not None:
            cols = driveout.columns(self.run, self.arm, rate)
            files[output] = (
                drivebag.mcap_bytes(self.run, cols, rate)
                if rosbag.is_mcap(output)
                else states.states_bytes(cols, states.output_format(output))
            )
        if plot is not None:
            from armcli.drive import plot as driveplot  # matplotlib: only for a plot

            files[plot] = driveplot.plot_png(self.run, self.arm, self.verdict)
        return files


def drive_robot(
    file: RobotFile,
    opts: SimOptions,
    cmd_vel: Path,
    *,
    gate: Callable[[Urdf], None] | None = None,
    progress: Callable[[int, int], None] | None = None,
    world: Path | Scene | None = None,
    sensors: bool = True,
) -> Driven:
    """Drive a spec's whole robot (`file`) by the /cmd_vel commands in `cmd_vel` (drive.job).

    `world`: a scene file (or Scene) of obstacles in the world frame (sim.world);
    `sensors`: simulate the spec's sensors (sim.sensors).
    """
    job = drive.prepare(file, opts, cmd_vel, gate=gate, world=world, sensors=sensors)
    warnings = (*job.arm.trajectory.warnings, *job.cmd.warnings, *job.model.notes)
    run = drive.run(job, progress)
    warnings = (*warnings, *run.notes)
    arm = driveout.arm_result(run, driveout.plot_steps_of(run.steps, job.dt, job.arm.rate))
    return Driven(job, run, arm, driveout.tip_verdict(run), warnings)
