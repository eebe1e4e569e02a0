"""Who publishes /joint_states in a Gazebo Harmonic launch: the bridge counts, remaps move."""

from __future__ import annotations

from pathlib import Path

from tests.check.ros_packages.workspaces import findings

MANIFEST = (
    "<package format='3'><name>bringup</name>"
    + "".join(
        f"<exec_depend>{d}</exec_depend>"
        for d in (
            "ros_gz_sim",
            "ros_gz_bridge",
            "joint_state_publisher_gui",
            "robot_state_publisher",
        )
    )
    + "</package>\n"
)
# The course's Harmonic variant (a student's arm_gazebo.launch.xml): the bridge brings
# Gazebo's joint states to /joint_states; the display launch's slider GUI is left in.
LAUNCH = """<launch>
  <include file="$(find-pkg-share ros_gz_sim)/launch/gz_sim.launch.py" />
  <node pkg="ros_gz_bridge" exec="parameter_bridge">
    <param name="config_file" value="$(find-pkg-share bringup)/config/bridge.yaml" />
    <param name="use_sim_time" value="true" />
  </node>
  <node pkg="joint_state_publisher_gui" exec="joint_state_publisher_gui"{remap}>
    <param name="use_sim_time" value="true" />
  </node>
</launch>
"""
BRIDGE = """- ros_topic_name: /joint_states
  ros_type_name: sensor_msgs/msg/JointState
  gz_topic_name: /world/empty/model/arm/joint_state
  gz_type_name: gz.msgs.Model
  direction: GZ_TO_ROS
"""


def workspace(root: Path, remap: str = "") -> Path:
    (root / "launch").mkdir(parents=True)
    (root / "config").mkdir()
    (root / "package.xml").write_text(MANIFEST)
    (root / "config" / "bridge.yaml").write_text(BRIDGE)
    (root / "launch" / "arm_gazebo.launch.xml").write_text(LAUNCH.format(remap=remap))
    return root


def test_bridged_joint_states_beside_the_gui(tmp_path: Path) -> None:
    found = [f for f in findings(workspace(tmp_path)) if f.rule.startswith("ros-")]
    assert [(f.rule, f.line, f.values["publisher"]) for f in found] == [
        ("ros-joint-states-twice", 7, "joint_state_publisher_gui")
    ]
    assert "ros_gz_bridge" in found[0].message


def test_a_gui_remapped_elsewhere_is_no_second_publisher(tmp_path: Path) -> None:
    root = workspace(tmp_path, remap="")
    launch = root / "launch" / "arm_gazebo.launch.xml"
    launch.write_text(
        launch.read_text().replace(
            '    <param name="use_sim_time" value="true" />\n  </node>\n</launch>',
            '    <param name="use_sim_time" value="true" />\n'
            '    <remap from="joint_states" to="gui_joint_states" />\n  </node>\n</launch>',
        )
    )
    assert [f.rule for f in findings(root) if f.rule.startswith("ros-")] == []
