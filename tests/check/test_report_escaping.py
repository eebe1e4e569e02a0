"""Workflow-command injection (issue 20): no file name or value starts a line of its own.

GitHub Actions reads workflow commands (`::add-mask::`, `::error::`, `::stop-commands::`)
from stdout and stderr, one per line. A URDF named `b\\n::add-mask::armcli\\nz.urdf` made
`check --format github` print a standalone `::add-mask::` line on stderr (the line for an
unusable file), and a `#` in a name sent the annotation to another file.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from armcli.check.findings import Finding
from armcli.check.report import to_github
from armcli.errors import split_source
from armcli.io.oneline import one_line
from tests.cli.test_check import armcli
from tests.helpers import ROOT

EVIL = [
    "b\n::add-mask::armcli\nz.urdf",
    "b\r::add-mask::armcli\rz.urdf",
    "b\r\n::stop-commands::x\r\n.urdf",
]
ANNOTATION = re.compile(r"::(error|warning|notice) [^\r\n]*::")


def commands(text: str) -> list[str]:
    """The lines GitHub reads as workflow commands (it splits at CR, LF and CRLF)."""
    return [ln.strip() for ln in re.split(r"\r\n|\r|\n", text) if ln.strip().startswith("::")]


def _dir_with(tmp_path: Path, evil: str) -> Path:
    (tmp_path / evil).write_text("this is not XML\n")  # an unusable file: a stderr line
    broken = (ROOT / "urdf" / "my_robot.urdf").read_text()
    (tmp_path / f"{evil[:-5]}-mass.urdf").write_text(  # a usable file with an error finding
        broken.replace('<mass value="0.3"/>', '<mass value="-0.3"/>', 1)
    )
    return tmp_path


@pytest.mark.parametrize("evil", EVIL, ids=["lf", "cr", "crlf"])
@pytest.mark.parametrize("fmt", ["github", "table"])
def test_file_names_cannot_inject_workflow_commands(fmt: str, evil: str, tmp_path: Path) -> None:
    r = armcli("check", "--format", fmt, _dir_with(tmp_path, evil))
    assert r.returncode in (1, 2), r.stderr
    for stream in (r.stdout, r.stderr):
        for line in commands(stream):
            assert ANNOTATION.match(line), line  # before: "::add-mask::armcli" on stderr
    if fmt == "github":
        assert "b%0A%3A%3Aadd-mask%3A%3Aarmcli%0Az.urdf" in r.stdout or "%0D" in r.stdout
    assert len(r.stderr.splitlines()) == len(re.split(r"\r\n|\r|\n", r.stderr.rstrip("\n")))


def test_hash_in_a_file_name_is_part_of_the_file() -> None:
    f = Finding("mass-nonpositive", "error", "robots/a#b.urdf", 7, "mass -0.3 kg")
    assert to_github([f]).startswith(
        "::error file=robots/a#b.urdf,line=7,"
    )  # before: file=robots/a
    spec = Finding("mass-nonpositive", "error", "robot.yaml#arm.urdf", 7, "mass -0.3 kg")
    assert to_github([spec]).startswith("::error file=robot.yaml,title=")  # a spec's URDF part
    assert to_github([spec]).rstrip().endswith("::arm.urdf:7: mass -0.3 kg")


@pytest.mark.parametrize(
    ("source", "split"),
    [
        ("a#b.urdf", ("a#b.urdf", "")),
        ("robot.yaml#arm.urdf", ("robot.yaml", "arm.urdf")),
        ("my#robot.yaml#arm.urdf", ("my#robot.yaml", "arm.urdf")),
        ("x#y.xacro#expanded", ("x#y.xacro", "expanded")),
        ("robot.yaml#../arm.urdf", ("robot.yaml#../arm.urdf", "")),
    ],
)
def test_split_source(source: str, split: tuple[str, str]) -> None:
    assert split_source(source) == split


def test_one_line_escapes_every_line_break_and_control() -> None:
    text = "a\nb\rc\x1b[31md\x85e\u2028f\u2029g\x00h\x7f"
    assert one_line(text) == "a\\nb\\rc\\x1b[31md\\x85e\\u2028f\\u2029g\\x00h\\x7f"
    assert one_line("plain: ü, 1e-3 kg·m²") == "plain: ü, 1e-3 kg·m²"


XACRO_NOTE = (
    '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
    '<xacro:arg name="x" default="v&#10;::add-mask::ARG&#13;::error::bad"/>'
    '<link name="base"><inertial><mass value="1"/>'
    '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link></robot>'
)


@pytest.mark.parametrize("fmt", ["github", "table"])
def test_notes_on_stderr_cannot_inject_workflow_commands(fmt: str, tmp_path: Path) -> None:
    """The `note:` line of a xacro file names the file and its argument defaults, both
    the author's: a newline in either started a `::add-mask::` line on stderr."""
    evil = tmp_path / "a\n::add-mask::FILE\nb.urdf.xacro"
    evil.write_text(XACRO_NOTE)
    other = tmp_path / "c.urdf.xacro"  # two files: the note names its file
    other.write_text(XACRO_NOTE)
    r = armcli("check", "--format", fmt, evil, other)
    assert r.returncode in (0, 1), r.stderr
    assert "defaults taken x:=v\\n::add-mask::ARG\\r::error::bad" in r.stderr
    for stream in (r.stdout, r.stderr):
        for line in commands(stream):
            assert ANNOTATION.match(line), line  # before: "::add-mask::ARG", "::error::bad"
