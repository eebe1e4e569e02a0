"""Spec `ros2_control` -> `<ros2_control>` XML, the one writer for build and both ROS targets.

Interfaces are written in the spec's order with their parameters `min`, `max`,
`initial_value` first, then the others; a target may put a xacro expression in place
of a joint's position `initial_value` (MoveIt's initial_positions.yaml).
"""

from __future__ import annotations

from collections.abc import Mapping

from lxml import etree

from armcli.compiler.xmlfmt import fmt, literal, sub
from armcli.spec.model import Hardware, Interface, JointControl, Ros2Control

STANDARD_PARAMS = ("min", "max", "initial_value")


def _param(parent: etree._Element, name: str, value: str) -> None:
    sub(parent, "param", name=literal(name)).text = value


def interface_element(
    parent: etree._Element, tag: str, name: str, iface: Interface, initial: str | None = None
) -> etree._Element:
    """`<command_interface>` / `<state_interface>` with its parameters."""
    el = sub(parent, tag, name=literal(name))
    for key in STANDARD_PARAMS:
        value = getattr(iface, key)
        if key == "initial_value" and initial is not None:
            _param(el, key, initial)
        elif value is not None:
            _param(el, key, fmt(value))
    for key, text in iface.params.items():
        _param(el, key, literal(text))
    return el


def joint_block(
    parent: etree._Element, name: str, joint: JointControl, initial: str | None = None
) -> etree._Element:
    """`<joint name>`: command interfaces, state interfaces, parameters.

    `initial`, when given, is the text of the position state's `initial_value`.
    """
    el = sub(parent, "joint", name=name)
    for iname, iface in joint.command_interfaces.items():
        interface_element(el, "command_interface", iname, iface)
    for iname, iface in joint.state_interfaces.items():
        interface_element(
            el, "state_interface", iname, iface, initial if iname == "position" else None
        )
    for key, text in joint.params.items():
        _param(el, key, literal(text))
    return el


def hardware_element(parent: etree._Element, hardware: Hardware) -> etree._Element:
    """`<hardware>`: the plugin and its parameters."""
    hw = sub(parent, "hardware")
    sub(hw, "plugin").text = literal(hardware.plugin)
    for key, text in hardware.params.items():
        _param(hw, key, literal(text))
    return hw


def block_name(robot: str, control: Ros2Control | None) -> str:
    """The block's name: the spec's, else `<robot>_system`."""
    return control.name if control is not None and control.name else f"{robot}_system"


def ros2_control_element(
    robot: str, control: Ros2Control, joints: Mapping[str, JointControl] | None = None
) -> etree._Element:
    """The whole block of a spec whose `ros2_control` has a hardware plugin."""
    assert control.hardware is not None
    rc = etree.Element("ros2_control", name=literal(block_name(robot, control)), type=control.type)
    hardware_element(rc, control.hardware)
    for name, joint in (joints if joints is not None else control.joints).items():
        joint_block(rc, name, joint)
    return rc
