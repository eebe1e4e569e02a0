"""One broken fixture per package rule: ros-package's own output with one classic mistake.

Each edit is what the issue's threads and the course repositories show going wrong; the
unchanged packages have no package finding at all, and each edited one fails with exactly
its rule, on the file and line that must change, with the fix.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import pytest

from tests.check.ros_packages.workspaces import copy, edit, findings, package_rules

DESC, BRINGUP, MOVEIT = "my_robot_description", "my_robot_bringup", "my_robot_moveit_config"
GZ_LAUNCH = f"{BRINGUP}/launch/my_robot_gz.launch.py"
CLASSIC_LAUNCH = f"{BRINGUP}/launch/my_robot_gazebo.launch.py"
GZ_XACRO = f"{DESC}/urdf/my_robot_gz.urdf.xacro"
CONTROLLERS = f"{BRINGUP}/config/my_robot_controllers.yaml"
SRDF = f"{MOVEIT}/config/my_robot.srdf"


@pytest.mark.parametrize("target", ["jazzy", "classic"])
def test_generated_packages_have_no_package_finding(
    target: str, jazzy_pkgs: Path, classic_pkgs: Path
) -> None:
    found = findings(jazzy_pkgs if target == "jazzy" else classic_pkgs)
    assert package_rules(found) == set(), [f.message for f in found]


def _gui_beside_gazebo(root: Path) -> None:
    """The course's display launch's slider GUI left in the Gazebo launch."""
    edit(root / CLASSIC_LAUNCH, "            IncludeLaunchDescription(",
         '            Node(package="joint_state_publisher_gui", '
         'executable="joint_state_publisher_gui", parameters=[{"use_sim_time": True}]),\n'
         "            IncludeLaunchDescription(")  # fmt: skip
    edit(root / f"{BRINGUP}/package.xml", "<exec_depend>gazebo_plugins</exec_depend>",
         "<exec_depend>gazebo_plugins</exec_depend>\n"
         "  <exec_depend>joint_state_publisher_gui</exec_depend>")  # fmt: skip


def _control_node(root: Path) -> None:
    """ros2_control_node started beside gz_ros2_control (a ros2_control tutorial's launch)."""
    edit(root / GZ_LAUNCH, "            spawn,\n",
         "            spawn,\n            Node(package=\"controller_manager\", "
         "executable=\"ros2_control_node\", parameters=[controllers]),\n")  # fmt: skip


def _separation(root: Path) -> None:
    edit(root / GZ_XACRO, "<wheel_separation>0.45</wheel_separation>",
         "<wheel_separation>0.4</wheel_separation>")  # fmt: skip


def _diameter(root: Path) -> None:
    edit(root / f"{DESC}/urdf/mobile_base_gazebo.xacro", "<wheel_diameter>0.2</wheel_diameter>",
         "<wheel_diameter>0.22</wheel_diameter>")  # fmt: skip


def _typo_joint(root: Path) -> None:
    edit(root / CONTROLLERS, "      - forearm_hand_joint\n", "      - forearm_hand_jont\n")


def _srdf_link(root: Path) -> None:
    edit(root / SRDF, 'tip_link="hand_link"', 'tip_link="hand_lnk"')


def _classic_plugin(root: Path) -> None:
    """A Gazebo classic plugin left in the Harmonic description (the course's arm_gazebo)."""
    edit(root / GZ_XACRO, "</robot>",
         '  <gazebo>\n    <plugin name="joint_state_publisher_controller" '
         'filename="libgazebo_ros_joint_state_publisher.so">\n'
         "      <update_rate>10</update_rate>\n    </plugin>\n  </gazebo>\n</robot>")  # fmt: skip


def _wall_clock(root: Path) -> None:
    edit(root / GZ_LAUNCH, 'parameters=[{"use_sim_time": True}]',
         'parameters=[{"use_sim_time": False}]')  # fmt: skip


def _no_integral(root: Path) -> None:
    """The course gains as they were before issue 41: p 50, i 0 (the arm sags 0.028 rad)."""
    path = root / CONTROLLERS
    text = re.sub(r"(\n\s+i): [0-9.]+", r"\1: 0.0", path.read_text())
    path.write_text(re.sub(r"(\n\s+i_clamp): [0-9.]+", r"\1: 0.0", text))


def _no_depend(root: Path) -> None:
    edit(
        root / f"{BRINGUP}/package.xml", "  <exec_depend>robot_state_publisher</exec_depend>\n", ""
    )


# rule -> (target, edit, the file that must change, the fix's keys)
CASES: dict[str, tuple[str, Callable[[Path], None], str, set[str]]] = {
    "ros-joint-states-twice": ("classic", _gui_beside_gazebo, CLASSIC_LAUNCH, set()),
    "ros-control-node-with-sim": ("jazzy", _control_node, GZ_LAUNCH, set()),
    "ros-wheel-geometry": ("jazzy", _separation, "my_robot_gz.urdf.xacro", {"wheel_separation"}),
    "ros-unknown-joint": ("jazzy", _typo_joint, CONTROLLERS, {"joint"}),
    "ros-srdf-unknown": ("jazzy", _srdf_link, SRDF, {"link"}),
    "ros-classic-plugin": ("jazzy", _classic_plugin, "my_robot_gz.urdf.xacro", set()),
    "ros-sim-time": ("jazzy", _wall_clock, GZ_LAUNCH, {"use_sim_time"}),
    "ros-start-sag": ("jazzy", _no_integral, CONTROLLERS, {"p"}),
    "ros-missing-depend": ("jazzy", _no_depend, f"{BRINGUP}/package.xml", {"exec_depend"}),
}


def test_every_package_rule_has_a_fixture() -> None:
    from armcli.check.rules import RULES

    assert set(CASES) == {r for r in RULES if r.startswith("ros-")}


@pytest.mark.parametrize("rule", sorted(CASES))
def test_fixture_fails_with_exactly_its_rule(
    rule: str, jazzy_pkgs: Path, classic_pkgs: Path, tmp_path: Path
) -> None:
    target, broken, where, fix = CASES[rule]
    root = copy(jazzy_pkgs if target == "jazzy" else classic_pkgs, tmp_path / "ws")
    broken(root)
    found = findings(root)
    assert package_rules(found) == {rule}, [(f.rule, f.message) for f in found]
    mine = [f for f in found if f.rule == rule]
    for f in mine:
        place = f.origin.file if f.origin is not None else f.file
        assert place.endswith(where), (place, where)
        assert f.origin.line if f.origin is not None else f.line, f
        assert set(f.fix) == fix, f.fix
        assert f.hint


def test_wheel_diameter_of_the_classic_plugin(classic_pkgs: Path, tmp_path: Path) -> None:
    root = copy(classic_pkgs, tmp_path / "ws")
    _diameter(root)
    found = [f for f in findings(root) if f.rule == "ros-wheel-geometry"]
    # the plugin's 0.22 m diameter is a 0.11 m radius; the URDF's wheel cylinder is 0.1 m
    assert [f.fix for f in found] == [{"wheel_radius": 0.1}]
    assert found[0].origin is not None and found[0].origin.file.endswith("mobile_base_gazebo.xacro")
