"""The kinematic tree of a URDF: links, joints with types and limits, as text or Graphviz.

One tree type for every reader of a URDF's structure: `KinematicTree.of` builds it from
any parsed document, however malformed (several roots, cycles, a link with two parents,
joints naming missing links), and records what is wrong; `check` reports that as
findings (check/structure.py), `tree_from_urdf` accepts only one sound tree (what `tree`,
`view` and `render` draw).

`armcli tree` is the stand-in for `check_urdf` and `urdf_to_graphviz`, which
most armcli users do not have; the DOT output follows urdf_to_graphviz's
layout (links as boxes, joints as blue ellipses, origins on the edges, children
in joint-name order) so the same tooling can read it.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass, replace
from typing import Any

from armcli.errors import InputError
from armcli.io.terminal import wrap_parts
from armcli.spec.graph import root_links
from armcli.spec.joint_types import JOINT_TYPES, MOVABLE_TYPES, position_bounds
from armcli.urdf.doc import Joint, Urdf
from armcli.urdf.read import parse_urdf


@dataclass(frozen=True)
class KinematicTree:
    """The links and joints of one robot, as far as they form a tree.

    Each link hangs from the first joint naming it as child (`parent_joint`); a later
    one is in `extra_parents`, a joint naming a missing link is no edge. `roots` are the
    links no joint holds (a tree has exactly one); with one root, `orphans` are the
    links it does not reach (a cycle) apart from those below a joint whose parent link
    is missing, and `moving` the links below at least one joint that is not fixed.
    Walking follows `parent_joint` only, so it ends on any input.
    """

    robot: str
    links: tuple[str, ...]  # unique names, in document order
    joints: tuple[Joint, ...]  # every joint of the document
    parent_joint: Mapping[str, Joint]  # child link -> the joint above it
    roots: tuple[str, ...]  # links no joint holds, in document order
    extra_parents: tuple[Joint, ...] = ()  # joints naming a child that already has a parent
    orphans: tuple[str, ...] = ()  # sorted; found only when there is one root
    moving: frozenset[str] = frozenset()  # empty unless there is one root

    @classmethod
    def of(cls, urdf: Urdf) -> KinematicTree:
        """The tree of a parsed URDF, whatever its shape; never raises."""
        links = tuple(dict.fromkeys(lk.name for lk in urdf.links))
        known = set(links)
        parent_joint: dict[str, Joint] = {}
        extra: list[Joint] = []
        for j in urdf.joints:
            if j.child is None or j.child not in known:
                continue
            if j.child in parent_joint:
                extra.append(j)
            else:
                parent_joint[j.child] = j
        roots = tuple(root_links(links, parent_joint))
        tree = cls(urdf.name, links, urdf.joints, parent_joint, roots, tuple(extra))
        if len(roots) != 1:
            return tree
        moving, reached = tree._reach([roots[0]])
        # links below a joint whose parent link is missing are that joint's problem
        _, below = tree._reach(c for c, j in parent_joint.items() if j.parent not in known)
        orphans = tuple(sorted(known - reached - below))
        return replace(tree, orphans=orphans, moving=frozenset(moving))

    def _reach(self, starts: Iterable[str]) -> tuple[set[str], set[str]]:
        """(links below a joint that is not fixed, links reached) from `starts`."""
        moving: set[str] = set()
        reached: set[str] = set()
        for start in starts:
            reached.add(start)
            frontier = [(start, False)]
            while frontier:
                link, below_moving = frontier.pop()
                for j in self.children(link):
                    if j.child in reached:
                        continue
                    reached.add(str(j.child))
                    if below_moving or j.type != "fixed":
                        moving.add(str(j.child))
                    frontier.append((str(j.child), below_moving or j.type != "fixed"))
        return moving, reached

    @property
    def root(self) -> str | None:
        """The root link; with several (a malformed tree) the first by name, with none None."""
        return min(self.roots) if self.roots else None

    def is_moving(self, link: str) -> bool:
        """Whether `link` is below at least one joint that is not fixed."""
        return link in self.moving

    def children(self, link: str) -> list[Joint]:
        """The joints holding a link below `link`, in name order (as urdfdom stores them)."""
        return sorted(
            (j for j in self.parent_joint.values() if j.parent == link), key=lambda j: j.name
        )

    def walk(self) -> Iterator[tuple[int, Joint]]:
        """Depth-first (depth, joint) pairs from the root (none without one)."""
        if self.root is None:
            return
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
    for j in urdf.joints:
        _valid(j, source)
    tree = KinematicTree.of(urdf)
    known = set(tree.links)
    for j in urdf.joints:
        for role in ("parent", "child"):
            if getattr(j, role) not in known:
                raise InputError(
                    f"joint {j.name!r}: unknown {role} link {getattr(j, role)!r}",
                    file=source,
                    line=j.line,
                )
    if not tree.links:
        raise InputError("no <link> elements: not a robot description", file=source)
    if len(tree.roots) != 1:
        found = ", ".join(tree.roots) if tree.roots else "none: the joints form a cycle"
        raise InputError(f"expected exactly one root link, found {found}", file=source)
    if tree.extra_parents or tree.orphans:
        raise InputError("links are not one tree (a link has two parents, or a cycle)", file=source)
    twice = [n for n, k in Counter(lk.name for lk in urdf.links).items() if k > 1]
    if twice:
        raise InputError(f"link {twice[0]!r} is defined more than once", file=source)
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
        root = t.root or ""  # tree_from_urdf's trees have one
        yield Text.assemble((root, "bold"), ("  ", ""), (f"(robot {t.robot})", "dim"))
        width = options.max_width
        yield from self._below(root, "", width)

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
        f"{_q(n)} [label={_q(n)}];"
        for n in [tree.root or "", *(str(j.child) for _, j in tree.walk())]
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
