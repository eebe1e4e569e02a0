"""`ros-controller-unstable` on a spec: the ros2_control controller at its update rate.

The example specs run their controllers at 1000 Hz and pass; the same spec at 100 Hz (the
rate the specs had, controller_manager's default) fails with exactly this rule, on the
spec's `control.controller_update_rate` line, and each remedy it writes passes when
applied. The bound itself is held against a zero-order-hold simulation in
tests/analysis/test_rate.py; here: where the finding points and what it asks for.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from armcli.check.inputs import run_check
from armcli.check.options import CheckOptions
from armcli.check.rules import RULES
from armcli.spec.load import load_spec
from tests.helpers import DEFAULT_SPEC, SPECS

RULE = "ros-controller-unstable"
EXAMPLES = sorted(SPECS.glob("*.yaml"))


def _findings(path: Path) -> list:
    run = run_check([path], CheckOptions())
    return [f for r in run.results for f in r.findings]


def _at_rate(tmp_path: Path, rate: int, text: str | None = None) -> Path:
    text = DEFAULT_SPEC.read_text() if text is None else text
    out = tmp_path / "my_robot.yaml"
    out.write_text(re.sub(r"controller_update_rate: \d+", f"controller_update_rate: {rate}", text))
    return out


@pytest.mark.parametrize("spec", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_specs_pass_at_their_rate(spec: Path) -> None:
    run = run_check([spec], CheckOptions())
    assert [f.message for r in run.results for f in r.findings if f.rule == RULE] == []
    rates = [r.summary.rate for r in run.results if r.summary is not None]
    assert rates and all(v is not None and v.stable for v in rates)
    assert all(v.rate == load_spec(spec).control.controller_update_rate for v in rates)


def test_100_hz_fails_with_exactly_the_rule_on_the_rate(tmp_path: Path) -> None:
    path = _at_rate(tmp_path, 100)
    found = _findings(path)
    assert {f.rule for f in found} == {RULE}
    line = next(
        i for i, t in enumerate(path.read_text().splitlines(), 1) if "update_rate: 100" in t
    )
    for f in found:  # one per URDF of the spec (the whole robot, the arm alone)
        assert f.spec is not None and f.spec.line == line
        assert f.spec.field == "control.controller_update_rate"
        assert f.severity == RULES[RULE].severity == "error"
        assert set(f.fix) == {"controller_update_rate", "kp", "kd"}  # no ki: the spec has none
        assert "100 Hz" in f.message and "10 ms" in f.message
        assert f.values["hold_max"] < 0.01 <= f.values["hold"]


def test_the_rate_it_asks_for_passes(tmp_path: Path) -> None:
    (f, *_) = _findings(_at_rate(tmp_path, 100))
    rate = int(f.fix["controller_update_rate"])
    assert rate > 100 and 1.0 / rate <= f.values["hold_max"]
    assert [g.rule for g in _findings(_at_rate(tmp_path, rate))] == []


def test_the_gains_it_asks_for_pass_at_100_hz(tmp_path: Path) -> None:
    (f, *_) = _findings(_at_rate(tmp_path, 100))
    kp, kd = f.fix["kp"], f.fix["kd"]
    assert isinstance(kp, list) and isinstance(kd, list) and len(kp) == len(kd) == 2
    text = DEFAULT_SPEC.read_text()
    text = text.replace("arm_base_forearm_joint: {kp: 50, kd: 1.5}",
                        f"arm_base_forearm_joint: {{kp: {kp[0]}, kd: {kd[0]}}}")  # fmt: skip
    text = text.replace("forearm_hand_joint: {kp: 50, kd: 1.5}",
                        f"forearm_hand_joint: {{kp: {kp[1]}, kd: {kd[1]}}}")  # fmt: skip
    assert RULE not in {g.rule for g in _findings(_at_rate(tmp_path, 100, text))}


def test_an_arm_commanded_by_position_is_not_judged(tmp_path: Path) -> None:
    # JTC on a position interface closes no PID on torque: the spec's gains are not used
    control = """
ros2_control:
  joints:
    arm_base_forearm_joint:
      command_interfaces: {position: {}}
      state_interfaces: {position: {}, velocity: {}}
    forearm_hand_joint:
      command_interfaces: {position: {}}
      state_interfaces: {position: {}, velocity: {}}
"""
    path = _at_rate(tmp_path, 100, DEFAULT_SPEC.read_text() + control)
    run = run_check([path], CheckOptions())
    assert RULE not in {f.rule for r in run.results for f in r.findings}
    assert all(r.summary is None or r.summary.rate is None for r in run.results)
