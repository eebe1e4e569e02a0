"""CI output of findings in xacro files with hostile or undecodable names (issue 42).

Before: the expansion's source map listed its files one per line, so a finding in a file
included after one whose name held a newline was placed in the wrong file, the tail of the
hostile name (`file=::error title=INJ::.xacro` in the annotation); a file name with a
non-UTF-8 byte (reached by a glob include) was an internal UnicodeEncodeError in
`--format sarif`, and the raw byte went into the GitHub annotation and the table.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from tests.check.test_sarif import validate
from tests.helpers import ROOT

XACRO = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'
INERTIA = '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>'
EVIL = "a\n::error title=INJ::.xacro"


def _part(link: str, mass: str) -> str:
    return (
        f'<robot {XACRO}>\n<link name="{link}"><inertial><mass value="{mass}"/>{INERTIA}'
        f'</inertial></link>\n<joint name="j{link}" type="fixed"><parent link="base"/>'
        f'<child link="{link}"/></joint>\n</robot>\n'
    )


def _top(includes: str) -> str:
    base = f'<link name="base"><inertial><mass value="1"/>{INERTIA}</inertial></link>'
    return f'<robot name="r" {XACRO}>\n{includes}\n{base}\n</robot>\n'


def _check(cwd: Path, fmt: str) -> tuple[int, bytes, bytes]:
    """`armcli check top.urdf.xacro --format FMT`: exit code and the raw bytes it wrote."""
    proc = subprocess.run(
        [sys.executable, "-m", "armcli.cli", "check", "top.urdf.xacro", "--format", fmt],
        capture_output=True,
        timeout=120,
        check=False,
        cwd=cwd,
        env={**os.environ, "COLUMNS": "200", "PYTHONPATH": str(ROOT / "src")},
    )
    return proc.returncode, proc.stdout, proc.stderr


def test_a_name_with_a_newline_does_not_move_the_next_files_findings(tmp_path: Path) -> None:
    (tmp_path / EVIL).write_text(_part("a", "1"))
    (tmp_path / "b.xacro").write_text(_part("b", "-1"))
    includes = '<xacro:include filename="a&#10;::error title=INJ::.xacro"/>\n'
    (tmp_path / "top.urdf.xacro").write_text(_top(includes + '<xacro:include filename="b.xacro"/>'))
    code, out, err = _check(tmp_path, "github")
    assert code == 1, err
    lines = out.decode().splitlines()
    mass = [line for line in lines if "mass-nonpositive" in line]
    assert mass == [
        "::error file=b.xacro,line=2,title=armcli mass-nonpositive::link 'b': negative mass -1 kg"
        " (fix: give the link its real mass)"
    ]  # before: file=%3A%3Aerror title=INJ%3A%3A.xacro
    assert all(line.startswith(("::error file=", "::warning file=")) for line in lines), lines


def test_an_undecodable_file_name_is_shown_as_its_byte(tmp_path: Path) -> None:
    parts = tmp_path / "parts"
    parts.mkdir()
    (Path(os.fsdecode(bytes(parts) + b"/c\xff.xacro"))).write_text(_part("c", "-1"))
    (tmp_path / "top.urdf.xacro").write_text(_top('<xacro:include filename="parts/*.xacro"/>'))
    code, out, err = _check(tmp_path, "sarif")
    assert code == 1, err  # before: exit 1 with "internal error: UnicodeEncodeError"
    doc = json.loads(out.decode("utf-8"))  # strict UTF-8
    validate(doc)
    (result,) = [r for r in doc["runs"][0]["results"] if r["ruleId"] == "mass-nonpositive"]
    location = result["locations"][0]["physicalLocation"]
    assert location["artifactLocation"]["uri"] == "parts/c%FF.xacro"  # the byte, percent-encoded
    code, out, err = _check(tmp_path, "github")
    assert b"file=parts/c\\xff.xacro,line=2" in out  # before: the raw byte 0xff
    out.decode("utf-8")
    code, out, err = _check(tmp_path, "table")
    assert b"parts/c\\xff.xacro:2" in out
    out.decode("utf-8")
