"""/cmd_vel command files: held values, ROS time forms, and refusals naming line and field."""

from __future__ import annotations

import numpy as np
import pytest

from armcli.drive.cmdvel import load_cmd_vel, loads_cmd_vel
from armcli.errors import SpecError
from tests.helpers import ROOT

GOOD = """commands:
  - {linear: {x: 0.2}, time_from_start: 1.0}
  - {angular: {z: 0.5}, time_from_start: {sec: 3, nanosec: 500000000}}
  - {time_from_start: 5}
"""


def test_each_command_holds_until_the_next() -> None:
    cmd = loads_cmd_vel(GOOD)
    assert cmd.times.tolist() == [1.0, 3.5, 5.0]  # {sec, nanosec} as ROS reads it
    lin, ang = cmd.at(np.array([0.0, 0.999, 1.0, 3.49, 3.5, 4.9, 5.0, 100.0]))
    assert lin.tolist() == [0.0, 0.0, 0.2, 0.2, 0.0, 0.0, 0.0, 0.0]  # zero before the first
    assert ang.tolist() == [0.0, 0.0, 0.0, 0.0, 0.5, 0.5, 0.0, 0.0]
    assert cmd.warnings == ()


def test_components_a_diff_drive_ignores_are_named() -> None:
    cmd = loads_cmd_vel("commands:\n  - {linear: {x: 0.1, y: 0.3}, time_from_start: 0}\n")
    assert len(cmd.warnings) == 1 and "commands[0].linear.y" in cmd.warnings[0]


@pytest.mark.parametrize(
    ("text", "line", "field"),
    [
        ("commands:\n  - {linear: {x: 0.1}, speed: 2}\n", 2, "commands[0].speed"),
        ("commands:\n  - {linear: {x: .nan}, time_from_start: 0}\n", 2, "commands[0].linear.x"),
        ("commands:\n  - {linear: {w: 1}, time_from_start: 0}\n", 2, "commands[0].linear.w"),
        ("commands:\n  - {time_from_start: 2}\n  - {time_from_start: 1}\n", 3,
         "commands[1].time_from_start"),
        ("commands:\n  - {time_from_start: 2}\n  - {time_from_start: 2}\n", 3,
         "commands[1].time_from_start"),
        ("cmds: []\n", 1, "cmds"),
        ("commands: []\n", 1, "commands"),
        ("commands:\n  - [0.1, 0.2]\n", 2, "commands[0]"),
        ("commands:\n  - {linear: 0.2}\n", 2, "commands[0].linear"),
    ],
)  # fmt: skip
def test_bad_files_name_line_and_field(text: str, line: int, field: str) -> None:
    with pytest.raises(SpecError) as info:
        loads_cmd_vel(text, source="drive.yaml")
    fields = {(p.field, p.line) for p in info.value.problems}
    assert (field, line) in fields, fields


def test_the_shipped_example_loads() -> None:
    cmd = load_cmd_vel(ROOT / "specs" / "trajectories" / "drive.yaml")
    assert cmd.times.tolist() == [0.5, 3.0, 5.5, 7.0] and cmd.warnings == ()


def test_many_bad_commands_are_one_line_per_kind() -> None:
    """Issue 42: 25,000 bad commands printed 25,001 error lines (2 MB)."""
    body = "".join(
        "- {linear: {x: b}, time_from_start: 0}\n" if k % 2 else "- {linear: {x: b}}\n"
        for k in range(25_000)
    )  # every command a bad number; every second one also back at 0 s
    with pytest.raises(SpecError) as info:
        loads_cmd_vel("commands:\n" + body)
    lines = info.value.lines()
    assert len(lines) == 2, lines[:5]
    first = "<cmd_vel>:2 commands[0].linear.x: must be a finite number, got 'b'"
    assert lines[0] == f"{first} (and 24999 more)"
    assert lines[1].startswith("<cmd_vel>:3 commands[1].time_from_start: times must increase")
    assert lines[1].endswith("(and 12499 more)")


@pytest.mark.parametrize(
    ("text", "words"),
    [
        # the valid names once, not "expected one of (valid: ...)"
        ("commands:\n  - {linear: {w: 1}, time_from_start: 0}\n", "unknown key; valid: x, y, z"),
        ("commands:\n  - {lineer: {x: 1}}\n",
         "unknown key; did you mean 'linear'? valid: angular, linear, time_from_start"),
        # a list at the top: the key the file needs, with an example
        ("- {linear: {x: 0.2}}\n", "must be a YAML mapping with a `commands:` list"),
    ],
)  # fmt: skip
def test_error_wording_says_it_once(text: str, words: str) -> None:
    with pytest.raises(SpecError) as info:
        loads_cmd_vel(text, source="drive.yaml")
    assert any(words in line for line in info.value.lines()), info.value.lines()
