"""ros-package --target jazzy refuses a controller that diverges at its update rate.

gz_ros2_control holds the JointTrajectoryController's effort for 1/update_rate; the course
gains held for 10 ms diverge (tests/analysis/test_rate.py simulates it). The refusal is
`check`'s verdict (rule ros-controller-unstable) on the gains ros-package writes (with the
integral term of ros/holding.py), one line naming the spec file and the field, and no
package written; the course target teleports the arm in Gazebo classic (the gains never
reach a torque loop there) and is not refused. The README states the loop's margin.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from armcli.analysis import pdloop, rate, zoh
from armcli.errors import InputError
from armcli.robot import sampling
from armcli.robot.model import Robot
from armcli.ros.controller_rate import RATE_FIELD, jazzy_control
from armcli.ros.holding import integral_terms
from armcli.ros.packages import ros_packages
from armcli.spec.load import load_spec, loads_spec
from armcli.urdf.read import parse_urdf
from armcli.urdf.source import spec_urdfs
from tests.helpers import DEFAULT_SPEC, run_cli

SAMPLES = 200  # collision-matrix samples: irrelevant here


def _slow_text() -> str:
    return re.sub(r"controller_update_rate: \d+", "controller_update_rate: 100",
                  DEFAULT_SPEC.read_text())  # fmt: skip


def test_jazzy_refuses_the_course_gains_at_100_hz() -> None:
    spec = loads_spec(_slow_text())
    with pytest.raises(InputError) as info:
        ros_packages(spec, samples=SAMPLES, target="jazzy", source="slow.yaml")
    err = info.value
    assert err.file == "slow.yaml" and err.field == RATE_FIELD
    assert "100 Hz" in err.message and f"{RATE_FIELD} >= " in err.message and "kp" in err.message
    # the classic target's arm is teleported by joint_pose_trajectory: not refused
    ros_packages(spec, samples=SAMPLES, target="humble-classic")


def test_the_verdict_is_on_the_written_gains() -> None:
    # the whole robot (its free wheels leave the arm the least inertia) with the integral
    # term the controllers YAML gets: the same loop judged independently here
    spec = load_spec(DEFAULT_SPEC)
    xml = spec_urdfs(spec)["my_robot.urdf"]
    control = jazzy_control(spec, xml, None)
    assert control.holding == integral_terms(spec, xml)
    robot = Robot.load(parse_urdf(xml, "my_robot.urdf"), strict=False)
    names = list(spec.control.gains)
    g = [spec.control.gains[n] for n in names]
    pd = pdloop.PD.of([robot.joint(n).idx_v for n in names], [x.kp for x in g],
                      [x.kd for x in g], [robot.joint(n).damping for n in names])  # fmt: skip
    ki = np.array([control.holding[n].i for n in names])
    lin = pdloop.linearise(robot, [q for _, q in sampling.configurations(robot)])
    want = rate.rate_verdict(lin, zoh.Pid.of(pd, ki), spec.control.controller_update_rate)
    assert control.rate == want and want.stable


def test_readme_states_the_margin(tmp_path: Path) -> None:
    spec = load_spec(DEFAULT_SPEC)
    files = ros_packages(spec, samples=SAMPLES, target="jazzy").files
    text = files["my_robot_bringup/README.md"].decode()
    v = jazzy_control(spec, spec_urdfs(spec)["my_robot.urdf"], None).rate
    assert v is not None
    assert f"a hold up to {v.hold_max * 1e3:.3g} ms" in text
    assert "every 1 ms" in text  # 1 / controller_update_rate (1000 Hz)


def test_cli_refusal_is_one_line_and_writes_nothing(tmp_path: Path) -> None:
    spec = tmp_path / "slow.yaml"
    spec.write_text(_slow_text())
    out = tmp_path / "ros"
    proc = run_cli(["ros-package", spec, "-o", out, "--target", "jazzy"])
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and str(spec) in lines[0] and RATE_FIELD in lines[0], proc.stderr
    assert not out.exists()
