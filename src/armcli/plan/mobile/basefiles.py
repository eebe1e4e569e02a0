"""The base plan's files: /cmd_vel commands as `simulate --cmd-vel` reads them, a nav_msgs/Path.

Deterministic text: floats in Python's shortest round-trip repr, times as {sec, nanosec}
(as ROS writes them), no timestamps of the run. The commands are the twist of the wheels'
midpoint, as the plugin reads /cmd_vel; the path's poses are the base frame's (the robot's
`robot_base_frame`), every PATH_PERIOD and at the end of every turn and leg, in the scene's
world frame.
"""

from __future__ import annotations

import json
import math

import numpy as np

from armcli.drive.cmdvel import CmdVel
from armcli.plan.mobile.basetime import BaseTiming
from armcli.plan.mobile.nav2 import FRAME
from armcli.plan.mobile.wheels import to_base

PATH_PERIOD = 0.1  # [s] between two poses of the nav_msgs/Path


def _f(x: float) -> str:
    return repr(float(x) + 0.0)


def _stamp(t: float) -> str:
    sec, nanosec = divmod(round(t * 1e9), 1_000_000_000)
    return f"{{sec: {sec}, nanosec: {nanosec}}}"


def _read_back(t: float) -> float:
    """[s] the time `_stamp(t)` reads back as (trajectory.message's {sec, nanosec} rule)."""
    sec, nanosec = divmod(round(t * 1e9), 1_000_000_000)
    return float(sec) + nanosec * 1e-9


def cmd_vel_yaml(timing: BaseTiming, comment: str = "") -> bytes:
    """The commands: one per plugin period (each held until the next), then a stop."""
    times, lin, ang = timing.commands()
    lines = [f"# {c}" for c in comment.splitlines() if c]
    lines.append("commands:")
    for t, v, w in zip(times, lin, ang, strict=True):
        lines.append(
            f"  - {{linear: {{x: {_f(v)}}}, angular: {{z: {_f(w)}}}, "
            f"time_from_start: {_stamp(float(t))}}}"
        )
    lines.append(
        f"  - {{linear: {{x: 0.0}}, angular: {{z: 0.0}}, "
        f"time_from_start: {_stamp(timing.duration)}}}"
    )
    return ("\n".join(lines) + "\n").encode("utf-8")


def cmd_vel_of(timing: BaseTiming, source: str = "cmd_vel.yaml") -> CmdVel:
    """The commands `cmd_vel_yaml` writes, as `drive.cmdvel.load_cmd_vel` reads them back.

    Value for value (floats round-trip through their repr, times through {sec, nanosec}),
    without writing and parsing the text: `plan --base --execute` runs its own plan.
    """
    times, lin, ang = timing.commands()
    n = len(times)
    linear, angular = np.zeros((n + 1, 3)), np.zeros((n + 1, 3))
    linear[:n, 0] = [float(v) + 0.0 for v in lin]
    angular[:n, 2] = [float(w) + 0.0 for w in ang]
    t = [_read_back(float(x)) for x in times] + [_read_back(timing.duration)]
    return CmdVel(np.array(t, dtype=float), linear, angular, source)


def path_times(timing: BaseTiming) -> np.ndarray:
    """When the path's poses are taken [s]: every PATH_PERIOD and every motion's end."""
    ends = [m.t0 + m.duration for m in timing.motions]
    grid = np.arange(0.0, timing.duration, PATH_PERIOD)
    return np.unique(np.round(np.concatenate([grid, [0.0], ends]), 9))


def path_yaml(timing: BaseTiming, axle: np.ndarray, comment: str = "") -> bytes:
    """nav_msgs/Path of the base frame's planned poses (see the module docstring).

    The timing is the wheels' midpoint's, `axle` (x, y) [m] in the base frame.
    """
    t = path_times(timing)
    poses = to_base(timing.pose_at(t), axle)
    frame = json.dumps(FRAME)
    lines = [f"# {c}" for c in comment.splitlines() if c]
    lines += [f"header: {{frame_id: {frame}}}", "poses:"]
    for tk, (x, y, yaw) in zip(t, poses, strict=True):
        lines += [
            f"  - header: {{frame_id: {frame}, stamp: {_stamp(float(tk))}}}",
            f"    pose: {{position: {{x: {_f(x)}, y: {_f(y)}, z: 0.0}}, orientation: "
            f"{{x: 0.0, y: 0.0, z: {_f(math.sin(yaw / 2))}, w: {_f(math.cos(yaw / 2))}}}}}",
        ]
    return ("\n".join(lines) + "\n").encode("utf-8")
