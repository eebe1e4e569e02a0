"""A fixed-base run and its balance: what `simulate`, `plan --execute` and `check -t` run.

`simulate_arm` is the library call behind `armcli simulate --trajectory`: prepare the
job (sim.job, the model gate a caller passes), refuse a reference faster than a velocity
limit, set up the whole robot's zero-moment point (sim.tipping), run, and report. The
run itself, with its balance, is `run_balanced`, the one place that keeps the steps the
zero-moment point needs and turns the run into its series and report.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from armcli.errors import InputError
from armcli.io.scene import Scene
from armcli.sim import job as simjob
from armcli.sim import precheck, tipping
from armcli.sim.job import SimJob
from armcli.sim.options import SimOptions
from armcli.sim.sensors.armsense import arm_readings, arm_sensors, sensor_steps
from armcli.sim.sensors.messages import channels as sensor_channels
from armcli.sim.sensors.reading import Reading
from armcli.sim.simulate import SimResult
from armcli.sim.world import load_world
from armcli.urdf.doc import Urdf
from armcli.urdf.meshes import MeshSearch
from armcli.urdf.source import RobotFile

if TYPE_CHECKING:
    from armcli.analysis.stance import Stance
    from armcli.analysis.zmp import ZmpSeries
    from armcli.sim.tipping import Tipping, ZmpReport
    from armcli.spec.sensors import Sensor

Gate = Callable[[Urdf], None]  # refuses a model (ModelRefusedError): check's error rules
Progress = Callable[[int, int], None]


@dataclass(frozen=True)
class ArmRun:
    """A run, and its zero-moment point when the robot stands on a base."""

    job: SimJob
    result: SimResult
    tip: Tipping | None = None
    series: ZmpSeries | None = None
    balance: ZmpReport | None = None
    notes: tuple[str, ...] = ()  # `note: ...` lines: what the job's set-up decided
    balance_notes: tuple[str, ...] = ()  # why there is no zero-moment point (fixed base)
    warnings: tuple[str, ...] = ()  # what the trajectory asks that the arm cannot do
    readings: tuple[Reading, ...] = ()  # the sensors on the arm (sim.sensors.armsense)

    def files(self, output: Path | None, plot: Path | None) -> dict[Path, bytes]:
        """The states file (.csv, .json, .mcap) and the tracking plot, as bytes by path."""
        from armcli.sim import rosbag, states

        files: dict[Path, bytes] = {}
        res, job = self.result, self.job
        if output is not None and rosbag.is_mcap(output):
            files[output] = rosbag.run_mcap_bytes(
                res, job.rate, job.urdf, sensor_channels(self.readings)
            )
        elif output is not None:
            cols = states.sample_states(res, job.rate)
            if self.series is not None:
                cols = {**cols, **tipping.columns(self.series, res, job.rate)}
            files[output] = states.states_bytes(cols, states.output_format(output))
        if plot is not None:
            from armcli.sim.plot import tracking_png  # matplotlib: only for a plot

            row = tipping.plot_row(self.series) if self.series is not None else None
            files[plot] = tracking_png(res, job.robot.effort, row)
        return files


def run_balanced(
    job: SimJob,
    tip: Tipping | None,
    progress: Progress | None = None,
    *,
    plot: bool = False,
    every_step: bool = False,
    also: Callable[[int], np.ndarray] | None = None,
) -> ArmRun:
    """Run `job`, keeping the steps `tip`, `also` (the sensors) and `every_step` need."""

    def keep(steps: int) -> np.ndarray:
        out = np.arange(steps + 1) if every_step else np.zeros(0, dtype=np.int64)
        if also is not None:
            out = np.union1d(out, also(steps))
        return out if tip is None else np.union1d(out, tip.steps(job, steps))

    res = simjob.run(job, progress, plot=plot, extra=keep)
    if tip is None:
        return ArmRun(job, res)
    series = tip.series(job, res)
    return ArmRun(job, res, tip, series, tipping.report(tip, series))


def trajectory_zmp(
    file: RobotFile,
    urdf: Urdf,
    stance: Stance,
    trajectory: Path,
    base_accel: float | None,
    threshold: float,
) -> ZmpReport:
    """Simulate the spec's arm along a trajectory file; the whole robot's zero-moment point.

    What `simulate` reports, for `check --trajectory`. Raises what `sim.job.prepare` raises
    (bad trajectory, gains the integrator refuses) and SimulationError.
    """
    job = simjob.prepare(file, SimOptions(trajectory=trajectory))
    accel, source = tipping.base_acceleration(tipping.TipOptions(base_accel=base_accel), urdf)
    run = run_balanced(job, tipping.Tipping(stance, accel, source, threshold))
    assert run.balance is not None  # a Tipping was given
    return run.balance


def simulate_arm(
    file: RobotFile,
    opts: SimOptions,
    balance: tipping.TipOptions | None = None,
    search: MeshSearch | None = None,
    *,
    gate: Gate | None = None,
    balance_gate: Gate | None = None,
    progress: Progress | None = None,
    plot: bool = False,
    world: Path | Scene | None = None,
) -> ArmRun:
    """Prepare and run `opts` (`file.arm`: the spec's arm or a URDF) with its zero-moment point.

    `gate` refuses the simulated model and, for a spec's arm on a base, the whole robot;
    `balance_gate` refuses the whole robot when only its balance is at stake (the base's
    links are not simulated). InputError (`SimOptions.trajectory`/`message`) for a
    reference faster than a velocity limit; the effort limits gravity exceeds are warnings.
    The spec's sensors on the arm's links are sampled from the run (sim.sensors.armsense),
    among `world`'s objects (seen, not touched).
    """
    job = simjob.prepare(file, opts, gate=gate)
    whole = tipping.whole_robot(file)
    if file.compiled:  # a spec's whole robot, as `check` sees it
        if whole is not job.urdf and balance_gate is not None:
            balance_gate(whole)
        elif gate is not None:
            gate(whole)
    _refuse_too_fast(job, opts)
    notes: list[str] = []
    tip = tipping.prepare(file, job, balance or tipping.TipOptions(), search or MeshSearch(), notes)
    warnings = (*precheck.holding_problems(job), *job.trajectory.warnings)
    sensors, scene = _arm_sensing(file, job, world)
    also = (lambda steps: sensor_steps(sensors, steps, job.config.dt)) if sensors else None
    run = run_balanced(job, tip, progress, plot=plot, also=also)
    readings: tuple[Reading, ...] = ()
    if sensors and job.urdf is not None:
        readings, sensor_notes = arm_readings(job.urdf, run.result, sensors, scene)
        warnings = (*warnings, *sensor_notes)
    return replace(
        run, notes=job.notes, balance_notes=tuple(notes), warnings=warnings, readings=readings
    )


def _arm_sensing(
    file: RobotFile, job: SimJob, world: Path | Scene | None
) -> tuple[dict[str, Sensor], Scene | None]:
    """The spec's sensors the simulated arm carries, and the world they see (read here)."""
    spec = file.spec
    if spec is None or not file.compiled or job.urdf is None:
        return {}, None
    if isinstance(world, Path):
        world = load_world(world, [lk.name for lk in job.urdf.links])
    return arm_sensors(spec.sensors, job.urdf), world


def _refuse_too_fast(job: SimJob, opts: SimOptions) -> None:
    """InputError naming the trajectory: a reference faster than a joint's velocity limit.

    Every later number would be a consequence of the wrong times, not of the robot.
    """
    fast = precheck.speed_problems(job)
    if not fast:
        return
    more = f" (and {len(fast) - 1} more joint(s))" if len(fast) > 1 else ""
    source = job.trajectory.source
    text = fast[0].removeprefix(source).lstrip() + more
    if opts.message is not None:
        raise InputError(text, field="SimOptions.message")
    raise InputError(text, file=source)
