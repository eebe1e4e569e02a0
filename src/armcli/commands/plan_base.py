"""`armcli plan --base`: where to park, the drive there and the arm, written to a directory."""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from armcli.commands.flags import flag_errors
from armcli.errors import InputError, PlanningError
from armcli.io.terminal import say

if TYPE_CHECKING:
    from armcli.plan.mobile.execute import Executed
    from armcli.plan.mobile.virtual import MobileRobot
    from armcli.plan.mobile.whole import WholePlan
    from armcli.urdf.source import RobotInput

FLAGS = {
    "base": "--base",
    "start": "--from",
    "target": "--to-xyz",
    "tolerance": "--tolerance",
    "execute": "--execute",
}
FILES = ("arm.yaml", "cmd_vel.yaml", "path.yaml")
RUN_FILES = ("run.csv", "run.mcap")


def plan_base(
    robot: RobotInput,
    urdf: Path | None,
    scene: Path | None,
    start: str | None,
    to_xyz: tuple[float, ...] | None,
    base_start: tuple[float, ...] | None,
    planner: str,
    timeout: float,
    seed: int,
    output: Path | None,
    fmt: str,
    execute: bool,
    tolerance: float = 0.02,
) -> None:
    """Plan the base and the arm (plan.mobile.whole), write -o DIR's files, print."""
    from armcli.io.outdir import check_output_file
    from armcli.io.scene import require_file
    from armcli.plan.api import PlanOptions
    from armcli.plan.mobile.virtual import load_mobile
    from armcli.plan.mobile.whole import BaseGoal, files, plan_whole

    if to_xyz is None:
        raise InputError("--base plans for a point: give --to-xyz X,Y,Z", field="--to-xyz")
    if execute and output is None:
        raise InputError(
            "--execute with --base writes run.csv and run.mcap: give -o DIR", field="--execute"
        )
    if output is not None:
        for name in FILES + (RUN_FILES if execute else ()):
            check_output_file(output / name, "--output", parents=True)
    if scene is not None:
        require_file(scene)
    robot_file = robot.read(urdf)
    origin = tuple(base_start) if base_start is not None else (0.0, 0.0, 0.0)
    what = f"from {start or 'the start pose'} to xyz {','.join(f'{v:g}' for v in to_xyz)}"
    opts = PlanOptions(
        planner=planner,
        timeout=timeout,
        seed=seed,
        comment=f"armcli plan --base {what}, {planner}, seed {seed}",
    )
    try:
        with flag_errors(FLAGS):
            mobile = load_mobile(robot_file, scene=scene, search=robot.packages)
            if execute:  # refused before planning (nothing written), after "needs a drive"
                _executable(mobile)
            goal = BaseGoal(
                (to_xyz[0], to_xyz[1], to_xyz[2]), (origin[0], origin[1], origin[2]), start
            )
            whole = plan_whole(mobile, goal, opts)
    except PlanningError as exc:
        if fmt == "json":
            _json({"status": "failed", "output": None, "reason": exc.reason})
            raise typer.Exit(1) from None
        raise
    written = files(whole, output, opts.comment) if output is not None else {}
    if written:
        from armcli.io.together import write_files_together

        write_files_together(written, parents=True)
    done = _execute(whole, output, written, tolerance) if execute and output else None
    if fmt == "json":
        doc = document(whole, output, planner, seed)
        if done is not None:
            doc["execute"] = executed(done)
        _json(doc)
    else:
        text = [*lines(whole, what, planner, seed), *(f"wrote {p}" for p in written)]
        if done is not None and output is not None:
            text += executed_lines(done, output)
        say("\n".join(text))
    if done is not None and done.failed:
        raise typer.Exit(1)


def _executable(mobile: MobileRobot) -> None:
    from armcli.plan.mobile.execute import executable
    from armcli.plan.mobile.wheels import drive_params

    drive_params(mobile)
    executable(mobile.robot_file)


def _execute(whole: WholePlan, out: Path, written: dict[Path, bytes], tolerance: float) -> Executed:
    from armcli.io.together import write_files_together
    from armcli.plan.mobile.basefiles import cmd_vel_of
    from armcli.plan.mobile.execute import execute_whole, run_files

    cmd_vel = cmd_vel_of(whole.timing, str(out / "cmd_vel.yaml"))  # as written, not re-read
    done = execute_whole(whole, cmd_vel, written[out / "arm.yaml"], tolerance)
    write_files_together(run_files(whole, done, out), parents=True)
    return done


def executed(done: Executed) -> dict[str, Any]:
    """The execution's JSON fields."""
    return {
        "failed": done.failed,
        "problems": list(done.problems),
        "tool_error_m": done.tool_error,
        "base_error_m": done.base_error[0],
        "base_yaw_error_rad": done.base_error[1],
        "arrived_s": done.arrived,
        "localizer_hz": done.localize,
        "peak_effort": {n: p for n, (p, _) in done.peak_effort.items()},
        "effort_limit": {n: e for n, (_, e) in done.peak_effort.items()},
        "tips": done.verdict.tips,
        "real_time_factor": float(done.run.t[-1] / max(done.run.wall_time, 1e-9)),
    }


def _localised(done: Executed) -> list[str]:
    """Say how the base was followed: the ground-truth fixes stand in for a localiser."""
    if done.localize <= 0:
        return ["  followed on the encoder odometry alone"]
    return [
        f"  followed on the encoder odometry with a {done.localize:g} Hz ground-truth fix "
        "(a stand-in for a localiser such as AMCL)"
    ]


def executed_lines(done: Executed, out: Path) -> list[str]:
    """The execution's text summary."""
    run = done.run
    efforts = ", ".join(f"{n} {p:.3g} of {e:g}" for n, (p, e) in done.peak_effort.items())
    return [
        f"executed on the MuJoCo drive ({run.t[-1]:.2f} s in {run.wall_time:.2f} s): "
        f"tool {done.tool_error * 1e3:.1f} mm from the target (ground truth)",
        *_localised(done),
        f"  base: {done.base_error[0] * 1e3:.1f} mm and "
        f"{math.degrees(done.base_error[1]):.2f}° off its goal; arrived at "
        + (f"{done.arrived:.2f} s" if done.arrived is not None else "never"),
        f"  peak efforts: {efforts}",
        f"  {done.verdict.line()}",
        *(f"  failed: {p}" for p in done.problems),
        f"wrote {out / 'run.csv'}",
        f"wrote {out / 'run.mcap'}",
    ]


def document(w: WholePlan, output: Path | None, planner: str, seed: int) -> dict[str, Any]:
    """`plan`'s JSON fields for the arm's motion, and the base's."""
    r, v = w.arm, w.placement.verdict
    return {
        "status": "planned",
        "planning_time_s": r.planning_time_s,
        "path_time_s": r.path_time_s,
        "certify_time_s": r.certify_time_s + w.base_certify_time_s,
        "duration_s": w.timing.duration + r.duration_s,
        "path_length_rad": r.path_length_rad,
        "waypoints": len(r.path),
        "points": len(r.timed.times) + 1,
        "joints": list(r.joints),
        "planner": planner,
        "seed": seed,
        "output": str(output) if output is not None else None,
        "base_time_s": w.timing.duration,
        "base_path_length_m": w.path.length,
        "base_planning_time_s": w.base_planning_time_s,
        "base": {"x": v.base[0], "y": v.base[1], "yaw": v.base[2]},
        "tool_error_m": v.error,
    }


def lines(w: WholePlan, what: str, planner: str, seed: int) -> list[str]:
    """The text summary."""
    r, v = w.arm, w.placement.verdict
    turns = len(w.path.turns)
    notes = [f"  note: {n}" for n in w.timing.limits.notes]
    return [
        f"planned the base and the arm {what} ({planner}, seed {seed})",
        f"  base: {w.path.length:.3f} m in {len(w.path.legs)} leg(s) and {turns} turn(s), "
        f"{w.timing.duration:.2f} s, to x {v.base[0]:.3f} m, y {v.base[1]:.3f} m, yaw "
        f"{math.degrees(v.base[2]) + 0.0:.1f}° (planned in {w.base_planning_time_s * 1e3:.1f} ms; "
        "checked in 3-D)",
        *notes,
        f"  arm ({', '.join(r.joints)}): path {r.path_length_rad:.4f} rad, {r.duration_s:.3f} s in "
        f"{len(r.timed.times)} points after the base stops (planned in "
        f"{r.planning_time_s * 1e3:.1f} ms; certified at 1 kHz)",
        f"  tool error at the goal {v.error * 1e3:.2f} mm; whole motion "
        f"{w.timing.duration + r.duration_s:.2f} s",
    ]


def _json(doc: dict[str, Any]) -> None:
    from armcli.io.jsondoc import dumps

    sys.stdout.write(dumps(doc))
