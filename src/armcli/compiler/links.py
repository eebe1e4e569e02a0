"""Spec links -> URDF `<link>` elements: shapes, materials and inertials.

A shorthand link (the course's one solid) becomes xacro properties for its size and
mass, one visual and one collision that use them, and a call of the inertia macro of
its shape, as a person following the course writes it. A general link lists its
shapes with literal values; its inertial is a macro call (primitive), numbers computed
from the mesh (closed mesh), or the numbers given.
"""

from __future__ import annotations

import re

from lxml import etree

from armcli.compiler.massprops import mesh_mass_properties, primitive_mass
from armcli.compiler.meshfiles import MeshNames
from armcli.compiler.passthrough import copy_into
from armcli.compiler.xmlfmt import XACRO_NS, comment_text, fmt, literal, sub, vec
from armcli.spec.model import Geometry, InlineMaterial, Link, Origin, Shape

X = f"{{{XACRO_NS}}}"

# Solid-body inertia about the centroid, shape axes = inertial frame axes.
# Box: l along x, w along y, h along z. Cylinder: axis along z. [kg·m²]
INERTIA_MACROS = {
    "box_inertia": (
        "m l w h xyz rpy",
        {
            "ixx": "${(m/12) * (w*w + h*h)}",
            "iyy": "${(m/12) * (l*l + h*h)}",
            "izz": "${(m/12) * (l*l + w*w)}",
        },
    ),
    "cylinder_inertia": (
        "m r h xyz rpy",
        {
            "ixx": "${(m/12) * (3*r*r + h*h)}",
            "iyy": "${(m/12) * (3*r*r + h*h)}",
            "izz": "${(m/2) * (r*r)}",
        },
    ),
    "sphere_inertia": (
        "m r xyz rpy",
        {"ixx": "${(2/5) * m * r*r}", "iyy": "${(2/5) * m * r*r}", "izz": "${(2/5) * m * r*r}"},
    ),
}
_NOT_IDENTIFIER = re.compile(r"[^A-Za-z0-9_]")


def stems(link_names: list[str]) -> dict[str, str]:
    """Property prefix per link: the name without `_link`, unless that would clash."""
    safe = {n: _NOT_IDENTIFIER.sub("_", n) for n in link_names}
    short = {n: s[: -len("_link")] if s.endswith("_link") else s for n, s in safe.items()}
    clash = {s for s in short.values() if list(short.values()).count(s) > 1}
    return {n: (safe[n] if s in clash else s) for n, s in short.items()}


def link_properties(root: etree._Element, stem: str, link: Link) -> dict[str, str]:
    """Emit xacro properties for a shorthand link's dimensions and mass; return name -> ${ref}."""
    geo = link.geometry
    assert geo is not None and link.mass is not None
    values: dict[str, float] = {}
    if geo.box is not None:
        values = dict(zip(("length", "width", "height"), geo.box.size, strict=True))
    elif geo.cylinder is not None:
        values = {"radius": geo.cylinder.radius, "length": geo.cylinder.length}
    elif geo.sphere is not None:
        values = {"radius": geo.sphere.radius}
    values["mass"] = link.mass
    refs = {}
    for key, value in values.items():
        prop = f"{stem}_{key}"
        sub(root, X + "property", name=prop, value=fmt(value))
        refs[key] = f"${{{prop}}}"
    return refs


def _dims(geo: Geometry, refs: dict[str, str] | None) -> dict[str, str]:
    """Size attributes of a primitive: property references (shorthand) or literal values."""
    if geo.box is not None:
        if refs:
            return {"size": f"{refs['length']} {refs['width']} {refs['height']}"}
        return {"size": vec(geo.box.size)}
    if geo.cylinder is not None:
        if refs:
            return {"radius": refs["radius"], "length": refs["length"]}
        return {"radius": fmt(geo.cylinder.radius), "length": fmt(geo.cylinder.length)}
    assert geo.sphere is not None
    return {"radius": refs["radius"] if refs else fmt(geo.sphere.radius)}


def _geometry(
    parent: etree._Element, geo: Geometry, names: MeshNames, refs: dict[str, str] | None
) -> None:
    el = sub(parent, "geometry")
    if geo.mesh is not None:
        attrs = {"filename": literal(names.uri(geo.mesh.filename))}
        if geo.mesh.scale != (1.0, 1.0, 1.0):
            attrs["scale"] = vec(geo.mesh.scale)
        sub(el, "mesh", **attrs)
    else:
        sub(el, geo.kind, **_dims(geo, refs))


def _material(parent: etree._Element, material: str | InlineMaterial, names: MeshNames) -> None:
    if isinstance(material, str):
        sub(parent, "material", name=material)
        return
    el = sub(parent, "material", name=literal(material.name))
    if material.rgba is not None:
        sub(el, "color", rgba=vec(material.rgba))
    if material.texture is not None:
        sub(el, "texture", filename=literal(names.uri(material.texture)))


def shape_element(
    parent: etree._Element,
    tag: str,
    shape: Shape,
    names: MeshNames,
    refs: dict[str, str] | None = None,
) -> None:
    """Append a `<visual>` or `<collision>`: geometry, origin, material (visuals)."""
    el = sub(parent, tag, **({"name": literal(shape.name)} if shape.name is not None else {}))
    _geometry(el, shape.geometry, names, refs)
    sub(el, "origin", xyz=vec(shape.origin.xyz), rpy=vec(shape.origin.rpy))
    if shape.material is not None:
        _material(el, shape.material, names)


def _macro_call(
    parent: etree._Element, shape: Shape, mass: str, refs: dict[str, str] | None
) -> None:
    geo = shape.geometry
    args = {"m": mass}
    if geo.box is not None:
        l_, w, h = (
            (refs["length"], refs["width"], refs["height"]) if refs else map(fmt, geo.box.size)
        )
        args.update(l=l_, w=w, h=h)
    elif geo.cylinder is not None:
        r, h = (
            (refs["radius"], refs["length"])
            if refs
            else (fmt(geo.cylinder.radius), fmt(geo.cylinder.length))
        )
        args.update(r=r, h=h)
    else:
        assert geo.sphere is not None
        args.update(r=refs["radius"] if refs else fmt(geo.sphere.radius))
    args.update(xyz=vec(shape.origin.xyz), rpy=vec(shape.origin.rpy))
    sub(parent, X + f"{geo.kind}_inertia", **args)


def _explicit(
    parent: etree._Element,
    origin: Origin,
    mass: float,
    inertia: tuple[float, float, float, float, float, float],
) -> None:
    el = sub(parent, "inertial")
    sub(el, "origin", xyz=vec(origin.xyz), rpy=vec(origin.rpy))
    sub(el, "mass", value=fmt(mass))
    keys = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
    sub(el, "inertia", **{k: fmt(v) for k, v in zip(keys, inertia, strict=True)})


def inertial_element(
    parent: etree._Element,
    link: Link,
    names: MeshNames,
    refs: dict[str, str] | None,
    field: str,
) -> None:
    """Append the link's mass properties (nothing for a massless frame)."""
    source = link.inertial_source()
    if source is None:
        return
    if source.shape is None:
        assert source.mass is not None and source.inertia is not None
        _explicit(parent, source.origin or Origin(), source.mass, source.inertia.values())
        return
    shape = link.shape(source.shape)
    if shape.geometry.mesh is None:
        mass = refs["mass"] if refs else fmt(primitive_mass(shape, source))
        _macro_call(parent, shape, mass, refs)
        return
    props = mesh_mass_properties(shape, source, names.base_dir, f"{field}.inertial.shape")
    about = comment_text(shape.geometry.mesh.filename)  # "---" kept a "--" with replace
    parent.append(etree.Comment(f" mass properties computed from {about} "))
    _explicit(parent, Origin(xyz=props.com, rpy=props.rpy), props.mass, props.inertia)


def link_element(
    root: etree._Element, name: str, link: Link, refs: dict[str, str], names: MeshNames, field: str
) -> None:
    """Append the `<link>`: visuals, collisions, then the inertial."""
    el = sub(root, "link", name=name)
    r = refs or None
    for shape in link.visuals():
        shape_element(el, "visual", shape, names, r)
    for shape in link.collisions():
        shape_element(el, "collision", shape, names, r)
    inertial_element(el, link, names, r, field)
    copy_into(el, link.passthrough)
