"""The vertices of a mesh file, read without trimesh where the format is simple.

`check` needs only the points of the collision meshes (their lowest ones touch the
ground), and importing trimesh (with scipy.spatial) cost about 2 s of the ~3 s `check`
took on a robot with STL meshes. Binary and ASCII STL and OBJ are read here with numpy;
other formats (COLLADA, ...) through trimesh. The file is the bounded real path
`io.mesh_confine` gives.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from armcli.io.mesh_confine import MAX_MESH_BYTES, bounded_mesh_file
from armcli.io.userfile import read_regular
from armcli.urdf.meshlog import quiet_trimesh

_FLOAT = rb"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_ASCII_VERTEX = re.compile(
    rb"vertex\s+(" + _FLOAT + rb")\s+(" + _FLOAT + rb")\s+(" + _FLOAT + rb")"
)
_OBJ_VERTEX = re.compile(
    rb"^\s*v\s+(" + _FLOAT + rb")\s+(" + _FLOAT + rb")\s+(" + _FLOAT + rb")", re.M
)
_FACET = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])


def stl_vertices(data: bytes) -> NDArray[np.float64]:
    """(n, 3) vertices of a binary or ASCII STL (one row per face corner); empty if neither."""
    if len(data) >= 84:
        n = int(np.frombuffer(data, "<u4", 1, 80)[0])
        if len(data) == 84 + 50 * n:  # binary: 80-byte header, count, 50 bytes per face
            rec = np.frombuffer(data, dtype=_FACET, count=n, offset=84)
            return np.asarray(rec["v"], dtype=np.float64).reshape(-1, 3)
    return np.array(_ASCII_VERTEX.findall(data), dtype=np.float64).reshape(-1, 3)


def obj_vertices(data: bytes) -> NDArray[np.float64]:
    """(n, 3) vertices of a Wavefront OBJ (its `v x y z` lines)."""
    return np.array(_OBJ_VERTEX.findall(data), dtype=np.float64).reshape(-1, 3)


def read_vertices(path: Path | None, source: str) -> NDArray[np.float64] | None:
    """The mesh file's vertices [file units] (n, 3), or None when missing or unreadable."""
    if path is None or not path.is_file():
        return None
    try:
        real = bounded_mesh_file(path, source)
        suffix = real.suffix.lower()
        if suffix in (".stl", ".obj"):
            data = read_regular(real, max_bytes=MAX_MESH_BYTES, what="mesh file")
            v = stl_vertices(data) if suffix == ".stl" else obj_vertices(data)
        else:
            v = _trimesh_vertices(real)
    except Exception:  # an unreadable file gives no points; the caller says which
        return None
    ok = v.ndim == 2 and v.shape[1] == 3 and len(v) and bool(np.all(np.isfinite(v)))
    return v if ok else None


def _trimesh_vertices(real: Path) -> NDArray[np.float64]:
    import trimesh

    with quiet_trimesh():  # a missing texture does not move a vertex
        mesh = trimesh.load(str(real), force="mesh", process=False)
    return np.asarray(getattr(mesh, "vertices", np.empty((0, 3))), dtype=np.float64)
