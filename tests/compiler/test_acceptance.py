"""A spec with meshes, several shapes per link, a mimic gripper and passthrough XML builds a
URDF that every parser accepts: check_urdf (urdfdom), Pinocchio (model and meshes), MuJoCo
and SDFormat (`ign sdf -k`, Gazebo's own URDF parser). Parsers that are not installed skip
with the reason (scripts/sysdeps.sh installs them)."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest
from lxml import etree

from armcli.compiler.expand import build
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
    from armcli.check.rules import CheckOptions
    from armcli.check.run import check_urdf
    from armcli.spec.load import load_spec
    from armcli.urdf.read import read_urdf

    spec = load_spec(built.parent.parent / "armcli.yaml")
    result = check_urdf(read_urdf(built), CheckOptions(spec=spec))
    about_fingers = [f for f in result.findings if "finger" in f.message]
    assert about_fingers == []


def test_simulate_refuses_mimic_joints_naming_the_way_out(built: Path) -> None:
    from armcli.errors import InputError
    from armcli.sim.job import refuse_mimic
    from armcli.urdf.read import read_urdf

    doc = read_urdf(built)
    with pytest.raises(InputError) as info:
        refuse_mimic(doc, None)
    message = str(info.value)
    assert "'right_finger_joint' mimics 'left_finger_joint'" in message
    hint = message.split("lock the followers with `SimOptions.joints` ")[1]
    assert hint.startswith("shoulder_pan_joint,") and "right_finger_joint" not in hint
    refuse_mimic(doc, ["shoulder_pan_joint", "left_finger_joint"])  # followers locked: accepted
