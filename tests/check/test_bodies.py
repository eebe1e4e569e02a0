"""`mass-nonpositive` on moving bodies says what MuJoCo really does (issue 19).

The message said "MuJoCo rejects it" for files MuJoCo loads: its URDF import gives a
link without <inertial> a mass from its collision geometry. The reference here is
MuJoCo itself, compiling each case.
"""

from __future__ import annotations

import pytest

from armcli.check.options import CheckOptions
from armcli.check.run import check_urdf
from armcli.urdf.read import parse_urdf

ROBOT = (
    '<robot name="r"><link name="a"><inertial><mass value="1"/>'
    '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>'
    '{b}<joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>'
    '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>'
)
BOX = '<geometry><box size="0.1 0.1 0.1"/></geometry>'
ZERO = (
    '<inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/>'
    "</inertial>"
)
CASES = {
    "collision-no-inertial": f'<link name="b"><collision>{BOX}</collision></link>',
    "visual-only": f'<link name="b"><visual>{BOX}</visual></link>',
    "empty": '<link name="b"/>',
    "zero-mass-with-collision": f'<link name="b">{ZERO}<collision>{BOX}</collision></link>',
}


@pytest.mark.parametrize("case", CASES)
def test_massless_body_message_matches_mujoco(case: str) -> None:
    mujoco = pytest.importorskip("mujoco")
    xml = ROBOT.format(b=CASES[case])
    try:
        mujoco.MjModel.from_xml_string(xml)
        loads = True
    except ValueError:
        loads = False
    findings = check_urdf(parse_urdf(xml.encode(), "r.urdf"), CheckOptions()).findings
    [mass] = [f for f in findings if f.rule == "mass-nonpositive"]
    assert "has no mass" in mass.message
    assert ("MuJoCo refuses it" in mass.message) == (not loads), mass.message
    assert ("MuJoCo's URDF import loads it" in mass.message) == loads, mass.message
