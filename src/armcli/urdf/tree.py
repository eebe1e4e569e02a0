"""The kinematic tree of a URDF: links, joints with types and limits, as text or Graphviz.

`armcli tree` is the stand-in for `check_urdf` and `urdf_to_graphviz`, which
most armcli users do not have; the DOT output follows urdf_to_graphviz's
layout (links as boxes, joints as blue ellipses, origins on the edges, children
in joint-name order) so the same tooling can read it.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from armcli.errors import InputError
from armcli.io.terminal import wrap_parts
from armcli.spec.graph import root_links
from armcli.spec.joint_types import JOINT_TYPES, MOVABLE_TYPES, position_bounds
from armcli.urdf.doc import Joint, Urdf
from armcli.urdf.read import parse_urdf


@dataclass(frozen=True)
class KinematicTree:
    """Links and joints of one robot, with its single root link."""

    robot: str
    root: str
    links: tuple[str, ...]
    joints: tuple[Joint, ...]  # validated: known type, parent and child links of this tree

    def children(self, link: str) -> list[Joint]:
        """Joints whose parent is `link`, in name order (as urdfdom stores them)."""
        return sorted((j for j in self.joints if j.parent == link), key=lambda j: j.name)

    def walk(self) -> Iterator[tuple[int, Joint]]:
        """Depth-first (depth, joint) pairs from the root."""
        stack = [(1, j) for j in reversed(self.children(self.root))]
        while stack:
            depth, j = stack.pop()
            yield depth, j
            stack.extend((depth + 1, c) for c in reversed(self.children(str(j.child))))

    def movable(self) -> list[Joint]:
        """Joints that move, in depth-first order."""
        return [j for _, j in self.walk() if j.type in MOVABLE_TYPES]


def _valid(j: Joint, source: str) -> Joint:
    """The joint itself, once its type is known and it names both links."""
    if j.type not in JOINT_TYPES:
        raise InputError(
            f"joint {j.name!r}: unknown type {j.type!r}; known: {', '.join(JOINT_TYPES)}",
            file=source,
            line=j.line,
        )
    if not j.parent or not j.child:
        raise InputError(
            f"joint {j.name!r}: needs <parent link=...> and <child link=...>",
            file=source,
            line=j.line,
        )
    return j


def tree_from_urdf(urdf: Urdf) -> KinematicTree:
    """The tree of a parsed URDF: exactly one root, no cycles, sound numbers, or InputError."""
    source = urdf.source
    if urdf.problems:
        p = urdf.problems[0]
        raise InputError(f"{p.where}: {p.kind} number {p.text!r}", file=source, line=p.line)
    links = tuple(lk.name for lk in urdf.links)
    joints = tuple(_valid(j, source) for j in urdf.joints)
    known = set(links)
    for j in joints:
        for role in ("parent", "child"):
            if getattr(j, role) not in known:
                raise InputError(
                    f"joint {j.name!r}: unknown {role} link {getattr(j, role)!r}",
                    file=source,
                    line=j.line,
                )
    children = [str(j.child) for j in joints]
    roots = root_links(links, children)
    if not links:
        raise InputError("no <link> elements: not a robot description", file=source)
    if len(roots) != 1:
        found = ", ".join(roots) if roots else "none: the joints form a cycle"
        raise InputError(f"expected exactly one root link, found {found}", file=source)
    tree = KinematicTree(urdf.name, roots[0], links, joints)
    reached = {tree.root} | {str(j.child) for _, j in tree.walk()}
    if len(reached) != len(known) or len(set(children)) != len(children):
        raise InputError("links are not one tree (a link has two parents, or a cycle)", file=source)
    return tree


def parse_tree(xml: str | bytes, source: str = "<urdf>") -> KinematicTree:
    """Parse URDF text safely (see armcli.urdf.read) into its KinematicTree."""
    data = xml.encode("utf-8") if isinstance(xml, str) else xml
    return tree_from_urdf(parse_urdf(data, source))


def _num(x: float) -> str:
    """Shortest readable form, like C++ ostream's default (6 significant digits)."""
    return f"{x:.6g}"


def _vec(v: tuple[float, ...]) -> str:
    return " ".join(_num(x) for x in v)


def joint_parts(j: Joint) -> list[str]:
    """Type, axis and limits of a joint with units, one part each (URDF's default axis is x)."""
    parts = [j.type]
    if j.type != "fixed":
        parts.append(f"axis ({_vec(j.axis or (1.0, 0.0, 0.0))})")
    unit = "m" if j.type == "prismatic" else "rad"
    lim = j.limit
    if lim is None:
        return parts
    bounds = position_bounds(j.type, lim)
    if bounds is not None:
        parts.append(f"[{_num(bounds[0])}, {_num(bounds[1])}] {unit}")
    if lim.effort is not None:
        parts.append(f"effort {_num(lim.effort)} {'N' if unit == 'm' else 'N·m'}")
    if lim.velocity is not None:
        parts.append(f"velocity {_num(lim.velocity)} {unit}/s")
    return parts


def joint_summary(j: Joint) -> str:
    """The joint's parts in one line, as the DOT labels and the text tree show them."""
    return ", ".join(joint_parts(j))


@dataclass(frozen=True)
class TreeView:
    """The tree as text: each link under its parent, with its joint's type and limits.

    At a terminal a long line breaks between the joint's parts (never inside
    `[0, 1.5708] rad`); into a file or pipe each link stays on one line.
    """

    tree: KinematicTree

    def __rich_console__(self, console: Any, options: Any) -> Any:
        from rich.text import Text

        t = self.tree
        yield Text.assemble((t.root, "bold"), ("  ", ""), (f"(robot {t.robot})", "dim"))
        width = options.max_width
        yield from self._below(t.root, "", width)

    def _below(self, link: str, prefix: str, width: int) -> Any:
        from rich.text import Text

        kids = self.tree.children(link)
        for i, j in enumerate(kids):
            last = i == len(kids) - 1
            style = "cyan" if j.type in MOVABLE_TYPES else "dim"
            head = Text.assemble((str(j.child), "bold"), ("  ", ""), (f"← {j.name}:", style))
            parts = [head, *(Text(p, style=style) for p in joint_parts(j))]
            seps = [" ", *([", "] * (len(parts) - 2))]
            inner = prefix + ("    " if last else "│   ")
            first = prefix + ("└── " if last else "├── ")
            yield from wrap_parts(parts, width, first, inner + "  ", seps)
            yield from self._below(str(j.child), inner, width)


def to_rich(tree: KinematicTree) -> TreeView:
    """A rich renderable of the tree (see TreeView)."""
    return TreeView(tree)


def _q(text: str) -> str:
    r"""A DOT double-quoted string (text may hold DOT's own `\n` line breaks)."""
    return '"' + text.replace('"', '\\"') + '"'


def to_dot(tree: KinematicTree) -> str:
    """Graphviz text in urdf_to_graphviz's layout, joint nodes labelled with type and limits."""
    out = ["digraph G {", "node [shape=box];"]
    out += [
        f"{_q(n)} [label={_q(n)}];" for n in [tree.root, *(str(j.child) for _, j in tree.walk())]
    ]
    out.append("node [shape=ellipse, color=blue, fontcolor=blue];")
    for _, j in tree.walk():
        label = _q(f"{j.name}\\n{joint_summary(j)}")
        out.append(f"{_q(j.name)} [label={label}];")
    for _, j in tree.walk():
        label = _q(f"xyz: {_vec(j.origin.xyz)} \\nrpy: {_vec(j.origin.rpy)}")
        out.append(f"{_q(str(j.parent))} -> {_q(j.name)} [label={label}]")
        out.append(f"{_q(j.name)} -> {_q(str(j.child))}")
    out.append("}")
    return "\n".join(out) + "\n"
