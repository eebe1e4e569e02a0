"""`ros-controller-unstable` in `check DIR`: the controllers YAML's update_rate and gains.

ros-package's own output for every spec under specs/ passes on every target; the course
package at 100 Hz fails with exactly this rule on the `update_rate` line (the fixture of
test_rule_fixtures.py), and each remedy it writes passes when written into the file.
Whether the bound is right is tests/analysis/test_rate.py's (a zero-order-hold simulation).
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import yaml

from tests.check.ros_packages.workspaces import copy, edit, findings, generate, package_rules
from tests.helpers import SPECS

RULE = "ros-controller-unstable"
CONTROLLERS = "my_robot_bringup/config/my_robot_controllers.yaml"
EXAMPLES = sorted(SPECS.glob("*.yaml"))


@pytest.mark.parametrize("target", ["jazzy", "humble-classic"])
@pytest.mark.parametrize("spec", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_generated_packages_of_every_spec_pass(spec: Path, target: str, tmp_path: Path) -> None:
    found = findings(generate(tmp_path, target, spec))
    assert package_rules(found) == set(), [(f.rule, f.message) for f in found]
    assert not [f for f in found if f.rule.startswith("pd-")]


def _slow(jazzy_pkgs: Path, tmp_path: Path) -> Path:
    root = copy(jazzy_pkgs, tmp_path / "ws")
    edit(root / CONTROLLERS, "update_rate: 1000", "update_rate: 100")
    return root


def test_100_hz_names_the_rate_the_hold_and_both_remedies(jazzy_pkgs: Path, tmp_path: Path) -> None:
    root = _slow(jazzy_pkgs, tmp_path)
    (f,) = [f for f in findings(root) if f.rule == RULE]
    line = next(
        i
        for i, text in enumerate((root / CONTROLLERS).read_text().splitlines(), 1)
        if "update_rate: 100" in text
    )
    assert f.file.endswith(CONTROLLERS) and f.line == line
    assert "arm_controller at 100 Hz" in f.message and "10 ms" in f.message
    assert f.values["update_rate"] == 100 and f.values["hold_max"] < 0.01  # type: ignore[operator]
    rate = int(f.fix["update_rate"])  # type: ignore[arg-type]
    # the rate: the file with it passes
    text = (root / CONTROLLERS).read_text()
    (root / CONTROLLERS).write_text(text.replace("update_rate: 100", f"update_rate: {rate}"))
    assert RULE not in {g.rule for g in findings(root)}


def test_the_gains_it_asks_for_pass_at_100_hz(jazzy_pkgs: Path, tmp_path: Path) -> None:
    root = _slow(jazzy_pkgs, tmp_path)
    (f,) = [f for f in findings(root) if f.rule == RULE]
    doc = yaml.safe_load((root / CONTROLLERS).read_text())
    gains = doc["arm_controller"]["ros__parameters"]["gains"]
    joints = doc["arm_controller"]["ros__parameters"]["joints"]
    for k, joint in enumerate(joints):
        for key in ("p", "d", "i"):
            gains[joint][key] = f.fix[key][k]  # type: ignore[index]
    (root / CONTROLLERS).write_text(yaml.safe_dump(doc, sort_keys=False))
    assert RULE not in {g.rule for g in findings(root)}


def test_without_update_rate_the_manager_default_counts(jazzy_pkgs: Path, tmp_path: Path) -> None:
    root = copy(jazzy_pkgs, tmp_path / "ws")
    path = root / CONTROLLERS
    path.write_text(re.sub(r"\n\s+update_rate: 1000", "", path.read_text()))
    (f,) = [f for f in findings(root) if f.rule == RULE]
    assert "controller_manager's default 100 Hz" in f.message
    lines = path.read_text().splitlines()
    assert f.line is not None and lines[f.line - 2].strip() == "ros__parameters:"  # the manager's
    assert lines[f.line - 3].strip() == "controller_manager:"  # block, where update_rate goes
