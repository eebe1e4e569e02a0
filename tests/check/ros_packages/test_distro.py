"""--distro changes only what differs between the distros: the facts of distro.py, each
from the distribution's own sources (ros2_controllers, control_toolbox, gz_ros2_control)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from armcli.check.ros_packages.distro import TABLE, detect
from tests.check.ros_packages.test_rule_fixtures import CONTROLLERS
from tests.check.ros_packages.workspaces import copy, edit, findings, package_rules


@pytest.mark.parametrize(
    ("distro", "gains", "cap"),
    [
        # Humble: Pid(p, i, d, i_clamp, -i_clamp), i_term clamped; i_clamp defaults to 0
        ("humble", {"i": 5.0}, 0.0),
        ("humble", {"i": 5.0, "i_clamp": 2.0}, 2.0),
        ("humble", {"i": 5.0, "i_clamp_max": 2.0}, 0.0),  # not a Humble parameter
        # Jazzy: i_clamp_max/min when finite, else the deprecated i_clamp (default inf)
        ("jazzy", {"i": 5.0}, math.inf),
        ("jazzy", {"i": 5.0, "i_clamp": 2.0}, 2.0),
        ("jazzy", {"i": 5.0, "i_clamp": 2.0, "i_clamp_max": 3.0, "i_clamp_min": -1.0}, 1.0),
        # Kilted and later: i_clamp is gone (ignored), i_clamp_max/min default to +-inf
        ("kilted", {"i": 5.0, "i_clamp": 2.0}, math.inf),
        ("lyrical", {"i": 5.0, "i_clamp_max": 4.0, "i_clamp_min": -4.0}, 4.0),
        ("jazzy", {"i": 0.0, "i_clamp": 9.0}, 0.0),  # no integral gain, no integral torque
    ],
)
def test_integral_cap_per_distro(distro: str, gains: dict[str, float], cap: float) -> None:
    assert TABLE[distro].integral_cap(gains) == cap


def test_detect_from_plugin_names() -> None:
    assert detect(["libgazebo_ros_diff_drive.so"])[0] == "humble"
    assert detect(["ign_ros2_control-system"])[0] == "humble"
    assert detect(["gz_ros2_control-system", "libgazebo_ros_camera.so"])[0] == "jazzy"
    assert detect(["robot_state_publisher"]) == ("jazzy", "no Gazebo plugin or package names one")


def test_humble_needs_i_clamp_for_the_integral_term(jazzy_pkgs: Path, tmp_path: Path) -> None:
    """Without i_clamp the generated integral term holds on Jazzy (unbounded) but not on
    Humble (clamped to 0): the same file sags there."""
    root = copy(jazzy_pkgs, tmp_path / "ws")
    edit(root / CONTROLLERS, "        i_clamp: 100.0\n", "", count=2)
    assert package_rules(findings(root)) == set()
    assert package_rules(findings(root, distro="kilted")) == set()
    humble = findings(root, distro="humble")
    # ... and Humble's Fortress has no gz_ros2_control: the Jazzy package is for Jazzy
    assert package_rules(humble) == {"ros-start-sag", "ros-classic-plugin"}
    assert all("i_clamp >= " in f.message for f in humble if f.rule == "ros-start-sag")


DIFF_DRIVE = """base_controller:
  ros__parameters:
    left_wheel_names: [base_left_wheel_joint]
    right_wheel_names: [base_right_wheel_joint]
    wheel_separation: 0.45
    wheel_radius: 0.1
    use_stamped_vel: false
"""


def test_twist_or_twiststamped_on_the_diff_drive_controller(
    jazzy_pkgs: Path, tmp_path: Path
) -> None:
    """Humble's controller takes Twist with use_stamped_vel false; from Jazzy on the
    parameter is gone and ~/cmd_vel is TwistStamped only."""
    root = copy(jazzy_pkgs, tmp_path / "ws")
    path = root / CONTROLLERS
    edit(path, "    joint_state_broadcaster:\n",
         "    base_controller:\n      type: diff_drive_controller/DiffDriveController\n"
         "    joint_state_broadcaster:\n")  # fmt: skip
    path.write_text(path.read_text() + DIFF_DRIVE)
    humble = findings(root, distro="humble")
    assert not [f for f in humble if f.rule == "ros-wheel-geometry"]  # right: 0.45 m, 0.1 m
    jazzy = [f for f in findings(root) if f.rule == "ros-wheel-geometry"]
    assert [f.values["parameter"] for f in jazzy] == ["use_stamped_vel"]
    assert "TwistStamped" in jazzy[0].message and jazzy[0].file == str(path)
    assert jazzy[0].line == path.read_text().splitlines().index("    use_stamped_vel: false") + 1
