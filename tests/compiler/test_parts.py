"""Reusable parts: the course's wheel macro, and mirrored left/right arms checked by
Pinocchio (the right arm's frames are the reflection of the left arm's, for every pose)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from lxml import etree

from armcli.compiler.expand import expand_urdfs
from armcli.compiler.xacro_writer import xacro_files
from armcli.errors import SpecError
from armcli.importer.compare import compare_urdf
from armcli.spec.load import loads_spec
from armcli.spec.parts import mirror_axis, mirror_origin
from armcli.spec.shapes import Origin
from tests.helpers import DEFAULT_SPEC, ROOT

FK_TOL = 1e-12  # [m], [-]: a reflection is exact up to rounding
M = np.diag([1.0, -1.0, 1.0])  # reflection through the x-z plane


def course_with_wheel_part() -> str:
    """specs/my_robot.yaml with its two wheel links written once, as the course's macro."""
    s = DEFAULT_SPEC.read_text()
    s = s[: s.index("    base_right_wheel_link:")] + s[s.index("    caster_wheel_link:") :]
    s = s[: s.index("    base_right_wheel_joint:")] + s[s.index("    caster_wheel_joint:") :]
    placements = "\n".join(
        f"    - {{part: wheel, prefix: base_{side}_, parent: base_link, "
        f"joint: base_{side}_wheel_joint, type: continuous, "
        f"origin: {{xyz: [-0.15, {y}, 0]}}, axis: [0, 1, 0]}}"
        for side, y in (("right", -0.225), ("left", 0.225))
    )
    s = s.replace("  diff_drive:", f"  parts:\n{placements}\n  diff_drive:")
    part = (
        "parts:\n  wheel:\n    links:\n      wheel_link:\n"
        "        geometry: {cylinder: {radius: 0.1, length: 0.05}}\n"
        "        origin: {rpy: [pi/2, 0, 0]}\n        material: grey\n        mass: 1.0\n\n"
    )
    return s.replace("mobile_base:", part + "mobile_base:", 1)


def test_the_wheel_macro_builds_the_course_robot() -> None:
    spec = loads_spec(course_with_wheel_part())
    built = etree.fromstring(expand_urdfs(spec)["my_robot.urdf"])
    committed = etree.parse(str(ROOT / "urdf" / "my_robot.urdf")).getroot()
    assert compare_urdf(committed, built) == []
    base = xacro_files(spec)["mobile_base.xacro"].decode()
    assert '<xacro:macro name="wheel" params="prefix">' in base
    assert '<link name="${prefix}wheel_link">' in base
    assert base.count("<xacro:wheel prefix=") == 2 and "reflect" not in base


ARMS = """
name: two_arms
parts:
  arm:
    links:
      shoulder:
        visual:
          - geometry: {box: {size: [0.05, 0.08, 0.1]}}
            origin: {xyz: [0.01, 0.03, 0.05], rpy: [0.2, 0.1, 0.3]}
        inertial:
          mass: 1.2
          origin: {xyz: [0.01, 0.02, 0.04], rpy: [0.1, 0.2, 0.3]}
          inertia: {ixx: 0.004, ixy: 0.0005, ixz: 0.0003, iyy: 0.005, iyz: -0.0004, izz: 0.003}
      upper:
        geometry: {cylinder: {radius: 0.03, length: 0.3}}
        origin: {xyz: [0, 0.02, 0.15], rpy: [0, 0.1, 0]}
        mass: 0.8
      slider:
        geometry: {box: {size: [0.02, 0.03, 0.1]}}
        origin: {xyz: [0.01, -0.01, 0.05]}
        mass: 0.2
    joints:
      elbow: {type: revolute, parent: shoulder, child: upper, axis: [0.2, 1, 0.3],
              origin: {xyz: [0, 0.05, 0.1], rpy: [0.3, -0.2, 0.5]},
              limit: {lower: -2, upper: 2, effort: 10, velocity: 2}}
      slide: {type: prismatic, parent: upper, child: slider, axis: [0.3, 0.5, 0.8],
              origin: {xyz: [0.02, 0.01, 0.3]},
              limit: {lower: 0, upper: 0.1, effort: 10, velocity: 1}}
arm:
  links:
    torso: {geometry: {box: {size: [0.2, 0.4, 0.5]}}, origin: {xyz: [0, 0, 0.25]}, mass: 10}
  parts:
    - {part: arm, prefix: left_, parent: torso, joint: left_shoulder_joint, type: revolute,
       origin: {xyz: [0.05, 0.2, 0.45], rpy: [0.4, 0.1, 0.2]}, axis: [0.1, 0.2, 1],
       limit: {lower: -3, upper: 3, effort: 20, velocity: 2}}
    - {part: arm, prefix: right_, parent: torso, joint: right_shoulder_joint, type: revolute,
       origin: {xyz: RIGHT_XYZ, rpy: RIGHT_RPY}, axis: RIGHT_AXIS,
       limit: {lower: -3, upper: 3, effort: 20, velocity: 2}, mirror: true}
"""


def _arms_spec() -> str:
    left = Origin(xyz=(0.05, 0.2, 0.45), rpy=(0.4, 0.1, 0.2))
    right = mirror_origin(left)
    axis = mirror_axis("revolute", (0.1, 0.2, 1.0))
    return (
        ARMS.replace("RIGHT_XYZ", str(list(right.xyz)))
        .replace("RIGHT_RPY", str(list(right.rpy)))
        .replace("RIGHT_AXIS", str(list(axis)))
    )


def test_a_mirrored_arm_is_the_reflection_of_the_left_in_every_pose() -> None:
    spec = loads_spec(_arms_spec())
    xml = expand_urdfs(spec)["standalone_arm.urdf"].decode()
    model = pin.buildModelFromXML(xml)
    data = model.createData()
    rng = np.random.default_rng(0)
    left = ["left_shoulder_joint", "left_elbow", "left_slide"]
    for _ in range(20):
        q = pin.neutral(model)
        for name, v in zip(left, rng.uniform([-3, -2, 0], [3, 2, 0.1]), strict=True):
            for side in ("left_", "right_"):
                q[model.idx_qs[model.getJointId(name.replace("left_", side))]] = v
        pin.forwardKinematics(model, data, q)
        pin.centerOfMass(model, data, q)
        for name in left:
            a = data.oMi[model.getJointId(name)]
            b = data.oMi[model.getJointId(name.replace("left_", "right_"))]
            np.testing.assert_allclose(b.translation, M @ a.translation, atol=FK_TOL)
            np.testing.assert_allclose(b.rotation, M @ a.rotation @ M, atol=FK_TOL)
    # the whole robot's centre of mass lies on the mirror plane (the torso is symmetric)
    assert abs(data.com[0][1]) < FK_TOL


def test_the_mirrored_part_is_one_macro_with_reflect() -> None:
    arm = xacro_files(loads_spec(_arms_spec()))["arm.xacro"].decode()
    assert '<xacro:macro name="arm" params="prefix reflect">' in arm
    assert '<xacro:arm prefix="left_" reflect="1"/>' in arm
    assert '<xacro:arm prefix="right_" reflect="-1"/>' in arm
    assert 'ixy="${reflect*0.0005}"' in arm and 'iyz="${reflect*-0.0004}"' in arm


@pytest.mark.parametrize(
    ("old", "new", "fragment"),
    [
        ("{part: arm, prefix: left_", "{part: leg, prefix: left_", "unknown part 'leg'"),
        ("prefix: right_", "prefix: left_", "names already used: left_elbow"),
        ("parent: torso, joint: right_", "parent: nowhere, joint: right_", "unknown link"),
    ],
)
def test_placement_mistakes(old: str, new: str, fragment: str) -> None:
    with pytest.raises(SpecError) as info:
        loads_spec(_arms_spec().replace(old, new, 1))
    assert any(fragment in line for line in info.value.lines()), info.value.lines()
