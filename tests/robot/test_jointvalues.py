"""Joint values as a user types them (plan --to, render --q) and the limits' edge."""

from __future__ import annotations

import math

import pytest

from armcli.errors import InputError
from armcli.robot.jointvalues import SNAP, parse_joint_values, snap_to_limits

JOINTS = ("shoulder", "elbow")


def test_positional_and_named_values_take_pi_expressions() -> None:
    assert parse_joint_values("pi/2, -pi/4", JOINTS, "q") == {
        "shoulder": math.pi / 2,
        "elbow": -math.pi / 4,
    }
    assert parse_joint_values("elbow=3*pi/4", JOINTS, "q") == {"elbow": 3 * math.pi / 4}


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("1,2,3", "expected 2 value(s), one for each of shoulder, elbow"),
        ("wrist=1", "unknown joint 'wrist'; valid: shoulder, elbow"),
        ("1,__import__", "elbow: only numbers, pi and + - * / are allowed"),
        ("1,1/0", "elbow: division by zero"),
    ],
)
def test_bad_values_name_the_field_and_the_valid_joints(text: str, words: str) -> None:
    with pytest.raises(InputError) as info:
        parse_joint_values(text, JOINTS, "--to")
    assert info.value.field == "--to" and words in info.value.message


def test_a_hair_beyond_a_limit_is_the_limit_with_a_note() -> None:
    limits = {"shoulder": (0.0, math.pi / 2), "elbow": (0.0, math.pi / 2)}
    # 1.5708 is pi/2 as printed to 5 significant digits (3.7e-6 above it)
    values, notes = snap_to_limits({"shoulder": 1.5708, "elbow": -0.5 * SNAP}, limits)
    assert values == {"shoulder": math.pi / 2, "elbow": 0.0}
    assert len(notes) == 2 and "upper limit" in notes[0] and "lower limit" in notes[1]
    far = {"shoulder": math.pi / 2 + 2 * SNAP, "elbow": 0.3}  # beyond: left for the refusal
    assert snap_to_limits(far, limits) == (far, [])
