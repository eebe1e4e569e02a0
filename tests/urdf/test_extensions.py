"""The simulator extensions, read once into the typed document (urdf/extensions.py)."""

from __future__ import annotations

from armcli.check.interface import read_interfaces
from armcli.check.joints import driven_joints
from armcli.export.mjcf_report import scan
from armcli.urdf.doc import Gazebo, Plugin, Ros2Control, Transmission
from armcli.urdf.read import parse_urdf

GZ = "gz_ros2_control-system"
XML = f"""<robot name="r">
  <link name="a"/><link name="b"/><link name="c"/>
  <joint name="j1" type="revolute"><parent link="a"/><child link="b"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="b"/><child link="c"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
    <mimic joint="j1" multiplier="-2" offset="0.5"/></joint>
  <gazebo reference="b"><mu1>0.8</mu1><mu2 value="0.4"/><!-- c --><material>Gazebo/Red</material>
  </gazebo>
  <gazebo><plugin filename="{GZ}" name="gz">
    <position_proportional_gain> 0.3 </position_proportional_gain></plugin></gazebo>
  <ros2_control name="sys" type="system">
    <hardware><plugin> gz_ros2_control/GazeboSimSystem </plugin></hardware>
    <joint name="j1"><command_interface name="position"/><state_interface name="position"/>
    </joint>
  </ros2_control>
  <transmission name="t2"><joint name="j2"/></transmission>
</robot>"""


def test_the_extensions_are_typed_fields_of_the_document() -> None:
    urdf = parse_urdf(XML.encode(), "r.urdf")
    assert urdf.gazebo == (
        Gazebo("b", {"mu1": "0.8", "mu2": "0.4", "material": "Gazebo/Red"}, 8),
        Gazebo(None, {"plugin": ""}, 10),
    )
    assert urdf.ros2_control == (
        Ros2Control("sys", "gz_ros2_control/GazeboSimSystem", {"j1": ("position",)}, 12),
    )
    assert urdf.transmissions == (Transmission("t2", ("j2",), 17),)
    assert urdf.plugins == (
        Plugin(GZ, "gz", {"position_proportional_gain": "0.3"}, 10),
        Plugin(None, None, {}, 13),
    )


def test_every_consumer_reads_them_from_the_document() -> None:
    urdf = parse_urdf(XML.encode(), "r.urdf")
    ifaces = read_interfaces(urdf)
    assert ifaces is not None and ifaces.gazebo and ifaces.gain == 0.3
    assert ifaces.position_joints() == ["j1"] and ifaces.line == 12
    assert driven_joints(urdf) == {"j1", "j2"}
    extras = scan(urdf)
    mimic = extras.mimic["j2"]
    assert (mimic.leader, mimic.multiplier, mimic.offset) == ("j1", -2.0, 0.5)
    assert extras.mu1 == {"b": 0.8}
    assert extras.tags == {"gazebo": 2, "transmission": 1, "ros2_control": 1}
