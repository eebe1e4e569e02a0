"""Links in the general form: shape lists, shape references, inertial sources, materials."""

from __future__ import annotations

import pytest

from armcli.errors import SpecError
from armcli.spec.load import loads_spec
from armcli.spec.model import RobotSpec

HEAD = """
name: shapes
materials: {grey: {rgba: [0.5, 0.5, 0.5, 1]}}
arm:
  links:
    base_link:
"""


def _spec(link: str) -> RobotSpec:
    body = "\n".join("      " + ln for ln in link.strip("\n").splitlines())
    return loads_spec(HEAD + body + "\n", "specs/shapes.yaml")


def _problems(link: str) -> list[str]:
    with pytest.raises(SpecError) as info:
        _spec(link)
    return info.value.lines()


def test_shorthand_reads_as_the_general_form() -> None:
    spec = _spec(
        "geometry: {box: {size: [1, 2, 3]}}\norigin: {xyz: [0, 0, 1]}\nmaterial: grey\nmass: 2"
    )
    link = spec.arm.links["base_link"]
    assert link.shorthand
    (visual,) = link.visuals()
    (collision,) = link.collisions()
    assert visual.geometry == collision.geometry and visual.origin == collision.origin
    assert visual.material == "grey" and collision.material is None
    source = link.inertial_source()
    assert source is not None and source.mass == 2 and link.shape(source.shape or "") == visual


def test_shape_references_by_index_and_name() -> None:
    spec = _spec(
        """
visual:
  - {geometry: {sphere: {radius: 0.1}}}
  - name: shell
    geometry: {mesh: {filename: package://pkg/meshes/a.stl, scale: [0.001, 0.001, 0.001]}}
collision:
  - {geometry: {cylinder: {radius: 0.1, length: 0.2}}}
inertial: {shape: collision, density: 1000}
"""
    )
    link = spec.arm.links["base_link"]
    assert link.shape("visual.1").name == "shell"
    assert link.shape("shell").geometry.mesh is not None
    assert link.shape("collision").geometry.kind == "cylinder"
    with pytest.raises(ValueError, match=r"known: visual\.0, visual\.1, collision\.0, shell"):
        link.shape("visual.2")


@pytest.mark.parametrize(
    ("link", "field", "fragment"),
    [
        ("inertial: {shape: visual.3, mass: 1}\nvisual: [{geometry: {sphere: {radius: 1}}}]",
         "arm.links.base_link", "no shape 'visual.3'"),
        ("visual: [{geometry: {sphere: {radius: 1}}}]\ninertial: {shape: visual}",
         "arm.links.base_link.inertial", "exactly one of mass, density"),
        ("visual: [{geometry: {sphere: {radius: 1}}}]\n"
         "inertial: {shape: visual, mass: 1, inertia: {ixx: 1, iyy: 1, izz: 1}}",
         "arm.links.base_link.inertial", "give them or a shape"),
        ("inertial: {mass: 1}", "arm.links.base_link.inertial", "mass and inertia"),
        ("inertial: {density: 3, mass: 1, inertia: {ixx: 1, iyy: 1, izz: 1}}",
         "arm.links.base_link.inertial", "density needs a shape"),
        ("geometry: {sphere: {radius: 1}}\nmass: 1\nvisual: [{geometry: {sphere: {radius: 1}}}]",
         "arm.links.base_link", "either geometry"),
        ("collision: [{geometry: {sphere: {radius: 1}}, material: grey}]",
         "arm.links.base_link", "collision shape has no material"),
        ("visual: [{geometry: {sphere: {radius: 1}}, material: purple}]",
         "arm.links.base_link.visual[0].material", "unknown material 'purple'"),
        ("visual: [{geometry: {mesh: {filename: 'http://evil/x.stl'}}}]",
         "arm.links.base_link.visual[0].geometry.mesh.filename", "unsupported URI scheme"),
        ("visual: [{geometry: {mesh: {filename: a.stl, scale: [1, 0, 1]}}}]",
         "arm.links.base_link.visual[0].geometry.mesh.scale", "flattens"),
        ("visual: [{geometry: {box: {size: [1, 1, 1]}, sphere: {radius: 1}}}]",
         "arm.links.base_link.visual[0].geometry", "exactly one of box, cylinder, sphere, mesh"),
        ("origin: {xyz: [0, 0, 1]}", "arm.links.base_link", "without geometry"),
    ],
)  # fmt: skip
def test_link_mistakes_name_the_field(link: str, field: str, fragment: str) -> None:
    lines = _problems(link)
    hits = [ln for ln in lines if f" {field}: " in ln]
    assert hits, lines
    assert fragment in hits[0]


def test_explicit_inertial_keeps_its_numbers() -> None:
    spec = _spec(
        "inertial: {mass: 0, origin: {xyz: [0, 0, 0.1]}, "
        "inertia: {ixx: 1e-6, ixy: -2e-7, iyy: 2e-6, izz: 3e-6}}"
    )
    inertial = spec.arm.links["base_link"].inertial
    assert inertial is not None and inertial.inertia is not None
    assert inertial.mass == 0.0  # massless dummy links exist in real URDFs
    assert inertial.inertia.values() == (1e-6, -2e-7, 0.0, 2e-6, 0.0, 3e-6)


def test_inline_material_takes_any_urdf_name() -> None:
    spec = _spec(
        "visual: [{geometry: {box: {size: [1, 1, 1]}}, "
        "material: {name: 'Grey Steel', rgba: [0.4, 0.4, 0.4, 1]}}]"
    )
    material = spec.arm.links["base_link"].visual[0].material
    assert not isinstance(material, str) and material is not None
    assert material.name == "Grey Steel" and material.rgba == (0.4, 0.4, 0.4, 1)
