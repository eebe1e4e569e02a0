"""`--write`: only the gain values change; new joints get a line; read-only is refused."""

from __future__ import annotations

import stat
from pathlib import Path

import pytest

from armcli.errors import InputError
from armcli.spec.load import load_spec
from armcli.tune.write import fmt_gain, updated_text, write_gains
from tests.helpers import COURSE_GAINS, ROOT, gains_text

SPEC = ROOT / "specs" / "my_robot.yaml"


def test_only_the_values_change(tmp_path: Path) -> None:
    path = tmp_path / "robot.yaml"
    original = SPEC.read_text(encoding="utf-8")
    path.write_text(original, encoding="utf-8")
    write_gains(path, {"arm_base_forearm_joint": (163.71, 6.8696),
                       "forearm_hand_joint": (12345.6, 0.5)})  # fmt: skip
    new = path.read_text(encoding="utf-8")
    old_lines, new_lines = original.splitlines(), new.splitlines()
    changed = [i for i, (a, b) in enumerate(zip(old_lines, new_lines, strict=True)) if a != b]
    assert [new_lines[i].strip() for i in changed] == [
        "arm_base_forearm_joint: {kp: 163.7, kd: 6.87}",
        "forearm_hand_joint: {kp: 12350, kd: 0.5}",
    ]
    gains = load_spec(path).control.gains
    assert (gains["forearm_hand_joint"].kp, gains["arm_base_forearm_joint"].kd) == (12350, 6.87)


def test_block_style_entries_and_a_new_joint(tmp_path: Path) -> None:
    text = (
        gains_text(SPEC.read_text(encoding="utf-8"), COURSE_GAINS)
        .replace(
            "    arm_base_forearm_joint: {kp: 50, kd: 5}\n",
            "    arm_base_forearm_joint:\n      kp: 50   # hand-tuned\n      kd: 5\n",
        )
        .replace("    forearm_hand_joint: {kp: 50, kd: 5}\n", "")
    )
    new = updated_text(
        text,
        tmp_path / "x.yaml",
        {"arm_base_forearm_joint": (70, 7), "forearm_hand_joint": (30, 3)},
    )
    assert (
        "      kp: 70   # hand-tuned\n      kd: 7\n    forearm_hand_joint: {kp: 30, kd: 3}\n" in new
    )


def test_no_exponent_form() -> None:
    # PyYAML reads 1e+04 as a string; the writer must not produce it.
    assert fmt_gain(1e4) == "10000"
    assert fmt_gain(1.23456e-5) == "0.00001235"


def test_read_only_spec_is_refused_untouched(tmp_path: Path) -> None:
    path = tmp_path / "robot.yaml"
    path.write_text(SPEC.read_text(encoding="utf-8"), encoding="utf-8")
    before = path.read_bytes()
    path.chmod(stat.S_IRUSR)
    with pytest.raises(InputError, match="read-only"):
        write_gains(path, {"arm_base_forearm_joint": (1, 1)})
    assert path.read_bytes() == before


def test_private_symlinked_spec_stays_private_and_linked(tmp_path: Path) -> None:
    """Issue 20: `--write` made a 0600 spec 0644 and replaced a symlinked spec with a copy."""
    real = tmp_path / "configs" / "robot.yaml"
    real.parent.mkdir()
    real.write_text(SPEC.read_text(encoding="utf-8"), encoding="utf-8")
    real.chmod(0o600)
    link = tmp_path / "robot.yaml"
    link.symlink_to(real)
    write_gains(link, {"arm_base_forearm_joint": (163.71, 6.8696)})
    assert link.is_symlink()  # before: a plain file with the new gains; the real spec unchanged
    assert load_spec(real).control.gains["arm_base_forearm_joint"].kp == 163.7
    assert stat.S_IMODE(real.stat().st_mode) == 0o600  # before: 0644
