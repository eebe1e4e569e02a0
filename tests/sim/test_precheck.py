"""The trajectory's own impossibilities, named before any simulated verdict (issue 31).

Before: a first point 1 ms after the start (600 rad/s against a 100 rad/s limit) ran and
ended in a 4.7 m zero-moment-point excursion; an effort below the gravity torque ended
in "the robot tips over"."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from armcli.sim.job import prepare
from armcli.sim.options import SimOptions
from armcli.sim.precheck import holding_problems, speed_problems
from armcli.spec.load import loads_spec
from armcli.urdf.source import RobotFile
from tests.helpers import DEFAULT_SPEC, ROOT, run_main, spec_file

PICK = ROOT / "specs" / "trajectories" / "pick.yaml"
G = 9.81  # [m/s²] the spec's gravity (Pinocchio's default)
M, L = 0.3, 0.3  # [kg], [m]: the course's forearm and hand links, centres of mass at L / 2


def _fast(t: float) -> str:
    return (
        "{joint_names: [arm_base_forearm_joint, forearm_hand_joint], "
        f"points: [{{positions: [0.6, 0.4], time_from_start: {t}}}]}}"
    )


def test_a_segment_faster_than_the_limit_is_named() -> None:
    job = prepare(spec_file(DEFAULT_SPEC), SimOptions(message=_fast(0.001)))
    first, second = speed_problems(job)
    # linear interpolation from home (0, 0): 0.6 rad in 1 ms = 600 rad/s against 100 rad/s,
    # so the segment needs 0.6 / 100 = 0.006 s
    assert "arm_base_forearm_joint moves at up to 600 rad/s" in first
    assert "velocity limit 100 rad/s; give that segment at least 0.006 s" in first
    assert "forearm_hand_joint moves at up to 400 rad/s" in second
    assert speed_problems(prepare(spec_file(DEFAULT_SPEC), SimOptions(message=_fast(0.006)))) == []


def test_an_effort_below_gravity_is_named() -> None:
    text = DEFAULT_SPEC.read_text().replace("effort: 100, velocity", "effort: 0.5, velocity")
    spec = loads_spec(text)
    (line,) = holding_problems(prepare(RobotFile.of_spec(spec), SimOptions(trajectory=PICK)))
    # worst point (0.9, 1.2): tau = M g (L/2 sin q1) + M g (L sin q1 + L/2 sin(q1 + q2))
    q1, q2 = 0.9, 1.2
    tau = M * G * (L / 2 * math.sin(q1)) + M * G * (L * math.sin(q1) + L / 2 * math.sin(q1 + q2))
    assert f"points[1]: arm_base_forearm_joint needs {tau:.3g} N·m" in line
    assert "above its effort limit 0.5 N·m" in line
    assert holding_problems(prepare(spec_file(DEFAULT_SPEC), SimOptions(trajectory=PICK))) == []


def test_simulate_says_the_cause_first(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run_main(["simulate", DEFAULT_SPEC, "--message", _fast(0.001)], capsys)
    assert code == 2 and out == "" and "zero-moment" not in err
    assert err.startswith("error: --message: points[0]: arm_base_forearm_joint moves at up to")
