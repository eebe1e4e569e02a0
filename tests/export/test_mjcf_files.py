"""Issue 20: `export mjcf` writes its files all-or-nothing and its comments stay comments.

Before: meshes were written before a failure (full disk, `scene.xml` a directory), killed
runs left `.tmp` files forever, a symlinked `meshes/` was written through, and a name
holding `--` or `-->` broke the model's header comment or injected markup after it.
"""

from __future__ import annotations

import errno
import os
import struct
from pathlib import Path

import pytest
from lxml import etree

from armcli.errors import ArmcliError, OutputRefusedError
from armcli.export.mjcf_files import export_mjcf
from armcli.io import together

mujoco = pytest.importorskip("mujoco")

TET = (  # a tetrahedron's four faces, outward
    (0, 0, 0, 0, 0.1, 0, 0.1, 0, 0),
    (0, 0, 0, 0.1, 0, 0, 0, 0, 0.1),
    (0, 0, 0, 0, 0, 0.1, 0, 0.1, 0),
    (0.1, 0, 0, 0, 0.1, 0, 0, 0, 0.1),
)
# binary STL: 80-byte header, face count, per face a normal (zero: MuJoCo recomputes it),
# three vertices and a 2-byte attribute
TET_STL = (
    b"\0" * 80 + struct.pack("<I", 4) + b"".join(struct.pack("<12fH", 0, 0, 0, *t, 0) for t in TET)
)


def _robot(tmp: Path, name: str = "r", mass: float = 1.0, file: str = "r.urdf") -> Path:
    (tmp / "tet.stl").write_bytes(TET_STL)
    (tmp / file).write_text(
        f'<robot name="{name}"><link name="base"><inertial><mass value="{mass}"/>'
        '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'
        '<visual><geometry><mesh filename="tet.stl"/></geometry></visual></link></robot>'
    )
    return tmp / file


def _tree(root: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(root)): p.read_bytes()
        for p in sorted(root.rglob("*"))
        if p.is_file() and not p.is_symlink()
    }


def test_scene_xml_being_a_directory_writes_nothing(tmp_path: Path) -> None:
    out = tmp_path / "mj"
    (out / "scene.xml").mkdir(parents=True)
    with pytest.raises(ArmcliError, match=r"scene\.xml"):
        export_mjcf(_robot(tmp_path), out / "robot.xml")
    assert sorted(p.name for p in out.iterdir()) == ["scene.xml"]  # no model, no meshes/


def test_a_failed_write_leaves_the_previous_export_whole(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A full disk while staging the second file: every file stays the old one."""
    out = tmp_path / "mj" / "robot.xml"
    export_mjcf(_robot(tmp_path), out)
    before = _tree(out.parent)
    real_fsync, calls = os.fsync, []

    def full_disk(fd: int) -> None:
        calls.append(fd)
        if len(calls) == 2:
            raise OSError(errno.ENOSPC, "No space left on device")
        real_fsync(fd)

    monkeypatch.setattr("armcli.io.together.os.fsync", full_disk)
    with pytest.raises(ArmcliError, match="No space left"):
        export_mjcf(_robot(tmp_path, mass=2.0), out)
    monkeypatch.undo()
    assert _tree(out.parent) == before  # nothing new, nothing half-written, no staging left


def test_stale_staging_files_of_killed_runs_are_removed(tmp_path: Path) -> None:
    out = tmp_path / "mj" / "robot.xml"
    out.parent.mkdir()
    dead = 2**22 + 12345  # above Linux's default pid_max: no such process
    stale = out.parent / f"{together.TAG}{dead}-{'5' * 16}-0.tmp"  # as io.journal names them
    stale.write_bytes(b"half a model")
    export_mjcf(_robot(tmp_path), out)
    assert not stale.exists()
    assert sorted(p.name for p in out.parent.iterdir()) == ["meshes", "robot.xml", "scene.xml"]


def test_a_symlinked_meshes_directory_is_refused_as_build_refuses_links(tmp_path: Path) -> None:
    out = tmp_path / "mj" / "robot.xml"
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    out.parent.mkdir()
    (out.parent / "meshes").symlink_to(elsewhere)
    with pytest.raises(OutputRefusedError, match="symlink"):
        export_mjcf(_robot(tmp_path), out)
    assert list(elsewhere.iterdir()) == [] and not out.exists()


def test_a_symlinked_output_directory_is_written_through(tmp_path: Path) -> None:
    real = tmp_path / "real"
    real.mkdir()
    (tmp_path / "mj").symlink_to(real)
    export_mjcf(_robot(tmp_path), tmp_path / "mj" / "robot.xml")
    assert (tmp_path / "mj").is_symlink()
    assert sorted(_tree(real)) == ["meshes/tet.stl", "robot.xml", "scene.xml"]


def test_names_with_double_hyphens_stay_inside_the_header_comment(tmp_path: Path) -> None:
    """A file named like `a---b-->c.urdf` (legal on Linux; only / is not) once ended the comment."""
    evil = "my--robot---x--><!DOCTYPE m [<!ENTITY e SYSTEM 'passwd.ent'>]>-.urdf"
    src = _robot(tmp_path, name="r--b", file=evil)
    out = tmp_path / "mj" / "robot.xml"
    export_mjcf(src, out)
    for path in (out, out.parent / "scene.xml"):
        doc = etree.parse(str(path), etree.XMLParser(resolve_entities=False))
        assert doc.docinfo.doctype == "" and doc.getroot().tag == "mujoco"
        comments = [c.text for c in doc.getroot().itersiblings(preceding=True)]
        assert comments and all("--" not in (c or "") for c in comments)
    mujoco.MjModel.from_xml_path(str(out.parent / "scene.xml"))
