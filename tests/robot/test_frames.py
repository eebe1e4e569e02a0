"""armcli.robot.frames: the rotation maths against scipy's Rotation (an independent
implementation), the frame lookup that prefers a link over a joint of its name (ANYmal C's
`LF_HFE`), and reducing a model whose links and joints share names."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from armcli.errors import InputError
from armcli.robot import frames
from armcli.robot.frames import frame_id, link_frame
from armcli.robot.model import Robot
from armcli.urdf.read import parse_urdf
from tests.helpers import FIXTURES, ROOT, run_cli

EXACT = 1e-12  # the same rotation, rounded differently
SEED = 4
RPY = [(0, 0, 0), (math.pi / 2, 0, 0), (0.3, -0.7, 1.1), (-2.0, 1.2, 0.4), (0.1, math.pi / 2, 0)]


def _same_rotation(a: tuple[float, ...], b: np.ndarray) -> bool:
    """(x, y, z, w) quaternions of one rotation (q and -q are the same one)."""
    a_ = np.asarray(a)
    return bool(np.allclose(a_, b, atol=EXACT) or np.allclose(a_, -b, atol=EXACT))


@pytest.mark.parametrize("rpy", RPY)
def test_rpy_is_urdf_fixed_axis_xyz(rpy: tuple[float, float, float]) -> None:
    # URDF: rotate about fixed X by roll, then fixed Y by pitch, then fixed Z by yaw;
    # scipy's lower-case "xyz" is exactly that extrinsic sequence.
    ref = Rotation.from_euler("xyz", rpy)
    np.testing.assert_allclose(frames.rpy_matrix(rpy), ref.as_matrix(), atol=EXACT)
    np.testing.assert_allclose(frames.rpy_rotation(rpy), ref.as_matrix(), atol=EXACT)
    assert _same_rotation(frames.rpy_quaternion(rpy), ref.as_quat())
    T = frames.pose_matrix((0.1, -0.2, 0.3), rpy)
    np.testing.assert_allclose(T[:3, :3], ref.as_matrix(), atol=EXACT)
    np.testing.assert_array_equal(T[:3, 3], (0.1, -0.2, 0.3))
    np.testing.assert_array_equal(T[3], (0, 0, 0, 1))


def test_quaternion_matrix_round_trip_and_product() -> None:
    rng = np.random.default_rng(SEED)
    for R in Rotation.random(50, random_state=SEED):
        quat = frames.matrix_quaternion(R.as_matrix())
        assert quat[3] >= 0.0 and _same_rotation(quat, R.as_quat())
        np.testing.assert_allclose(frames.quaternion_matrix(quat), R.as_matrix(), atol=EXACT)
        v = rng.normal(size=3)
        np.testing.assert_allclose(frames.rotate(quat, v), R.apply(v), atol=EXACT)
    a, b = Rotation.random(2, random_state=SEED + 1)
    ab = frames.quaternion_product(a.as_quat(), b.as_quat())  # b first, then a
    assert _same_rotation(tuple(ab), (a * b).as_quat())
    # a half turn (trace -1): Shepperd's other branch
    assert _same_rotation(
        frames.matrix_quaternion(np.diag([1.0, -1.0, -1.0])), np.array([1, 0, 0, 0])
    )


def test_axis_and_yaw_quaternions() -> None:
    axis = np.array([1.0, 2.0, 2.0]) / 3.0
    ref = Rotation.from_rotvec(0.7 * axis).as_quat()
    assert _same_rotation(tuple(frames.axis_quaternion(axis, 0.7)), ref)
    assert _same_rotation(frames.yaw_quaternion(-2.5), Rotation.from_euler("z", -2.5).as_quat())


def test_rpy_and_tilt_of_quaternion_rows() -> None:
    rpy = np.array([[0.3, -0.7, 1.1], [0.0, 0.2, 3.0], [0.0, 0.0, -3.0]])
    xyzw = Rotation.from_euler("xyz", rpy).as_quat()
    wxyz = np.roll(xyzw, 1, axis=1)
    roll, pitch, yaw = frames.quaternion_rpy(wxyz)
    np.testing.assert_allclose(roll, rpy[:, 0], atol=EXACT)
    np.testing.assert_allclose(pitch, rpy[:, 1], atol=EXACT)
    # yaw unwrapped: 3.0 then -3.0 is a step of 2 pi - 6 through pi, not -6
    np.testing.assert_allclose(yaw, [1.1, 3.0, 2 * math.pi - 3.0], atol=EXACT)
    z_axes = Rotation.from_euler("xyz", rpy).apply([0.0, 0.0, 1.0])
    np.testing.assert_allclose(frames.tilt(wxyz), np.arccos(z_axes[:, 2]), atol=1e-7)


NAMESAKE = b"""<robot name="r"><link name="base"/><link name="LF_HFE"/><link name="shin"/>
  <joint name="LF_HFE" type="revolute"><parent link="base"/><child link="LF_HFE"/>
    <origin xyz="0 0 1"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="knee" type="fixed"><parent link="LF_HFE"/><child link="shin"/>
    <origin xyz="0.5 0 0"/></joint></robot>"""


def test_a_link_wins_over_a_joint_of_its_name() -> None:
    """ANYmal C names a link and a joint LF_HFE; a bare lookup matched several frames."""
    robot = Robot.load(parse_urdf(NAMESAKE, "r.urdf"))
    model = robot.model
    link, joint = frames.link_frame(model, "LF_HFE"), frames.joint_frame(model, "LF_HFE")
    assert link is not None and joint is not None and link != joint
    assert frames.frame_id(model, "LF_HFE") == robot.frame("LF_HFE") == link
    knee = frames.frame_id(model, "knee")  # a fixed joint's frame, no link of it
    assert model.frames[knee].name == "knee" and frames.link_frame(model, "knee") is None
    with pytest.raises(InputError, match="no link or frame named 'nope'; links: LF_HFE, base"):
        robot.frame("nope")


SHARED = FIXTURES / "robot" / "shared_names.urdf"


def _robot() -> Robot:
    return Robot.load(parse_urdf(SHARED.read_bytes(), str(SHARED)), strict=False)


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
    """Pinocchio's name lookups, its reduction and its rpy maths live in robot/frames.py only."""
    calls = ("getFrameId(", "existFrame(", "buildReducedModel(", "rpy.rpyToMatrix(")
    found = [
        f"{path.relative_to(ROOT)}:{n}"
        for path in sorted((ROOT / "src" / "armcli").rglob("*.py"))
        if path.name != "frames.py" or path.parent.name != "robot"
        for n, line in enumerate(path.read_text().splitlines(), 1)
        if any(c in line for c in calls)
    ]
    assert found == []
