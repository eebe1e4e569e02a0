"""armcli.robot.bodies against Pinocchio: its URDF parser lumps fixed-joint links into the
moving body, and its `Inertia` adds rigid inertias; both are independent references."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from armcli.robot import bodies
from armcli.robot.frames import rpy_matrix
from armcli.urdf.read import parse_urdf

LUMP_TOL = 1e-12  # [kg, m, kg·m²] two engines summing the same terms in another order

# A hinge carrying an arm link, a tilted sensor fixed to it and a tool fixed to the sensor
# (a chain of fixed joints), each with an offset, rotated inertial.
URDF = b"""<robot name="lump">
  <link name="base"/>
  <link name="arm"><inertial><origin xyz="0.1 0.02 -0.03" rpy="0.3 -0.2 0.5"/>
    <mass value="2.0"/><inertia ixx="0.02" ixy="0.001" ixz="-0.002" iyy="0.03" iyz="0.0005"
    izz="0.015"/></inertial></link>
  <link name="sensor"><inertial><origin xyz="0.01 0 0.02" rpy="0.1 0.4 -0.3"/>
    <mass value="0.3"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0.0001"
    izz="0.0015"/></inertial></link>
  <link name="tool"><inertial><origin xyz="0 0 0.05"/><mass value="0.5"/>
    <inertia ixx="0.004" ixy="0" ixz="0" iyy="0.004" iyz="0" izz="0.001"/></inertial></link>
  <link name="marker"/>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.5" rpy="0 0.2 0"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
  <joint name="sensor_mount" type="fixed"><parent link="arm"/><child link="sensor"/>
    <origin xyz="0.3 0 0.1" rpy="0.5 0 1.0"/></joint>
  <joint name="tool_mount" type="fixed"><parent link="sensor"/><child link="tool"/>
    <origin xyz="0 0.1 0.05" rpy="0 -0.7 0"/></joint>
  <joint name="marker_mount" type="fixed"><parent link="tool"/><child link="marker"/></joint>
</robot>"""


def test_lumped_body_equals_pinocchios_body() -> None:
    doc = parse_urdf(URDF, "lump.urdf")
    links = {lk.name: lk for lk in doc.links}
    body = bodies.lump(links, doc.joints[0], doc.joints)
    assert body.links == ("arm", "sensor", "tool", "marker") and not body.unknown
    model = pin.buildModelFromXML(URDF.decode())
    ref = model.inertias[model.getJointId("hinge")]  # in the joint frame = arm's frame
    assert body.mass == pytest.approx(ref.mass, abs=LUMP_TOL)
    assert np.allclose(body.com, ref.lever, atol=LUMP_TOL)
    assert np.allclose(body.inertia, ref.inertia, atol=LUMP_TOL)


def _random_mass(rng: np.random.Generator) -> bodies.Mass:
    A = rng.normal(size=(3, 3))
    return bodies.Mass(float(rng.uniform(0.1, 3.0)), rng.normal(size=3), A @ A.T + 0.01 * np.eye(3))


def test_combine_equals_pinocchios_inertia_sum() -> None:
    rng = np.random.default_rng(28)
    parts = [_random_mass(rng) for _ in range(4)]
    ref = pin.Inertia.Zero()
    for p in parts:
        ref += pin.Inertia(p.mass, p.com, p.J)
    got = bodies.combine(parts)
    assert got.mass == pytest.approx(ref.mass, abs=LUMP_TOL)
    assert np.allclose(got.com, ref.lever, atol=LUMP_TOL)
    assert np.allclose(got.J, ref.inertia, atol=LUMP_TOL)
    assert bodies.join(parts[0], None) is parts[0] and bodies.join(None, None) is None


def test_moved_is_pinocchios_placement_and_inverts() -> None:
    rng = np.random.default_rng(1)
    x = _random_mass(rng)
    xyz, rpy = (0.2, -0.1, 0.4), (0.3, -0.5, 1.1)
    up = bodies.moved(x, xyz, rpy)
    M = pin.SE3(rpy_matrix(rpy), np.array(xyz))  # the child frame in the parent's
    ref = M.act(pin.Inertia(x.mass, x.com, x.J))
    assert np.allclose(up.com, ref.lever, atol=LUMP_TOL)
    assert np.allclose(up.J, ref.inertia, atol=LUMP_TOL)
    back = bodies.moved(up, xyz, rpy, inverse=True)
    assert np.allclose(back.com, x.com, atol=LUMP_TOL) and np.allclose(back.J, x.J, atol=LUMP_TOL)


def test_unusable_numbers_mark_the_body_unknown() -> None:
    doc = parse_urdf(URDF.replace(b'<mass value="0.3"/>', b'<mass value="nan"/>'), "nan.urdf")
    links = {lk.name: lk for lk in doc.links}
    body = bodies.lump(links, doc.joints[0], doc.joints)
    assert body.unknown
    assert body.mass == pytest.approx(2.0 + 0.5, abs=LUMP_TOL)  # arm and tool: the sensor left out
