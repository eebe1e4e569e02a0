"""The Gazebo classic extensions of a part: link colours, friction and the course's plugins."""

from __future__ import annotations

from lxml import etree

from armcli.compiler.xmlfmt import fmt, robot, sub
from armcli.spec.model import Link, RobotSpec


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


def plugin(root: etree._Element, name: str, filename: str, params: list[tuple[str, str]]) -> None:
    """A `<gazebo><plugin>` with one text element per parameter, in order."""
    el = sub(sub(root, "gazebo"), "plugin", name=name, filename=filename)
    for key, value in params:
        etree.SubElement(el, key).text = value


def _flag(b: bool) -> str:
    return "true" if b else "false"


def mobile_base_gazebo(spec: RobotSpec) -> etree._Element:
    """The mobile_base_gazebo.xacro body: base link colours and the diff-drive plugin."""
    root = robot()
    assert spec.mobile_base is not None
    link_extensions(root, spec, spec.mobile_base.links)
    dd = spec.mobile_base.diff_drive
    if dd is not None:
        plugin(
            root,
            "diff_drive_controller",
            "libgazebo_ros_diff_drive.so",
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
    return root


def arm_gazebo(spec: RobotSpec) -> etree._Element:
    """The arm_gazebo.xacro body: arm link colours and the joint state/trajectory plugins."""
    root = robot()
    link_extensions(root, spec, spec.arm.links)
    jsp = spec.arm.joint_state_publisher
    if jsp is not None:
        params = [("update_rate", fmt(jsp.update_rate))]
        params += [("joint_name", j) for j in jsp.joints]
        plugin(
            root,
            "joint_state_publisher_controller",
            "libgazebo_ros_joint_state_publisher.so",
            params,
        )
    jpt = spec.arm.joint_pose_trajectory
    if jpt is not None:
        plugin(
            root,
            "joint_pose_trajectory_controller",
            "libgazebo_ros_joint_pose_trajectory.so",
            [("update_rate", fmt(jpt.update_rate))],
        )
    return root
