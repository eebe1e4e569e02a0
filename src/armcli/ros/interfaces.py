"""Which ros2_control interfaces each ROS target gives a joint: the spec's, else its defaults.

A joint listed under the spec's `ros2_control.joints` gets exactly its interfaces on both
targets. Otherwise: the Humble MoveIt demo commands position (mock hardware) and reports
position and velocity; the Jazzy bringup commands effort within +-the effort limit (the
spec's PD gains close the loop in the JointTrajectoryController) and reports position,
velocity and effort. Joints outside the planning chain only report state.
"""

from __future__ import annotations

from dataclasses import dataclass

from armcli.errors import InputError
from armcli.spec.model import Interface, JointControl, RobotSpec

GAIN_INTERFACES = ("effort", "velocity")  # JTC closes a PID loop on these (gains needed)


@dataclass(frozen=True)
class TargetDefaults:
    """A target's interfaces for joints the spec says nothing about."""

    command: str
    states: tuple[str, ...]
    effort_limits: bool  # an effort command interface carries min/max = -+effort limit


HUMBLE = TargetDefaults("position", ("position", "velocity"), effort_limits=False)
JAZZY = TargetDefaults("effort", ("position", "velocity", "effort"), effort_limits=True)
PASSIVE_STATES = ("position", "velocity")


def commanded(spec: RobotSpec, name: str, d: TargetDefaults) -> JointControl:
    """The interfaces of a commanded joint on a target."""
    given = spec.ros2_control.joints.get(name) if spec.ros2_control else None
    if given is not None and given.command_interfaces:
        return given
    lim = spec.all_joints()[name].limit
    command = Interface()
    if d.command == "effort" and d.effort_limits and lim is not None:
        command = Interface(min=-lim.effort, max=lim.effort)
    states = {s: Interface() for s in d.states}
    return JointControl(command_interfaces={d.command: command}, state_interfaces=states)


def passive(spec: RobotSpec, name: str) -> JointControl:
    """The interfaces of a joint that only reports state (wheels, fingers, mimic followers)."""
    given = spec.ros2_control.joints.get(name) if spec.ros2_control else None
    if given is not None and given.state_interfaces:
        return JointControl(state_interfaces=given.state_interfaces, params=given.params)
    return JointControl(state_interfaces={s: Interface() for s in PASSIVE_STATES})


def trajectory_interface(
    spec: RobotSpec, joints: list[str], d: TargetDefaults, source: str | None = None
) -> str:
    """The command interface the JointTrajectoryController uses: one every joint offers."""
    offered = [list(commanded(spec, j, d).command_interfaces) for j in joints]
    common = [i for i in (offered[0] if offered else [d.command]) if all(i in o for o in offered)]
    if not common:
        raise InputError(
            "the arm joints share no command interface for one JointTrajectoryController: "
            + "; ".join(f"{j}: {', '.join(o)}" for j, o in zip(joints, offered, strict=True)),
            file=source,
            field="ros2_control.joints",
        )
    return common[0]
