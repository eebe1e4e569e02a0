"""The robot's differential drive as a base plan needs it: the plugin's numbers, the limits.

A spec states it (`mobile_base.diff_drive`, `drive.diffdrive.DriveParams.of`); a URDF
carries it as a Gazebo plugin: gazebo_ros_diff_drive (`wheel_separation`,
`wheel_diameter`, `max_wheel_torque`, `max_wheel_acceleration`, `update_rate`,
`left_joint`, `right_joint`; ROS 1's camelCase names too: `wheelSeparation`, `leftJoint`,
`wheelTorque`, ...) or gz-sim's DiffDrive (`wheel_separation`, `wheel_radius`,
`max_linear_acceleration`). The rim speed limit is the wheel joints' velocity limit when
the URDF gives one, else DEFAULT_SPEED; the rim acceleration is the plugin's limit, else
TORQUE_SHARE of what max_wheel_torque gives the whole robot.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from armcli.drive.diffdrive import DriveParams
from armcli.errors import InputError
from armcli.plan.mobile.basetime import DEFAULT_SPEED, TORQUE_SHARE, DriveLimits
from armcli.plan.mobile.virtual import MobileRobot
from armcli.robot.frames import joint_frame
from armcli.urdf.doc import Urdf

NEEDS_DRIVE = (
    "needs a differential drive (mobile_base.diff_drive in a spec, or a Gazebo diff-drive "
    "plugin in the URDF)"
)
PLUGINS = ("diff_drive", "diffdrive", "diff-drive")  # in a plugin's filename, any case
DEFAULT_RATE = 50.0  # [Hz] a plugin's update rate when it states none
DEFAULT_TORQUE = 20.0  # [N·m] gazebo_ros_diff_drive's max_wheel_torque default
GRAVITY = 9.81  # [m/s²]
TIP_SHARE = 0.5  # of the acceleration that would tip the robot: the most the base plans


def _number(params: Mapping[str, str], *tags: str) -> float | None:
    for tag in tags:
        text = params.get(tag)
        if text is None:
            continue
        try:
            value = float(text)
        except ValueError:
            continue
        if math.isfinite(value):
            return value
    return None


def _plugin(urdf: Urdf) -> DriveParams | None:
    """The first diff-drive plugin of the URDF as DriveParams, None without one."""
    for plugin in urdf.plugins:
        name = (plugin.filename or "").lower() + (plugin.name or "").lower()
        if not any(p in name for p in PLUGINS):
            continue
        p = plugin.params
        separation = _number(p, "wheel_separation", "wheelSeparation")
        diameter = _number(p, "wheel_diameter", "wheelDiameter")
        radius = _number(p, "wheel_radius")
        left = p.get("left_joint") or p.get("leftJoint")
        right = p.get("right_joint") or p.get("rightJoint")
        if separation is None or (diameter is None and radius is None) or not left or not right:
            continue
        return DriveParams(
            left,
            right,
            separation,
            radius if radius is not None else 0.5 * float(diameter or 0),
            _number(p, "max_wheel_torque", "wheelTorque") or DEFAULT_TORQUE,
            _number(p, "max_wheel_acceleration", "max_linear_acceleration", "wheelAcceleration")
            or 0.0,
            _number(p, "update_rate", "updateRate") or DEFAULT_RATE,
            p.get("odometry_frame") or p.get("odometryFrame") or "odom",
            p.get("robot_base_frame") or p.get("robotBaseFrame") or "base_footprint",
        )
    return None


def drive_params(mobile: MobileRobot) -> DriveParams:
    """The robot's diff drive; InputError (field `base`) when it has none."""
    spec = mobile.robot_file.spec
    if spec is not None and spec.mobile_base is not None and spec.mobile_base.diff_drive:
        return DriveParams.of(spec)
    found = _plugin(mobile.robot_file.robot)
    if found is None:
        raise InputError(NEEDS_DRIVE, field="base")
    return found


def drive_limits(
    mobile: MobileRobot, params: DriveParams, travel: np.ndarray | None = None
) -> DriveLimits:
    """Rim speed and acceleration limits, half the track and the command period.

    With the arm's travel configuration, the acceleration also stays under TIP_SHARE of
    the one that would tip the robot: braking or speeding up by a moves the zero-moment
    point a·h/g (h the centre of mass's height) toward an edge, so a <= g·margin/h.
    """
    notes = []
    joints = {j.name: j for j in mobile.robot_file.robot.joints}
    speeds = []
    for name in (params.left_joint, params.right_joint):
        lim = joints[name].limit if name in joints else None
        if lim is not None and lim.velocity and math.isfinite(lim.velocity) and lim.velocity > 0:
            speeds.append(lim.velocity * params.radius)
    speed = min(speeds) if speeds else DEFAULT_SPEED
    if not speeds:
        notes.append(
            f"the wheel joints give no velocity limit: the base drives at most "
            f"{DEFAULT_SPEED:g} m/s"
        )
    accel = params.max_accel
    if accel <= 0:
        mass = mobile.stance.mass if mobile.stance is not None else 0.0
        if mass <= 0:
            raise InputError(
                "the robot has no mass to size the drive's acceleration by", field="base"
            )
        accel = TORQUE_SHARE * 2 * params.max_torque / (params.radius * mass)
        notes.append(
            f"max_wheel_acceleration is 0 (no limit): the base accelerates at "
            f"{accel:.3g} m/s² ({TORQUE_SHARE:g} of what the wheel torque "
            "gives)"
        )
    if travel is not None and mobile.stance is not None:
        from armcli.analysis.balance import MarginAt

        balance = MarginAt(mobile.stance, mobile.arm)
        tip = GRAVITY * max(balance(travel), 0.0) / max(balance.height(travel), 1e-6)
        if TIP_SHARE * tip < accel:
            accel = TIP_SHARE * tip
            notes.append(
                f"the base accelerates at most {accel:.3g} m/s²: {TIP_SHARE:g} of what "
                "would tip it with the arm stowed"
            )
    if accel <= 0:
        raise InputError(
            "the robot would tip over at any acceleration with its arm stowed", field="base"
        )
    return DriveLimits(speed, accel, 0.5 * params.separation, params.period, tuple(notes))


def axle_offset(mobile: MobileRobot, params: DriveParams) -> np.ndarray:
    """(x, y) [m] of the wheels' midpoint in the base frame: the point a diff drive turns about.

    /cmd_vel's twist is this point's, and the plugin's odometry integrates it; a turn in
    place swings the base frame around it when the two differ (the course robot's wheels
    are 0.15 m behind base_footprint).
    """
    robot = mobile.robot.robot
    wheels = []
    for joint in (params.left_joint, params.right_joint):
        frame = joint_frame(robot.model, joint)
        if frame is None:
            raise InputError(
                f"the diff drive's joint {joint!r} is not a joint of the robot", field="base"
            )
        wheels.append(frame)
    arm = mobile.arm_robot()
    rest = [arm.robot.rest(j) for j in arm.joints]
    q = mobile.robot.q(mobile.x((0.0, 0.0, 0.0), rest))
    ends = [robot.frame_pose(f, q)[:2, 3] for f in wheels]  # a joint's frame: its origin
    return np.asarray(0.5 * (ends[0] + ends[1]), dtype=float)


def to_axle(pose: Sequence[float], c: np.ndarray) -> tuple[float, float, float]:
    """The wheels' midpoint pose of a base pose (x, y, yaw)."""
    co, si = math.cos(pose[2]), math.sin(pose[2])
    return (
        float(pose[0] + co * c[0] - si * c[1]),
        float(pose[1] + si * c[0] + co * c[1]),
        float(pose[2]),
    )


def to_base(poses: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Base poses (N, 3) of the wheels' midpoint poses (N, 3)."""
    co, si = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    return np.stack(
        [poses[:, 0] - co * c[0] + si * c[1], poses[:, 1] - si * c[0] - co * c[1], poses[:, 2]],
        axis=1,
    )
