"""A hand-written workspace in the style of the course's students' repositories.

tests/fixtures/ros_packages/course_ws holds what the course repositories we read show
(XML launch files, a description with Gazebo classic plugins): the slider GUI left in the
Gazebo launch beside the joint-state plugin, no use_sim_time anywhere, the diff-drive's
wheel separation typed as 0.4 while the wheels sit 0.45 m apart, and a bringup
package.xml that forgot what its launch file starts. Each finding, on its file and line.
"""

from __future__ import annotations

from pathlib import Path

from tests.check.ros_packages.workspaces import findings
from tests.helpers import FIXTURES

WS = FIXTURES / "ros_packages" / "course_ws"
LAUNCH = "my_robot_gazebo.launch.xml"


def test_every_course_mistake_on_its_line() -> None:
    got = set()
    for f in findings(WS):
        file, line = (f.origin.file, f.origin.line) if f.origin else (f.file, f.line)
        got.add((f.rule, Path(file).name, line, f.values.get("package") or f.values.get("node")))
    assert got == {
        ("ros-joint-states-twice", LAUNCH, 10, None),  # the GUI node: the one to remove
        ("ros-sim-time", LAUNCH, 4, "robot_state_publisher/robot_state_publisher"),
        ("ros-sim-time", LAUNCH, 10, "joint_state_publisher_gui/joint_state_publisher_gui"),
        ("ros-sim-time", LAUNCH, 11, "rviz2/rviz2"),
        ("ros-wheel-geometry", "my_robot.urdf.xacro", 69, None),  # the plugin, in the xacro
        ("ros-missing-depend", "package.xml", 11, "joint_state_publisher_gui"),
        ("ros-missing-depend", "package.xml", 11, "rviz2"),
        ("ros-missing-depend", "package.xml", 11, "xacro"),
    }


def test_the_wheel_separation_fix_is_the_urdfs() -> None:
    (f,) = [f for f in findings(WS) if f.rule == "ros-wheel-geometry"]
    # the wheel joints sit at y = +-0.225 m along their y axes: 0.45 m apart
    assert f.fix == {"wheel_separation": 0.45}
