"""The kinematic tree of a URDF: links, joints with types and limits, as text or Graphviz.

`armcli tree` is the stand-in for `check_urdf` and `urdf_to_graphviz`, which
most armcli users do not have; the DOT output follows urdf_to_graphviz's
layout (links as boxes, joints as blue ellipses, origins on the edges, children
in joint-name order) so the same tooling can read it.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from lxml import etree

from armcli.errors import InputError

MOVABLE = ("revolute", "continuous", "prismatic", "floating", "planar")
_TYPES = ("fixed", *MOVABLE)


@dataclass(frozen=True)
class JointInfo:
    """One URDF joint as the tree shows it; lengths [m], angles [rad]."""

    name: str
    type: str
    parent: str
    child: str
    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]
    axis: tuple[float, float, float]
    lower: float | None = None
    upper: float | None = None
    effort: float | None = None
    velocity: float | None = None


@dataclass(frozen=True)
class KinematicTree:
    """Links and joints of one robot, with its single root link."""

    robot: str
    root: str
    links: tuple[str, ...]
    joints: tuple[JointInfo, ...]

    def children(self, link: str) -> list[JointInfo]:
        """Joints whose parent is `link`, in name order (as urdfdom stores them)."""
        return sorted((j for j in self.joints if j.parent == link), key=lambda j: j.name)

    def walk(self) -> Iterator[tuple[int, JointInfo]]:
        """Depth-first (depth, joint) pairs from the root."""
        stack = [(1, j) for j in reversed(self.children(self.root))]
        while stack:
            depth, j = stack.pop()
            yield depth, j
            stack.extend((depth + 1, c) for c in reversed(self.children(j.child)))

    def movable(self) -> list[JointInfo]:
        """Joints that move, in depth-first order."""
        return [j for _, j in self.walk() if j.type in MOVABLE]


def _floats(text: str | None, n: int, default: tuple[float, ...], where: str) -> Any:
    if text is None:
        return default
    try:
        vals = tuple(float(x) for x in text.split())
    except ValueError:
        vals = ()
    if len(vals) != n or not all(math.isfinite(v) for v in vals):
        raise InputError(f"{where}: expected {n} finite numbers, got {text!r}")
    return vals


def _attr_float(el: Any, name: str, where: str) -> float | None:
    if el is None or el.get(name) is None:
        return None
    return float(_floats(el.get(name), 1, (0.0,), f"{where} {name}")[0])


def _joint(el: Any, source: str) -> JointInfo:
    name = el.get("name") or ""
    jtype = el.get("type") or ""
    where = f"joint {name!r}"
    if jtype not in _TYPES:
        raise InputError(f"{where}: unknown type {jtype!r}; known: {', '.join(_TYPES)}", file=source)
    parent, child, origin = el.find("parent"), el.find("child"), el.find("origin")
    if parent is None or child is None or not parent.get("link") or not child.get("link"):
        raise InputError(f"{where}: needs <parent link=...> and <child link=...>", file=source)
    lim = el.find("limit")
    try:
        return JointInfo(
            name=name,
            type=jtype,
            parent=parent.get("link"),
            child=child.get("link"),
            xyz=_floats(origin.get("xyz") if origin is not None else None, 3, (0.0,) * 3, where),
            rpy=_floats(origin.get("rpy") if origin is not None else None, 3, (0.0,) * 3, where),
            axis=_floats(
                el.find("axis").get("xyz") if el.find("axis") is not None else None,
                3,
                (1.0, 0.0, 0.0),
                where,
            ),
            lower=_attr_float(lim, "lower", where),
            upper=_attr_float(lim, "upper", where),
            effort=_attr_float(lim, "effort", where),
            velocity=_attr_float(lim, "velocity", where),
        )
    except InputError as exc:
        raise InputError(exc.message, file=source) from None


def parse_tree(xml: str, source: str = "<urdf>") -> KinematicTree:
    """Parse URDF text into a KinematicTree; exactly one root and no cycles, or InputError."""
    parser = etree.XMLParser(resolve_entities=False, no_network=True, huge_tree=False)
    try:
        root_el = etree.fromstring(xml.encode("utf-8"), parser)
    except etree.XMLSyntaxError as exc:
        raise InputError(f"not well-formed XML: {exc}", file=source) from None
    if root_el.tag != "robot":
        raise InputError(f"expected a <robot> URDF, found <{root_el.tag}>", file=source)
    links = tuple(el.get("name") or "" for el in root_el.findall("link"))
    joints = tuple(_joint(el, source) for el in root_el.findall("joint"))
    known = set(links)
    for j in joints:
        for role in ("parent", "child"):
            if getattr(j, role) not in known:
                raise InputError(
                    f"joint {j.name!r}: unknown {role} link {getattr(j, role)!r}", file=source
                )
    children = [j.child for j in joints]
    roots = [n for n in links if n not in children]
    if len(roots) != 1:
        raise InputError(f"expected exactly one root link, found {roots}", file=source)
    tree = KinematicTree(root_el.get("name") or "", roots[0], links, joints)
    reached = {tree.root} | {j.child for _, j in tree.walk()}
    if len(reached) != len(known) or len(set(children)) != len(children):
        raise InputError("links are not one tree (a link has two parents, or a cycle)", file=source)
    return tree


def _num(x: float) -> str:
    """Shortest readable form, like C++ ostream's default (6 significant digits)."""
    return f"{x:.6g}"


def _vec(v: tuple[float, ...]) -> str:
    return " ".join(_num(x) for x in v)


def joint_summary(j: JointInfo) -> str:
    """Type, axis and limits of a joint in one line with units."""
    parts = [j.type]
    if j.type != "fixed":
        parts.append(f"axis ({_vec(j.axis)})")
    unit = "m" if j.type == "prismatic" else "rad"
    if j.lower is not None and j.upper is not None and j.type != "continuous":
        parts.append(f"[{_num(j.lower)}, {_num(j.upper)}] {unit}")
    if j.effort is not None:
        parts.append(f"effort {_num(j.effort)} {'N' if unit == 'm' else 'N·m'}")
    if j.velocity is not None:
        parts.append(f"velocity {_num(j.velocity)} {unit}/s")
    return ", ".join(parts)


def to_rich(tree: KinematicTree) -> Any:
    """A rich.tree.Tree: links in bold, each reached through its joint and its summary."""
    from rich.markup import escape
    from rich.tree import Tree

    top = Tree(f"[bold]{escape(tree.root)}[/bold]  [dim](robot {escape(tree.robot)})[/dim]")
    nodes = {tree.root: top}
    for _, j in tree.walk():
        style = "cyan" if j.type in MOVABLE else "dim"
        label = (
            f"[bold]{escape(j.child)}[/bold]  [{style}]← {escape(j.name)}: "
            f"{escape(joint_summary(j))}[/{style}]"
        )
        nodes[j.child] = nodes[j.parent].add(label)
    return top


def _q(text: str) -> str:
    """A DOT double-quoted string (text may hold DOT's own `\\n` line breaks)."""
    return '"' + text.replace('"', '\\"') + '"'


def to_dot(tree: KinematicTree) -> str:
    """Graphviz text in urdf_to_graphviz's layout, joint nodes labelled with type and limits."""
    out = ["digraph G {", "node [shape=box];"]
    out += [f"{_q(n)} [label={_q(n)}];" for n in [tree.root, *(j.child for _, j in tree.walk())]]
    out.append("node [shape=ellipse, color=blue, fontcolor=blue];")
    for _, j in tree.walk():
        label = _q(f"{j.name}\\n{joint_summary(j)}")
        out.append(f"{_q(j.name)} [label={label}];")
    for _, j in tree.walk():
        label = _q(f"xyz: {_vec(j.xyz)} \\nrpy: {_vec(j.rpy)}")
        out.append(f"{_q(j.parent)} -> {_q(j.name)} [label={label}]")
        out.append(f"{_q(j.name)} -> {_q(j.child)}")
    out.append("}")
    return "\n".join(out) + "\n"
