"""XML and YAML launch files: the same actions, `$(...)` substitutions from literals only."""

from __future__ import annotations

from pathlib import Path

from armcli.check.ros_packages.files import Jail
from armcli.check.ros_packages.launch_model import LaunchDoc
from armcli.check.ros_packages.launch_xml import read_xml_launch
from armcli.check.ros_packages.substitute import HOLE, Shares, expand

# The course's bringup launch (ROS2 for Beginners Level 2), as the students write it.
COURSE_XML = """<launch>
    <let name="urdf_path"
        value="$(find-pkg-share my_robot_description)/urdf/my_robot.urdf.xacro" />
    <arg name="gui" default="false" />
    <node pkg="robot_state_publisher" exec="robot_state_publisher">
        <param name="robot_description"
                value="$(command 'xacro $(var urdf_path) use_camera:=true')" />
    </node>
    <include file="$(find-pkg-share gazebo_ros)/launch/gazebo.launch.py">
        <arg name="world" value="$(find-pkg-share my_robot_bringup)/worlds/my_world.world" />
    </include>
    <node pkg="gazebo_ros" exec="spawn_entity.py" args="-topic robot_description -entity r" />
    <node pkg="joint_state_publisher_gui" exec="joint_state_publisher_gui" if="$(var gui)" />
    <group>
        <set_parameter name="use_sim_time" value="true" />
        <node pkg="rviz2" exec="rviz2" output="screen" />
    </group>
</launch>
"""

COURSE_YAML = """launch:
- arg: {name: gui, default: "true"}
- node:
    pkg: robot_state_publisher
    exec: robot_state_publisher
    param:
    - {name: use_sim_time, value: true}
- node: {pkg: joint_state_publisher_gui, exec: joint_state_publisher_gui, if: $(var gui)}
"""


def read(
    tmp_path: Path, name: str, text: str, args: dict[str, str | None] | None = None
) -> LaunchDoc:
    path = tmp_path / name
    path.write_text(text)
    shares = Shares({"my_robot_description": tmp_path / "desc"})
    return read_xml_launch(Jail(tmp_path), path, shares, args or {})


def test_course_xml_launch(tmp_path: Path) -> None:
    doc = read(tmp_path, "gazebo.launch.xml", COURSE_XML)
    rsp, spawn, gui, rviz = doc.nodes
    assert rsp.description is not None
    assert rsp.description.file == f"{tmp_path}/desc/urdf/my_robot.urdf.xacro"
    assert dict(rsp.description.args) == {"use_camera": "true"}
    assert spawn.arguments == ("-topic", "robot_description", "-entity", "r")
    assert gui.active is False and rviz.active is True
    assert doc.includes[0].target == "package://gazebo_ros/launch/gazebo.launch.py"
    assert doc.global_params == {"use_sim_time": True}
    assert (rsp.where.line, gui.where.line) == (5, 13)
    assert doc.uses["xacro"] == 7  # libxml2 gives a tag spread over lines its last line


def test_course_yaml_launch_and_an_includers_argument(tmp_path: Path) -> None:
    doc = read(tmp_path, "display.launch.yaml", COURSE_YAML, {"gui": "false"})
    rsp, gui = doc.nodes
    assert rsp.params == {"use_sim_time": True} and rsp.param_lines["use_sim_time"] == 7
    assert gui.active is False and gui.where.line == 8


def test_substitutions_that_are_not_literal_leave_a_hole() -> None:
    shares = Shares({})
    assert expand("$(env HOME)/x", {}, shares, 1) == f"{HOLE}/x"
    assert expand("$(eval 1+1)", {}, shares, 1) == HOLE
    assert expand("$(find-pkg-share a)/$(var b)", {"b": "c"}, shares, 1) == "package://a/c"


def test_malformed_xml_and_yaml_are_one_problem_each(tmp_path: Path) -> None:
    xml = read(tmp_path, "bad.launch.xml", "<launch>\n  <node pkg='a'>\n</launch>\n")
    (p,) = xml.problems
    assert p.file.endswith("bad.launch.xml") and p.line == 3 and "well-formed" in p.message
    yml = read(tmp_path, "bad.launch.yaml", "launch:\n- node:\n\tpkg: a\n")
    (q,) = yml.problems
    assert q.file.endswith("bad.launch.yaml") and q.line == 3 and "tab" in q.message
    ent = read(tmp_path, "ent.launch.xml", '<!DOCTYPE l [<!ENTITY x "y">]>\n<launch/>\n')
    assert "DOCTYPE" in ent.problems[0].message


def test_doubling_lets_stay_bounded(tmp_path: Path) -> None:
    lets = "".join(f'  <let name="a{k + 1}" value="$(var a{k})$(var a{k})"/>\n' for k in range(40))
    node_xml = '  <node pkg="p" exec="$(var a40)"/>\n'
    text = f'<launch>\n  <let name="a0" value="x"/>\n{lets}{node_xml}</launch>\n'
    (node,) = read(tmp_path, "big.launch.xml", text).nodes
    assert node.executable is None  # 2**40 characters: not a literal


def test_a_comment_naming_a_doctype_is_read_a_prolog_doctype_is_refused(tmp_path: Path) -> None:
    # Before io/xml.py the checker searched the bytes for "<!DOCTYPE" and refused this file,
    # whose comment only names one; the URDF reader reads the prolog (issue 42): both agree now.
    noted = "<launch>\n  <!-- no <!DOCTYPE here -->\n  <node pkg='a' exec='b'/>\n</launch>\n"
    ok = read(tmp_path, "noted.launch.xml", noted)
    assert not ok.problems
    assert [n.package for n in ok.nodes] == ["a"]
    late = read(tmp_path, "late.launch.xml", "<?xml version='1.0'?>\n\n<!DOCTYPE l>\n<launch/>\n")
    (p,) = late.problems
    assert p.line == 3 and "DOCTYPE" in p.message
    latin = tmp_path / "latin.launch.xml"
    latin.write_bytes("<launch>\n<!-- caf\xe9 -->\n</launch>\n".encode("latin-1"))
    (q,) = read_xml_launch(Jail(tmp_path), latin, Shares({}), {}).problems
    assert q.line == 2 and "UTF-8" in q.message
