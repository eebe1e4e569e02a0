"""The Jazzy arm controller's loop at its update rate: ros-package refuses one that diverges.

gz_ros2_control updates the JointTrajectoryController every 1/update_rate and holds its
effort in between (analysis.zoh). `ros-package --target jazzy` writes the spec's gains,
with the integral term of ros/holding.py, at `control.controller_update_rate`; gains made
for the 1 ms physics step diverge at 100 Hz (the course arm: stable for a hold up to 2.41
ms only), and the arm would oscillate or fly apart in Gazebo. So the spec is refused with
`check`'s verdict and remedy (rule ros-controller-unstable), and the README states the
loop's margin. Judged on the robot the controller drives (the whole robot when there is
a base: its free wheels leave the arm the least inertia), over `check`'s joint samples.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from armcli.analysis import pdloop
from armcli.analysis.rate import RateVerdict, message, rate_verdict
from armcli.analysis.zoh import Pid
from armcli.errors import InputError
from armcli.robot import sampling
from armcli.robot.model import Robot
from armcli.ros.holding import Integral, integral_terms
from armcli.ros.interfaces import JAZZY, trajectory_interface
from armcli.ros.srdf import chain_joints
from armcli.spec.model import RobotSpec
from armcli.urdf.read import parse_urdf

RATE_FIELD = "control.controller_update_rate"


def controller_verdict(
    spec: RobotSpec, urdf_xml: bytes, holding: Mapping[str, Integral]
) -> tuple[RateVerdict, list[str], list[tuple[dict[str, float], Any]]] | None:
    """The written controller's loop at the spec's rate, its joints and the samples.

    None when the arm takes no effort (a position or velocity interface) or has no gains.
    """
    joints = chain_joints(spec)
    if trajectory_interface(spec, joints, JAZZY) != "effort":
        return None
    robot = Robot.load(parse_urdf(urdf_xml, f"{spec.name}.urdf"), strict=False)
    names = [j for j in joints if j in spec.control.gains and j in robot.names]
    if not names:
        return None
    gains = [spec.control.gains[j] for j in names]
    pd = pdloop.PD.of(
        [robot.joint(j).idx_v for j in names],
        [g.kp for g in gains],
        [g.kd for g in gains],
        [robot.joint(j).damping for j in names],
    )
    ki = [holding[j].i if j in holding else g.ki for j, g in zip(names, gains, strict=True)]
    samples = sampling.configurations(robot)
    lin = pdloop.linearise(robot, [q for _, q in samples])
    return rate_verdict(lin, Pid.of(pd, ki), spec.control.controller_update_rate), names, samples


@dataclass(frozen=True)
class Control:
    """What the Jazzy controllers YAML and README need beyond the spec."""

    holding: Mapping[str, Integral]  # the integral terms (ros/holding.py)
    rate: RateVerdict | None  # the loop at the update rate (None: the arm takes no effort)


def jazzy_control(spec: RobotSpec, urdf_xml: bytes, source: str | None) -> Control:
    """The integral terms and the loop's verdict; InputError when that loop diverges."""
    holding = integral_terms(spec, urdf_xml)
    judged = controller_verdict(spec, urdf_xml, holding)
    if judged is None:
        return Control(holding, None)
    v, names, samples = judged
    if not v.stable:
        at = samples[v.worst][0]
        text = message(
            v,
            names,
            [at[j] for j in names],
            what="the arm controller",
            rate_name=RATE_FIELD,
            gain_names=("kp", "kd", "ki"),
        )
        raise InputError(text, file=source, field=RATE_FIELD)
    return Control(holding, v)
