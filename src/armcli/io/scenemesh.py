"""A scene's mesh file read as bytes: never a file it names, never over the scene's budgets.

trimesh opened the scene's mesh by path and followed what the file names: an OBJ's
`mtllib` or a glTF's external buffers beside it, so one that was a FIFO hung the scene
reader (issue 42). Here the file passes the mesh caps (`mesh_confine.bounded_mesh_file`:
size, compression bombs, declared triangles), is read once as bytes, its declared
triangles are counted against what is left of the scene's budget before trimesh parses
it, and trimesh parses the bytes with no resolver: an OBJ's material library is not
read, and a glTF whose buffers are files beside it is refused (a .glb, or buffers as
`data:` URIs, hold their data).
"""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np

from armcli.errors import InputError
from armcli.io.mesh_confine import MAX_MESH_BYTES, bounded_mesh_file
from armcli.io.meshbound import declared_triangles
from armcli.io.userfile import read_regular


class OverBudgetError(InputError):
    """A mesh that would take the scene past its triangle budget."""


def _external_buffers(data: bytes) -> list[str]:
    """The buffer and image URIs of a .gltf document that are files, not `data:` URIs."""
    try:
        doc = json.loads(data.decode("utf-8"))
    except ValueError:
        return []  # trimesh will say what is wrong with it
    named = (
        [*(doc.get("buffers") or []), *(doc.get("images") or [])] if isinstance(doc, dict) else []
    )
    uris = [b.get("uri") for b in named if isinstance(b, dict)]
    return [u for u in uris if isinstance(u, str) and not u.startswith("data:")]


def read_scene_mesh(file: Path, source: str, budget: int) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (V, 3) [file units] and triangles (F, 3) of a mesh file of a scene.

    `budget`: the triangles the scene may still add. Raises OverBudgetError past it, and
    InputError (message only: the caller names the field) for a file trimesh cannot read.
    """
    import trimesh

    real = bounded_mesh_file(file, source)
    data = read_regular(real, max_bytes=MAX_MESH_BYTES, what="mesh file")
    declared = declared_triangles(data)
    if declared > budget:
        raise OverBudgetError(f"declares {declared} triangles, more than the {budget} left")
    kind = real.suffix.lstrip(".").lower()
    if kind == "gltf" and (names := _external_buffers(data)):
        raise InputError(
            f"a glTF whose data is in other files ({names[0]!r}) is not read; "
            "armcli reads no file a mesh names: use a .glb"
        )
    try:
        loaded = trimesh.load(io.BytesIO(data), file_type=kind, force="mesh", process=False)
    except Exception as exc:  # trimesh raises many kinds on a bad file
        raise InputError(f"cannot read the mesh: {exc}") from None
    vertices = np.array(getattr(loaded, "vertices", []), dtype=np.float64).reshape(-1, 3)
    faces = np.array(getattr(loaded, "faces", []), dtype=np.int64).reshape(-1, 3)
    if len(faces) > budget:
        raise OverBudgetError(f"holds {len(faces)} triangles, more than the {budget} left")
    return vertices, faces
