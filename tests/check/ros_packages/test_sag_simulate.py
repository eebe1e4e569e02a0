"""ros-start-sag's number against `armcli simulate` running the same gains at the pose.

The generated course packages with the old gains (p 50, i 0): the rule reports the
forearm 0.028 rad low at `reach`; `simulate` commands the same pose with Kp 50, Kd 1.5 and
the arm settles within its joint friction's band (0.05 N·m / 50 = 1 mrad, which the rule
leaves out) of that. The issue asks for agreement within 10 %.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.check.ros_packages.test_rule_fixtures import _no_integral
from tests.check.ros_packages.workspaces import copy, findings
from tests.helpers import DEFAULT_SPEC, run_main

AGREEMENT = 0.10  # relative, the bound
JOINTS = ("arm_base_forearm_joint", "forearm_hand_joint")


def test_rule_sag_agrees_with_simulate(
    jazzy_pkgs: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    root = copy(jazzy_pkgs, tmp_path / "ws")
    _no_integral(root)
    (reach,) = [
        f for f in findings(root) if f.rule == "ros-start-sag" and f.values["pose"] == "reach"
    ]
    joint, rule_sag = reach.values["joint"], float(reach.values["sag"])  # type: ignore[arg-type]
    assert joint == JOINTS[0]
    pose = [0.7853981633974483, 0.7853981633974483]  # the SRDF's group_state reach (pi/4)
    point = f"{{positions: {pose}, time_from_start: {{sec: 0}}}}"
    message = f"{{joint_names: [{', '.join(JOINTS)}], points: [{point}]}}"
    out = tmp_path / "held.json"
    code, _, err = run_main(
        ["simulate", DEFAULT_SPEC, "-m", message, "--kp", "50", "--kd", "1.5",
         "--duration", "4", "-o", out],
        capsys,
    )  # fmt: skip
    assert code == 0, err
    states = json.loads(out.read_text())
    sim_sag = states[f"{joint}.position"][-1] - pose[0]
    assert abs(sim_sag - rule_sag) <= AGREEMENT * rule_sag, (sim_sag, rule_sag)
