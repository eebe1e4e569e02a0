"""What the generated packages depend on (package.xml's <depend>): one table per package.

Humble's lists; jazzy.py adds what its Gazebo and MoveIt launch files import. A table is
a space-separated string, one package per word, so it reads as the list it is.
"""

from __future__ import annotations


def _words(text: str) -> list[str]:
    return text.split()


DESCRIPTION_DEPENDS = _words(
    "ament_index_python joint_state_publisher_gui launch launch_ros "
    "robot_state_publisher rviz2 urdf xacro"
)
BRINGUP_DEPENDS = _words(
    "ament_index_python gazebo_plugins gazebo_ros launch launch_ros "
    "robot_state_publisher rviz2 xacro"
)
MOVEIT_DEPENDS = _words(
    "controller_manager hardware_interface joint_state_broadcaster "
    "joint_trajectory_controller moveit_configs_utils moveit_kinematics "
    "moveit_planners moveit_ros_move_group moveit_ros_visualization "
    "moveit_simple_controller_manager robot_state_publisher rviz2 tf2_ros xacro"
)
