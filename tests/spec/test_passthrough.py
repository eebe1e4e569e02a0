"""Passthrough XML is data: nothing in it ever becomes xacro (issue 27).

xacro acts on the literal tag `xacro:include` whatever its namespace, and lxml may
write an element of the xacro namespace under any prefix, so a passthrough element or
attribute is refused when its namespace URI is a xacro one (under any prefix) or its
prefix is `xacro` (bound to anything); so is a comment that turns on xacro's comment
evaluation. `${`/`$(` text stays text (escaped). Each refusal names the file, the line
and the field.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from lxml import etree

from armcli.compiler.expand import expand_urdfs
from armcli.errors import SpecError
from armcli.spec.load import load_spec
from tests.helpers import SPECS

HOSTILE = {
    "include, xacro URI": '<gazebo xmlns:xacro="http://www.ros.org/wiki/xacro">'
    '<xacro:include filename="{secret}"/></gazebo>',
    "include, other prefix": '<gazebo xmlns:x="http://www.ros.org/wiki/xacro">'
    '<x:include filename="{secret}"/></gazebo>',
    "include, default namespace": '<gazebo><include xmlns="http://ros.org/wiki/xacro"'
    ' filename="{secret}"/></gazebo>',
    "include, xacro prefix on another URI": '<gazebo xmlns:xacro="urn:anything">'
    '<xacro:include filename="{secret}"/></gazebo>',
    "element renamed by xacro:element": '<gazebo xmlns:xacro="urn:x">'
    '<xacro:element xacro:name="link"/></gazebo>',
    "attribute in the xacro namespace": '<gazebo xmlns:q="http://www.ros.org/wiki/xacro"'
    ' q:name="x"/>',
    "comment evaluation switched on": "<gazebo><!-- xacro:eval-comments -->"
    "<!-- ${{1}} --></gazebo>",
    "substitution in a namespace URI": '<gazebo xmlns:v="urn:$(find x)"><v:a/></gazebo>',
    "root element itself": '<xacro:include xmlns:xacro="http://wiki.ros.org/xacro"'
    ' filename="{secret}"/>',
}


def _spec(tmp_path: Path, element: str) -> Path:
    text = (SPECS / "my_robot.yaml").read_text()
    quoted = element.replace("'", "''")
    path = tmp_path / "robot.yaml"
    path.write_text(f"{text.rstrip()}\npassthrough:\n  - '{quoted}'\n")
    return path


@pytest.mark.parametrize("case", sorted(HOSTILE))
def test_xacro_in_passthrough_is_refused_with_file_line_field(case: str, tmp_path: Path) -> None:
    secret = tmp_path / "secret.xml"
    secret.write_text('<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><leaked/></robot>')
    path = _spec(tmp_path, HOSTILE[case].format(secret=secret))
    with pytest.raises(SpecError) as info:
        expand_urdfs(load_spec(path))
    line = str(info.value)
    lineno = path.read_text().splitlines().index("passthrough:") + 2
    assert str(path) in line and f":{lineno}" in line and "passthrough[0]" in line, line
    assert "xacro" in line


def test_dollar_text_stays_text(tmp_path: Path) -> None:
    """`${`/`$(` in text, attributes and tails come out as written, not evaluated."""
    element = '<gazebo a="$(eval 1+1)">${1+1}<b/>$(find x)$${2}</gazebo>'
    urdfs = expand_urdfs(load_spec(_spec(tmp_path, element)))
    root = etree.fromstring(urdfs["my_robot.urdf"])
    gz = root.findall("gazebo")[-1]
    assert gz.get("a") == "$(eval 1+1)" and (gz.text or "").strip() == "${1+1}"
    assert (gz[0].tail or "").strip() == "$(find x)$${2}"


def test_foreign_namespaces_are_kept(tmp_path: Path) -> None:
    """Elements of other namespaces (a vendor's) are data and stay."""
    element = '<gazebo xmlns:v="urn:vendor"><v:plugin v:k="1">x</v:plugin></gazebo>'
    urdfs = expand_urdfs(load_spec(_spec(tmp_path, element)))
    assert b'<v:plugin v:k="1">x</v:plugin>' in urdfs["my_robot.urdf"]
