"""The Gazebo classic extensions of a part: link colours, friction and the course's plugins.

Each plugin has its own builder (`diff_drive_element`, ...), so that `armcli import` can
tell whether a plugin it reads is exactly one the spec can type.
"""

from __future__ import annotations

from lxml import etree

from armcli.compiler.sensors import classic_sensor
from armcli.compiler.xmlfmt import fmt, robot, sub
from armcli.spec.model import (
    DiffDrive,
    JointPoseTrajectory,
    JointStatePublisher,
    Link,
    RobotSpec,
)

DIFF_DRIVE = ("diff_drive_controller", "libgazebo_ros_diff_drive.so")
JOINT_STATE_PUBLISHER = (
    "joint_state_publisher_controller",
    "libgazebo_ros_joint_state_publisher.so",
)
JOINT_POSE_TRAJECTORY = (
    "joint_pose_trajectory_controller",
    "libgazebo_ros_joint_pose_trajectory.so",
)


def gazebo_material(spec: RobotSpec, link: Link) -> str | None:
    """The link's Gazebo classic colour: that of its first visual's named material, if any."""
    for shape in link.visuals():
        if isinstance(shape.material, str):
            return spec.materials[shape.material].gazebo
    return None


def link_extensions(root: etree._Element, spec: RobotSpec, links: dict[str, Link]) -> None:
    """`<gazebo reference=LINK>` with the link's colour and friction, link by link."""
    for name, link in links.items():
        colour = gazebo_material(spec, link)
        if colour is None and link.contact is None:
            continue
        gz = sub(root, "gazebo", reference=name)
        if colour is not None:
            etree.SubElement(gz, "material").text = colour
        if link.contact is not None:
            sub(gz, "mu1", value=fmt(link.contact.mu1))
            sub(gz, "mu2", value=fmt(link.contact.mu2))


def plugin_element(names: tuple[str, str], params: list[tuple[str, str]]) -> etree._Element:
    """A `<gazebo><plugin name filename>` with one text element per parameter, in order."""
    gz = etree.Element("gazebo")
    el = sub(gz, "plugin", name=names[0], filename=names[1])
    for key, value in params:
        etree.SubElement(el, key).text = value
    return gz


def _flag(b: bool) -> str:
    return "true" if b else "false"


def diff_drive_element(dd: DiffDrive) -> etree._Element:
    """gazebo_ros_diff_drive with every parameter the spec holds."""
    return plugin_element(
        DIFF_DRIVE,
        [
            ("update_rate", fmt(dd.update_rate)),
            ("left_joint", dd.left_joint),
            ("right_joint", dd.right_joint),
            ("wheel_separation", fmt(dd.wheel_separation)),
            ("wheel_diameter", fmt(dd.wheel_diameter)),
            ("max_wheel_torque", fmt(dd.max_wheel_torque)),
            ("max_wheel_acceleration", fmt(dd.max_wheel_acceleration)),
            ("publish_odom", _flag(dd.publish_odom)),
            ("publish_odom_tf", _flag(dd.publish_odom_tf)),
            ("publish_wheel_tf", _flag(dd.publish_wheel_tf)),
            ("odometry_frame", dd.odometry_frame),
            ("robot_base_frame", dd.robot_base_frame),
        ],
    )


def joint_state_publisher_element(jsp: JointStatePublisher) -> etree._Element:
    """gazebo_ros_joint_state_publisher: the rate and one joint_name per joint."""
    params = [("update_rate", fmt(jsp.update_rate))]
    params += [("joint_name", j) for j in jsp.joints]
    return plugin_element(JOINT_STATE_PUBLISHER, params)


def joint_pose_trajectory_element(jpt: JointPoseTrajectory) -> etree._Element:
    """gazebo_ros_joint_pose_trajectory: the rate."""
    return plugin_element(JOINT_POSE_TRAJECTORY, [("update_rate", fmt(jpt.update_rate))])


def mobile_base_gazebo(spec: RobotSpec) -> etree._Element:
    """The mobile_base_gazebo.xacro body: base link colours and the diff-drive plugin."""
    root = robot()
    assert spec.mobile_base is not None
    link_extensions(root, spec, spec.mobile_base.links)
    if spec.mobile_base.diff_drive is not None:
        root.append(diff_drive_element(spec.mobile_base.diff_drive))
    _sensors(root, spec, spec.mobile_base.links)
    return root


def arm_gazebo(spec: RobotSpec) -> etree._Element:
    """The arm_gazebo.xacro body: arm link colours and the joint state/trajectory plugins."""
    root = robot()
    link_extensions(root, spec, spec.arm.links)
    if spec.arm.joint_state_publisher is not None:
        root.append(joint_state_publisher_element(spec.arm.joint_state_publisher))
    if spec.arm.joint_pose_trajectory is not None:
        root.append(joint_pose_trajectory_element(spec.arm.joint_pose_trajectory))
    _sensors(root, spec, spec.arm.links)
    return root


def _sensors(root: etree._Element, spec: RobotSpec, links: dict[str, Link]) -> None:
    """The Gazebo classic sensors fixed on this part's links."""
    for name, sensor in spec.sensors.items():
        if sensor.link in links:
            root.append(classic_sensor(name, sensor))
