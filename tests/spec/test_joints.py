"""Joint additions: mimic, safety controller, calibration, and their cross-checks."""

from __future__ import annotations

import pytest

from armcli.errors import SpecError
from armcli.spec.load import loads_spec

SPEC = """
name: fingers
arm:
  links:
    palm: {{}}
    left: {{}}
    right: {{}}
  joints:
    left_joint:
      type: prismatic
      parent: palm
      child: left
      axis: [0, 1, 0]
      limit: {{lower: 0, upper: 0.04, effort: 20, velocity: 0.1}}
      safety_controller:
        {{soft_lower_limit: 0.001, soft_upper_limit: 0.039, k_position: 20, k_velocity: 1}}
      calibration: {{rising: 0.01}}
    right_joint:
      type: prismatic
      parent: palm
      child: right
      axis: [0, -1, 0]
      limit: {{lower: 0, upper: 0.04, effort: 20, velocity: 0.1}}
      mimic: {mimic}
{extra}
"""


def _problems(mimic: str, extra: str = "") -> list[str]:
    with pytest.raises(SpecError) as info:
        loads_spec(SPEC.format(mimic=mimic, extra=extra), "fingers.yaml")
    return info.value.lines()


def test_mimic_and_safety_controller_load() -> None:
    spec = loads_spec(
        SPEC.format(mimic="{joint: left_joint, multiplier: -1, offset: 0.001}", extra="")
    )
    right = spec.arm.joints["right_joint"]
    assert right.mimic is not None
    assert (right.mimic.joint, right.mimic.multiplier, right.mimic.offset) == (
        "left_joint",
        -1,
        0.001,
    )
    left = spec.arm.joints["left_joint"]
    assert left.safety_controller is not None and left.safety_controller.k_position == 20
    assert left.calibration is not None and left.calibration.falling is None


@pytest.mark.parametrize(
    ("mimic", "extra", "field", "fragment"),
    [
        ("{joint: thumb}", "", "arm.joints.right_joint.mimic.joint", "unknown arm joint"),
        ("{joint: right_joint}", "", "arm.joints.right_joint.mimic.joint", "cannot mimic itself"),
        ("{joint: left_joint}", "control: {gains: {right_joint: {kp: 1, kd: 0}}}",
         "control.gains.right_joint", "give gains to the lead joint"),
        ("{joint: left_joint}", "poses: {open: {right_joint: 0.01}}",
         "poses.open.right_joint", "give the lead joint"),
        ("{joint: left_joint, multiplier: .nan}", "", "arm.joints.right_joint.mimic.multiplier",
         "finite"),
    ],
)  # fmt: skip
def test_mimic_mistakes(mimic: str, extra: str, field: str, fragment: str) -> None:
    lines = _problems(mimic, extra)
    hits = [ln for ln in lines if f" {field}: " in ln]
    assert hits, lines
    assert fragment in hits[0]


def test_a_revolute_limit_needs_both_bounds() -> None:
    text = SPEC.format(mimic="{joint: left_joint}", extra="").replace(
        "{lower: 0, upper: 0.04, effort: 20", "{upper: 0.04, effort: 20", 1
    )
    with pytest.raises(SpecError, match="limit needs lower and upper"):
        loads_spec(text)
