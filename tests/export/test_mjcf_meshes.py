"""Meshes in `export mjcf`: the caps `check` applies, and the forms MuJoCo decodes.

Before: an ASCII STL (example-robot-data's simple_humanoid) and a misoriented OBJ
(alex's nub) exported with exit 0 into models MuJoCo refused; a 25 MB mesh was copied
as is and a 3 GB sparse one took 2.9 GB of memory (issue 20). Reference for the
converted STL: the vertices parsed back from the ASCII text by numpy.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from lxml import etree

from armcli.errors import InputError
from armcli.export.mjcf_files import export_mjcf
from armcli.export.mjcf_meshes import MJ_STL_MAX_FACES, is_flat, read_mesh
from armcli.io.mesh_confine import MAX_MESH_BYTES, MAX_MESH_TOTAL_BYTES

mujoco = pytest.importorskip("mujoco")

FACET = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
TET = np.array([[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]])
TET_FACES = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]


def _ascii_stl(path: Path) -> np.ndarray:
    tris = TET[np.array(TET_FACES)]
    lines = ["solid tet"]
    for t in tris:
        lines += ["  facet normal 0 0 0", "    outer loop"]
        lines += [f"      vertex {x:.6e} {y:.6e} {z:.6e}" for x, y, z in t]
        lines += ["    endloop", "  endfacet"]
    path.write_text("\n".join([*lines, "endsolid tet", ""]))
    return tris


def _urdf(tmp: Path, mesh: str) -> Path:
    (tmp / "r.urdf").write_text(
        '<robot name="r"><link name="base"><inertial><mass value="1"/>'
        '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'
        f'<visual><geometry><mesh filename="{mesh}"/></geometry></visual>'
        f'<collision><geometry><mesh filename="{mesh}"/></geometry></collision></link></robot>'
    )
    return tmp / "r.urdf"


def test_ascii_stl_is_rewritten_as_binary(tmp_path: Path) -> None:
    tris = _ascii_stl(tmp_path / "tet.stl")
    res = export_mjcf(_urdf(tmp_path, "tet.stl"), tmp_path / "out" / "robot.xml")
    data = (tmp_path / "out" / "meshes" / "tet.stl").read_bytes()
    n = int(np.frombuffer(data, "<u4", 1, 80)[0])
    assert len(data) == 84 + 50 * n and n == len(TET_FACES)
    got = np.frombuffer(data, FACET, n, 84)["v"]
    assert np.allclose(got, tris, atol=1e-7)  # float32 of the ASCII values
    assert "tet.stl" in res.report and "rewritten as binary STL" in res.report
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "out" / "scene.xml"))
    assert m.nmesh == 1 and m.mesh_facenum[0] == len(TET_FACES)


def test_flat_and_misoriented_meshes_load(tmp_path: Path) -> None:
    """A flat OBJ (a square) gets inertia="shell"; a misoriented one the hull's inertia."""
    (tmp_path / "flat.obj").write_text("v 0 0 0\nv 0 1 0\nv 0 1 1\nv 0 0 1\nf 1 2 3\nf 1 3 4\n")
    res = export_mjcf(_urdf(tmp_path, "flat.obj"), tmp_path / "a" / "robot.xml")
    doc = etree.parse(str(tmp_path / "a" / "robot.xml"))
    assert doc.find("asset/mesh").get("inertia") == "shell" and "flat.obj" in res.report
    classes = [g.get("class") for g in doc.find("worldbody").iter("geom")]
    assert classes == ["visual"]  # no convex hull, so no contact in MuJoCo: drawn only
    assert res.verdict.compiled
    faces = " ".join(f"f {c + 1} {b + 1} {a + 1}" for a, b, c in TET_FACES)  # inside out
    obj = "".join(f"v {x} {y} {z}\n" for x, y, z in TET) + faces.replace(" f", "\nf") + "\n"
    (tmp_path / "inv.obj").write_text(obj)
    res = export_mjcf(_urdf(tmp_path, "inv.obj"), tmp_path / "b" / "robot.xml")
    assert res.verdict.compiled  # MuJoCo's default ("legacy") inertia refuses this mesh


def test_is_flat_tells_planes_from_solids() -> None:
    rng = np.random.default_rng(0)
    plane = np.c_[rng.normal(size=(50, 2)), np.zeros(50)] @ np.linalg.qr(rng.normal(size=(3, 3)))[0]
    assert is_flat(plane) and not is_flat(TET) and is_flat(TET[:3])


def test_stl_beyond_mujocos_face_limit_is_left_out(tmp_path: Path) -> None:
    n = MJ_STL_MAX_FACES + 1
    rec = np.zeros(n, FACET)
    rec["v"] = TET[np.array(TET_FACES)][np.arange(n) % 4]
    (tmp_path / "big.stl").write_bytes(b"\0" * 80 + np.uint32(n).tobytes() + rec.tobytes())
    assert read_mesh(tmp_path / "big.stl").skip is not None
    res = export_mjcf(_urdf(tmp_path, "big.stl"), tmp_path / "out" / "robot.xml")
    assert "big.stl" in res.report and not (tmp_path / "out" / "meshes").exists()
    assert res.verdict.compiled


def _sparse(path: Path, size: int) -> None:
    with open(path, "wb") as fh:
        fh.truncate(size)  # no disk blocks: the 3 GB case of issue 20 costs nothing here


def test_mesh_over_checks_byte_cap_is_refused_before_anything_is_written(tmp_path: Path) -> None:
    _sparse(tmp_path / "huge.stl", MAX_MESH_BYTES + 1)
    with pytest.raises(InputError, match="cap"):
        export_mjcf(_urdf(tmp_path, "huge.stl"), tmp_path / "out" / "robot.xml")
    assert not (tmp_path / "out").exists()


def test_meshes_over_the_robot_total_are_refused(tmp_path: Path) -> None:
    k = MAX_MESH_TOTAL_BYTES // MAX_MESH_BYTES + 1
    links = ""
    for i in range(k):
        _sparse(tmp_path / f"m{i}.stl", MAX_MESH_BYTES)
        mesh = f'<mesh filename="m{i}.stl"/>'
        links += f'<link name="l{i}"><visual><geometry>{mesh}</geometry></visual></link>'
    joints = "".join(
        f'<joint name="j{i}" type="fixed"><parent link="l0"/><child link="l{i}"/></joint>'
        for i in range(1, k)
    )
    (tmp_path / "r.urdf").write_text(f'<robot name="r">{links}{joints}</robot>')
    with pytest.raises(InputError, match="cap"):
        export_mjcf(tmp_path / "r.urdf", tmp_path / "out" / "robot.xml")
    assert not (tmp_path / "out").exists()
    assert os.path.getsize(tmp_path / "m0.stl") == MAX_MESH_BYTES  # untouched


DAE = Path(__file__).parents[1] / "fixtures" / "real_robots" / "meshes" / "textured.dae"


@pytest.mark.parametrize("unit", [1.0, 0.001])
def test_collada_collision_meshes_become_binary_stl_in_metres(tmp_path: Path, unit: float) -> None:
    """Doosan M1013: every collision mesh is COLLADA, which MuJoCo cannot read; they were
    left out with exit 0. The fixture is TET with the same faces (its texture is missing,
    as PR2's); a millimetre copy (unit 0.001, coordinates x1000) must give the same metres.
    """
    text = DAE.read_text()
    if unit != 1.0:
        text = text.replace('<unit name="meter" meter="1"/>', f'<unit name="mm" meter="{unit}"/>')
        text = text.replace("0 0 0 0.1 0 0 0 0.1 0 0 0 0.1", "0 0 0 100 0 0 0 100 0 0 0 100")
        assert f'meter="{unit}"' in text and "100 0 0" in text
    (tmp_path / "tet.dae").write_text(text)
    res = export_mjcf(_urdf(tmp_path, "tet.dae"), tmp_path / "out" / "robot.xml")
    data = (tmp_path / "out" / "meshes" / "tet.stl").read_bytes()
    n = int(np.frombuffer(data, "<u4", 1, 80)[0])
    assert len(data) == 84 + 50 * n and n == len(TET_FACES)
    got = np.frombuffer(data, FACET, n, 84)["v"]
    assert np.allclose(got, TET[np.array(TET_FACES)], atol=1e-7)  # float32 of 0.1
    assert "tet.dae" in res.report and "converted to binary STL" in res.report
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "out" / "scene.xml"))
    assert m.nmesh == 1 and m.mesh_facenum[0] == len(TET_FACES)
    assert int(np.sum(m.geom_type == mujoco.mjtGeom.mjGEOM_MESH)) == 2  # visual + collision
