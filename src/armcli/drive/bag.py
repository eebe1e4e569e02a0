"""A drive run as a rosbag2 MCAP file: sim.rosbag's topics plus the drive's.

/joint_states with the wheels, /odom (nav_msgs/msg/Odometry: the plugin's encoder
odometry at each output time, its covariance), /cmd_vel (geometry_msgs/msg/Twist at each
command's time) and in /tf `odom -> base` plus `world -> odom`: the drift a perfect
localiser would remove, so that `world -> base` is the ground truth (as map -> odom in ROS);
then the sensors' topics (sim.sensors.messages) and, latched, the world's objects on
`/world` (visualization_msgs/msg/MarkerArray, sim.world).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from armcli.drive.job import DriveRun, start_data
from armcli.robot.frames import matrix_quaternion, pose_matrix, yaw_quaternion
from armcli.sim import rosbag
from armcli.sim.sensors.messages import channels as sensor_channels
from armcli.sim.states import TIME, sample_steps
from armcli.sim.world import marker_array

WORLD = rosbag.WORLD
ODOMETRY = "nav_msgs/msg/Odometry"
TWIST = "geometry_msgs/msg/Twist"
ODOM, CMD_VEL = "/odom", "/cmd_vel"
MARKER_ARRAY, WORLD_TOPIC = "visualization_msgs/msg/MarkerArray", "/world"
# the plugin's covariance (x, y, yaw), its defaults; 1e12 for the unobserved z, roll, pitch
COVARIANCE = {0: 1e-5, 7: 1e-5, 14: 1e12, 21: 1e12, 28: 1e12, 35: 1e-3}


def mcap_bytes(
    run: DriveRun,
    cols: dict[str, np.ndarray],
    rate: float,
    more: Sequence[rosbag.Channel] = (),
) -> bytes:
    """The run as rosbag2 MCAP bytes (sim.rosbag's topics plus the drive's, plus `more`)."""
    job = run.job
    wheels = [job.params.left_joint, job.params.right_joint]
    chans = rosbag.channels(cols, [*job.arm.robot.names, *wheels], job.robot)
    stamps = [round(float(t) * 1e9) for t in cols[TIME]]
    extra = _base_transforms(job.params.odom_frame, job.params.base_frame, cols, stamps)
    chans = [
        rosbag.Channel(
            c.topic,
            c.datatype,
            c.qos,
            [
                (ns, {"transforms": [*extra[i], *m["transforms"]]})
                for i, (ns, m) in enumerate(c.messages)
            ],
        )
        if c.topic == rosbag.TF
        else c
        for c in chans
    ]
    k = sample_steps(run.steps, job.dt, rate)
    chans.append(rosbag.Channel(ODOM, ODOMETRY, rosbag.qos(10, False), _odometry(run, k, stamps)))
    chans.append(rosbag.Channel(CMD_VEL, TWIST, rosbag.qos(10, False), _cmd_vel(run)))
    chans += sensor_channels(run.readings)
    if job.model.world:
        data = start_data(job.model, job.arm.q0)
        world = marker_array(job.model.model, data, job.model.world)
        chans.append(
            rosbag.Channel(WORLD_TOPIC, MARKER_ARRAY, rosbag.qos(1, True), [(stamps[0], world)])
        )
    return rosbag.mcap_bytes([*chans, *more])


def _tf(parent: str, child: str, ns: int, xyz: Any, quat: Sequence[float]) -> Any:
    return {
        "header": {"stamp": rosbag.stamp(ns), "frame_id": parent},
        "child_frame_id": child,
        "transform": {
            "translation": dict(zip("xyz", map(float, xyz), strict=True)),
            "rotation": dict(zip("xyzw", map(float, quat), strict=True)),
        },
    }


def _base_transforms(
    odom: str, base: str, cols: dict[str, np.ndarray], stamps: list[int]
) -> list[list[Any]]:
    """Per output time: world -> odom (truth composed with odometry's inverse), odom -> base."""
    out = []
    for i, ns in enumerate(stamps):
        T_odom_base = _pose(
            cols["odom.x"][i], cols["odom.y"][i], 0.0, 0.0, 0.0, cols["odom.yaw"][i]
        )
        T_world_base = _pose(
            *(cols[f"base.{n}"][i] for n in ("x", "y", "z", "roll", "pitch", "yaw"))
        )
        T_world_odom = T_world_base @ np.linalg.inv(T_odom_base)
        out.append(
            [
                _tf(WORLD, odom, ns, T_world_odom[:3, 3], matrix_quaternion(T_world_odom[:3, :3])),
                _tf(odom, base, ns, T_odom_base[:3, 3], yaw_quaternion(float(cols["odom.yaw"][i]))),
            ]
        )
    return out


def _pose(x: float, y: float, z: float, roll: float, pitch: float, yaw: float) -> np.ndarray:
    return pose_matrix((x, y, z), (roll, pitch, yaw))


def _odometry(run: DriveRun, k: np.ndarray, stamps: list[int]) -> list[Any]:
    p, o = run.job.params, run.odometry
    cov = [COVARIANCE.get(i, 0.0) for i in range(36)]
    zero = {"x": 0.0, "y": 0.0, "z": 0.0}
    out = []
    for i, ns in enumerate(stamps):
        j = int(k[i])
        qx, qy, qz, qw = yaw_quaternion(float(o.yaw[j]))
        out.append(
            (
                ns,
                {
                    "header": {"stamp": rosbag.stamp(ns), "frame_id": p.odom_frame},
                    "child_frame_id": p.base_frame,
                    "pose": {
                        "pose": {
                            "position": {"x": float(o.x[j]), "y": float(o.y[j]), "z": 0.0},
                            "orientation": {"x": qx, "y": qy, "z": qz, "w": qw},
                        },
                        "covariance": cov,
                    },
                    "twist": {
                        "twist": {
                            "linear": {**zero, "x": float(o.linear[j])},
                            "angular": {**zero, "z": float(o.angular[j])},
                        },
                        "covariance": cov,
                    },
                },
            )
        )
    return out


def _cmd_vel(run: DriveRun) -> list[Any]:
    cmd, end = run.job.cmd, run.t[-1]
    out = []
    for t, lin, ang in zip(cmd.times, cmd.linear, cmd.angular, strict=True):
        if t <= end:
            out.append(
                (
                    round(float(t) * 1e9),
                    {
                        "linear": dict(zip("xyz", map(float, lin), strict=True)),
                        "angular": dict(zip("xyz", map(float, ang), strict=True)),
                    },
                )
            )
    return out
