"""Mass properties a spec derives from a shape: solid-body primitives and closed meshes.

Primitives keep the course's xacro inertia macros (common_properties.xacro); only their
mass follows from a density here. A mesh's volume, centre of mass and inertia tensor are
computed by trimesh (divergence theorem over the closed surface), so the mesh must be
watertight with consistent winding: an open or non-manifold mesh has no inside, and is
refused naming the file.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from armcli.compiler.meshfiles import locate
from armcli.errors import InputError
from armcli.io.meshbound import check_mesh_payload
from armcli.io.userfile import check_regular
from armcli.spec.model import Inertial, Shape

MAX_MESH_BYTES = 20_000_000  # same cap as urdf.mesh_confine for meshes check and view load
MIN_VOLUME = 1e-15  # [m³] below this a "solid" is a sheet


@dataclass(frozen=True)
class MassProperties:
    """Mass [kg], centre of mass [m] and inertia about it [kg·m²] in the frame `rpy` [rad]."""

    mass: float
    com: tuple[float, float, float]
    rpy: tuple[float, float, float]
    inertia: tuple[float, float, float, float, float, float]  # ixx ixy ixz iyy iyz izz


def primitive_mass(shape: Shape, inertial: Inertial) -> float:
    """The mass [kg] of a primitive shape: given, or density times its volume."""
    if inertial.mass is not None:
        return inertial.mass
    volume = shape.geometry.volume()
    assert volume is not None and inertial.density is not None
    return inertial.density * volume


def _load(path: Path, filename: str, field: str | None) -> object:
    import trimesh

    size = check_regular(path, "mesh file")
    if size > MAX_MESH_BYTES:
        raise InputError(
            f"mesh {filename} is {size} bytes, more than {MAX_MESH_BYTES}", field=field
        )
    try:  # compressed meshes inflated under a cap, declared triangles counted (issue 27)
        check_mesh_payload(path, MAX_MESH_BYTES)
    except InputError as exc:
        raise InputError(exc.message, field=field) from None
    try:
        mesh = trimesh.load(str(path), force="mesh", process=True)
    except Exception as exc:  # trimesh raises many types for unreadable files
        raise InputError(f"cannot read mesh {filename}: {exc}", field=field) from None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise InputError(f"mesh {filename} has no triangles", field=field)
    return mesh


def mesh_mass_properties(
    shape: Shape, inertial: Inertial, base_dir: Path, field: str | None = None
) -> MassProperties:
    """Mass properties of a closed mesh shape, in the link frame (tensor in the shape's frame).

    Raises:
        InputError: the file is missing or unreadable, or the mesh is open or non-manifold.
    """
    import numpy as np
    import trimesh

    mesh_spec = shape.geometry.mesh
    assert mesh_spec is not None
    filename = mesh_spec.filename
    mesh = _load(locate(filename, base_dir, field), filename, field)
    assert isinstance(mesh, trimesh.Trimesh)
    with np.errstate(all="ignore"):  # a huge scale overflows: refused below, not warned
        props = _scaled_properties(mesh, mesh_spec.scale, shape, inertial, filename, field)
    if not all(math.isfinite(x) for x in (props.mass, *props.com, *props.inertia)):
        raise InputError(
            f"mesh {filename} scaled by {list(mesh_spec.scale)} has a non-finite volume or "
            "inertia (the scale is out of range); give a sensible scale or an explicit inertial",
            field=field,
        )
    return props


def _scaled_properties(
    mesh: Any,
    scale_xyz: tuple[float, float, float],
    shape: Shape,
    inertial: Inertial,
    filename: str,
    field: str | None,
) -> MassProperties:
    """Mass properties of a loaded mesh under `scale_xyz` (see mesh_mass_properties)."""
    import numpy as np
    import trimesh

    scale = np.diag([*scale_xyz, 1.0])
    mesh.apply_transform(scale)
    if not (mesh.is_watertight and mesh.is_winding_consistent):
        unpaired = len(trimesh.grouping.group_rows(mesh.edges_sorted, require_count=1))  # type: ignore[no-untyped-call]
        why = "open or non-manifold" if not mesh.is_watertight else "inconsistently wound"
        raise InputError(
            f"mesh {filename} is {why} ({unpaired} edges without a partner face); "
            "its volume and inertia are undefined: close the mesh or give an explicit inertial",
            field=field,
        )
    if mesh.volume < 0:  # inside-out (or mirrored by a negative scale)
        mesh.invert()
    volume = float(mesh.volume)
    if volume < MIN_VOLUME:
        raise InputError(f"mesh {filename} encloses no volume ({volume:g} m³)", field=field)
    density = inertial.density if inertial.density is not None else (inertial.mass or 0.0) / volume
    J = np.asarray(mesh.moment_inertia, dtype=float) / float(mesh.density) * density
    T = trimesh.transformations.euler_matrix(*shape.origin.rpy, axes="sxyz")  # type: ignore[no-untyped-call]
    com = np.asarray(shape.origin.xyz, float) + T[:3, :3] @ np.asarray(mesh.center_mass, float)
    return MassProperties(
        mass=density * volume,
        com=(float(com[0]), float(com[1]), float(com[2])),
        rpy=shape.origin.rpy,
        inertia=tuple(float(J[i, k]) for i, k in ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))),  # type: ignore[arg-type]
    )
