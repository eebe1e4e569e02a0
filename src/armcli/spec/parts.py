"""Reusable parts: links and joints defined once, placed several times with a prefix.

A placement hangs a copy of the part from a `parent` link by its own joint, with every
link and joint name prefixed (`left_` + `wheel_link`), and optionally mirrored through the
parent's x-z plane (`mirror: true`, the right arm of a left arm). A mirrored frame is the
conjugate M R M of the original (M = diag(1, -1, 1)): origins flip y, roll and yaw;
revolute axes (axial vectors) flip x and z, prismatic axes y; meshes flip their y scale;
inertia tensors flip ixy and iyz. Symmetric primitives are their own mirror image.

`expand` turns placements into ordinary links and joints of the arm or the base, so
everything after validation sees one robot; the compiler writes each part once as a
xacro macro and each placement as a call (`compiler.parts`).
"""

from __future__ import annotations

from typing import Annotated

from pydantic import Field

from armcli.spec.graph import root_links
from armcli.spec.joint_types import ROTARY_TYPES, JointType
from armcli.spec.joints import Dynamics, Joint, Limit, Mimic
from armcli.spec.shapes import Geometry, Inertia, Link, Mesh, Origin, Shape
from armcli.spec.types import Name, UrdfName, Vec3, _Model

# path-like segments (`left/`), but no segment starts with `.` or `/`: `../../x/` and `/abs_`
# made names no link may have (issue 27: an internal error instead of the field's)
Prefix = Annotated[str, Field(pattern=r"^(?:[A-Za-z0-9_][A-Za-z0-9_.-]*/?)*$", max_length=64)]


class Part(_Model):
    """A reusable group of links and the joints between them (one tree)."""

    links: dict[UrdfName, Link] = Field(min_length=1, description="links by name, unprefixed")
    joints: dict[UrdfName, Joint] = Field({}, description="joints between the part's links")


class Placement(_Model):
    """One copy of a part, hung from `parent` by the joint `joint`."""

    part: Name = Field(description="name of an entry of `parts`")
    prefix: Prefix = Field(description="put before every link and joint name of the part")
    parent: UrdfName = Field(description="link the part hangs from")
    joint: UrdfName = Field(description="name of the joint from `parent` to the part's root")
    type: JointType = Field("fixed", description="type of that joint")
    origin: Origin = Field(Origin(), description="pose of that joint in the parent frame")
    axis: Vec3 = Field((0.0, 0.0, 1.0), description="its axis, for a moving joint [-]")
    limit: Limit | None = Field(None, description="its limits, for a revolute or prismatic one")
    dynamics: Dynamics | None = Field(None, description="its friction and damping")
    mimic: Mimic | None = Field(None, description="it follows another joint (a gripper finger)")
    mirror: bool = Field(
        False, description="reflect the part through the parent's x-z plane (left <-> right)"
    )


def mirror_origin(o: Origin) -> Origin:
    """The origin of a frame reflected through the x-z plane (M R M, M t)."""
    x, y, z = o.xyz
    r, p, yaw = o.rpy
    return Origin(xyz=(x, -y, z), rpy=(-r, p, -yaw))


def _mirror_geometry(g: Geometry) -> Geometry:
    if g.mesh is None:
        return g  # boxes, cylinders and spheres are symmetric about their y = 0 plane
    sx, sy, sz = g.mesh.scale
    return Geometry(mesh=Mesh(filename=g.mesh.filename, scale=(sx, -sy, sz)))


def _mirror_shape(s: Shape) -> Shape:
    return s.model_copy(
        update={"geometry": _mirror_geometry(s.geometry), "origin": mirror_origin(s.origin)}
    )


def mirror_link(link: Link) -> Link:
    """A link reflected through its frame's x-z plane."""
    if link.shorthand:
        return link.model_copy(update={"origin": mirror_origin(link.origin)})
    ine = link.inertial
    if ine is not None and ine.inertia is not None:
        i = ine.inertia
        ine = ine.model_copy(
            update={
                "origin": mirror_origin(ine.origin or Origin()),
                "inertia": Inertia(
                    ixx=i.ixx, ixy=-i.ixy, ixz=i.ixz, iyy=i.iyy, iyz=-i.iyz, izz=i.izz
                ),
            }
        )
    return link.model_copy(
        update={
            "visual": [_mirror_shape(s) for s in link.visual],
            "collision": [_mirror_shape(s) for s in link.collision],
            "inertial": ine,
        }
    )


def mirror_axis(joint_type: str, axis: tuple[float, float, float]) -> tuple[float, float, float]:
    """A joint axis reflected through the x-z plane: axial for rotations, polar otherwise."""
    x, y, z = axis
    return (-x, y, -z) if joint_type in ROTARY_TYPES else (x, -y, z)


def _prefixed(p: Placement, name: str) -> str:
    return f"{p.prefix}{name}"


def placed_links(p: Placement, part: Part) -> dict[str, Link]:
    """The placement's links: prefixed names, mirrored if asked."""
    return {_prefixed(p, n): (mirror_link(lk) if p.mirror else lk) for n, lk in part.links.items()}


def placed_joints(p: Placement, part: Part, root: str) -> dict[str, Joint]:
    """The placement's joints: the attaching joint, then the part's own, prefixed."""
    attach = Joint(
        type=p.type,
        parent=p.parent,
        child=_prefixed(p, root),
        origin=p.origin,
        axis=p.axis,
        limit=p.limit,
        dynamics=p.dynamics,
        mimic=p.mimic,
    )
    out = {p.joint: attach}
    for name, j in part.joints.items():
        update: dict[str, object] = {
            "parent": _prefixed(p, j.parent),
            "child": _prefixed(p, j.child),
        }
        if j.mimic is not None and j.mimic.joint in part.joints:
            update["mimic"] = j.mimic.model_copy(update={"joint": _prefixed(p, j.mimic.joint)})
        if p.mirror:
            update["origin"] = mirror_origin(j.origin)
            update["axis"] = mirror_axis(j.type, j.axis)
        out[_prefixed(p, name)] = j.model_copy(update=update)
    return out


def part_root(part: Part) -> str:
    """The part's root link: the one that is no joint's child (first in order if several)."""
    roots = root_links(part.links, (j.child for j in part.joints.values()))
    return roots[0] if roots else next(iter(part.links))


def placed_names(p: Placement, part: Part) -> tuple[set[str], set[str]]:
    """(link names, joint names) a placement adds, the attaching joint included."""
    links = {_prefixed(p, n) for n in part.links}
    return links, {p.joint, *(_prefixed(p, n) for n in part.joints)}
