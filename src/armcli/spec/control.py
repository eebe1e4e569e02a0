"""ros2_control in the spec: per-joint command and state interfaces, and the hardware.

`ros2_control.joints` says, joint by joint, which interfaces the hardware offers
(`position`, `velocity`, `effort`, ...) with their limits (`min`, `max`) and start values
(`initial_value`). Both ROS targets build their `<ros2_control>` blocks and controller
configuration from it, and the MJCF export can read the actuator kind and range from it
(`armcli.spec.control.command_interfaces`). With `hardware` given, `armcli build` also
writes the block into the description itself (as many vendor descriptions do).
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from armcli.spec.types import Real, Text, UrdfName, _Model

STANDARD_INTERFACES = ("position", "velocity", "effort", "acceleration")


class Interface(_Model):
    """One command or state interface: limits, start value, other hardware parameters."""

    min: Real | None = Field(None, description="lowest command (`<param name=min>`) [SI]")
    max: Real | None = Field(None, description="highest command (`<param name=max>`) [SI]")
    initial_value: Real | None = Field(
        None, description="state at start (`<param name=initial_value>`) [SI]"
    )
    params: dict[Text, Text] = Field({}, description="other `<param>` values, verbatim")


class JointControl(_Model):
    """What ros2_control offers for one joint: interfaces by name, in order."""

    command_interfaces: dict[Text, Interface] = Field(
        {}, description="commands the hardware takes, e.g. position, velocity, effort"
    )
    state_interfaces: dict[Text, Interface] = Field(
        {}, description="states the hardware reports, e.g. position, velocity, effort"
    )
    params: dict[Text, Text] = Field({}, description="joint `<param>` values, verbatim")


class Hardware(_Model):
    """The hardware plugin and its parameters (`<hardware>`)."""

    plugin: Text = Field(description="pluginlib class, e.g. mock_components/GenericSystem")
    params: dict[Text, Text] = Field({}, description="`<param>` values, verbatim")


class Ros2Control(_Model):
    """The robot's `<ros2_control>`: its joints' interfaces and, optionally, the hardware."""

    name: Text | None = Field(None, description="block name; default `<robot name>_system`")
    type: Literal["system", "actuator", "sensor"] = Field("system", description="component type")
    hardware: Hardware | None = Field(
        None, description="the hardware plugin; given: `build` writes the block into the URDF"
    )
    joints: dict[UrdfName, JointControl] = Field(
        {}, description="interfaces per joint, in the order the block lists them"
    )


def command_interfaces(control: Ros2Control | None, joint: str) -> list[str]:
    """The command interfaces the spec gives `joint` ([] when it says nothing)."""
    if control is None or joint not in control.joints:
        return []
    return list(control.joints[joint].command_interfaces)
