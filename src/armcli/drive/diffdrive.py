"""gazebo_ros_diff_drive (ROS 2), step for step: its wheel controller and encoder odometry.

Controller (`OnUpdate`, every 1/update_rate): the desired rim speeds are
`linear.x -+ angular.z * wheel_separation / 2` (left, right). When
max_wheel_acceleration is 0 (no limit, the plugin's default), or both wheels' rim speeds
are within 0.01 m/s of their targets, both joints are commanded their targets directly
(the ROS 2 branch since gazebo_ros_pkgs PR #1009; ROS 1's plugin takes either wheel,
which lets the other jump to its target mid-ramp); otherwise each wheel's
instructed rim speed moves by `desired - current`, clipped to
±max_wheel_acceleration * (time since the last update). The joint motor holds the
commanded speed with at most max_wheel_torque (ODE's `vel`/`fmax`; here a MuJoCo
clutch, drive.wheelmotor). The plugin's quirks are kept: the instructed
speed accumulates from its previous value rather than from the measured speed, and
the comparison is >= on the left and > on the right.

Odometry (`UpdateOdometryEncoder`, every simulation step, from the joint velocities
at the start of the step): with s_l, s_r the rim distances of the step,
`theta += (s_r - s_l) / b`, position += `(s_l + s_r)/2 * (cos, sin)(theta + (s_r - s_l)/(2b))`;
its twist is `|dx, dy| / dt` (unsigned, as the plugin publishes it) and `dtheta / dt`.
The plugin publishes ground truth by default (`odometry_source` 1); armcli's /odom is
the encoder odometry (`odometry_source` 0), and the states file has the truth beside it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from armcli.errors import InputError

if TYPE_CHECKING:
    from armcli.spec.model import RobotSpec

REACHED = 0.01  # [m/s] the plugin's "target speed reached" band on the rim speed


@dataclass(frozen=True)
class DriveParams:
    """The plugin's parameters, in SI units."""

    left_joint: str
    right_joint: str
    separation: float  # [m]
    radius: float  # [m] wheel_diameter / 2
    max_torque: float  # [N·m]
    max_accel: float  # [m/s²] of the rim speed; 0: none
    update_rate: float  # [Hz]
    odom_frame: str
    base_frame: str

    @property
    def period(self) -> float:
        """[s] between two controller updates."""
        return 1.0 / self.update_rate

    @classmethod
    def of(cls, spec: RobotSpec) -> DriveParams:
        """The spec's `mobile_base.diff_drive`; InputError when it has none."""
        dd = spec.mobile_base.diff_drive if spec.mobile_base is not None else None
        if dd is None:
            raise InputError(
                "the robot has no differential-drive plugin to follow --cmd-vel "
                "(add mobile_base.diff_drive to the spec)",
                field="mobile_base.diff_drive",
            )
        return cls(
            dd.left_joint,
            dd.right_joint,
            float(dd.wheel_separation),
            0.5 * float(dd.wheel_diameter),
            float(dd.max_wheel_torque),
            float(dd.max_wheel_acceleration),
            float(dd.update_rate),
            dd.odometry_frame,
            dd.robot_base_frame,
        )


class DiffDriveController:
    """The plugin's wheel-speed controller: call `update` once per controller period."""

    def __init__(self, params: DriveParams) -> None:
        self.p = params
        self.instructed = np.zeros(2)  # [m/s] left, right: wheel_speed_instr_
        self.command = np.zeros(2)  # [rad/s] the joint speeds last set (SetParam "vel")

    def desired(self, linear_x: float, angular_z: float) -> tuple[float, float]:
        """(left, right) rim speeds [m/s] for a Twist (UpdateWheelVelocities)."""
        half = angular_z * self.p.separation / 2.0
        return linear_x - half, linear_x + half

    def update(
        self, linear_x: float, angular_z: float, wheel_speed: np.ndarray, elapsed: float
    ) -> np.ndarray:
        """Joint speeds [rad/s] (left, right) to hold until the next update.

        `wheel_speed`: the joints' measured speeds [rad/s]; `elapsed`: seconds since the
        last update.
        """
        r = self.p.radius
        left, right = self.desired(linear_x, angular_z)
        cur_l, cur_r = float(wheel_speed[0]) * r, float(wheel_speed[1]) * r
        a = self.p.max_accel * elapsed
        if self.p.max_accel == 0 or (abs(left - cur_l) < REACHED and abs(right - cur_r) < REACHED):
            self.command = np.array([left / r, right / r])
            return self.command
        if left >= cur_l:
            self.instructed[0] += min(left - cur_l, a)
        else:
            self.instructed[0] += max(left - cur_l, -a)
        if right > cur_r:
            self.instructed[1] += min(right - cur_r, a)
        else:
            self.instructed[1] += max(right - cur_r, -a)
        self.command = self.instructed / r
        return self.command


@dataclass(frozen=True)
class Odometry:
    """Encoder odometry after each step: pose in the odometry frame and its twist."""

    x: np.ndarray  # (N + 1,) [m] state k: after k steps
    y: np.ndarray
    yaw: np.ndarray  # [rad], unwrapped
    linear: np.ndarray  # (N + 1,) [m/s] unsigned, as published (0 at the start)
    angular: np.ndarray  # [rad/s]


def encoder_odometry(
    wheel_left: np.ndarray, wheel_right: np.ndarray, dt: float, radius: float, separation: float
) -> Odometry:
    """The plugin's odometry from the joint speeds [rad/s] at the start of every step."""
    sl = np.asarray(wheel_left, dtype=float) * radius * dt
    sr = np.asarray(wheel_right, dtype=float) * radius * dt
    dtheta = (sr - sl) / separation
    theta = np.concatenate([[0.0], np.cumsum(dtheta)])
    heading = theta[:-1] + (sr - sl) / (2.0 * separation)
    dx = (sl + sr) / 2.0 * np.cos(heading)
    dy = (sl + sr) / 2.0 * np.sin(heading)
    x = np.concatenate([[0.0], np.cumsum(dx)])
    y = np.concatenate([[0.0], np.cumsum(dy)])
    v = np.concatenate([[0.0], np.hypot(dx, dy) / dt])
    w = np.concatenate([[0.0], dtheta / dt])
    return Odometry(x, y, theta, v, w)
