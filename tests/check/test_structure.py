"""Document structure rules: the robot's name, materials defined once and only named ones
conflicting (26 warnings once fired on visuals' own unnamed colours in real descriptions)."""

from __future__ import annotations

from typing import Any

from lxml import etree

from armcli.check.options import CheckOptions
from armcli.check.run import check_urdf
from armcli.urdf.read import parse_urdf
from tests.check.edited import BASE, findings


def _visual(material: str) -> str:
    return f'<visual><geometry><box size="0.1 0.1 0.1"/></geometry>{material}</visual>'


def _conflicts(*materials: str) -> list[str]:
    links = "".join(f'<link name="l{i}">{_visual(m)}</link>' for i, m in enumerate(materials))
    joints = "".join(
        f'<joint name="j{i}" type="fixed"><parent link="l0"/><child link="l{i}"/></joint>'
        for i in range(1, len(materials))
    )
    xml = f'<robot name="r">{links}{joints}</robot>'.encode()
    findings = check_urdf(parse_urdf(xml, "r.urdf"), CheckOptions()).findings
    return [f.message for f in findings if f.rule == "material-conflict"]


def test_unnamed_materials_never_conflict() -> None:
    red, blue = '<color rgba="1 0 0 1"/>', '<color rgba="0 0 1 1"/>'
    assert (
        _conflicts(f'<material name="">{red}</material>', f'<material name="">{blue}</material>')
        == []
    )
    assert _conflicts(f"<material>{red}</material>", f"<material>{blue}</material>") == []
    named = _conflicts(
        f'<material name="paint">{red}</material>', f'<material name="paint">{blue}</material>'
    )
    assert named == [
        "material 'paint' redefined: rgba [0.0, 0.0, 1.0, 1.0] vs [1.0, 0.0, 0.0, 1.0]"
    ]


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
