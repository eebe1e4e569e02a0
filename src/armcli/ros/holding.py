"""The integral term the Jazzy effort controller needs so the arm holds its named poses.

A PD hold settles gravity / Kp away from its command (analysis.sag); the course arm's
Kp 50 leaves the forearm 0.028 rad low at `reach`, and MoveIt then refuses the next plan
(allowed_start_tolerance 0.01 rad). The spec's gains are what `simulate` and `tune` judge,
so they stay; the JointTrajectoryController gets an integral term on top, only when the
PD gains alone sag more than the start tolerance at some named pose: i chosen a tenth of
the continuous PID loop's Routh bound `i < (Kd + D) Kp / J` (J: the joint's largest
inertia over the poses), so the loop stays well damped, and `i_clamp` the effort limit.
tests/ros/test_holding.py runs the arm under this PID at the controller's rate and checks
that it settles at the pose.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from armcli.analysis.sag import Hold, settle
from armcli.robot.model import Robot
from armcli.ros.srdf import chain_joints
from armcli.spec.model import RobotSpec
from armcli.urdf.read import parse_urdf

START_TOLERANCE = 0.01  # [rad] MoveIt's trajectory_execution.allowed_start_tolerance default
ROUTH_FRACTION = 0.1  # i as a fraction of the PID loop's stability bound (Kd + D) Kp / J


@dataclass(frozen=True)
class Integral:
    """One joint's integral gain [N·m/(rad·s)] and the clamp on its torque [N·m]."""

    i: float
    i_clamp: float


def sag_at_poses(spec: RobotSpec, robot: Robot) -> float:
    """The largest PD sag [rad] over the spec's named poses (0 without poses or gains)."""
    joints = [j for j in chain_joints(spec) if j in spec.control.gains]
    if not joints or not spec.poses:
        return 0.0
    hold = Hold.pd(joints, [spec.control.gains[j].kp for j in joints])
    return max(settle(robot, spec.pose(p), hold).worst[1] for p in spec.poses)


def integral_terms(
    spec: RobotSpec, urdf_xml: bytes, tolerance: float = START_TOLERANCE
) -> Mapping[str, Integral]:
    """Joint -> the integral term to write, for the chain joints; {} when PD alone holds.

    `urdf_xml`: the robot the controller drives. Joints whose spec already has `ki` keep
    it (their clamp: the effort limit).
    """
    robot = Robot.load(parse_urdf(urdf_xml, f"{spec.name}.urdf"), strict=False)
    joints = [j for j in chain_joints(spec) if j in spec.control.gains]
    if sag_at_poses(spec, robot) <= tolerance:
        return {}
    inertia = _largest_inertia(spec, robot, joints)
    out: dict[str, Integral] = {}
    for j in joints:
        g = spec.control.gains[j]
        lim = spec.all_joints()[j].limit
        effort = float(lim.effort) if lim is not None else float(np.inf)
        damping = robot.joint(j).damping
        i = g.ki if g.ki > 0 else ROUTH_FRACTION * (g.kd + damping) * g.kp / inertia[j]
        out[j] = Integral(float(_two_digits(i)), effort)
    return out


def _largest_inertia(spec: RobotSpec, robot: Robot, joints: list[str]) -> dict[str, float]:
    """Each joint's largest diagonal mass-matrix entry [kg·m²] over the named poses."""
    out = {j: 0.0 for j in joints}
    for name in spec.poses:
        M = robot.mass_matrix(robot.q(robot.follow(spec.pose(name))))
        for j in joints:
            k = robot.joint(j).idx_v
            out[j] = max(out[j], float(M[k, k]))
    return out


def _two_digits(x: float) -> float:
    """Rounded down to two significant digits (a gain a user reads)."""
    if x <= 0 or not np.isfinite(x):
        return x
    scale = 10.0 ** (np.floor(np.log10(x)) - 1)
    return float(np.floor(x / scale) * scale)
