"""The MoveIt config's robot description: the course xacro plus a ros2_control block.

The MoveIt demo runs the arm on ros2_control's mock hardware, which needs a
`<ros2_control>` tag naming every commanded joint and its initial position.
The course description stays untouched: `config/<name>.urdf.xacro` includes
it from the description package and adds the tag, as the Setup Assistant does.
"""

from __future__ import annotations

from lxml import etree

from armcli.compiler.ros2_control import joint_block
from armcli.compiler.xmlfmt import XACRO_NS, to_bytes
from armcli.ros.interfaces import HUMBLE, commanded, passive
from armcli.ros.moveit import passive_joints
from armcli.ros.srdf import chain_joints
from armcli.spec.model import RobotSpec

X = f"{{{XACRO_NS}}}"
MOCK_PLUGIN = "mock_components/GenericSystem"
INITIAL_POSITIONS_FILE = "initial_positions.yaml"


def _robot(name: str | None = None) -> etree._Element:
    attrs = {"name": name} if name else {}
    return etree.Element("robot", attrs, nsmap={"xacro": XACRO_NS})


def macro_name(robot: str) -> str:
    """Name of the xacro macro that emits the robot's `<ros2_control>` block."""
    return f"{robot}_ros2_control"


def ros2_control_xacro(spec: RobotSpec, header: str | None = None) -> bytes:
    """A xacro macro emitting the `<ros2_control>` block of the MoveIt demo (mock hardware).

    Chain joints take commands (position unless the spec's `ros2_control` says otherwise);
    the others only report state. Positions start at initial_positions.yaml.
    """
    robot = spec.name
    root = _robot()
    macro = etree.SubElement(
        root, X + "macro", name=macro_name(robot), params="name initial_positions_file"
    )
    etree.SubElement(
        macro,
        X + "property",
        name="initial_positions",
        value="${xacro.load_yaml(initial_positions_file)['initial_positions']}",
    )
    rc = etree.SubElement(macro, "ros2_control", name="${name}", type="system")
    hw = etree.SubElement(rc, "hardware")
    etree.SubElement(hw, "plugin").text = MOCK_PLUGIN
    blocks = [(j, commanded(spec, j, HUMBLE)) for j in chain_joints(spec)]
    blocks += [(j, passive(spec, j)) for j in passive_joints(spec)]
    for j, control in blocks:
        joint_block(rc, j, control, initial="${initial_positions['" + j + "']}")
    return to_bytes(root, header_comment=header)


def moveit_urdf_xacro(
    robot: str, description_pkg: str, top_xacro: str, header: str | None = None
) -> bytes:
    """`config/<robot>.urdf.xacro`: the course description plus the ros2_control macro call."""
    root = _robot(robot)
    etree.SubElement(root, X + "arg", name="initial_positions_file", default=INITIAL_POSITIONS_FILE)
    etree.SubElement(root, X + "include", filename=f"$(find {description_pkg})/urdf/{top_xacro}")
    etree.SubElement(root, X + "include", filename=f"{robot}.ros2_control.xacro")
    etree.SubElement(
        root,
        X + macro_name(robot),
        name="MockSystem",
        initial_positions_file="$(arg initial_positions_file)",
    )
    return to_bytes(root, header_comment=header)
