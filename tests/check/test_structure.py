"""`material-conflict` only between named materials (issue 19: 26 warnings fired on
visuals' own unnamed colours in real descriptions)."""

from __future__ import annotations

from armcli.check.rules import CheckOptions
from armcli.check.run import check_urdf
from armcli.urdf.read import parse_urdf


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
