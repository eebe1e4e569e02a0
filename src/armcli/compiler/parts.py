"""Reusable parts -> xacro macros, placements -> macro calls plus their attaching joints.

Each part is written once, as `<xacro:macro name=PART params="prefix [reflect]">`,
holding its links and joints with `${prefix}` names; a part that is placed mirrored
takes `reflect` (1 or -1) and multiplies it into every value the x-z reflection flips
(see `spec.parts`). A placement is then one line, `<xacro:PART prefix="left_"
reflect="1"/>`, and the joint that hangs it from its parent: the generated xacro
reads like the course's wheel macro.
"""

from __future__ import annotations

from lxml import etree

from armcli.compiler.joints import joint_element
from armcli.compiler.links import link_element
from armcli.compiler.meshfiles import MeshNames
from armcli.compiler.xmlfmt import XACRO_NS, sub
from armcli.spec.joint_types import ROTARY_TYPES
from armcli.spec.model import Part, Placement, RobotSpec
from armcli.spec.parts import part_root, placed_joints

X = f"{{{XACRO_NS}}}"
# Which components of a vector attribute flip under the x-z reflection.
_FLIP_ORIGIN = {"xyz": (1,), "rpy": (0, 2)}


def _reflect(text: str, components: tuple[int, ...]) -> str:
    parts = text.split()
    for i in components:
        v = parts[i]
        if v in ("0", "-0"):
            continue
        parts[i] = "${reflect}" if v == "1" else "${-reflect}" if v == "-1" else f"${{reflect*{v}}}"
    return " ".join(parts)


def _mirror(macro: etree._Element) -> None:
    """Multiply `reflect` into every value the reflection flips, in place."""
    for el in macro.iter():
        if el.tag in ("origin",) or str(el.tag).endswith("_inertia"):
            for attr, comps in _FLIP_ORIGIN.items():
                if el.get(attr) is not None:
                    el.set(attr, _reflect(str(el.get(attr)), comps))
        elif el.tag == "mesh":
            el.set("scale", _reflect(el.get("scale", "1 1 1"), (1,)))
        elif el.tag == "inertia":
            for attr in ("ixy", "iyz"):
                el.set(attr, _reflect(str(el.get(attr, "0")), (0,)))
        elif el.tag == "joint":
            axis = el.find("axis")
            if axis is not None:
                comps = (0, 2) if el.get("type") in ROTARY_TYPES else (1,)
                axis.set("xyz", _reflect(str(axis.get("xyz")), comps))


def _prefix(macro: etree._Element, part: Part) -> None:
    """`${prefix}` before every link and joint name the part defines."""
    for el in macro.iter("link", "joint"):
        el.set("name", "${prefix}" + str(el.get("name")))
    for el in macro.iter("parent", "child"):
        el.set("link", "${prefix}" + str(el.get("link")))
    for el in macro.iter("mimic"):
        if el.get("joint") in part.joints:
            el.set("joint", "${prefix}" + str(el.get("joint")))


def macro_element(
    parent: etree._Element, name: str, part: Part, reflect: bool, names: MeshNames
) -> None:
    """Append the part's macro definition to `parent`."""
    params = "prefix reflect" if reflect else "prefix"
    macro = sub(parent, X + "macro", name=name, params=params)
    for lname, link in part.links.items():
        link_element(macro, lname, link, {}, names, f"parts.{name}.links.{lname}")
    for jname, joint in part.joints.items():
        joint_element(macro, jname, joint)
    _prefix(macro, part)
    if reflect:
        _mirror(macro)


def _reflects(spec: RobotSpec, part: str) -> bool:
    return any(p.mirror for p in spec.parts_placements() if p.part == part)


def macros_xml(
    root: etree._Element, spec: RobotSpec, placements: list[Placement], names: MeshNames
) -> None:
    """The macros of the parts placed here, once each."""
    for pname in dict.fromkeys(p.part for p in placements):
        macro_element(root, pname, spec.parts[pname], _reflects(spec, pname), names)


def placements_xml(root: etree._Element, spec: RobotSpec, placements: list[Placement]) -> None:
    """Each placement: its macro call and the joint that hangs it from its parent."""
    for p in placements:
        part = spec.parts[p.part]
        reflect = _reflects(spec, p.part)
        attrs = {"prefix": p.prefix, **({"reflect": "-1" if p.mirror else "1"} if reflect else {})}
        sub(root, X + p.part, **attrs)
        attach = placed_joints(p, part, part_root(part))[p.joint]
        joint_element(root, p.joint, attach)


def placed(spec: RobotSpec, placements: list[Placement]) -> tuple[set[str], set[str]]:
    """Link and joint names that placements add (written by macros, not one by one)."""
    links: set[str] = set()
    joints: set[str] = set()
    for p in placements:
        part = spec.parts[p.part]
        links |= {f"{p.prefix}{n}" for n in part.links}
        joints |= {p.joint, *(f"{p.prefix}{n}" for n in part.joints)}
    return links, joints
