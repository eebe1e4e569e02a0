"""`ros-unknown-joint`: a joint a controller, `<ros2_control>` or MoveIt names, not the URDF.

Reported with the closest name that exists.

ros2_control refuses to configure a controller whose joint has no interfaces, a
`<ros2_control>` joint the URDF lacks stops the hardware from loading, and MoveIt drops
a controller whose joints it does not know ("no controller handles joint ..."). Each
file is compared with the robot it belongs to: the description whose Gazebo plugin or
launch loads a controllers file, a MoveIt config's own URDF, else (a controllers file
nothing names) the descriptions that share a joint with it.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable
from pathlib import Path

from armcli.check.ros_packages.context import PackageContext
from armcli.check.ros_packages.moveit import MoveItConfig, moveit_controller_joints
from armcli.check.ros_packages.params import Controller
from armcli.urdf.doc import Urdf

RULE = "ros-unknown-joint"
SUBSTITUTION = "$("  # a name a launch substitutes at run time: not literal
# Controller packages whose `joints`/`joint` parameters are URDF joints. Others use the
# word for hardware interfaces that are no joint (picknik's twist_controller: `joint: tcp`).
JOINT_CONTROLLERS = (
    "joint_trajectory_controller",
    "joint_state_broadcaster",
    "diff_drive_controller",
    "forward_command_controller",
    "position_controllers",
    "velocity_controllers",
    "effort_controllers",
    "gripper_controllers",
    "parallel_gripper_action_controller",
    "admittance_controller",
    "tricycle_controller",
)


def did_you_mean(name: str, valid: Iterable[str]) -> str | None:
    """The closest valid name (difflib, 0.6 similarity), or None."""
    close = difflib.get_close_matches(name, sorted(set(valid)), n=1, cutoff=0.6)
    return close[0] if close else None


def _suffix(name: str, valid: Iterable[str]) -> tuple[str, dict[str, str]]:
    guess = did_you_mean(name, valid)
    return (f"; did you mean {guess!r}?", {"joint": guess}) if guess else ("", {})


def check(ctx: PackageContext) -> None:
    """Controllers files, `<ros2_control>` blocks and MoveIt configs, each against its robot."""
    owners = ctx.owners()
    for path, robots in owners.items():
        cf = ctx.controllers(path)
        for c in cf.controllers.values() if cf is not None else ():
            if (c.type or "").split("/")[0] in JOINT_CONTROLLERS:
                _controller(ctx, c, robots)
    for urdf in ctx.robots.values():
        _ros2_control(ctx, urdf)
    for cfg in ctx.moveit:
        _moveit(ctx, cfg)


def _moveit(ctx: PackageContext, cfg: MoveItConfig) -> None:
    """moveit_controllers.yaml, joint_limits.yaml and initial_positions.yaml of a config."""
    robot = ctx.moveit_urdf(cfg)
    if robot is None:
        return
    names = {j.name for j in robot.joints}
    if cfg.controllers is not None and (doc := ctx.yaml(cfg.controllers)) is not None:
        for controller, joint, line in moveit_controller_joints(doc):
            if joint not in names and SUBSTITUTION not in joint:
                what = f"MoveIt controller {controller!r}"
                _report(ctx, cfg.controllers, line, what, joint, robot)
    optional: tuple[tuple[Path | None, str], ...] = (
        (cfg.joint_limits, "joint_limits"),
        (cfg.initial_positions, "initial_positions"),
    )
    for file, key in optional:
        doc = ctx.yaml(file) if file is not None else None
        block = doc.data.get(key) if doc is not None and isinstance(doc.data, dict) else None
        for joint in block if isinstance(block, dict) else {}:
            if joint not in names and SUBSTITUTION not in joint and file and doc:
                _report(ctx, file, doc.line_of((key, joint)), file.name, joint, robot)


def _controller(ctx: PackageContext, c: Controller, robots: list[Urdf]) -> None:
    """A joint is unknown when none of the controller's robots has it."""
    known = {j.name for u in robots for j in u.joints}
    for joint, at in c.joint_entries():
        if joint not in known and SUBSTITUTION not in joint:
            _report(ctx, Path(c.file), c.line(*at), f"controller {c.name!r}", joint, robots[0])


def _ros2_control(ctx: PackageContext, urdf: Urdf) -> None:
    names = {j.name for j in urdf.joints}
    for rc in urdf.ros2_control:
        for joint in rc.commands:
            if joint and joint not in names:
                line = _joint_line(urdf, rc.line, joint)
                hint, fix = _suffix(joint, names)
                ctx.add_in(
                    RULE,
                    urdf,
                    line,
                    f"<ros2_control> {rc.name!r} names joint {joint!r}, which "
                    f"{urdf.name!r} does not have: the hardware will not load{hint}",
                    fix,
                    joint=joint,
                )


def _joint_line(urdf: Urdf, start: int | None, joint: str) -> int | None:
    """The line of `<joint name="joint"` after a `<ros2_control>` element's line."""
    lines = urdf.text.decode("utf-8", "replace").splitlines()
    first = (start or 1) - 1
    for k in range(first, len(lines)):
        if f'name="{joint}"' in lines[k] and "<joint" in lines[k]:
            return k + 1
    return start


def _report(
    ctx: PackageContext, file: Path, line: int | None, what: str, joint: str, robot: Urdf
) -> None:
    hint, fix = _suffix(joint, (j.name for j in robot.joints))
    ctx.add(
        RULE,
        file,
        line,
        f"{what} names joint {joint!r}, which {robot.name!r} ({_short(robot.source)}) "
        f"does not have{hint}",
        fix,
        joint=joint,
    )


def _short(source: str) -> str:
    return source.rsplit("/", 1)[-1]
