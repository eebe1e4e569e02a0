"""`armcli plan`: a certified collision-free motion between two poses, as a JointTrajectory."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from armcli.commands.flags import flag_errors
from armcli.commands.options import choice, option, seed_option
from armcli.commands.robot_input import robot_options
from armcli.commands.values import Names, Numbers, names, numbers, point
from armcli.defaults import MAX_PLAN_TIMEOUT_S, PLANNERS
from armcli.io.outdir import existing, wrote
from armcli.io.terminal import say, say_line

if TYPE_CHECKING:
    from armcli.plan.api import PlanResult
    from armcli.plan.execute import Execution
    from armcli.urdf.source import RobotInput

FORMATS = ("text", "json")
FROM_HELP = "Start: a named pose (spec poses, SRDF group states) or q1,q2,... [rad]."
TO_HELP = "Goal: a named pose or q1,q2,... [rad] in the order of --joints."
XYZ_HELP = "Goal of the tool point x,y,z [m] in the robot's root frame (inverse kinematics)."
RPY_HELP = (
    "With --to-xyz: the tool link's roll,pitch,yaw [rad] (default: position only < 6 joints)."
)
SCENE_HELP = "Obstacles: YAML shaped like moveit_msgs/PlanningScene world.collision_objects."
SRDF_HELP = "SRDF of a --urdf: its disable_collisions, group_state and group entries."
GROUP_HELP = "Plan the joints of this planning group of --srdf (MoveIt's), e.g. arm."
TIMEOUT_HELP = f"Planning time limit [s], at most {MAX_PLAN_TIMEOUT_S:g}"
EXECUTE_HELP = "Simulate the plan right away; exit 1 if it breaks a limit or tips over."
BASE_HELP = (
    "Also drive the base (a differential drive): where to park for --to-xyz, the path there, "
    "then the arm; -o is then a directory for arm.yaml, cmd_vel.yaml and path.yaml."
)
TOLERANCE_HELP = "With --base --execute: the tool farther from the target [m] fails the run"
BASE_START_HELP = "With --base: where the base stands, x,y,yaw [m, m, rad] (default: 0,0,0)."
FLAGS = {
    "start": "--from",
    "goal": "--to",
    "joints": "--joints",
    "pose": "--from/--to",
    "to-xyz": "--to-xyz",
    "to-rpy": "--to-rpy",
    "to_xyz": "--to-xyz",
    "to_rpy": "--to-rpy",
    "planner": "--planner",
    "group": "--group",
    "srdf": "--srdf",
    "timeout": "--timeout",
    "base": "--base",
    "base_start": "--base-start",
    "execute": "--execute",
    "output": "--output",
}


@flag_errors(FLAGS)
@robot_options("spec")
def plan_cmd(
    robot: RobotInput,
    start: str = option(None, "--from", help=FROM_HELP + " Default: home."),
    goal: str = option(None, "--to", help=TO_HELP),
    to_xyz: Numbers = option(
        None, "--to-xyz", parser=point("--to-xyz"), metavar="X,Y,Z", help=XYZ_HELP
    ),
    to_rpy: Numbers = option(
        None,
        "--to-rpy",
        parser=numbers("--to-rpy", 3, "r,p,y [rad]"),
        metavar="R,P,Y",
        help=RPY_HELP,
    ),
    urdf: Path = option(None, "--urdf", help="Plan for this URDF or xacro file instead of a spec."),
    srdf: Path = option(None, "--srdf", help=SRDF_HELP),
    scene: Path = option(None, "--scene", help=SCENE_HELP),
    joints: Names = option(
        None,
        "--joints",
        parser=names,
        metavar="JOINT,...",
        help="Comma-separated joints to plan (default: arm).",
    ),
    group: str = option(None, "--group", help=GROUP_HELP),
    planner: str = choice(
        "rrtconnect", PLANNERS, "--planner", help="OMPL planner (default: rrtconnect)."
    ),
    timeout: float = option(1.0, "--timeout", help=TIMEOUT_HELP),
    seed: int = seed_option("Random seed: same inputs and seed, same bytes"),
    output: Path = option(None, "--output", "-o", help="JointTrajectory YAML to write."),
    fmt: str = choice("text", FORMATS, "--format", help="Output format (default: text)."),
    execute: bool = option(False, "--execute", help=EXECUTE_HELP),
    base: bool = option(False, "--base", help=BASE_HELP),
    tolerance: float = option(0.02, "--tolerance", help=TOLERANCE_HELP),
    base_start: Numbers = option(
        None,
        "--base-start",
        parser=numbers("--base-start", 3, "x,y,yaw [m, m, rad]"),
        metavar="X,Y,YAW",
        help=BASE_START_HELP,
    ),
) -> None:
    """Plan a collision-free motion, time it within the limits, certify it, write it."""
    from armcli.plan.api import PlanOptions
    from armcli.plan.request import PlanRequest
    from armcli.plan.run import plan

    if base or base_start is not None:
        from armcli.commands.plan_base import plan_base

        plan_base(robot, urdf, scene, start, to_xyz, base_start, planner, timeout, seed, output,
                  fmt, execute, tolerance)  # fmt: skip
        return
    request = PlanRequest(start, goal, to_xyz, to_rpy, srdf, scene, joints or None, group)
    before = existing(output)
    planned = plan(
        robot,
        request,
        PlanOptions(planner, timeout, seed),
        urdf=urdf,
        output=output,
        run=execute,
        warn=_warn,
    )
    result, done = planned.result, planned.executed
    if fmt == "json":
        _json(_summary(result, output, planner, seed, done))
    else:
        written = wrote(output, output in before) if output else None
        _print(result, written, planned.what, planner, seed, done)
    if done is not None and done.broken:
        raise typer.Exit(1)


def _warn(line: str) -> None:
    say_line(f"warning: {line}", sys.stderr)


def _summary(
    r: PlanResult, output: Path | None, planner: str, seed: int, done: Execution | None
) -> dict[str, Any]:
    doc: dict[str, Any] = {
        "status": "planned",
        "planning_time_s": r.planning_time_s,
        "path_time_s": r.path_time_s,
        "certify_time_s": r.certify_time_s,
        "duration_s": r.duration_s,
        "path_length_rad": r.path_length_rad,
        "waypoints": len(r.path),
        "points": len(r.timed.times),
        "joints": list(r.joints),
        "planner": planner,
        "seed": seed,
        "output": str(output) if output is not None else None,
        "notes": list(r.notes),
    }
    if done is not None:
        doc["execute"] = {
            "broken": done.broken,
            "problems": list(done.problems),
            "max_tracking_error_rad": {m.name: m.max_error for m in done.metrics},
            "peak_effort": dict(zip(done.joints, done.peak_effort.tolist(), strict=True)),
            "effort_limit": dict(zip(done.joints, done.effort_limit.tolist(), strict=True)),
            "tip_margin_m": done.tip_margin,
        }
    return doc


def _json(doc: dict[str, Any]) -> None:
    from armcli.io.jsondoc import dumps

    sys.stdout.write(dumps(doc))


def _print(
    r: PlanResult, written: str | None, what: str, planner: str, seed: int, done: Execution | None
) -> None:
    """The summary; `written`: io.outdir.wrote's line, None when there was no -o."""
    lines = [
        f"planned {what} ({planner}, seed {seed})",
        f"  joints: {', '.join(r.joints)}",
        f"  path: {len(r.path)} waypoints, {r.path_length_rad:.4f} rad; "
        f"motion {r.duration_s:.3f} s in {len(r.timed.times)} points",
        f"  planning {r.planning_time_s * 1e3:.1f} ms; certified at 1 kHz "
        f"({r.certify_time_s * 1e3:.0f} ms): limits and collisions",
    ]
    if done is not None:
        lines.append("  executed in simulation:")
        for m, tau, lim in zip(done.metrics, done.peak_effort, done.effort_limit, strict=True):
            lines.append(
                f"    {m.name}: max error {m.max_error:.4f} rad, peak effort {tau:.3g} of {lim:g}"
            )
        if done.tip_margin is not None:
            lines.append(f"    tip-over margin {done.tip_margin * 1e3:.1f} mm")
        lines += [f"    broken: {p}" for p in done.problems]
    lines += [f"  note: {n}" for n in r.notes]
    lines.append(written or "not written: no -o FILE given (the trajectory is only checked)")
    say("\n".join(lines))  # one line each in a log; wrapped at a terminal


def register(app: typer.Typer) -> None:
    """Add the `plan` command to the typer app."""
    app.command("plan")(plan_cmd)
