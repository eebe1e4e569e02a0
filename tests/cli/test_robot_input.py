"""The robot-input option group: declared once, the same on every command, parsed before work.

Every command that reads a robot takes its file, xacro's NAME:=VALUE arguments,
--package-dir, --env and --trust-xacro from `commands.robot_input.robot_options`; these
tests read the commands click builds, so a command that declares them by hand again (or
forgets one) fails here, and they show a malformed value refused before any file is read.
"""

from __future__ import annotations

from pathlib import Path

import click
import pytest

from armcli.cli import COMMANDS, load_command
from armcli.commands import robot_input
from armcli.commands.values import names, numbers, point, size
from armcli.errors import InputError
from armcli.plan.api import PlanOptions
from armcli.plan.request import PlanRequest
from armcli.urdf.source import RobotInput, read_robot
from armcli.view.scene import load_robot
from armcli.xacro.args import XacroInputs
from tests.helpers import DEFAULT_SPEC, ROOT, run_main

GROUP = {"--package-dir", "--env", "--trust-xacro", "--trust-xacro-unsandboxed"}
XACRO_COMMANDS = {"check", "tree", "view", "render", "expand", "import", "simulate", "plan",
                  "place", "export mjcf"}  # fmt: skip
PARSERS = ("parse_args(", "parse_env(", "parse_package_dirs(", "trust_mode(", "find_spec(")


def _commands() -> dict[str, click.Command]:
    found: dict[str, click.Command] = {}
    for name in COMMANDS:
        cmd = load_command(name)
        if isinstance(cmd, click.Group):
            found.update({f"{name} {sub}": c for sub, c in cmd.commands.items()})
        else:
            found[name] = cmd
    return found


def _options(cmd: click.Command) -> dict[str, click.Parameter]:
    return {o: p for p in cmd.params for o in getattr(p, "opts", []) if o.startswith("--")}


def test_every_command_reading_a_xacro_takes_the_whole_group_with_one_help() -> None:
    commands = _commands()
    taking = {name for name, cmd in commands.items() if GROUP & set(_options(cmd))}
    assert taking == XACRO_COMMANDS | {"ros-package"}
    helps: dict[str, set[str | None]] = {flag: set() for flag in GROUP}
    for name in XACRO_COMMANDS:
        opts = _options(commands[name])
        assert set(opts) >= GROUP, name
        for flag in GROUP:
            helps[flag].add(getattr(opts[flag], "help", None))
        metavars = [p.human_readable_name for p in commands[name].params
                    if isinstance(p, click.Argument)]  # fmt: skip
        assert metavars[-1] == "[NAME:=VALUE]..." or name == "check", (name, metavars)
    assert all(len(texts) == 1 for texts in helps.values()), helps
    assert set(_options(commands["ros-package"])) & GROUP == {"--package-dir"}


def test_no_command_parses_the_group_itself() -> None:
    commands = ROOT / "src" / "armcli" / "commands"
    for path in commands.glob("*.py"):
        if path.name == "robot_input.py":
            continue
        text = path.read_text()
        assert not [p for p in PARSERS if p in text], path.name


@pytest.mark.parametrize(
    ("args", "flag"),
    [
        (["tree", "missing.urdf", "--env", "NOEQUALS"], "--env"),
        (["check", "missing.urdf", "--package-dir", "nopath"], "--package-dir"),
        (["render", "missing.urdf", "bad name:=1"], "NAME:=VALUE"),
        (["simulate", "missing.yaml", "--kp", "1,x"], "--kp"),
        (["simulate", "missing.yaml", "--joints", "a", "--kd", "nan"], "--kd"),
        (["plan", "missing.yaml", "--to-xyz", "1,2"], "--to-xyz"),
        (["render", "missing.urdf", "--size", "50x50"], "--size"),
        (["check", "missing.urdf", "--reach-point", "1,2,inf"], "--reach-point"),
        (["tune", "missing.yaml", "--mass-scale", "0.8"], "--mass-scale"),
    ],
)
def test_a_malformed_option_is_refused_before_the_robot_is_read(
    args: list[str], flag: str, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    code, out, err = run_main(args, capsys)
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and flag in err and "missing" not in err, err


def test_the_group_parses_into_one_robot_input() -> None:
    got = robot_input.parse("robot", robot_file=Path("r.xacro"), xacro_args=["a:=1"],
                            env=["V=2"], package_dir=["p=/tmp"], trust_xacro=True)  # fmt: skip
    assert got.paths == (Path("r.xacro"),) and got.trust is True
    assert dict(got.xacro.args) == {"a": "1"} and dict(got.xacro.env) == {"V": "2"}
    assert got.packages.package_dirs == {"p": Path("/tmp")}
    # `armcli tree a:=1`: click puts the argument where the file goes; no file: the spec
    alone = robot_input.parse("robot", robot_file=Path("a:=1"))
    assert alone.paths == () and dict(alone.xacro.args) == {"a": "1"}
    assert robot_input.parse("robot", unsandboxed=True).trust == "unsandboxed"
    files = robot_input.parse("paths", robot_file=["a.urdf", "n:=2", "b"])
    assert files.paths == (Path("a.urdf"), Path("b")) and dict(files.xacro.args) == {"n": "2"}
    with pytest.raises(InputError, match="FILE"):
        robot_input.parse("file", robot_file=Path("n:=1"))


def test_a_library_caller_names_a_robot_the_same_way() -> None:
    given = RobotInput((DEFAULT_SPEC,))
    assert given.read().robot.text == read_robot(DEFAULT_SPEC).robot.text
    by_path, by_input = load_robot(DEFAULT_SPEC), load_robot(given)
    assert (by_path.xml, by_path.poses, by_path.tool) == (by_input.xml, by_input.poses,
                                                          by_input.tool)  # fmt: skip
    assert RobotInput(xacro=XacroInputs()).path is None


def test_value_parsers() -> None:
    assert names(" a, b,,c ") == ("a", "b", "c") and names("") == ()
    assert numbers("--kp")("20, 30") == (20.0, 30.0)
    assert point("--p")("0.1,0,-2e-1") == (0.1, 0.0, -0.2)
    assert size("640X480") == (640, 480)
    for text in ("1,2", "1,2,3,4", "1,,x", "nan,0,0", "1e999,0,0"):
        with pytest.raises(InputError) as err:
            point("--reach-point")(text)
        assert err.value.field == "--reach-point"
    with pytest.raises(InputError, match=r"100\.\.8000"):
        size("99x200")


def test_a_plan_request_states_one_goal() -> None:
    assert PlanRequest(goal="reach").describe() == "from home to reach"
    assert PlanRequest(start="0,0", to_xyz=(0.2, 0.0, 0.15)).describe() == (
        "from 0,0 to xyz 0.2,0,0.15"
    )
    for bad in (
        {},
        {"goal": "reach", "to_xyz": (0.0, 0.0, 0.0)},
        {"goal": "a", "to_rpy": (0, 0, 0)},
    ):
        with pytest.raises(InputError) as err:
            PlanRequest(options=PlanOptions(), **bad)  # type: ignore[arg-type]
        assert "--" not in str(err.value)  # a library caller is told its own names
