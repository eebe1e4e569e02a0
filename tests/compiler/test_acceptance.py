"""A spec with meshes, several shapes per link, a mimic gripper and passthrough XML builds a
URDF that every parser accepts: check_urdf (urdfdom), Pinocchio (model and meshes), MuJoCo
and SDFormat (`ign sdf -k`, Gazebo's own URDF parser). Parsers that are not installed skip
with the reason (scripts/sysdeps.sh installs them)."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from lxml import etree

from armcli.compiler.expand import build
from armcli.urdf.source import RobotFile
from tests.helpers import FIXTURES
from tests.meshes import house_triangles, prism_triangles, write_stl

SPEC = FIXTURES / "spec" / "rich_arm.yaml"
URDF = "standalone_arm.urdf"


def write_meshes(project: Path) -> None:
    """The meshes rich_arm.yaml names, closed so that their inertias are defined."""
    write_stl(project / "meshes" / "base.stl", prism_triangles(0.08, 0.1, 32))
    write_stl(project / "meshes" / "link.stl", house_triangles())


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> Path:
    project = tmp_path_factory.mktemp("rich")
    shutil.copy(SPEC, project / "armcli.yaml")
    write_meshes(project)
    build(project / "armcli.yaml", project / "urdf")
    return project / "urdf" / URDF


def test_meshes_keep_their_place_relative_to_the_urdf(built: Path) -> None:
    root = etree.parse(str(built)).getroot()
    names = {m.get("filename") for m in root.iter("mesh")}
    assert names == {"../meshes/base.stl", "../meshes/link.stl"}
    for name in names:
        assert (built.parent / str(name)).is_file()


def test_check_urdf_accepts(built: Path) -> None:
    if shutil.which("check_urdf") is None:
        pytest.skip("check_urdf not installed (liburdfdom-tools; make sysdeps)")
    out = subprocess.run(["check_urdf", str(built)], capture_output=True, text=True, check=False)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "Successfully Parsed XML" in out.stdout


def test_sdformat_accepts(built: Path) -> None:
    if shutil.which("ign") is None:
        pytest.skip("ign not installed (libsdformat-dev + ignition-tools; make sysdeps)")
    out = subprocess.run(
        ["ign", "sdf", "-k", str(built)], capture_output=True, text=True, check=False
    )
    assert out.returncode == 0 and "Valid" in out.stdout, out.stdout + out.stderr
    sdf = subprocess.run(
        ["ign", "sdf", "-p", str(built)], capture_output=True, text=True, check=False
    )
    model = etree.fromstring(sdf.stdout.encode())
    # every moving joint survives the conversion (fixed ones are lumped by design)
    assert len(model.findall(".//joint")) == 8


def test_pinocchio_loads_model_and_meshes(built: Path) -> None:
    import pinocchio as pin

    model = pin.buildModelFromUrdf(str(built))
    assert model.njoints - 1 == 8  # the 8 moving joints
    assert (model.nq, model.nv) == (9, 8)  # the continuous wrist_3 has nq 2 (cos, sin), nv 1
    visual = pin.buildGeomFromUrdf(
        model, str(built), pin.GeometryType.VISUAL, package_dirs=[str(built.parent)]
    )
    meshes = [g.meshPath for g in visual.geometryObjects if g.meshPath.endswith(".stl")]
    assert len(meshes) == 5 and all(Path(m).is_file() for m in meshes)  # 2 from the fingers


def test_mujoco_compiles(built: Path) -> None:
    mujoco = pytest.importorskip("mujoco")
    root = etree.parse(str(built)).getroot()
    ext = etree.SubElement(root, "mujoco")
    etree.SubElement(ext, "compiler", meshdir=str(built.parent), strippath="false")
    model = mujoco.MjModel.from_xml_string(etree.tostring(root, encoding="unicode"))
    assert model.njnt == 8
    assert model.nmesh == 1  # MuJoCo's URDF import keeps collision shapes only: the one hull


def test_check_does_not_flag_the_mimic_gripper(built: Path) -> None:
    from armcli.check.options import CheckOptions
    from armcli.check.run import check_urdf
    from armcli.spec.load import load_spec
    from armcli.urdf.read import read_urdf

    spec = load_spec(built.parent.parent / "armcli.yaml")
    result = check_urdf(read_urdf(built), CheckOptions(spec=spec))
    about_fingers = [f for f in result.findings if "finger" in f.message]
    assert about_fingers == []


FINGERS = ("left_finger_joint", "right_finger_joint")


def _finger_job(built: Path, msg: str, joints: tuple[str, ...] = FINGERS) -> Any:
    from armcli.sim import job as simjob
    from armcli.sim.options import SimOptions
    from armcli.spec.load import load_spec

    spec = load_spec(built.parent.parent / "armcli.yaml")
    opts = SimOptions(message=msg, joints=joints, kp=(200.0,), kd=(2.0,), duration=1.5)
    return simjob.prepare(RobotFile.of_spec(spec), opts)


def test_simulate_drives_the_mimic_finger_through_its_leader(built: Path) -> None:
    """right_finger mimics left_finger (multiplier 1, offset 0): commanding the leader alone
    moves both, and the follower tracks the leader as gazebo_ros2_control makes it."""
    from armcli.sim import job as simjob

    msg = "{joint_names: [left_finger_joint], points: [{positions: [0.02], time_from_start: 0.5}]}"
    job = _finger_job(built, msg)
    assert job.robot.names == FINGERS
    # the coupling survives into the simulated robot (issue 38: it was dropped there)
    assert [(m.follower, m.leader) for m in job.robot.mimics] == [tuple(reversed(FINGERS))]
    q_ref, v_ref = job.reference.sample(np.array([0.0, 0.25, 0.5, 1.0]))
    np.testing.assert_array_equal(q_ref[:, 1], q_ref[:, 0])  # exactly: 1 * leader + 0
    np.testing.assert_array_equal(v_ref[:, 1], v_ref[:, 0])
    assert q_ref[-1, 0] == 0.02
    res = simjob.run(job)
    assert abs(res.q[-1, 0] - 0.02) < 1e-3 and abs(res.q[-1, 1] - 0.02) < 1e-3
    assert np.max(np.abs(res.q[:, 1] - res.q[:, 0])) < 1e-3  # twin fingers, twin motion


def test_simulate_refuses_commanding_a_follower_or_locking_its_leader(built: Path) -> None:
    from armcli.errors import InputError

    msg = "{joint_names: [right_finger_joint], points: [{positions: [0.02], time_from_start: 1}]}"
    with pytest.raises(InputError, match="command 'left_finger_joint' and 'right_finger_joint'"):
        _finger_job(built, msg)
    msg = "{joint_names: [wrist_3_joint], points: [{positions: [0.2], time_from_start: 1}]}"
    with pytest.raises(InputError, match="which is locked: lock 'right_finger_joint' too"):
        _finger_job(built, msg, ("wrist_3_joint", "right_finger_joint"))


def test_coupled_reference_adds_multiplier_and_offset() -> None:
    """q_f(t) = m q_l(t) + o, v_f = m v_l on every polynomial piece, chains leaders first."""
    from armcli.robot.mimic import Mimic
    from armcli.trajectory.message import loads_trajectory
    from armcli.trajectory.reference import build_reference, coupled

    limits = {n: (-5.0, 5.0) for n in ("a", "b", "c")}
    msg = (
        "{joint_names: [a], points: [{positions: [1.0], time_from_start: 1},"
        " {positions: [-0.5], time_from_start: 2}]}"
    )
    ref = build_reference(loads_trajectory(msg, limits, source="t"), ["a", "b", "c"], np.zeros(3))
    pairs = [(1, 0, Mimic("b", "a", -2.0, 0.1)), (2, 1, Mimic("c", "b", 0.5, 0.0))]
    q, v = coupled(ref, pairs).sample(np.linspace(0.0, 3.0, 31))
    np.testing.assert_allclose(q[:, 1], -2.0 * q[:, 0] + 0.1, rtol=0, atol=1e-15)
    np.testing.assert_allclose(q[:, 2], 0.5 * q[:, 1], rtol=0, atol=1e-15)
    np.testing.assert_allclose(v[:, 1], -2.0 * v[:, 0], rtol=0, atol=1e-14)


def test_simulate_asks_for_the_leaders_gains_only(built: Path) -> None:
    """The spec refuses gains on a follower, so a missing one is never asked for."""
    from armcli.errors import InputError
    from armcli.sim import job as simjob
    from armcli.sim.options import SimOptions
    from armcli.spec.load import load_spec

    spec = load_spec(built.parent.parent / "armcli.yaml")
    msg = "{joint_names: [left_finger_joint], points: [{positions: [0.02], time_from_start: 1}]}"
    with pytest.raises(InputError, match=r"no kp for left_finger_joint in the spec") as info:
        simjob.prepare(RobotFile.of_spec(spec), SimOptions(message=msg, joints=FINGERS))
    assert "right_finger_joint" not in str(info.value)
