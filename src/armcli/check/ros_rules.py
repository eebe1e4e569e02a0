"""The rules of `check DIR` over ROS 2 packages (check/ros_packages/), for the registry.

Kept apart from check/rules.py (the registry, which lists them between the model's rules
and `input-unusable`) so that neither table outgrows a module. `ros-controller-unstable`
is also reported on a spec: its `control.controller_update_rate` and gains are the ones
`ros-package --target jazzy` writes into the controllers YAML.
"""

from __future__ import annotations

from armcli.check.rule import ERROR, WARNING, Rule

ROS_RULES = [
    Rule(
        "ros-joint-states-twice",
        ERROR,
        "more than one publisher of /joint_states in one launch (joint_state_publisher[_gui] "
        "beside a joint_state_broadcaster spawner or Gazebo's joint-state plugin)",
        "remove the extra publisher (the message says which one stays)",
    ),
    Rule(
        "ros-control-node-with-sim",
        ERROR,
        "ros2_control_node launched for a robot whose <ros2_control> hardware is a simulator's "
        "system (gz_ros2_control, gazebo_ros2_control), which runs its own controller manager",
        "remove the ros2_control_node; spawn the controllers on the simulator's controller manager",
    ),
    Rule(
        "ros-wheel-geometry",
        ERROR,
        "diff-drive wheel separation or radius (plugin or controller YAML) more than 1 % from "
        "the URDF's wheels, or a diff_drive_controller parameter the distro no longer has",
        "write the URDF's value (in the message)",
    ),
    Rule(
        "ros-unknown-joint",
        ERROR,
        "a controller, <ros2_control> block or MoveIt YAML names a joint the URDF lacks",
        "use the URDF's joint name (the message suggests the closest)",
    ),
    Rule(
        "ros-srdf-unknown",
        ERROR,
        "an SRDF group, chain, end effector, group state, passive joint or collision entry "
        "names a joint, link or group the robot lacks",
        "use the URDF's name (the message suggests the closest)",
    ),
    Rule(
        "ros-classic-plugin",
        ERROR,
        "a Gazebo plugin the launch's simulator does not load (Gazebo classic's in Gazebo "
        "Harmonic or the reverse, or another distro's name)",
        "use the plugin of the simulator the launch starts",
    ),
    Rule(
        "ros-sim-time",
        WARNING,
        "a node of a launch that starts Gazebo without use_sim_time: true",
        "give the node use_sim_time: true (or SetParameter use_sim_time for the launch)",
    ),
    Rule(
        "ros-start-sag",
        WARNING,
        "at a named pose the arm, held by its controller's gains, settles farther from the "
        "command than MoveIt's allowed_start_tolerance or the goal tolerance: Execute fails",
        "raise p (the message gives the value that holds) or add an integral term",
    ),
    Rule(
        "ros-controller-unstable",
        ERROR,
        "a ros2_control effort controller's PD(+I) loop diverges at its update rate: "
        "gz_ros2_control holds the effort for 1/update_rate between updates",
        "raise the update rate or lower the gains (the message gives both)",
    ),
    Rule(
        "ros-missing-depend",
        WARNING,
        "a launch file uses a package its package.xml does not depend on",
        "add the <exec_depend> to package.xml",
    ),
]
