"""Frames by name where links and joints share names (ANYmal C's `LF_HFE`); reducing a model."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from armcli.errors import InputError
from armcli.robot.frames import frame_id, link_frame
from armcli.robot.model import Robot
from armcli.urdf.read import parse_urdf
from tests.helpers import FIXTURES, ROOT, run_cli

SHARED = FIXTURES / "robot" / "shared_names.urdf"
EXACT = 1e-12


def _robot() -> Robot:
    return Robot.from_urdf(parse_urdf(SHARED.read_bytes(), str(SHARED)))


def test_a_shared_name_means_the_link() -> None:
    import pinocchio as pin

    model = _robot().model
    with pytest.raises(ValueError, match="Several frames match"):
        model.getFrameId("HFE")  # Pinocchio's own lookup by name alone
    assert model.frames[frame_id(model, "HFE")].type == pin.BODY
    assert link_frame(model, "HFE") == frame_id(model, "HFE")
    assert model.frames[frame_id(model, "KFE_FOOT")].type == pin.FIXED_JOINT  # not a link
    with pytest.raises(InputError, match="no link or frame named 'wrist'"):
        frame_id(model, "wrist")


def test_reducing_keeps_names_and_kinematics() -> None:
    """The reduced model, HAA locked at 0, against the full one with HAA = 0: same foot."""
    import pinocchio as pin

    robot = _robot()
    small = robot.reduced(["HFE", "KFE"])
    assert list(small.model.names)[1:] == ["HFE", "KFE"]
    q_small = np.array([0.4, -0.9])
    q_full = robot.q({"HAA": 0.0, "HFE": 0.4, "KFE": -0.9})
    poses = []
    for model, q in ((robot.model, q_full), (small.model, q_small)):
        data = model.createData()
        pin.framesForwardKinematics(model, data, q)
        poses.append(data.oMf[link_frame(model, "FOOT")].translation.copy())
    assert poses[1] == pytest.approx(poses[0], abs=EXACT)


def test_simulate_two_joints_of_a_robot_with_shared_names(tmp_path: Path) -> None:
    traj = tmp_path / "t.yaml"
    traj.write_text(
        "joint_names: [HFE, KFE]\npoints:\n  - {positions: [0.3, -0.6], time_from_start: 1.0}\n"
    )
    proc = run_cli(["simulate", "--urdf", SHARED, "--joints", "HFE,KFE", "--kp", "50", "--kd", "5",
                    "--trajectory", traj], ROOT)  # fmt: skip
    assert proc.returncode == 0, proc.stderr  # was: internal error: Several frames match
    assert "HFE" in proc.stdout and "KFE" in proc.stdout


def test_every_lookup_by_name_goes_through_robot_frames() -> None:
    """Pinocchio's name lookups and its reduction live in robot/frames.py only."""
    calls = ("getFrameId(", "existFrame(", "buildReducedModel(")
    found = [
        f"{path.relative_to(ROOT)}:{n}"
        for path in sorted((ROOT / "src" / "armcli").rglob("*.py"))
        if path.name != "frames.py" or path.parent.name != "robot"
        for n, line in enumerate(path.read_text().splitlines(), 1)
        if any(c in line for c in calls)
    ]
    assert found == []
