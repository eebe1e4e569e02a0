"""Mass and inertia rules: one finding per bad mass, and the tiny-tensor verdict
(`inertia-not-pd`) agreeing with MuJoCo's compiler on iCub's ankle tensor."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from lxml import etree

from armcli.check.run import check_urdf
from armcli.urdf.read import parse_urdf
from tests.check.edited import findings


def test_nan_mass_is_one_finding() -> None:
    def edit(r: Any) -> None:
        r.find("link[@name='hand_link']/inertial/mass").set("value", "nan")

    assert [f.rule for f in findings(edit)] == ["non-finite"]


def test_negative_mass_is_one_finding() -> None:
    def edit(r: Any) -> None:
        r.find("link[@name='hand_link']/inertial/mass").set("value", "-0.3")

    assert [f.rule for f in findings(edit)] == ["mass-nonpositive"]


# A moving ankle with iCub's tensor (icub.urdf, l_ankle_2) and a foot fixed to it.
ANKLE = """<robot name="ankle">
  <link name="shin"/>
  <link name="ankle"><inertial><origin xyz="0.008 0 0.0553"/><mass value="0.2675"/>
    <inertia {tensor}/></inertial></link>
  <link name="foot"><inertial><mass value="0.5"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.002"/></inertial></link>
  <joint name="ankle_roll" type="revolute"><parent link="shin"/><child link="ankle"/>
    <axis xyz="1 0 0"/><limit lower="-0.4" upper="0.4" effort="11" velocity="100"/></joint>
  <joint name="foot_fixed" type="fixed"><parent link="ankle"/><child link="foot"/>
    <origin xyz="0.008 0 0.0553"/></joint>
</robot>"""
ICUB = 'ixx="0" ixy="0" ixz="1.35525e-20" iyy="0" iyz="0" izz="0"'
ZERO = 'ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"'
NOISE_DIAG = 'ixx="1e-20" ixy="0" ixz="0" iyy="1e-20" iyz="0" izz="1e-20"'


def mujoco_accepts(urdf: str) -> bool:
    """MuJoCo's compiler with inertias taken as written (as test_corpus.py does)."""
    import mujoco

    root = etree.fromstring(urdf)
    extra = etree.SubElement(root, "mujoco")
    etree.SubElement(
        extra,
        "compiler",
        inertiafromgeom="false",
        balanceinertia="false",
        boundmass="0",
        boundinertia="0",
    )
    try:
        mujoco.MjModel.from_xml_string(etree.tostring(root).decode())
    except ValueError:
        return False
    return True


@pytest.mark.parametrize("tensor", [ICUB, ZERO, NOISE_DIAG], ids=["icub", "zero", "noise"])
def test_tiny_tensor_verdict_agrees_with_mujoco(
    tensor: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    pytest.importorskip("mujoco")
    monkeypatch.chdir(tmp_path)  # MuJoCo may write MUJOCO_LOG.TXT
    urdf = ANKLE.format(tensor=tensor)
    result = check_urdf(parse_urdf(urdf.encode(), "ankle.urdf"))
    ours = [f for f in result.findings if f.rule == "inertia-not-pd"]
    assert (not ours) == mujoco_accepts(urdf)
    if tensor == ICUB:  # MuJoCo: "inertia must have positive eigenvalues"
        assert len(ours) == 1 and "rounding noise" in ours[0].message
