"""Mesh-derived inertials against independent references, and the refusal of open meshes.

References: the closed-form solid box, and a divergence-theorem sum over the same
triangles written in tests/meshes.py (no trimesh). Tolerance 1e-6 relative, as the
issue asks; the float32 coordinates of STL are used on both sides.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from lxml import etree

from armcli.compiler.expand import expand_urdfs
from armcli.compiler.massprops import mesh_mass_properties
from armcli.errors import InputError
from armcli.spec.load import load_spec
from armcli.spec.shapes import Geometry, Inertial, Mesh, Shape
from tests.meshes import (
    as_stored,
    box_triangles,
    house_triangles,
    mass_properties,
    prism_triangles,
    write_stl,
)

RTOL = 1e-6  # the tolerance for mesh inertias against an independent computation
ATOL_COM = 1e-9  # [m] float32 vertices: a few 1e-9 m of rounding on 0.1 m meshes

SPEC = """
name: meshy
arm:
  links:
    base_link:
      visual:
        - geometry: {{mesh: {{filename: meshes/house.stl, scale: {scale}}}}}
          origin: {{xyz: [0.01, -0.02, 0.03], rpy: [0.3, -0.2, 1.1]}}
      inertial: {{shape: visual, {amount}}}
    box_link:
      collision:
        - name: body
          geometry: {{mesh: {{filename: meshes/box.stl}}}}
      inertial: {{shape: body, mass: 2.0}}
    rod_link:
      collision:
        - geometry: {{mesh: {{filename: {rod}}}}}
      inertial: {{shape: collision, density: 2700}}
  joints:
    j1: {{type: revolute, parent: base_link, child: box_link,
         limit: {{lower: -1, upper: 1, effort: 5, velocity: 2}}}}
    j2: {{type: fixed, parent: box_link, child: rod_link}}
"""


def _inertial(urdf: bytes, link: str) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    el = etree.fromstring(urdf).find(f"link[@name='{link}']/inertial")
    assert el is not None
    i = {k: float(v) for k, v in el.find("inertia").attrib.items()}  # type: ignore[union-attr]
    J = np.array(
        [
            [i["ixx"], i["ixy"], i["ixz"]],
            [i["ixy"], i["iyy"], i["iyz"]],
            [i["ixz"], i["iyz"], i["izz"]],
        ]
    )
    origin = el.find("origin")
    xyz = np.array([float(x) for x in origin.get("xyz").split()])  # type: ignore[union-attr]
    rpy = np.array([float(x) for x in origin.get("rpy").split()])  # type: ignore[union-attr]
    return float(el.find("mass").get("value")), xyz, rpy, J  # type: ignore[union-attr]


@pytest.fixture
def project(tmp_path: Path) -> Path:
    write_stl(tmp_path / "meshes" / "house.stl", house_triangles())
    write_stl(tmp_path / "meshes" / "box.stl", box_triangles((0.3, 0.2, 0.1), (0.05, 0, 0)))
    write_stl(tmp_path / "parts" / "rod.stl", prism_triangles(0.02, 0.4, 48))
    return tmp_path


def _build(project: Path, scale: str = "[1, 1, 1]", amount: str = "mass: 1.5") -> bytes:
    rod = (project / "parts" / "rod.stl").as_posix()  # an absolute path, as a spec may give
    spec_path = project / "robot.yaml"
    spec_path.write_text(SPEC.format(scale=scale, amount=amount, rod=rod))
    return expand_urdfs(load_spec(spec_path))["standalone_arm.urdf"]


def test_box_mesh_matches_the_solid_box_formula(project: Path) -> None:
    mass, xyz, rpy, J = _inertial(_build(project), "box_link")
    ref = pin.Inertia.FromBox(2.0, 0.3, 0.2, 0.1)  # closed form, about the centre
    assert mass == pytest.approx(2.0, rel=1e-12)
    np.testing.assert_allclose(J, ref.inertia, rtol=RTOL, atol=RTOL * np.max(ref.inertia))
    np.testing.assert_allclose(xyz, [0.05, 0, 0], atol=ATOL_COM)  # the box is off-centre
    assert list(rpy) == [0, 0, 0]


@pytest.mark.parametrize(
    ("scale", "amount"),
    [("[1, 1, 1]", "mass: 1.5"), ("[0.5, 2, 1.5]", "mass: 1.5"), ("[1, 1, 1]", "density: 800")],
)
def test_asymmetric_mesh_matches_the_divergence_theorem(
    project: Path, scale: str, amount: str
) -> None:
    """Volume, centre of mass and tensor of a roofed box under scale, offset and rotation."""
    s = np.array([float(x) for x in scale.strip("[]").split(",")])
    tris = [tuple(v * s for v in t) for t in as_stored(house_triangles())]
    volume = mass_properties(tris, 1.0)[0]
    density = 800.0 if "density" in amount else 1.5 / volume
    m_ref, com_ref, J_ref = mass_properties(tris, density)  # in the mesh frame
    mass, xyz, rpy, J = _inertial(_build(project, scale, amount), "base_link")
    R = pin.rpy.rpyToMatrix(0.3, -0.2, 1.1)  # the visual's origin
    assert mass == pytest.approx(m_ref, rel=RTOL)
    np.testing.assert_allclose(xyz, np.array([0.01, -0.02, 0.03]) + R @ com_ref, atol=ATOL_COM)
    np.testing.assert_allclose(rpy, [0.3, -0.2, 1.1], rtol=0, atol=0)  # tensor in the shape frame
    np.testing.assert_allclose(J, J_ref, rtol=RTOL, atol=RTOL * np.max(np.abs(J_ref)))


def test_faceted_cylinder_by_density(project: Path) -> None:
    tris = as_stored(prism_triangles(0.02, 0.4, 48))
    m_ref, _, J_ref = mass_properties(tris, 2700.0)
    mass, _, _, J = _inertial(_build(project), "rod_link")
    assert mass == pytest.approx(m_ref, rel=RTOL)
    np.testing.assert_allclose(J, J_ref, rtol=RTOL, atol=RTOL * np.max(J_ref))
    # and a 48-gon is close to the round cylinder (a sanity check of the reference itself)
    round_mass = 2700.0 * math.pi * 0.02**2 * 0.4
    assert mass == pytest.approx(round_mass, rel=0.01)


def test_open_mesh_is_refused_naming_the_file(project: Path) -> None:
    write_stl(project / "meshes" / "box.stl", box_triangles((0.3, 0.2, 0.1))[:-1])  # a hole
    with pytest.raises(InputError) as info:
        _build(project)
    assert "meshes/box.stl" in str(info.value)
    assert "open or non-manifold" in str(info.value)
    assert info.value.field == "arm.links.box_link.inertial.shape"


def test_missing_mesh_is_refused_naming_the_file(project: Path) -> None:
    (project / "meshes" / "box.stl").unlink()
    with pytest.raises(InputError, match=r"mesh file meshes/box.stl not found"):
        _build(project)


@pytest.mark.parametrize("scale", [1e200, -1e200])
def test_a_huge_mesh_scale_is_one_input_error(scale: float, tmp_path: Path) -> None:
    """Issue 27: a scale of 1e200 overflowed to a NaN mass (then an internal error)."""
    write_stl(tmp_path / "house.stl", house_triangles())
    shape = Shape(geometry=Geometry(mesh=Mesh(filename="house.stl", scale=(scale,) * 3)))
    with pytest.raises(InputError, match="non-finite volume or inertia"):
        mesh_mass_properties(shape, Inertial(shape="visual", mass=1.0), tmp_path)
