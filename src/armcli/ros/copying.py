"""Which files `ros-package` may copy into a description package: data, never host files.

A spec names its meshes and textures by path; `ros-package` copies them into
`<name>_description/meshes`, where they are installed with mode 0644 and may be
published. So a file is copied only when it is a regular file of at most
MAX_MESH_BYTES whose real path (symlinks followed, `..` collapsed) lies inside the
spec's directory or a package root armcli's lookup found: the confinement `check`
applies to the meshes it reads (urdf.meshes.confined). `/etc/shadow`,
`../../proc/self/environ` or a symlink in the repository pointing outside it are
refused by name (issue 27).
"""

from __future__ import annotations

import os
from pathlib import Path

from armcli.compiler.meshfiles import package_meshes
from armcli.errors import InputError
from armcli.io.mesh_confine import MAX_MESH_BYTES, MAX_MESH_TOTAL_BYTES
from armcli.io.userfile import read_regular
from armcli.spec.model import RobotSpec
from armcli.urdf.meshes import MeshSearch, confined


def copy_source(path: Path, base_dir: Path, search: MeshSearch) -> bytes:
    """The bytes of a spec file to copy; InputError naming it and why when it may not be."""
    where = Path(os.path.abspath(base_dir / path))
    if not confined(str(where), where, base_dir, search):
        raise InputError(
            f"{path}: not copied into the package: it resolves to {os.path.realpath(where)}, "
            "outside the spec's directory and every package armcli found",
            field="meshes",
        )
    return read_regular(where, max_bytes=MAX_MESH_BYTES, what="mesh file")


def mesh_files(spec: RobotSpec, search: MeshSearch | None = None) -> dict[str, bytes]:
    """The spec's path-named meshes and textures, as copied under `meshes/`."""
    lookup = search if search is not None else MeshSearch()
    out: dict[str, bytes] = {}
    total = 0
    for rel, path in package_meshes(spec).items():
        out[rel] = copy_source(path, spec.base_dir, lookup)
        total += len(out[rel])
        if total > MAX_MESH_TOTAL_BYTES:
            raise InputError(
                f"the spec's meshes are more than {MAX_MESH_TOTAL_BYTES} bytes; not copied",
                field="meshes",
            )
    return out
