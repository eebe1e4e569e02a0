"""What differs between the ROS 2 distributions the package rules know.

And which one a package targets when `--distro` does not say (`detect`).

Only facts the rules use, each from the distribution's sources:

- Gazebo: Humble runs Gazebo classic (gazebo_ros) or Ignition Fortress (ros_gz with `ign`
  names: `ign_ros2_control-system`, `ignition-gazebo-*-system`); Jazzy runs Harmonic,
  Kilted Ionic, Lyrical Jetty, all with `gz` names (`gz_ros2_control-system`,
  `gz-sim-*-system`); gazebo_ros (classic) is not released after Humble.
- ros2_control's hardware plugin in Gazebo: `ign_ros2_control/IgnitionSystem` on Humble,
  `gz_ros2_control/GazeboSimSystem` (the `ign_` class name an alias) from Jazzy on.
- diff_drive_controller's `~/cmd_vel`: Humble takes TwistStamped unless
  `use_stamped_vel: false` (then Twist); from Jazzy on TwistStamped only, and
  `use_stamped_vel`, `wheels_per_side`, `has_velocity_limits`, ... are gone
  (ros2_controllers doc/migration, #812, #958, #1315).
- JointTrajectoryController's PID integral clamp: Humble `i_clamp` (default 0: no integral
  action at all), Jazzy `i_clamp_max`/`i_clamp_min` (default unbounded) before the
  deprecated `i_clamp` (default unbounded since the 2025 backport), Kilted and later only
  `i_clamp_max`/`i_clamp_min` (`i_clamp` is ignored; control_toolbox #298).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from armcli.defaults import ROS_DISTROS

DISTROS = ROS_DISTROS
DEFAULT_DISTRO = "jazzy"  # the current LTS, when no plugin or launch names a distro


@dataclass(frozen=True)
class Distro:
    """One ROS 2 distribution's facts for the package rules."""

    name: str
    classic: bool  # Gazebo classic (gazebo_ros) is released
    gz_prefix: str  # "ign" (Fortress) or "gz" (Harmonic and later)
    gz_system: str  # ros2_control's Gazebo hardware class
    stamped_param: bool  # diff_drive_controller has use_stamped_vel (Humble)
    removed_diff_drive: tuple[str, ...]  # diff_drive_controller parameters that no longer exist
    integral_clamp: str  # "i_clamp", "either" or "min_max" (see module doc)

    def integral_cap(self, gains: Mapping[str, object]) -> float:
        """The torque [N·m] a JTC joint's integral term can supply under these gains."""
        i = _num(gains.get("i"), 0.0)
        if i <= 0:
            return 0.0
        lo, hi = _num(gains.get("i_clamp_min"), -math.inf), _num(gains.get("i_clamp_max"), math.inf)
        if self.integral_clamp == "i_clamp":
            return max(_num(gains.get("i_clamp"), 0.0), 0.0)
        if self.integral_clamp == "either" and not (math.isfinite(hi) or math.isfinite(lo)):
            return max(_num(gains.get("i_clamp"), math.inf), 0.0)
        return max(min(hi, -lo), 0.0)  # gravity may pull either way: the weaker side


def _num(x: object, default: float) -> float:
    return float(x) if isinstance(x, int | float) and not isinstance(x, bool) else default


_REMOVED = (
    "use_stamped_vel",
    "wheels_per_side",
    "has_velocity_limits",
    "has_acceleration_limits",
    "has_jerk_limits",
)
TABLE: dict[str, Distro] = {
    "humble": Distro("humble", True, "ign", "ign_ros2_control/IgnitionSystem", True, (), "i_clamp"),
    "jazzy": Distro(
        "jazzy", False, "gz", "gz_ros2_control/GazeboSimSystem", False, _REMOVED, "either"
    ),
    "kilted": Distro(
        "kilted", False, "gz", "gz_ros2_control/GazeboSimSystem", False, _REMOVED, "min_max"
    ),
    "lyrical": Distro(
        "lyrical", False, "gz", "gz_ros2_control/GazeboSimSystem", False, _REMOVED, "min_max"
    ),
}
# Names that only one generation of Gazebo (or of its ROS packages) has.
HUMBLE_EVIDENCE = (
    "libgazebo_ros",
    "gazebo_ros2_control",
    "ign_ros2_control",
    "ignition-gazebo",
    "ignition::gazebo",
    "ros_ign_gazebo",
    "gazebo_ros",
)
JAZZY_EVIDENCE = ("gz_ros2_control", "gz-sim-", "gz::sim::", "libgz-sim")


def detect(names: Iterable[str]) -> tuple[str, str]:
    """(distro, why) from plugin file names, hardware classes and packages a launch uses."""
    seen = list(names)
    humble = next((n for n in seen if any(e in n for e in HUMBLE_EVIDENCE)), None)
    jazzy = next((n for n in seen if any(e in n for e in JAZZY_EVIDENCE)), None)
    if jazzy is not None:
        return "jazzy", f"{jazzy!r} is a Gazebo Harmonic name"
    if humble is not None:
        return "humble", f"{humble!r} is a Gazebo classic / Ignition Fortress name"
    return DEFAULT_DISTRO, "no Gazebo plugin or package names one"
