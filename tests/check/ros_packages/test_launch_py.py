"""Python launch files read with `ast`: literals resolved, nothing imported or run."""

from __future__ import annotations

import textwrap
from pathlib import Path

from armcli.check.ros_packages.launch_model import UNKNOWN, LaunchDoc
from armcli.check.ros_packages.launch_py import read_python_launch
from armcli.check.ros_packages.substitute import Shares


def read(
    source: str, args: dict[str, str | None] | None = None, dirs: dict[str, Path] | None = None
) -> LaunchDoc:
    text = HEADER + textwrap.dedent(source)
    return read_python_launch(
        Path("/ws/pkg/launch/x.launch.py"), text, Shares(dirs or {}), args or {}
    )


def line(source: str, needle: str) -> int:
    """The 1-based line of `needle` in the launch file `read` builds from `source`."""
    text = HEADER + textwrap.dedent(source)
    return text[: text.index(needle)].count("\n") + 1


HEADER = """
import os
from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, IncludeLaunchDescription
from launch.conditions import IfCondition, UnlessCondition
from launch.substitutions import Command, LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare
"""


TURTLEBOT_STYLE = """
    def generate_launch_description():
        use_sim_time = LaunchConfiguration('use_sim_time', default='true')
        urdf = os.path.join(get_package_share_directory('desc'), 'urdf', 'robot.urdf.xacro')
        return LaunchDescription([
            DeclareLaunchArgument('gui', default_value='false'),
            Node(package='robot_state_publisher', executable='robot_state_publisher',
                 parameters=[{'use_sim_time': use_sim_time,
                              'robot_description': Command(['xacro ', urdf, ' prefix:=l_'])}]),
            Node(package='joint_state_publisher_gui', executable='joint_state_publisher_gui',
                 condition=IfCondition(LaunchConfiguration('gui'))),
        ])
    """


def test_turtlebot_style_names_and_defaults_resolve() -> None:
    doc = read(TURTLEBOT_STYLE, dirs={"desc": Path("/ws/desc")})
    rsp, gui = doc.nodes
    assert rsp.params["use_sim_time"] == "true"
    assert rsp.param_lines["use_sim_time"] == line(TURTLEBOT_STYLE, "'use_sim_time': use")
    assert rsp.description is not None
    assert rsp.description.file == "/ws/desc/urdf/robot.urdf.xacro"
    assert dict(rsp.description.args) == {"prefix": "l_"}
    assert gui.active is False  # gui defaults to false
    assert doc.uses == {"desc": line(TURTLEBOT_STYLE, "urdf = ")}


def test_includer_arguments_override_defaults_and_computed_values_stay_unknown() -> None:
    src = """
    def generate_launch_description():
        name = os.environ['ROBOT']
        return LaunchDescription([
            DeclareLaunchArgument('use_sim_time', default_value='false'),
            Node(package='rviz2', executable='rviz2', name=name,
                 parameters=[{'use_sim_time': LaunchConfiguration('use_sim_time'),
                              'computed': len(name)}]),
        ])
    """
    assert read(src).nodes[0].params["use_sim_time"] == "false"
    node = read(src, {"use_sim_time": "true"}).nodes[0]
    assert node.params["use_sim_time"] == "true"
    assert node.params["computed"] is UNKNOWN and node.name is None


def test_loops_comprehensions_and_dead_nodes() -> None:
    doc = read(
        """
    def generate_launch_description():
        unused = Node(package='never', executable='started')
        spawners = [Node(package='controller_manager', executable='spawner', arguments=[c])
                    for c in ['joint_state_broadcaster', 'arm_controller']]
        return LaunchDescription(spawners)
    """
    )
    assert [(n.package, n.arguments) for n in doc.nodes] == [
        ("controller_manager", ("joint_state_broadcaster",)),
        ("controller_manager", ("arm_controller",)),
    ]


def test_includes_with_their_arguments_and_python_expression_literals() -> None:
    doc = read(
        """
    from launch.launch_description_sources import PythonLaunchDescriptionSource
    from launch.substitutions import PythonExpression
    def generate_launch_description():
        sa = LaunchConfiguration('standalone')
        xacro_file = PythonExpression(["'arm.xacro' if '", sa, "' == 'true' else 'robot.xacro'"])
        return LaunchDescription([
            DeclareLaunchArgument('standalone', default_value='false'),
            IncludeLaunchDescription(PythonLaunchDescriptionSource(
                [FindPackageShare('ros_gz_sim'), '/launch/gz_sim.launch.py']),
                launch_arguments={'gz_args': '-r empty.sdf'}.items()),
            Node(package='robot_state_publisher', executable='robot_state_publisher',
                 parameters=[{'robot_description': Command(['xacro ', PathJoinSubstitution(
                     [FindPackageShare('desc'), 'urdf', xacro_file])])}]),
        ])
    """
    )
    (inc,) = doc.includes
    assert inc.target == "package://ros_gz_sim/launch/gz_sim.launch.py"
    assert dict(inc.args) == {"gz_args": "-r empty.sdf"}
    assert [d.file for d in doc.descriptions] == ["package://desc/urdf/robot.xacro"]


MOVEIT = """
from moveit_configs_utils import MoveItConfigsBuilder
from moveit_configs_utils.launches import generate_demo_launch

def generate_launch_description():
    cfg = MoveItConfigsBuilder("arm", package_name="arm_moveit").to_moveit_configs()
    return generate_demo_launch(cfg)
"""


def test_moveit_generators_name_their_config() -> None:
    doc = read(MOVEIT)
    (m,) = doc.moveit
    assert (m.generator, m.package, m.robot) == ("generate_demo_launch", "arm_moveit", "arm")
    assert doc.imports["moveit_configs_utils"] == line(MOVEIT, "from moveit_configs_utils")


def test_a_syntax_error_is_one_problem_with_its_line() -> None:
    source = "def generate_launch_description():\n    return [\n"
    doc = read(source)
    (p,) = doc.problems
    assert p.file.endswith("x.launch.py") and "syntax" in p.message
    assert p.line == line(source, "return [")  # where the bracket is left open


def test_nothing_in_the_file_runs(tmp_path: Path) -> None:
    """A launch file whose every statement would write a file if Python ran it."""
    planted = tmp_path / "ran"
    source = f"""
    open({str(planted)!r}, 'w').write('module')
    import os; os.system('touch {planted}')
    def generate_launch_description():
        open({str(planted)!r}, 'w').write('function')
        return __import__('launch').LaunchDescription([])
    class Evil:
        def __eq__(self, other):
            open({str(planted)!r}, 'w').write('compare')
            return True
    """
    doc = read(source)
    assert doc.problems == () and not planted.exists()


def test_doubling_names_stay_bounded() -> None:
    """`a1 = a0 + a0; a2 = a1 + a1; ...`: 60 doublings are 2**60 characters if followed."""
    chain = "\n".join(f"a{k + 1} = a{k} + a{k}" for k in range(60))
    source = f"a0 = 'x'\n{chain}\ndef generate_launch_description():\n"
    source += "    return LaunchDescription([Node(package='p', executable=a60)])\n"
    (node,) = read(source).nodes
    assert node.executable is None  # too long to be a literal; and it took no time
