"""Compressed mesh bombs and triangle floods are refused before any mesh library loads them
(issue 27: a 4.5 kB bz2 STL reached 3.0 GB in trimesh, a 3 MB zip mesh 2.2 GB)."""

from __future__ import annotations

import bz2
import gzip
import lzma
import struct
import zipfile
from pathlib import Path

import pytest

from armcli.compiler.massprops import mesh_mass_properties
from armcli.errors import InputError
from armcli.io.mesh_confine import MAX_MESH_BYTES, bounded_mesh_file
from armcli.io.meshbound import MAX_MESH_PAYLOAD_BYTES, MAX_MESH_TRIANGLES, check_mesh_payload
from armcli.spec.shapes import Geometry, Inertial, Mesh, Shape
from tests.meshes import house_triangles, write_stl

MIB = 1 << 20
BOMB_MIB = 40  # decompressed size of the bombs: twice the payload cap, small enough to build fast


def _zero_stl(n_triangles: int) -> bytes:
    """A binary STL of degenerate triangles (all zeros): compresses to almost nothing."""
    return b"\0" * 80 + struct.pack("<I", n_triangles) + b"\0" * (50 * n_triangles)


def _bomb(kind: str, path: Path) -> Path:
    stl = _zero_stl(BOMB_MIB * MIB // 50)
    if kind == "bz2":  # many small streams, as bz2 allows: quick to build, same to inflate
        one = bz2.compress(b"\0" * MIB)
        path.write_bytes(bz2.compress(stl[:84]) + one * BOMB_MIB)
    elif kind == "gzip":
        path.write_bytes(gzip.compress(stl, 1))
    elif kind == "xz":
        path.write_bytes(lzma.compress(stl, preset=0))
    else:
        with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
            zf.writestr("mesh.stl", stl)
    return path


@pytest.mark.parametrize("kind", ["bz2", "gzip", "xz", "zip"])
def test_compression_bombs_are_refused(kind: str, tmp_path: Path) -> None:
    path = _bomb(kind, tmp_path / "bomb.stl")
    assert path.stat().st_size < MAX_MESH_BYTES // 100  # small on disk
    with pytest.raises(InputError, match=f"decompresses to more than {MAX_MESH_PAYLOAD_BYTES}"):
        check_mesh_payload(path, MAX_MESH_BYTES)
    with pytest.raises(InputError, match="decompresses"):  # check, render, view, export, ground
        bounded_mesh_file(path, "robot.urdf")


def test_mesh_inertia_refuses_a_bomb(tmp_path: Path) -> None:
    _bomb("bz2", tmp_path / "bomb.stl")
    shape = Shape(geometry=Geometry(mesh=Mesh(filename="bomb.stl")))
    with pytest.raises(InputError, match="decompresses"):
        mesh_mass_properties(shape, Inertial(shape="visual", mass=1.0), tmp_path)


def test_triangle_flood_is_refused(tmp_path: Path) -> None:
    # an OBJ of one triangle repeated: 8 bytes a face, under the byte cap, over the face cap
    n = MAX_MESH_TRIANGLES + 1
    path = tmp_path / "flood.obj"
    path.write_bytes(b"v 0 0 0\nv 1 0 0\nv 0 1 0\n" + b"f 1 2 3\n" * n)
    assert path.stat().st_size < MAX_MESH_BYTES
    with pytest.raises(InputError, match=f"declares {n} triangles"):
        check_mesh_payload(path, MAX_MESH_BYTES)


def test_small_compressed_meshes_still_load(tmp_path: Path) -> None:
    """A modest gzip or zip mesh is inflated within the cap and passes."""
    plain = tmp_path / "house.stl"
    write_stl(plain, house_triangles())
    data = plain.read_bytes()
    (tmp_path / "house.stl.gz").write_bytes(gzip.compress(data))
    check_mesh_payload(plain, MAX_MESH_BYTES)
    check_mesh_payload(tmp_path / "house.stl.gz", MAX_MESH_BYTES)
    assert bounded_mesh_file(plain, "r.urdf") == plain.resolve()


def test_damaged_compressed_data_is_one_error(tmp_path: Path) -> None:
    path = tmp_path / "bad.stl"
    path.write_bytes(b"BZh9" + b"\x01" * 100)
    with pytest.raises(InputError, match="damaged compressed data"):
        check_mesh_payload(path, MAX_MESH_BYTES)
