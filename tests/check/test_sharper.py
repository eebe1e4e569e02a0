"""Issue 14's sharper `check`: limit-degrees as documented (both sides), the tiny-tensor
rule agreeing with MuJoCo, undefined materials, one finding per problem, numeric remedies."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest
from lxml import etree

from armcli.check.dynamics import EFFORT_MARGIN, round_up
from armcli.check.rules import CheckOptions
from armcli.check.run import check_urdf
from armcli.sim.verdict import round_down
from armcli.spec.load import load_spec
from armcli.urdf.read import parse_urdf
from tests.helpers import ROOT, course_gains_spec

BASE = (ROOT / "urdf" / "my_robot.urdf").read_bytes()
SPEC = load_spec(ROOT / "specs" / "my_robot.yaml")
G = 9.81  # [m/s²], Pinocchio's default gravity


def findings(edit: Any, spec: Any = None) -> list[Any]:
    root = etree.fromstring(BASE)
    edit(root)
    data = etree.tostring(root, xml_declaration=True, encoding="utf-8")
    return list(check_urdf(parse_urdf(data, "x.urdf"), CheckOptions(spec=spec)).findings)


def _joint(r: Any, name: str = "forearm_hand_joint") -> Any:
    return r.find(f"joint[@name='{name}']")


def limits(lower: str, upper: str) -> Any:
    def edit(r: Any) -> None:
        lim = _joint(r).find("limit")
        lim.set("lower", lower)
        lim.set("upper", upper)

    return edit


@pytest.mark.parametrize(
    ("lower", "upper", "fires"),
    [
        ("-10", "10", False),  # solo/bolt multi-turn range, docs/check.md: left alone
        ("-9.42477796", "9.42477796", False),  # 3 pi
        ("-1e16", "1e16", False),  # "unlimited" sentinel
        ("0", "15", True),  # the smallest round degree value flagged
        ("-90", "90", True),  # degrees typed as radians
        ("0", "360", True),
        ("0", "725", False),  # beyond 720: a sentinel, not degrees
    ],
)
def test_limit_degrees_both_sides(lower: str, upper: str, fires: bool) -> None:
    rules = {f.rule for f in findings(limits(lower, upper))}
    assert ("limit-degrees" in rules) is fires, rules


def test_limit_without_bounds_is_missing_limit_only() -> None:
    def edit(r: Any) -> None:
        lim = _joint(r).find("limit")
        del lim.attrib["lower"]
        del lim.attrib["upper"]

    fs = findings(edit)
    assert [f.rule for f in fs] == ["missing-limit"]
    assert "lower, upper" in fs[0].message


def test_nan_mass_is_one_finding() -> None:
    def edit(r: Any) -> None:
        r.find("link[@name='hand_link']/inertial/mass").set("value", "nan")

    assert [f.rule for f in findings(edit)] == ["non-finite"]


def test_negative_mass_is_one_finding() -> None:
    def edit(r: Any) -> None:
        r.find("link[@name='hand_link']/inertial/mass").set("value", "-0.3")

    assert [f.rule for f in findings(edit)] == ["mass-nonpositive"]


def test_nameless_robot_has_its_own_finding_and_line() -> None:
    data = BASE.replace(b'<robot name="my_robot"', b"<robot", 1)  # keeps the comments
    fs = check_urdf(parse_urdf(data, "x.urdf")).findings
    assert [f.rule for f in fs] == ["robot-name"]
    robot_line = next(i for i, t in enumerate(data.decode().splitlines(), 1) if "<robot" in t)
    assert fs[0].line == robot_line > 1


def _visual_material(name: str) -> Any:
    def edit(r: Any) -> None:
        r.find("link[@name='hand_link']/visual/material").set("name", name)

    return edit


def test_undefined_material_is_reported_once_per_name() -> None:
    def edit(r: Any) -> None:
        for link in ("hand_link", "forearm_link"):
            r.find(f"link[@name='{link}']/visual/material").set("name", "FlatBlack")

    fs = findings(edit)
    assert [(f.rule, f.values["material"]) for f in fs] == [("material-undefined", "FlatBlack")]


def test_material_with_only_a_texture_is_defined() -> None:
    def edit(r: Any) -> None:
        _visual_material("Tex")(r)
        r.insert(0, etree.fromstring('<material name="Tex"><texture filename="t.png"/></material>'))

    assert "material-undefined" not in {f.rule for f in findings(edit)}


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


def test_gravity_effort_remedy_covers_the_torque() -> None:
    def edit(r: Any) -> None:
        _joint(r, "arm_base_forearm_joint").find("limit").set("effort", "1")

    (f,) = [f for f in findings(edit) if f.rule == "gravity-effort"]
    # Worst gravity torque on joint 1: both 0.3 kg links horizontal, COMs at 0.15 and 0.45 m.
    torque = 0.3 * G * (0.15 + 0.45)
    assert f.values["gravity_max"] == pytest.approx(torque, rel=1e-9)
    assert f.fix["effort"] == round_up(EFFORT_MARGIN * torque) >= EFFORT_MARGIN * torque
    assert f'effort="{f.fix["effort"]:g}"' in f.message


def test_pd_remedy_is_stable(tmp_path: Path) -> None:
    """The suggested dt and Kd for the course gains must each make the explicit loop stable
    (docs/check.md: stable for dt <= 0.705 ms, or Kd x 0.697 with Kp kept)."""
    course = load_spec(course_gains_spec(tmp_path))  # the course's Kp 50, Kd 5
    (f,) = [f for f in findings(lambda r: None, course) if f.rule == "pd-explicit-unstable"]
    # 0.9 x the bounds, rounded down to 2 digits; Kp kept
    assert f.fix == {"dt": 0.00063, "kp": [50.0, 50.0], "kd": [3.1, 3.1]}
    lam = float(f.values["lambda_max"])  # type: ignore[arg-type]
    kp, damping = float(f.values["kp"]), 0.1  # type: ignore[arg-type]
    kd = float(f.values["kd_plus_damping"]) - damping  # type: ignore[arg-type]
    fixed_kd = max(f.fix["kd"])  # type: ignore[type-var]
    for dt, d in ((f.fix["dt"], kd + damping), (float(f.values["dt"]), fixed_kd + damping)):
        # Jury test on the semi-implicit Euler update: a + 2b < 4 (docs/check.md); with
        # equal gains the worst mode is lambda_max's.
        a, b = kp * float(dt) * float(dt) * lam, float(d) * float(dt) * lam  # type: ignore[arg-type]
        assert a + 2 * b < 4, (dt, d)


def test_rounding_helpers() -> None:
    assert round_up(4.3) == 4.3 and round_up(4.31) == 4.4 and round_up(0.0123) == 0.013
    assert round_down(0.000705) == 0.0007 and round_down(3.48) == 3.4
    assert math.isclose(round_up(2.6487), 2.7)
