"""Spec validation: the default spec loads, and every kind of mistake gets file:line field."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from armcli.errors import SpecError
from armcli.spec.load import load_spec, loads_spec


@pytest.fixture(scope="module")
def text(default_spec_path: Path) -> str:
    return default_spec_path.read_text()


def test_default_spec_holds_the_seed_values(default_spec_path: Path) -> None:
    spec = load_spec(default_spec_path)
    # Seed: two revolute joints 0..pi/2, effort 100, velocity 100, friction 0.05, damping 0.1.
    assert spec.movable_arm_joints() == ["arm_base_forearm_joint", "forearm_hand_joint"]
    for name in spec.movable_arm_joints():
        j = spec.arm.joints[name]
        assert j.type == "revolute"
        assert j.limit is not None and j.dynamics is not None
        assert (j.limit.lower, j.limit.upper) == (0.0, math.pi / 2)
        assert (j.limit.effort, j.limit.velocity) == (100.0, 100.0)
        assert (j.dynamics.friction, j.dynamics.damping) == (0.05, 0.1)
    links = spec.arm.links
    assert links["arm_base_link"].geometry.box.size == (0.1, 0.1, 0.02)
    assert links["forearm_link"].geometry.cylinder.radius == 0.02
    assert [links[n].mass for n in links] == [0.5, 0.3, 0.3]
    assert spec.arm.joint_state_publisher is not None
    assert spec.arm.joint_state_publisher.update_rate == 10
    assert spec.arm.joint_pose_trajectory is not None
    assert spec.arm.joint_pose_trajectory.update_rate == 2
    assert spec.arm_root() == "arm_base_link"
    assert "home" in spec.poses and len(spec.poses) >= 2


def _problems(text: str) -> list[str]:
    with pytest.raises(SpecError) as info:
        loads_spec(text, "specs/bad.yaml")
    return info.value.lines()


def _replace_in_arm(text: str, old: str, new: str) -> str:
    """Replace the first `old` at or after the `arm:` section (or anywhere if not there)."""
    start = text.index("\narm:")
    at = text.find(old, start)
    if at < 0:
        at = text.index(old)
    return text[:at] + new + text[at + len(old) :]


def _line_of(text: str, needle: str, start: int = 0) -> int:
    return text[: text.index(needle, start)].count("\n") + 1


def test_limits_out_of_order_names_file_line_and_field(text: str) -> None:
    start = text.index("forearm_hand_joint:")
    bad = text[:start] + text[start:].replace("upper: pi/2", "upper: -0.5", 1)
    lines = _problems(bad)
    line = _line_of(bad, "upper: -0.5")
    assert lines == [
        f"specs/bad.yaml:{line} arm.joints.forearm_hand_joint.limit.upper: must be >= lower (0)"
    ]


@pytest.mark.parametrize(
    ("old", "new", "field", "fragment"),
    [
        ("mass: 0.5", "mass: -0.5", "arm.links.arm_base_link.mass", "greater than 0"),
        ("mass: 0.5", "mass: .nan", "arm.links.arm_base_link.mass", "finite"),
        ("mass: 0.5", "mass: .inf", "arm.links.arm_base_link.mass", "finite"),
        ("mass: 0.5", "mass: heavy", "arm.links.arm_base_link.mass", "only numbers, pi"),
        ("mass: 0.5", "mass: true", "arm.links.arm_base_link.mass", "boolean"),
        ("mass: 0.5", "mass: 0.5\n      colour: red", "arm.links.arm_base_link.colour", "unknown"),
        (
            "effort: 100,",
            "effort: -1,",
            "arm.joints.arm_base_forearm_joint.limit.effort",
            "greater",
        ),
        (
            "parent: arm_base_link",
            "parent: nowhere",
            "arm.joints.arm_base_forearm_joint.parent",
            "unknown link",
        ),
        (
            "joints: [arm_base_forearm_joint,",
            "joints: [elbow,",
            "arm.joint_state_publisher.joints[0]",
            "unknown joint 'elbow'",
        ),
        (
            "material: orange",
            "material: purple",
            "arm.links.arm_base_link.material",
            "unknown material",
        ),
        (
            "rgba: [1.0, 0.5, 0.0, 1.0]",
            "rgba: [1.0, 1.5, 0.0, 1.0]",
            "materials.orange.rgba[1]",
            "less than or equal to 1",
        ),
        (
            "forearm_hand_joint: {kp: 50",
            "elbow_joint: {kp: 50",
            "control.gains.elbow_joint",
            "unknown arm joint",
        ),
        (
            "reach: {arm_base_forearm_joint: pi/4",
            "reach: {arm_base_forearm_joint: 2",
            "poses.reach.arm_base_forearm_joint",
            "outside the joint limits",
        ),
    ],
)
def test_field_errors(text: str, old: str, new: str, field: str, fragment: str) -> None:
    bad = _replace_in_arm(text, old, new)
    lines = _problems(bad)
    hits = [ln for ln in lines if f" {field}: " in ln]
    assert hits, lines
    assert fragment in hits[0]
    assert hits[0].startswith("specs/bad.yaml:")


def test_two_roots_and_unknown_mount(text: str) -> None:
    bad = text.replace("      child: hand_link\n", "      child: forearm_link\n", 1)
    lines = _problems(bad)
    assert any("arm.links: exactly one root link expected, found 2" in ln for ln in lines)


def test_every_problem_gets_its_own_line(text: str) -> None:
    bad = text.replace("mass: 0.5", "mass: -1", 1).replace("mass: 5.0", "mass: .nan", 1)
    lines = _problems(bad)
    assert len(lines) == 2


def test_not_a_mapping() -> None:
    assert _problems("- a\n- b\n") == ["specs/bad.yaml:1: a spec must be a YAML mapping"]
