"""Issue 19: `export mjcf` never writes a model MuJoCo refuses for its mass properties.

The fixtures reproduce what real descriptions do (planning-only industrial arms without
inertials, 1e-6 kg dummy links with singular tensors, CAD inertias violating the
triangle inequality, point masses); before the fix each exported with exit 0 and MuJoCo
refused the result. References: closed-form solids (robot.inertia) for the inertia MuJoCo
takes from geometry, Pinocchio on the original URDF for merges that must not change the
dynamics, and MuJoCo itself compiling every written model.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from armcli.errors import ExportRefusedError
from armcli.export.mjcf_files import export_mjcf
from armcli.export.mjcf_mass import DENSITY, POINT_RADIUS
from armcli.robot import inertia as inr

mujoco = pytest.importorskip("mujoco")
pin = pytest.importorskip("pinocchio")

SEED = 0
N_CONFIGS = 20
DYN_TOL = 1e-9  # [kg·m²] exact merges: MuJoCo's mass matrix against Pinocchio's
MASS_RTOL = 1e-9  # geometry masses against closed forms (MuJoCo computes the same solids)


def _inertial(mass: float, ixx: float, iyy: float, izz: float, ixy: float = 0.0) -> str:
    return (
        f'<inertial><origin xyz="0.01 0.02 0.03"/><mass value="{mass}"/>'
        f'<inertia ixx="{ixx}" ixy="{ixy}" ixz="0" iyy="{iyy}" iyz="0" izz="{izz}"/></inertial>'
    )


def _link(name: str, inertial: str = "", collision: str = "") -> str:
    col = f"<collision><geometry>{collision}</geometry></collision>" if collision else ""
    return f'<link name="{name}">{inertial}{col}</link>'


def _joint(name: str, parent: str, child: str, kind: str = "revolute", z: float = 0.2) -> str:
    limit = '<limit lower="-2" upper="2" effort="50" velocity="2"/>' if kind != "fixed" else ""
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="0.05 0 {z}" rpy="0.1 0.2 0.3"/><axis xyz="0 1 0"/>{limit}</joint>'
    )


def _robot(*parts: str) -> str:
    return '<?xml version="1.0"?>\n<robot name="r">' + "".join(parts) + "</robot>\n"


def _export(tmp: Path, urdf: str, **kw: Any) -> tuple[Any, Any]:
    src = tmp / "r.urdf"
    src.write_text(urdf)
    res = export_mjcf(src, tmp / "out" / "robot.xml", **kw)
    return res, mujoco.MjModel.from_xml_path(str(tmp / "out" / "scene.xml"))


def _topics(res: Any) -> set[str]:
    return {n.topic for n in res.export.notes}


GOOD = _inertial(1.0, 0.01, 0.012, 0.014)
# A planning-only arm (ROS-Industrial style): no <inertial> anywhere, collision solids.
PLANNING_ARM = _robot(
    _link("base_link", collision='<box size="0.3 0.3 0.1"/>'),
    _link("link_1", collision='<box size="0.1 0.1 0.4"/>'),
    _link("link_2", collision='<cylinder radius="0.05" length="0.3"/>'),
    _link("tool0", collision='<sphere radius="0.02"/>'),
    _joint("joint_1", "base_link", "link_1"),
    _joint("joint_2", "link_1", "link_2"),
    _joint("tool0_joint", "link_2", "tool0", "fixed"),
)


def test_planning_arm_takes_its_inertia_from_collision_geometry(tmp_path: Path) -> None:
    """As MuJoCo's URDF import: 1000 kg/m³ solids; the fixed tool0 stays massless."""
    res, m = _export(tmp_path, PLANNING_ARM)
    assert "mass: inertia from geometry" in _topics(res)
    box_m = DENSITY * 0.1 * 0.1 * 0.4
    cyl_m = DENSITY * math.pi * 0.05**2 * 0.3
    assert m.body("link_1").mass[0] == pytest.approx(box_m, rel=MASS_RTOL)
    assert m.body("link_2").mass[0] == pytest.approx(cyl_m, rel=MASS_RTOL)
    assert m.body("tool0").mass[0] == 0.0  # as in the URDF (Pinocchio): no mass
    want = np.sort(np.diag(inr.box_inertia(box_m, 0.1, 0.1, 0.4)))
    assert np.sort(m.body("link_1").inertia) == pytest.approx(want, rel=MASS_RTOL)
    want = np.sort(np.diag(inr.cylinder_inertia(cyl_m, 0.05, 0.3)))
    assert np.sort(m.body("link_2").inertia) == pytest.approx(want, rel=MASS_RTOL)


def test_point_masses_keep_their_mass(tmp_path: Path) -> None:
    """A moving point mass: with geometry its shape, else a 1 mm sphere; mass kept."""
    urdf = _robot(
        _link("base", GOOD),
        _link("leg", _inertial(2.0, 0, 0, 0), '<box size="0.1 0.2 0.3"/>'),
        _link("wrist", _inertial(0.1, 0, 0, 0)),  # between two joints, no geometry
        _link("hand", GOOD),
        _joint("hip", "base", "leg"),
        _joint("wrist_pitch", "leg", "wrist"),
        _joint("wrist_yaw", "wrist", "hand"),
    )
    res, m = _export(tmp_path, urdf)
    assert {"mass: inertia from geometry", "mass: point mass"} <= _topics(res)
    assert m.body("leg").mass[0] == pytest.approx(2.0, rel=MASS_RTOL)
    want = np.sort(np.diag(inr.box_inertia(2.0, 0.1, 0.2, 0.3)))
    assert np.sort(m.body("leg").inertia) == pytest.approx(want, rel=MASS_RTOL)
    assert m.body("wrist").mass[0] == 0.1
    assert m.body("wrist").inertia == pytest.approx([0.4 * 0.1 * POINT_RADIUS**2] * 3)


# Dummy links on fixed joints: a 1e-6 kg singular tensor (quadruped and TIAGo bases and
# antennas), a non-positive-definite one, a camera violating the triangle inequality.
DUMMY = _inertial(1e-6, 2.371e-8, 2.833e-8, 3.849e-8, ixy=6.119e-8)  # eigenvalue < 0
ROD = _inertial(1e-6, 0.0, 0.0, 3e-6)  # singular, A + B < C
CAMERA = _inertial(0.16, 1e-4, 1e-4, 5e-4)  # A + B < C
STATIC_DUMMIES = _robot(
    _link("base", ROD),
    _link("trunk", _inertial(5.0, 0.1, 0.2, 0.25)),
    _link("arm", _inertial(1.0, 0.01, 0.012, 0.014)),
    _link("antenna", DUMMY),
    _link("camera", CAMERA),
    _link("forearm", _inertial(0.5, 0.004, 0.005, 0.006)),
    _joint("base_trunk", "base", "trunk", "fixed"),
    _joint("j1", "trunk", "arm"),
    _joint("arm_antenna", "arm", "antenna", "fixed"),
    _joint("antenna_camera", "antenna", "camera", "fixed"),
    _joint("j2", "arm", "forearm"),
)


def _pin_M(urdf: str, q: np.ndarray) -> np.ndarray:
    model = pin.buildModelFromXML(urdf)  # loads the refused tensors as they are
    M = pin.crba(model, model.createData(), q)
    return np.asarray(np.triu(M) + np.triu(M, 1).T)


def test_static_dummies_merge_into_their_parent_with_the_urdf_dynamics(tmp_path: Path) -> None:
    """The merged rigid group has the URDF's mass, centre and inertia: M(q) is Pinocchio's."""
    res, m = _export(tmp_path, STATIC_DUMMIES)
    assert {"mass: welded to the world", "mass: merged into the parent"} <= _topics(res)
    assert m.body("antenna").mass[0] == 0.0 and m.body("camera").mass[0] == 0.0
    d = mujoco.MjData(m)
    rng = np.random.default_rng(SEED)
    for _ in range(N_CONFIGS):
        d.qpos[:] = rng.uniform(-2.0, 2.0, m.nq)  # MuJoCo and Pinocchio order: j1, j2
        mujoco.mj_forward(m, d)
        M = np.zeros((m.nv, m.nv))
        mujoco.mj_fullM(m, d, M)
        assert np.max(np.abs(M - _pin_M(STATIC_DUMMIES, d.qpos.copy()))) < DYN_TOL


def test_free_base_dummy_moves_into_its_rigid_child(tmp_path: Path) -> None:
    res, m = _export(tmp_path, STATIC_DUMMIES, base="free")
    assert "mass: merged into a rigid child" in _topics(res)
    urdf_mass = 1e-6 + 5.0 + 1.0 + 1e-6 + 0.16 + 0.5
    assert float(sum(m.body_mass)) == pytest.approx(urdf_mass, rel=1e-12)
    assert m.body("base").mass[0] == 0.0


def test_triangle_violation_gets_the_smallest_isotropic_fix(tmp_path: Path) -> None:
    a, b, c = 1e-4, 2e-4, 5e-4  # c - a - b = 2e-4
    urdf = _robot(
        _link("base", GOOD),
        _link("finger", _inertial(0.1, a, b, c)),
        _joint("j", "base", "finger"),
    )
    res, m = _export(tmp_path, urdf)
    assert "mass: triangle inequality" in _topics(res)
    got = np.sort(m.body("finger").inertia)
    assert got == pytest.approx(np.array([a, b, c]) + (c - a - b), rel=1e-6)
    assert got[0] + got[1] >= got[2]
    assert m.body("finger").mass[0] == 0.1


def test_unrepairable_moving_links_are_refused_naming_the_link(tmp_path: Path) -> None:
    massless_leaf = _robot(_link("base", GOOD), _link("tip"), _joint("j", "base", "tip"))
    with pytest.raises(ExportRefusedError, match="link 'tip': moves on joint 'j'"):
        _export(tmp_path, massless_leaf)
    negative = _robot(
        _link("base", GOOD),
        _link("thigh", _inertial(4.7, 0.05, 0.04, 0.01, ixy=0.06)),
        _joint("hip", "base", "thigh"),
    )
    with pytest.raises(ExportRefusedError, match="link 'thigh': a negative principal moment"):
        _export(tmp_path, negative)
    assert not (tmp_path / "out").exists()


def test_cli_exits_1_naming_the_link_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from armcli.cli import main

    src = tmp_path / "r.urdf"
    src.write_text(_robot(_link("base", GOOD), _link("tip"), _joint("j", "base", "tip")))
    out = tmp_path / "mj" / "robot.xml"
    out.parent.mkdir()  # output files need an existing directory (issue 20)
    with pytest.raises(SystemExit) as exc:
        main(["export", "mjcf", str(src), "-o", str(out)])
    assert exc.value.code == 1
    err = capsys.readouterr().err
    assert "link 'tip'" in err and "<inertial>" in err
    assert list(out.parent.iterdir()) == []


def _wrist_through_frame(wrist_inertial: str) -> str:
    """The Gen3 lite's end: a massless (or point-mass) wrist link turned by joint_6, then a
    massless frame (dummy_link), then the 0.14 kg gripper base, both on fixed joints."""
    return _robot(
        _link("base_link", GOOD),
        _link("upper_wrist_link", GOOD),
        _link("end_effector_link", wrist_inertial),
        _link("dummy_link"),
        _link("gripper_base_link", _inertial(0.1395, 1.16e-4, 1.03e-4, 9.7e-5)),
        _joint("joint_5", "base_link", "upper_wrist_link"),
        _joint("joint_6", "upper_wrist_link", "end_effector_link"),
        _joint("end_effector", "end_effector_link", "dummy_link", "fixed"),
        _joint("gripper_base_joint", "dummy_link", "gripper_base_link", "fixed"),
    )


@pytest.mark.parametrize(
    ("wrist", "merged"),
    [("", False), (_inertial(0.05, 0.0, 0.0, 0.0), True)],  # no inertial; a point mass
)
def test_a_moving_link_holds_mass_through_a_massless_frame(
    tmp_path: Path, wrist: str, merged: bool
) -> None:
    """Issue 32: the Gen3 lite was refused; the lumping looked one fixed joint down only.

    MuJoCo counts the gripper two welds down; the wrist's own point mass, when it has one,
    moves two frames down into it, and the mass matrix stays Pinocchio's.
    """
    urdf = _wrist_through_frame(wrist)
    res, m = _export(tmp_path, urdf)
    assert ("mass: merged into a rigid child" in _topics(res)) == merged
    d = mujoco.MjData(m)
    rng = np.random.default_rng(SEED)
    for _ in range(N_CONFIGS):
        d.qpos[:] = rng.uniform(-2.0, 2.0, m.nq)
        mujoco.mj_forward(m, d)
        M = np.zeros((m.nv, m.nv))
        mujoco.mj_fullM(m, d, M)
        assert np.max(np.abs(M - _pin_M(urdf, d.qpos.copy()))) < DYN_TOL
